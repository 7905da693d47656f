"""A dated catalogue under uncertainty (issue 29 item 5): wall time and rows/s, measured on a sample, extrapolated.

``python benchmarks/bench_catalogue_uncertainty.py [--rows N] [--samples S] [--workers W ...]``
writes N LEO rows drawn like a catalogue of today's small satellites (perigee 350-600 km,
three in four near-circular with the apogee up to 20 km higher, the rest up to 300 km
higher, ballistic loads 20-200 kg/m^2, inclinations 0-98 deg; seed 0) and runs, as a
user does, ``orbit-env lifetime --batch rows.csv --out OUT --epoch 2026-12-01
--uncertainty --samples S --rule 5 --no-progress`` once per ``--workers`` value, in a disk
cache of its own that one untimed run of the same command has warmed (the bins' curves and
the air of the samples' forecasts are built once per machine: a first run at a new epoch
took three times as long), then the same with ``--address local`` (a local Ray) if Ray is
installed. It prints the wall time, rows/s, and the time a catalogue of 10^4 rows (and 3 x
10^4 on 64 workers) would take at the measured cost per row and
worker: an extrapolation, stated as such (lifetimes, hence costs, vary from row to row).
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

EPOCH = "2026-12-01"


def write_rows(path: Path, rows: int) -> None:
    """N catalogue rows (see the module docstring)."""
    rng = np.random.default_rng(0)
    perigee = rng.uniform(350.0, 600.0, rows)
    near = rng.random(rows) < 0.75
    apogee = perigee + np.where(near, rng.uniform(0.0, 20.0, rows), rng.uniform(20.0, 300.0, rows))
    load = np.exp(rng.uniform(np.log(20.0), np.log(200.0), rows))
    inclination = rng.uniform(0.0, 98.0, rows)
    lines = ["name,perigee_km,apogee_km,mass_per_area_kg_m2,cx,inclination_deg"]
    lines += [f"row{k},{perigee[k]:.1f},{apogee[k]:.1f},{load[k]:.1f},2.2,{inclination[k]:.1f}" for k in range(rows)]
    path.write_text("\n".join(lines) + "\n")


def run(rows_csv: Path, out: Path, samples: int, extra: list[str], cache_dir: str) -> float:
    """Wall time [s] of the batch command."""
    command = [sys.executable, "-m", "orbit_env.cli", "lifetime", "--batch", str(rows_csv), "--out", str(out)]
    command += ["--epoch", EPOCH, "--uncertainty", "--samples", str(samples), "--rule", "5", "--no-progress"]
    command += ["--force", *extra]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "ORBIT_ENV_CACHE_DIR": cache_dir})
    wall = time.perf_counter() - start
    if done.returncode not in (0, 1):  # 1: some rows have no lifetime (their status says why)
        raise RuntimeError(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip()[-500:]}")
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=24, help="rows measured (default 24)")
    parser.add_argument("--samples", type=int, default=1000, help="samples per row (default 1000)")
    parser.add_argument("--workers", type=int, nargs="+", default=[2], help="worker counts timed (default 2)")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="orbit-env-bench-catalogue-"))
    rows_csv = folder / "rows.csv"
    write_rows(rows_csv, args.rows)
    cache_dir = str(folder / "cache")
    run(rows_csv, folder / "warm-out.csv", args.samples, ["--workers", str(args.workers[0])], cache_dir)
    print(f"{args.rows} dated LEO rows x {args.samples} samples, --rule 5, from {EPOCH}; {os.cpu_count()} cores")
    runs = [(f"--workers {w}", ["--workers", str(w)], w) for w in args.workers]
    if importlib.util.find_spec("ray") is not None:
        runs.append(("--address local (Ray)", ["--address", "local"], os.cpu_count() or 1))
    print("| run | wall | rows/s | 10^4 rows (extrapolated) | 3 x 10^4 rows on 64 workers (extrapolated) |")
    print("|---|---|---|---|---|")
    for label, extra, workers in runs:
        wall = run(rows_csv, folder / "out.csv", args.samples, extra, cache_dir)
        per_row_worker = wall * workers / args.rows  # seconds of one worker per row
        ten_k = 1e4 * per_row_worker / workers
        cluster = 3e4 * per_row_worker / 64
        print(f"| {label} | {wall:.1f} s | {args.rows / wall:.3f} | {ten_k / 3600:.1f} h | {cluster / 3600:.1f} h |")


if __name__ == "__main__":
    main()
