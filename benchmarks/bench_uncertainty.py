"""The cost of ``--uncertainty``: 1000 Monte Carlo samples against one lifetime of the same orbit.

Whole processes (``python -m orbit_env.cli lifetime ...``), as a user runs them: a 3U
cubesat (4 kg, 0.03 m^2, c_x 2.2) on circular orbits at 350, 450 and 550 km
(``--perigees``; lives of about 4 months, 5 years and 18 years), inclination 97.5 deg,
air co-rotating, under NRLMSIS with the shipped solar record from an epoch
(``--epoch``). The issue's target (27, item 4): ``--uncertainty --samples 1000`` at most
10 times one lifetime, for the dated lifetimes of LEO satellites up to 5 years it
speaks of; the 18-year life is there to show what a long one costs.
The samples' solar nodes run in worker processes (``--workers``, default all cores): the
wall time falls with the cores, the CPU time does not.

The disk cache (curves and NRLMSIS profiles of every solar bin) is a temporary folder,
warmed by one run of the uncertainty command before anything is timed, so both
commands read the same tables from disk: the ratio is the cost of the samples, not of
tables built once per machine. ``--cold`` also times both commands from an empty
cache (each in a folder of its own), where the samples' solar bins are built too.
The cache's key hashes the package's source, so an edit to it during the run turns
the warm cache cold: the script counts the tables written during each timing and
says so if there were any.

Then it prints the uncertainty command's own output with ``--rule 5`` (the band and
the compliance probability under the 5-year rule).
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EPOCH = "2026-12-01"
PERIGEES_KM = ("350", "450", "550")
SATELLITE = ["--mass", "4", "--area", "0.03", "--cx", "2.2"]
SAMPLES = ["--uncertainty", "--samples", "1000", "--seed", "0"]


def one_lifetime(height_km: str) -> list[str]:
    """The command of one dated lifetime of the cubesat on the circular orbit at ``height_km``."""
    orbit = ["--perigee", height_km, "--apogee", height_km, "--inclination", "97.5", "--rotating-atmosphere"]
    return [sys.executable, "-m", "orbit_env.cli", "lifetime", *orbit, *SATELLITE, "--epoch", EPOCH]


def run(command: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    """Run a command, its output captured; on a failure, its error output printed and the benchmark stopped."""
    done = subprocess.run(command, capture_output=True, text=True, env=env)
    if done.returncode:
        sys.exit(f"failed ({done.returncode}): {' '.join(command)}\n{done.stderr}")
    return done


def timed(command: list[str], env: dict[str, str], repeats: int) -> tuple[float, float]:
    """Median wall time and median CPU time (user + system) of a whole process [s].

    The CPU time is what the process itself computed: on a machine shared with other
    work it moves less than the wall time, which waits for the cores.
    """
    walls, cpus = [], []
    folder = Path(env["ORBIT_ENV_CACHE_DIR"])
    tables = len(list(folder.iterdir()))
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        run(command, env)
        walls.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    built = len(list(folder.iterdir())) - tables
    if built:
        print(f"   (note: {built} tables written to the disk cache during the next timing: it was not warm)")
    return statistics.median(walls), statistics.median(cpus)


def report(label: str, one: tuple[float, float], spread: tuple[float, float]) -> None:
    """Print both commands' times and the ratios."""
    print(label)
    print(f"   one lifetime              {one[0]:8.2f} s wall {one[1]:8.2f} s CPU")
    print(f"   --uncertainty (1000)      {spread[0]:8.2f} s wall {spread[1]:8.2f} s CPU")
    print(f"   ratio                     {spread[0] / one[0]:8.1f}x wall {spread[1] / one[1]:7.1f}x CPU")


def main() -> None:
    """Time one lifetime and the 1000-sample uncertainty of each orbit; print their ratios."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per timing (median)")
    parser.add_argument(
        "--perigees", nargs="+", default=PERIGEES_KM, metavar="KM", help="circular orbits' heights (%(default)s)"
    )
    parser.add_argument("--cold", action="store_true", help="also time both from an empty disk cache")
    args = parser.parse_args()
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores, Python {sys.version.split()[0]}")
    env = {**os.environ, "ORBIT_ENV_CACHE_DIR": tempfile.mkdtemp(prefix="orbit-env-bench-")}
    for height in args.perigees:
        one_command = one_lifetime(height)
        print(f"orbit: {' '.join(one_command[3:])}")
        run([*one_command, *SAMPLES], env)  # warm the disk cache
        one = timed(one_command, env, args.repeats)
        spread = timed([*one_command, *SAMPLES], env, args.repeats)
        report(f"whole processes, disk cache warm, medians of {args.repeats}:", one, spread)
        if args.cold:
            cold = [{**os.environ, "ORBIT_ENV_CACHE_DIR": tempfile.mkdtemp(prefix="orbit-env-bench-")} for _ in "12"]
            report(
                "whole processes, disk cache empty, one run each:",
                timed(one_command, cold[0], 1),
                timed([*one_command, *SAMPLES], cold[1], 1),
            )
        out = run([*one_command, *SAMPLES, "--rule", "5"], env)
        print(f"$ orbit-env lifetime {' '.join([*one_command[4:], *SAMPLES, '--rule', '5'])}")
        print(out.stdout, end="")


if __name__ == "__main__":
    main()
