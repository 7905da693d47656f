"""The cost of a batch of element sets of many objects, each at its own epoch: cold and warm.

``python benchmarks/bench_sets_snapshot.py [--objects N] [--timeout S]`` makes N element sets
for a speed test only (not real objects: `sgp4`'s ``export_tle`` of orbits drawn with seed 3:
perigee 300-700 km, apogee up to 60 km higher, inclinations 40-98 deg, B* 2e-5 to 5e-4 /ER,
epochs spread over the two days from 2024-03-01, as a catalogue snapshot's are) and runs, as a
user does, ``orbit-env lifetime --batch sets.tle --out OUT --no-progress`` twice in a disk cache
of its own: empty (cold), then warm. Each object starts from its own set's epoch, all in one run
that each joins at its epoch (docs/how-to/catalogue.md, "A snapshot of many objects"); a run over
``--timeout`` seconds is stopped and said to be.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_dated import run

#: sgp4's gravity constant for the made sets [km^3/s^2] (WGS72's, as `sgp4init` takes them).
MU_KM3_S2 = 398600.8
EQUATORIAL_RADIUS_KM = 6378.137


def write_sets(path: Path, objects: int) -> None:
    """N two-line sets (see the module docstring), catalogue numbers 50000 on."""
    from sgp4.api import WGS72, Satrec
    from sgp4.exporter import export_tle

    rng = np.random.default_rng(3)
    lines = []
    first_day = float((np.datetime64("2024-03-01") - np.datetime64("1949-12-31")).astype(float))
    for k in range(objects):
        perigee_km = rng.uniform(300.0, 700.0)
        apogee_km = perigee_km + rng.uniform(0.0, 60.0)
        a_km = EQUATORIAL_RADIUS_KM + 0.5 * (perigee_km + apogee_km)
        satellite = Satrec()
        satellite.sgp4init(
            WGS72,
            "i",
            50000 + k,
            first_day + rng.uniform(0.0, 2.0),  # epoch, days since 1949-12-31
            rng.uniform(2e-5, 5e-4),  # B* [1/ER]
            0.0,
            0.0,
            (apogee_km - perigee_km) / (2.0 * a_km),  # eccentricity
            rng.uniform(0.0, 2.0 * math.pi),  # argument of perigee
            math.radians(rng.uniform(40.0, 98.0)),  # inclination
            rng.uniform(0.0, 2.0 * math.pi),  # mean anomaly
            math.sqrt(MU_KM3_S2 / a_km**3) * 60.0,  # mean motion [rad/min]
            rng.uniform(0.0, 2.0 * math.pi),  # right ascension of the node
        )
        lines += export_tle(satellite)
    path.write_text("\n".join(lines) + "\n")


def timed(command: list[str], cache_dir: str, timeout: float) -> str:
    """The wall time of a whole process in the cache ``cache_dir`` (`bench_dated.run`), or that it was stopped."""
    try:
        seconds, _ = run(command, cache_dir, timeout)
    except subprocess.TimeoutExpired:
        return f"over {timeout:.0f} s (stopped)"
    return f"{seconds:.1f} s"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--objects", type=int, default=8, help="element sets, one object each (default 8)")
    parser.add_argument("--timeout", type=float, default=600.0, help="stop a run after this many seconds")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="orbit-env-bench-sets-") as folder:
        sets = Path(folder) / "sets.tle"
        write_sets(sets, args.objects)
        out = Path(folder) / "out.csv"
        command = [sys.executable, "-m", "orbit_env.cli", "lifetime", "--batch", str(sets), "--out", str(out)]
        command += ["--no-progress", "--force"]
        cache_dir = str(Path(folder) / "cache")
        cold = timed(command, cache_dir, args.timeout)
        warm = timed(command, cache_dir, args.timeout)
        print(f"{args.objects} objects, each at its own epoch: cold {cold}, warm {warm}")
        if out.is_file():
            print(out.read_text(), end="")


if __name__ == "__main__":
    main()
