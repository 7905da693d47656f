"""Chunk length and bin step of the time-varying decay against a day-by-day reference.

Prints the lifetime error of ``orbit_env.decay.chunked.propagate`` for several chunk
lengths and bin steps against ``integrate_reference`` (averaged equations in time,
a fresh NRLMSIS profile every day). Needs pymsis; takes a few minutes.
"""

import sys
import time

import numpy as np

from orbit_env.decay.chunked import SolarDecayModel, cached_curves, integrate_reference, propagate
from orbit_env.decay.solar import CycleActivity, TableActivity, unix_days


def synthetic_table(start_days: float, years: float, seed: int = 7) -> TableActivity:
    """Rising solar cycle with a 27-day rotation and random geomagnetic storms (daily rows)."""
    rng = np.random.default_rng(seed)
    days = start_days + np.arange(int(years * 365.25) + 100)
    cycle = CycleActivity()
    _, f107a, _ = cycle.indices(days)
    f107 = f107a * (1.0 + 0.2 * np.sin(2 * np.pi * (days - days[0]) / 27.0))
    ap = np.clip(rng.lognormal(np.log(8.0), 0.8, days.size), 0.0, 300.0)
    return TableActivity(days, f107, f107a, ap, source="synthetic")


def main() -> None:
    start = unix_days("2021-06-01")
    cases = [
        ("cycle, circular 450 km", CycleActivity(), 450e3, 450e3, 2.2 * 1.0 / 100.0),
        ("cycle, 300 x 1000 km", CycleActivity(), 300e3, 1000e3, 2.2 * 1.0 / 40.0),
        ("daily table, circular 420 km", synthetic_table(start, 6.0), 420e3, 420e3, 2.2 * 1.0 / 100.0),
    ]
    only = sys.argv[1:]
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
            model = SolarDecayModel(activity, start, 51.6, chunk_days=chunk, bin_step=step)
            cached_curves.cache_clear()
            t = time.perf_counter()
            result = propagate(hp, ha, c, model)
            elapsed = time.perf_counter() - t
            days = float(result.days[0])
            print(f"{chunk:8g} {step:8g} {days:9.2f} {days / reference - 1:+8.3%} {result.bins_used:5d} {elapsed:7.2f}")


if __name__ == "__main__":
    main()
