"""Every speed target where users wait, as ratios against references measured in the same run.

One command (``python benchmarks/bench_all.py``) prints:

1. start-up, whole processes (medians of ``--repeats``), against ``python -c "import numpy"``:
   ``orbit-env --help``; a lifetime by the default method; a lifetime through the universal
   curves with the disk cache warm and with it off (the curves built);
2. ``orbit-env table2`` from scratch (``--no-cache``), whole process, against a naive numpy
   RK4 of the averaged model, cell by cell (a whole process too);
3. ``orbit-env evaluate`` (1000 episodes), of ``OrbitRaising-v0`` and of the uncertain
   variant (its oracle), with the DP's disk cache cold and warm: wall time, CPU time and
   peak memory;
4. the environments against Gymnasium's CartPole: ``benchmarks/bench_env.py`` (every
   registered id, random actions and coasting, single through ``gymnasium.make`` and the
   vector env at 4096 envs), and Gymnasium's own ``gymnasium.utils.performance.benchmark_step``
   for every registered id, in turn with CartPole-v1.

The machine is stated at the top. The disk cache is pointed at a temporary folder,
so the user's cache is neither read nor changed. So is Python's bytecode cache
(``PYTHONPYCACHEPREFIX``; ``PYTHONDONTWRITEBYTECODE`` is lifted for the children): an
installed package runs from bytecode compiled once, and each command of items 1-2 runs
once untimed before it is timed, so no timing includes compiling the package's source.
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

HERE = Path(__file__).resolve().parent

#: The naive reference of item 2: RK4 in p with a fixed step, one Table II cell after the other.
NAIVE_TABLE2 = """
import numpy as np
from orbit_env.decay.averaged import DecayModel
from orbit_env.constants import EARTH_RADIUS_M, REENTRY_ALTITUDE_M
from orbit_env.paper.table2 import load_table2
from orbit_env.physics.orbit import elements_from_heights

model = DecayModel()
table = load_table2()
STEP_M = {step_m}
nus = []
for hp_km, ha_km in zip(table.perigee_km, table.apogee_km):
    p, e = (float(x) for x in elements_from_heights(hp_km * 1e3, ha_km * 1e3))
    nu = 0.0

    def f(p, e):
        dp_dnu, de_dnu = model.rates_per_nu(p, max(e, 0.0))
        return float(de_dnu / dp_dnu), float(1.0 / dp_dnu)

    while p / (1.0 + e) - EARTH_RADIUS_M > REENTRY_ALTITUDE_M:
        h = -STEP_M
        k1 = f(p, e)
        k2 = f(p + h / 2, e + h / 2 * k1[0])
        k3 = f(p + h / 2, e + h / 2 * k2[0])
        k4 = f(p + h, e + h * k3[0])
        e += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        nu += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        p += h
    nus.append(nu)
print(len(nus), float(np.median(nus)))
"""


def wall(command: list[str], repeats: int, env: dict[str, str], warm: bool = True) -> tuple[float, float]:
    """Median wall time and median CPU time (user + system) of a whole process [s].

    After one untimed run if ``warm`` (it writes the bytecode). The CPU time is what the
    process computed itself: on a machine shared with other work it moves less than the
    wall time, which also waits for the cores.
    """
    if warm:
        subprocess.run(command, check=True, capture_output=True, env=env)
    times, cpus = [], []
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True, env=env)
        times.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return statistics.median(times), statistics.median(cpus)


#: Runs a command and prints its children's CPU time [s] and peak memory [kB] (ru_maxrss of
#: this wrapper's children is the command's own, not the largest of the benchmark's).
MEASURED_RUN = (
    "import resource, subprocess, sys\n"
    "subprocess.run(sys.argv[1:], check=True, capture_output=True)\n"
    "usage = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
    "print(usage.ru_utime + usage.ru_stime, usage.ru_maxrss)\n"
)


def measured_run(command: list[str], env: dict[str, str]) -> tuple[float, float, float]:
    """Wall time [s], CPU time [s] and peak memory [MB] of one whole process."""
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", MEASURED_RUN, *command], check=True, capture_output=True, env=env)
    seconds = time.perf_counter() - start
    cpu_s, peak_kb = (float(x) for x in out.stdout.split())
    return seconds, cpu_s, peak_kb / 1024


def main() -> None:
    """Run every benchmark and print its ratio."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs per whole-process timing (median)")
    parser.add_argument("--skip-env", action="store_true", help="leave out item 4 (the environments)")
    args = parser.parse_args()
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores, Python {sys.version.split()[0]}")
    folder = tempfile.mkdtemp(prefix="orbit-env-bench-")
    env = {**os.environ, "ORBIT_ENV_CACHE_DIR": folder, "PYTHONPYCACHEPREFIX": os.path.join(folder, "pycache")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    python, cli = sys.executable, [sys.executable, "-m", "orbit_env.cli"]
    repeats = args.repeats

    # 1. Start-up.
    numpy_s, numpy_cpu = wall([python, "-c", "import numpy"], repeats, env)
    print(f"1. start-up (whole processes, medians of {repeats}); reference python -c 'import numpy': {numpy_s:.3f} s")
    orbit = ["lifetime", "--perigee", "360", "--apogee", "800"]
    subprocess.run([*cli, *orbit, "--method", "curves"], check=True, capture_output=True, env=env)  # warm the cache
    for label, command in (
        ("orbit-env --help", [*cli, "--help"]),
        ("a lifetime, default method", [*cli, *orbit]),
        ("a lifetime through the curves, cache warm", [*cli, *orbit, "--method", "curves"]),
        ("a lifetime through the curves, no cache", [*cli, *orbit, "--method", "curves", "--no-cache"]),
    ):
        seconds, cpu = wall(command, repeats, env)
        ratios = f"ratio {seconds / numpy_s:5.2f}x import numpy (CPU {cpu / numpy_cpu:5.2f}x)"
        print(f"   {label:<44} {seconds:6.3f} s  {ratios}")

    # 2. Table II from scratch against the naive RK4.
    table_s, table_cpu = wall([*cli, "table2", "--no-cache"], repeats, env)
    naive_s, naive_cpu = wall([python, "-c", NAIVE_TABLE2.format(step_m=2000.0)], 1, env, warm=False)  # compiled above
    print(f"2. orbit-env table2 --no-cache {table_s:.3f} s; naive numpy RK4 (2 km steps, per cell) {naive_s:.2f} s")
    print(f"   ratio {naive_s / table_s:.1f}x (CPU {naive_cpu / table_cpu:.1f}x)")

    # 3. The main job: the first run solves the DP and writes it to the (temporary) cache,
    # the second reads it; then the uncertain variant's oracle (nine DP solutions).
    print("3. orbit-env evaluate (1000 episodes): wall time, CPU time, peak memory of the process")
    for label, command in (
        ("OrbitRaising-v0, cache cold (solves the DP)", [*cli, "evaluate"]),
        ("OrbitRaising-v0, cache warm", [*cli, "evaluate"]),
        ("OrbitRaisingUncertain-v0, cache cold", [*cli, "evaluate", "--env", "OrbitRaisingUncertain-v0"]),
        ("OrbitRaisingUncertain-v0, cache warm", [*cli, "evaluate", "--env", "OrbitRaisingUncertain-v0"]),
    ):
        seconds, cpu_s, peak_mb = measured_run(command, env)
        print(f"   {label:<46} {seconds:6.1f} s  CPU {cpu_s:6.1f} s  peak {peak_mb:5.0f} MB")

    if args.skip_env:
        return
    # 4. The environments.
    print("4. environments against CartPole (benchmarks/bench_env.py)")
    subprocess.run([python, str(HERE / "bench_env.py")], check=True, env=env)
    print("   gymnasium.utils.performance.benchmark_step (random actions): each id in turn with CartPole-v1,")
    print("   2 s each, three pairs; the median of the pairs' ratios")
    code = (
        "import statistics, gymnasium as gym, orbit_env\n"
        "from gymnasium.utils.performance import benchmark_step\n"
        "cartpole = gym.make('CartPole-v1')\n"
        "for env_id in orbit_env.envs.ENV_IDS:\n"
        "    env = gym.make(env_id)\n"
        "    pairs = [(benchmark_step(cartpole, target_duration=2), benchmark_step(env, target_duration=2))\n"
        "             for _ in range(3)]\n"
        "    ref, rate = (statistics.median(p[k] for p in pairs) for k in (0, 1))\n"
        "    ratio = statistics.median(b / a for a, b in pairs)\n"
        "    print(f'   {env_id:<27} {rate:10,.0f} steps/s  CartPole-v1 {ref:10,.0f}  ratio {ratio:.2f}x')\n"
    )
    subprocess.run([python, "-c", code], check=True, env=env)


if __name__ == "__main__":
    main()
