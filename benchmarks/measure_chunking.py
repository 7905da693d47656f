"""Chunk length and bin step of the time-varying decay against a day-by-day reference.

``python benchmarks/measure_chunking.py [WORD ...]`` prints the lifetime error of
``orbit_env.decay.chunked.propagate`` for several chunk lengths and bin steps against
``integrate_reference`` (averaged equations in time, a fresh NRLMSIS profile every
day), for the cases whose name contains a WORD (all by default; a few minutes).

``python benchmarks/measure_chunking.py short`` prints instead the short lives (10-40
days) under the shipped record, in seven storms and five quiet spells, on circular
orbits and orbits 20 km and 120 km wide: 108 cases, about six minutes. Needs pymsis.

``python benchmarks/measure_chunking.py near-circular`` prints the near-circular orbits'
coarser bins (`orbit_env.decay.chunked.NEAR_CIRCULAR_BIN_STEP`) against the fine bins,
3U cubesats under the shipped record from seven dates over two solar cycles, circular and
20 km wide, lives of 2 months to 19 years (co-rotating air, 51.6 deg): 35 cases.

``python benchmarks/measure_chunking.py placement`` prints lives at 20-, 5- and 1-day chunks against the
daily reference under the shipped record from 2019-01-10 (a quiet Sun whose daily Ap crosses the bins' edges
often, so that orbits are placed again on a new bin's curves many times): a 3U cubesat at 51.6 deg on a
circular, a 50 km wide and a 500 km wide orbit; about 4 minutes.

``python benchmarks/measure_chunking.py long`` prints one long life against the daily reference: GRACE's orbit
as `benchmarks/validate_reentries.py` flies it (483 x 508 km above the equatorial radius, 89 deg, from
2002-03-17 09:21, c_x A/m = 3.41 x 1.0 m^2 / 487 kg, co-rotating air), about 17 years; about 7 minutes.
"""

import sys
import time

import numpy as np

from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.chunked import SolarDecayModel, cached_curves, propagate
from orbit_env.decay.reference_path import integrate_reference
from orbit_env.decay.solar import CycleActivity, TableActivity, unix_days

#: Starts a week or so before a storm (its day in the comment), and quiet spells.
SHORT_LIFE_STARTS = [
    ("1989-03-05", "storm"),  # 1989-03-13
    ("2000-07-08", "storm"),  # 2000-07-15, the Bastille Day event
    ("2001-10-28", "storm"),  # 2001-11-06
    ("2003-10-20", "storm"),  # 2003-10-29 to 31, the Halloween storms
    ("2004-10-30", "storm"),  # 2004-11-08
    ("2015-03-08", "storm"),  # 2015-03-17, St Patrick's Day
    ("2024-05-01", "storm"),  # 2024-05-10
    ("2009-01-01", "quiet"),
    ("2019-06-01", "quiet"),
    ("2015-05-01", "quiet"),
    ("1996-06-01", "quiet"),
    ("2008-07-01", "quiet"),
]
#: Perigee and apogee offsets [m] from the circular height found for each life.
SHORT_LIFE_SHAPES = [(0.0, 0.0), (0.0, 20e3), (-20e3, 100e3)]
#: Lives aimed at [days].
SHORT_LIFE_TARGETS = (12.0, 25.0, 38.0)
C_CUBESAT_M2_KG = 0.0165  # a 3U cubesat: c_x 2.2, 0.03 m^2, 4 kg


def synthetic_table(start_days: float, years: float, seed: int = 7) -> TableActivity:
    """Rising solar cycle with a 27-day rotation and random geomagnetic storms (daily rows)."""
    rng = np.random.default_rng(seed)
    days = start_days + np.arange(int(years * DAYS_PER_YEAR) + 100)
    cycle = CycleActivity()
    _, f107a, _ = cycle.indices(days)
    f107 = f107a * (1.0 + 0.2 * np.sin(2 * np.pi * (days - days[0]) / 27.0))
    ap = np.clip(rng.lognormal(np.log(8.0), 0.8, days.size), 0.0, 300.0)
    return TableActivity(days, f107, f107a, ap, source="synthetic")


def short_lives() -> None:
    """The chunked decay of 10-40 day lives under the shipped record against the daily reference."""
    from orbit_env.decay.solar_record import load_record

    record = load_record()
    errors = []
    print(f"{'start':10} {'kind':5} {'orbit km':>13} {'reference d':>11} {'chunked d':>9} {'error':>8}")
    for date, kind in SHORT_LIFE_STARTS:
        for dp, da in SHORT_LIFE_SHAPES:
            model = SolarDecayModel(record, unix_days(date), 51.6, follow_season=True, rotating_atmosphere=True)
            # Heights for the target lives, from the chunked decay itself (one vectorized run).
            heights = np.arange(180e3, 400e3, 5e3)
            lives = propagate(heights + dp, heights + da, C_CUBESAT_M2_KG, model).days
            for target in SHORT_LIFE_TARGETS:
                h = float(np.interp(target, lives, heights))
                hp, ha = round(h + dp, -3), round(h + da, -3)
                reference = integrate_reference(hp, ha, C_CUBESAT_M2_KG, model)
                if not 10.0 <= reference <= 40.0:
                    continue
                days = float(propagate(hp, ha, C_CUBESAT_M2_KG, model).days[0])
                errors.append((reference, ha - hp, days / reference - 1.0))
                orbit = f"{hp / 1e3:.0f} x {ha / 1e3:.0f}"
                print(f"{date:10} {kind:5} {orbit:>13} {reference:11.3f} {days:9.3f} {days / reference - 1:+8.3%}")
    table = np.array(errors)
    for name, chosen in (("10-20 days", table[:, 0] < 20.0), ("20-40 days", table[:, 0] >= 20.0)):
        worst = np.abs(table[chosen, 2])
        print(
            f"{name}: {chosen.sum()} cases, median |error| {np.median(worst):.2%}, max {worst.max():.2%}, "
            f"{(worst > 5e-3).sum()} above 0.5%"
        )


def near_circular() -> None:
    """Lifetimes on the near-circular bins against the fine bins (`SolarDecayModel.near_circular_bins`)."""
    from orbit_env.decay.solar_record import load_record

    record = load_record()
    dates = ["2001-01-01", "2005-06-01", "2008-01-01", "2012-01-01", "2015-01-01", "2019-01-01", "2024-01-01"]
    orbits = [(350e3, 350e3), (550e3, 550e3), (440e3, 460e3), (530e3, 550e3), (480e3, 500e3)]
    errors, bins = [], np.zeros(2, dtype=int)
    print(f"{'start':10} {'orbit km':>9} {'fine d':>9} {'bins':>4} {'near-circular d':>15} {'bins':>4} {'change':>8}")
    for date in dates:
        for hp, ha in orbits:
            runs = []
            for coarse in (False, True):
                model = SolarDecayModel(
                    record, unix_days(date), 51.6, rotating_atmosphere=True, near_circular_bins=coarse
                )
                runs.append(propagate(hp, ha, C_CUBESAT_M2_KG, model))
            fine, near = (float(r.days[0]) for r in runs)
            errors.append(near / fine - 1.0)
            bins += [r.bins_used for r in runs]
            orbit = f"{hp / 1e3:.0f}x{ha / 1e3:.0f}"
            print(
                f"{date:10} {orbit:>9} {fine:9.2f} {runs[0].bins_used:4d} {near:15.2f} {runs[1].bins_used:4d} "
                f"{near / fine - 1:+8.3%}"
            )
    worst = np.abs(errors)
    print(
        f"{len(errors)} cases: median |change| {np.median(worst):.3%}, max {worst.max():.3%}; "
        f"bins visited {bins[0]} fine, {bins[1]} near-circular"
    )


def placement() -> None:
    """Lives at shorter chunks (more placements on a new bin's curves) against the daily reference."""
    from orbit_env.decay.solar_record import load_record

    record = load_record()
    start = unix_days("2019-01-10")
    for hp, ha in ((450e3, 450e3), (450e3, 500e3), (300e3, 800e3)):
        reference = integrate_reference(hp, ha, C_CUBESAT_M2_KG, SolarDecayModel(record, start, 51.6))
        lives = []
        for chunk in (20.0, 5.0, 1.0):
            model = SolarDecayModel(record, start, 51.6, chunk_days=chunk)
            days = float(propagate(hp, ha, C_CUBESAT_M2_KG, model).days[0])
            lives.append(f"{chunk:g} d: {days:.2f} ({days / reference - 1:+.3%})")
        print(f"{hp / 1e3:.0f} x {ha / 1e3:.0f} km, reference {reference:.2f} days; " + ", ".join(lives), flush=True)


def long_life() -> None:
    """GRACE's 17-year life at the default chunks against the daily reference."""
    from orbit_env.decay.solar_record import load_record

    start = unix_days("2002-03-17T09:21")
    model = SolarDecayModel(load_record(), start, 89.0, rotating_atmosphere=True)
    hp, ha, c = 490.137e3, 515.137e3, 3.41 * 1.0 / 487.0  # heights onto the 6371 km sphere: +7.137 km
    days = float(propagate(hp, ha, c, model).days[0])
    t = time.perf_counter()
    reference = integrate_reference(hp, ha, c, model)
    print(
        f"GRACE: {days:.2f} days at 20-day chunks, reference {reference:.2f} ({time.perf_counter() - t:.0f} s): "
        f"{days / reference - 1:+.2%}"
    )


#: The studies of their own, by the word that runs them (the module docstring).
STUDIES = {"placement": placement, "long": long_life, "short": short_lives, "near-circular": near_circular}


def main() -> None:
    only = sys.argv[1:]
    if len(only) == 1 and only[0] in STUDIES:
        STUDIES[only[0]]()
        return
    start = unix_days("2021-06-01")
    cases = [
        ("cycle, circular 450 km", CycleActivity(), 450e3, 450e3, 2.2 * 1.0 / 100.0),
        ("cycle, 300 x 1000 km", CycleActivity(), 300e3, 1000e3, 2.2 * 1.0 / 40.0),
        ("daily table, circular 420 km", synthetic_table(start, 6.0), 420e3, 420e3, 2.2 * 1.0 / 100.0),
    ]
    for name, activity, hp, ha, c in cases:
        if only and not any(word in name for word in only):
            continue
        base = SolarDecayModel(activity, start, 51.6)
        t = time.perf_counter()
        reference = integrate_reference(hp, ha, c, base)
        t_ref = time.perf_counter() - t
        print(f"\n{name}: reference {reference:.2f} days ({t_ref:.1f} s)")
        print(f"{'chunk d':>8} {'bin step':>8} {'days':>9} {'error':>8} {'bins':>5} {'time s':>7}")
        for chunk, step in ((5, 0.1), (10, 0.1), (20, 0.1), (30, 0.1), (60, 0.1), (20, 0.05), (20, 0.2), (20, 0.4)):
            model = SolarDecayModel(activity, start, 51.6, chunk_days=chunk, bin_step=step, near_circular_bins=False)
            cached_curves.cache_clear()
            t = time.perf_counter()
            result = propagate(hp, ha, c, model)
            elapsed = time.perf_counter() - t
            days = float(result.days[0])
            print(f"{chunk:8g} {step:8g} {days:9.2f} {days / reference - 1:+8.3%} {result.bins_used:5d} {elapsed:7.2f}")


if __name__ == "__main__":
    main()
