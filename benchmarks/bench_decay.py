"""Speed of the decay simulator, as ratios measured in one run (machines are shared and noisy).

Run: python benchmarks/bench_decay.py
"""

from __future__ import annotations

import contextlib
import csv
import io
import tempfile
import time
from pathlib import Path

import numpy as np

from orbit_env.cli import main as cli_main
from orbit_env.decay.averaged import DecayModel, integrate_averaged
from orbit_env.decay.curves import UniversalCurves, universal_curves
from orbit_env.paper.table2 import load_table2


def best_of(repeats: int, function) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    table = load_table2()
    hp, ha = table.perigee_km * 1e3, table.apogee_km * 1e3

    # 1. All 351 cells of Table II from scratch: build the curves (no cache) and look up.
    def from_scratch() -> None:
        UniversalCurves(DecayModel()).locate(hp, ha)

    scratch_s = best_of(3, from_scratch)
    sample = np.arange(0, hp.size, 10)  # the reference: the averaged ODE, cell by cell
    ode_s = best_of(1, lambda: [integrate_averaged(hp[k], ha[k]) for k in sample]) * hp.size / sample.size
    print(f"Table II, 351 cells from scratch (curves built): {scratch_s:.3f} s")
    print(f"  averaged ODE per cell (DOP853, 35 cells scaled): {ode_s:.2f} s  -> ratio {ode_s / scratch_s:.0f}x")

    # 2. 10^6 random orbits through the cached curves, against one ODE solution.
    curves = universal_curves()
    rng = np.random.default_rng(0)
    n = 1_000_000
    perigee = rng.uniform(150e3, 1000e3, n)
    apogee = perigee + rng.uniform(0.0, 1.0, n) * (4000e3 - perigee)
    lookup_s = best_of(3, lambda: curves.locate(perigee, apogee).nu)
    one_ode_s = best_of(3, lambda: integrate_averaged(360e3, 800e3))
    print(f"10^6 lifetimes through the curves (one core): {lookup_s:.3f} s")
    speedup = one_ode_s * n / lookup_s
    print(f"  one averaged ODE lifetime: {one_ode_s * 1e3:.1f} ms -> curves are {speedup:.0f}x faster per orbit")

    # 3. Advance 10^6 satellites by 1000 revolutions of the paper's sphere.
    point = curves.locate(perigee, apogee)
    advance_s = best_of(3, lambda: curves.advance(point, 1000 * 9.81 * 2 * np.pi * 0.0625 / 10))
    print(f"10^6 satellites advanced by a block of revolutions: {advance_s:.3f} s ({advance_s / lookup_s:.2f}x lookup)")

    # 4. A catalogue of 10^5 rows through the CLI's batch path (read CSV, look up, write CSV),
    #    against the bare lookup of the same orbits and against a per-row loop through the ODE.
    catalogue_benchmark(curves)

    # 5. Averaged against direct on the same orbit (see orbit_env.decay.direct).
    try:
        from orbit_env.decay.direct import integrate_direct
    except ImportError:
        return
    c = 2.0 * np.pi * 0.25**2 / 10.0
    direct_s = best_of(1, lambda: integrate_direct(200e3, 1000e3, c))
    averaged_s = best_of(3, lambda: integrate_averaged(200e3, 1000e3))
    curve_s = best_of(3, lambda: curves.locate(200e3, 1000e3))
    print(
        f"200 x 1000 km (291 revolutions of the sphere): direct {direct_s:.2f} s, "
        f"averaged ODE {averaged_s * 1e3:.1f} ms, "
        f"curves {curve_s * 1e6:.0f} us"
    )
    print(f"  direct / averaged ODE = {direct_s / averaged_s:.0f}x, direct / curves = {direct_s / curve_s:.0f}x")


def catalogue_benchmark(curves: UniversalCurves, n: int = 100_000) -> None:
    """``orbit-env lifetime --batch`` on n rows: its overhead over the lookup and its speedup over a loop."""
    rng = np.random.default_rng(0)
    hp_km = rng.uniform(200.0, 900.0, n)
    ha_km = hp_km + rng.exponential(200.0, n)
    area_m2 = rng.uniform(0.5, 2.0, n)
    with tempfile.TemporaryDirectory() as folder:
        sats, out = Path(folder) / "sats.csv", Path(folder) / "out.csv"
        with open(sats, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["name", "perigee_km", "apogee_km", "mass_kg", "area_m2", "cx"])
            writer.writerows(
                [f"sat{i}", f"{hp_km[i]:.3f}", f"{ha_km[i]:.3f}", "100", f"{area_m2[i]:.3f}", "2.2"] for i in range(n)
            )
        # --force: the repeats replace the results file (without it they stop at once, timing nothing).
        argv = ["lifetime", "--batch", str(sats), "--out", str(out), "--no-progress", "--force"]

        def batch() -> None:
            if cli_main(argv) != 0:
                raise RuntimeError(f"orbit-env {' '.join(argv)} failed")

        with contextlib.redirect_stdout(io.StringIO()):
            batch_s = best_of(3, batch)
    lookup_s = best_of(3, lambda: curves.locate(hp_km * 1e3, ha_km * 1e3).nu)
    sample = np.arange(0, n, n // 20)
    loop_s = best_of(1, lambda: [integrate_averaged(hp_km[k] * 1e3, ha_km[k] * 1e3) for k in sample]) * n / sample.size
    print(
        f"{n} catalogue rows through 'orbit-env lifetime --batch': {batch_s:.2f} s "
        f"({batch_s / lookup_s:.0f}x the bare lookup: CSV in and out)"
    )
    print(
        f"  a per-row loop through the averaged ODE (20 rows scaled): {loop_s:.0f} s -> ratio {loop_s / batch_s:.0f}x"
    )


if __name__ == "__main__":
    main()
