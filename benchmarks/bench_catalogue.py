"""An NRLMSIS catalogue spread over inclinations against one at a single inclination: cost and accuracy, one run.

Run: python benchmarks/bench_catalogue.py [--rows N] [--repeats R] [--no-exact] [--rotating] [--rule YEARS]
[--epoch DATE] (needs pymsis; the exact reference builds a curve family per 1-degree group, about 90 s a kind,
and with --epoch runs the time-stepped path once per group: give --no-exact there).

Two kinds of catalogue, 10^4 rows each (perigee 200-1000 km, ballistic loads 20-200
kg/m^2): near-circular orbits (apogee up to 100 km above perigee, ``SPREAD_MAX_SPAN_M``:
a density ratio along each decay) and wide ones (apogee 100-1500 km above perigee: the
ratio of the rates at which the life left falls). Each twice: every row at 51.6 deg,
and whole-degree inclinations uniform over 0-98 deg (whole degrees, so that the
1-degree groups below see the rows' own inclinations). Each is timed cold (no disk
cache, in-process caches cleared: the NRLMSIS profile and the curve family are built
as in a first run), from the CSV file to the results file, median of the repeats,
interleaved. Then the spread catalogue's lifetimes by the one-family path against a
family per 1-degree group (``exact_groups=True``). With ``--rule YEARS`` every run also
checks the disposal rule (the lowered perigee's search, as ``orbit-env lifetime --batch
--rule``), and the comparison adds the verdicts and the lowered perigees. With ``--epoch
DATE`` the catalogues decay from that date under the shipped solar record (the
time-stepped path, up to its 200-year cap): the spread catalogue on one family with
each row's inclination as a density multiplier (`orbit_env.decay.chunked.propagate`).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from orbit_env import cache
from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.catalogue import batch_lifetimes
from orbit_env.analysis.catalogue_io import read_batch, write_records
from orbit_env.analysis.scenario import Scenario
from orbit_env.decay import chunked
from orbit_env.decay.chunked import cached_curves
from orbit_env.decay.density_multiplier import log_density_slope_per_m
from orbit_env.decay.solar import ConstantActivity, unix_days
from orbit_env.decay.solar_record import load_record
from orbit_env.physics.atmosphere.msis import _cached_log_density_table

C_X = 2.2


#: Kinds of catalogue: name, and the range of apogee - perigee [km].
KINDS = (("near-circular", (0.0, 100.0)), ("wide", (100.0, 1500.0)))


def write_catalogue(
    path: Path, rows: int, inclination_deg: np.ndarray | float, span_km: tuple[float, float], seed: int = 3
) -> None:
    rng = np.random.default_rng(seed)
    perigee = rng.uniform(200.0, 1000.0, rows)
    apogee = perigee + rng.uniform(*span_km, rows)
    load = rng.uniform(20.0, 200.0, rows)
    inclination = np.broadcast_to(inclination_deg, (rows,))
    lines = ["perigee_km,apogee_km,mass_per_area_kg_m2,inclination_deg"]
    lines += [f"{p:.3f},{a:.3f},{m:.3f},{i:.3f}" for p, a, m, i in zip(perigee, apogee, load, inclination, strict=True)]
    path.write_text("\n".join(lines) + "\n")


def run(
    path: Path, out: Path, scenario: Scenario, *, exact_groups: bool = False, rule_years: float | None = None
) -> tuple[float, list[dict], int]:
    _cached_log_density_table.cache_clear()
    cached_curves.cache_clear()
    log_density_slope_per_m.cache_clear()
    for table in (
        chunked._log_ratio,
        chunked._log_ratios_by_day,
        chunked._log_bin_density,
        chunked._anchor_log_density,
    ):
        table.cache_clear()
    start = time.perf_counter()
    rows, hp, ha, c, inc, status = read_batch(path, C_X, C_X / 100.0, 51.6)
    records, summary = batch_lifetimes(
        rows, hp, ha, c, inc, status, scenario, progress=False, exact_groups=exact_groups, rule_years=rule_years
    )
    write_records(out, records)
    return time.perf_counter() - start, records, summary.groups


def column(records: list[dict], key: str) -> np.ndarray:
    """A numeric column of the results (NaN where empty)."""
    return np.array([float(r[key]) if r[key] else np.nan for r in records])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-exact", action="store_true", help="skip the 1-degree reference (90 s)")
    parser.add_argument("--rotating", action="store_true", help="co-rotating air")
    parser.add_argument("--rule", type=float, default=None, metavar="YEARS", help="also check this disposal rule")
    parser.add_argument("--epoch", default=None, metavar="DATE", help="decay from this date under the solar record")
    args = parser.parse_args()
    rule = {"rule_years": args.rule}
    cache.disable()
    if args.epoch:
        activity, sun = load_record(), f"the solar record from {args.epoch}"
        scenario = Scenario(MsisAir(activity, unix_days(args.epoch)), rotating_atmosphere=args.rotating)
    else:
        sun = "NRLMSIS F10.7 150, Ap 15"
        scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)), rotating_atmosphere=args.rotating)
    air = "co-rotating" if args.rotating else "still"
    checked = f", the {args.rule:g}-year rule checked" if args.rule else ""
    print(f"{args.rows} rows a catalogue, {sun}, {air} air{checked}, cold, median of {args.repeats}")
    with tempfile.TemporaryDirectory() as folder:
        for kind, span_km in KINDS:
            one, spread, out = Path(folder, "one.csv"), Path(folder, "spread.csv"), Path(folder, "out.csv")
            write_catalogue(one, args.rows, 51.6, span_km)
            inclinations = np.random.default_rng(11).integers(0, 99, args.rows).astype(float)
            write_catalogue(spread, args.rows, inclinations, span_km)
            times_one, times_spread = [], []
            for _ in range(args.repeats):  # interleaved: the machine's load moves both alike
                t, _, groups_one = run(one, out, scenario, **rule)
                times_one.append(t)
                t, records, groups_spread = run(spread, out, scenario, **rule)
                times_spread.append(t)
            t_one, t_spread = statistics.median(times_one), statistics.median(times_spread)
            print(f"{kind} orbits (apogee {span_km[0]:g}-{span_km[1]:g} km above perigee)")
            print(f"  one inclination (51.6 deg)       {t_one:7.2f} s   {groups_one} curve family")
            print(f"  spread over 0-98 deg             {t_spread:7.2f} s   {groups_spread} curve family")
            print(f"  ratio spread / one inclination   {t_spread / t_one:7.2f}")
            if not args.no_exact:
                t_exact, exact_records, groups = run(spread, out, scenario, exact_groups=True, **rule)
                days, exact = column(records, "days"), column(exact_records, "days")
                error = days / exact - 1.0
                finite = np.isfinite(error)
                abs_error = np.abs(error[finite])
                print(f"  a family per 1-degree group      {t_exact:7.2f} s   {groups} curve families")
                print(
                    f"  one family vs 1-degree groups ({finite.sum()} rows): median |error| "
                    f"{np.median(abs_error):.3%}, 99th percentile {np.percentile(abs_error, 99):.3%}, "
                    f"max {abs_error.max():.3%} (mean {np.mean(error[finite]):+.3%})"
                )
                if args.rule:
                    verdict = np.array([r["complies"] for r in records])
                    verdict_exact = np.array([r["complies"] for r in exact_records])
                    lowered = column(records, "new_perigee_km") - column(exact_records, "new_perigee_km")
                    print(
                        f"  verdicts that differ: {np.count_nonzero(verdict != verdict_exact)} of {verdict.size}; "
                        f"lowered perigees: max |difference| {np.nanmax(np.abs(lowered)):.3f} km"
                    )


if __name__ == "__main__":
    main()
