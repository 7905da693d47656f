"""What NRLMSIS's storm-time mode (3-hourly ap history) changes on each day, against its daily-Ap mode.

``python benchmarks/measure_storm_ap.py`` takes every day of four years of the shipped record
(2003: a storm year at high activity; 2009: the deep minimum; 2015: the declining cycle 24;
2024: the maximum of cycle 25) and computes each day's orbit-averaged NRLMSIS 2.1 density
on `RATIO_GRID_M` at `RATIO_NODES` twice: in the daily-Ap mode (the row the decay took
before, UT 12 h) and in the storm-time mode through the day's eight 3-hour slots (the row a
storm day takes, `orbit_env.decay.daily_air`). The days are binned by the largest of the 27
3-hourly ap the storm-time mode reads on them (`orbit_env.decay.chunked.STORM_AP`), and the
table gives, per bin, the storm-time row over the daily one at 250 and 400 km: median and
the 5th and 95th percentiles of the change, its mean and the largest |change|. It is what chooses
`STORM_AP`: below it the two modes must agree closely enough that the daily Ap is kept.
About 30 s.

``python benchmarks/measure_storm_ap.py lives`` prints storm-time short lives (a 3U cubesat,
c_x A/m = 2.2 x 0.03 m^2 / 4 kg, circular, 51.6 deg, co-rotating air, the shipped record)
from the storm starts of ``benchmarks/measure_chunking.py short``, under the daily Ap
(``storm_ap=False``, before), the storm-time mode on storm days (the default, after) and on
every day (`STORM_AP` = 0: what the criterion leaves out). About a minute.

``python benchmarks/measure_storm_ap.py cost`` times a cold air table (an empty disk cache)
for a 1-2-year life across an active year (a 3U cubesat at 450 km from 2003-01-01, 51.6
deg), with and without the storm-time mode: the NRLMSIS time of the air table's rows and
the whole call.
"""

import os
import sys
import tempfile
import time

import numpy as np

from orbit_env.decay.chunked import STORM_AP
from orbit_env.decay.density_multiplier import RATIO_GRID_M, RATIO_NODES
from orbit_env.decay.solar import day_of_year, unix_days
from orbit_env.decay.solar_record import shipped_record
from orbit_env.physics.atmosphere.msis import ap_histories, orbit_mean_density_by_day_kg_m3

YEARS = ("2003", "2009", "2015", "2024")
INCLINATIONS_DEG = (28.5, 51.6, 97.5)
#: Bins of the largest 3-hourly ap of a day's storm-time history (lower edges).
EDGES = (0, 15, 27, 39, 48, 80, 132, 207, 300)
HEIGHTS_KM = (250.0, 400.0)


def main() -> None:
    record = shipped_record()
    days = np.concatenate([unix_days(f"{y}-01-01") + np.arange(365.0) for y in YEARS])
    f107, f107a, ap = record.indices(days)
    history = record.ap_history(days)
    assert np.all(np.isfinite(history))
    doy = day_of_year(days)
    largest = history.max(axis=1)
    columns = [int(np.flatnonzero(RATIO_GRID_M == h * 1e3)[0]) for h in HEIGHTS_KM]
    t0 = time.perf_counter()
    change = []
    for inclination in INCLINATIONS_DEG:
        daily = orbit_mean_density_by_day_kg_m3(RATIO_GRID_M, f107, f107a, ap, doy, inclination, **RATIO_NODES)
        storm = orbit_mean_density_by_day_kg_m3(
            RATIO_GRID_M,
            f107,
            f107a,
            ap,
            doy,
            inclination,
            **RATIO_NODES,
            ap_history=ap_histories(ap, history),
        )
        change.append(storm[:, columns] / daily[:, columns] - 1.0)
    print(f"{days.size} days x {len(INCLINATIONS_DEG)} inclinations in {time.perf_counter() - t0:.1f} s")
    everything = np.stack(change)  # (inclinations, days, heights)
    print("storm-time over daily-Ap row - 1 [%], by the largest 3-hourly ap of the day's history:")
    header = " | ".join(f"{h:.0f} km: 5% median mean 95% max|.|" for h in HEIGHTS_KM)
    print(f"{'largest ap':>12} {'days':>5} | {header}")
    bins = [*zip(EDGES, (*EDGES[1:], 1000), strict=True), (0, STORM_AP), (STORM_AP, 1000)]
    for row, (low, high) in enumerate(bins):
        if row == len(EDGES):
            print(f"daily-Ap days (largest ap < STORM_AP = {STORM_AP:g}), then storm days:")
        chosen = (largest >= low) & (largest < high)
        if not chosen.any():
            continue
        cells = []
        for k in range(len(HEIGHTS_KM)):
            values = 100.0 * everything[:, chosen, k].ravel()
            p5, p50, p95 = np.percentile(values, (5, 50, 95))
            cells.append(f"{p5:+5.1f} {p50:+5.1f} {values.mean():+5.1f} {p95:+5.1f} {np.abs(values).max():5.1f}")
        print(f"{low:>5g}-{high:<6g} {int(chosen.sum()):>5} | " + " | ".join(cells))


#: Storm starts of benchmarks/measure_chunking.py (a week or so before each storm).
STORM_STARTS = ("1989-03-05", "2000-07-08", "2001-10-28", "2003-10-20", "2004-10-30", "2015-03-08", "2024-05-01")
#: A 3U cubesat: c_x 2.2, 0.03 m^2, 4 kg [m^2/kg].
C_CUBESAT_M2_KG = 2.2 * 0.03 / 4.0
#: Circular heights [m] tried at each start; the lives of 7-42 days are kept.
LIFE_HEIGHTS_M = (250e3, 270e3, 290e3, 310e3)


def lives() -> None:
    from orbit_env.decay import chunked
    from orbit_env.decay.chunked import SolarDecayModel, propagate

    record = shipped_record()
    heights = np.array(LIFE_HEIGHTS_M)
    print(
        "| start | circular | daily Ap (before) | storm-time on storm days (after) | change | on every day | vs after |"
    )
    print("|---|---|---|---|---|---|---|")
    changes, left_out = [], []
    for date in STORM_STARTS:
        runs = []
        for storm_ap, threshold in ((False, STORM_AP), (True, STORM_AP), (True, 0.0)):
            chunked.STORM_AP = threshold
            model = SolarDecayModel(record, unix_days(date), 51.6, rotating_atmosphere=True, storm_ap=storm_ap)
            runs.append(propagate(heights, heights, C_CUBESAT_M2_KG, model).days)
        chunked.STORM_AP = STORM_AP
        for k, h in enumerate(heights):
            before, after, every = (float(r[k]) for r in runs)
            if not 7.0 <= before <= 42.0:
                continue
            changes.append(after / before - 1.0)
            left_out.append(every / after - 1.0)
            print(
                f"| {date} | {h / 1e3:.0f} km | {before:.2f} d | {after:.2f} d | {after / before - 1:+.1%} "
                f"| {every:.2f} d | {every / after - 1:+.2%} |"
            )
    changes, left_out = np.array(changes), np.array(left_out)
    print(
        f"\n{changes.size} lives: change median {np.median(changes):+.1%}, from {changes.min():+.1%} to "
        f"{changes.max():+.1%}; storm-time mode on every day instead: at most {np.abs(left_out).max():.2%}"
    )


def cost() -> None:
    import subprocess

    for storm_ap in (False, True):
        with tempfile.TemporaryDirectory() as folder:
            env = dict(os.environ, ORBIT_ENV_CACHE_DIR=folder)
            out = subprocess.run(
                [sys.executable, __file__, "cost-one", str(storm_ap)],
                env=env,
                check=True,
                capture_output=True,
                text=True,
            ).stdout
            print(f"storm_ap={storm_ap}: {out.strip()}")


def cost_one(storm_ap: bool) -> None:
    from orbit_env.decay import daily_air
    from orbit_env.decay.chunked import SolarDecayModel, air_table, propagate

    spent = [0.0, 0]
    inner = daily_air.orbit_mean_density_by_day_kg_m3

    def timed(*args, **kwargs):
        start = time.perf_counter()
        rho = inner(*args, **kwargs)
        spent[0] += time.perf_counter() - start
        spent[1] += 1
        return rho

    daily_air.orbit_mean_density_by_day_kg_m3 = timed
    model = SolarDecayModel(
        shipped_record(), unix_days("2003-01-01"), 51.6, rotating_atmosphere=True, storm_ap=storm_ap
    )
    start = time.perf_counter()
    days = float(propagate(450e3, 450e3, C_CUBESAT_M2_KG, model).days[0])
    total = time.perf_counter() - start
    table = air_table(51.6, None, model.version)
    storm = sum(len(key) > 4 for key in model.daily_indices(model.start_days + np.arange(len(table), dtype=float)))
    print(
        f"life {days:.1f} d; air table {len(table)} rows ({storm} storm days among as many days from the start), "
        f"NRLMSIS {spent[0]:.2f} s in {spent[1]} calls; call {total:.2f} s"
    )


if __name__ == "__main__":
    if sys.argv[1:] == ["lives"]:
        lives()
    elif sys.argv[1:] == ["cost"]:
        cost()
    elif sys.argv[1:2] == ["cost-one"]:
        cost_one(sys.argv[2] == "True")
    else:
        main()
