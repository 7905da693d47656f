"""The cost of a dated lifetime (NRLMSIS 2.1 under the shipped record), cold and warm, and what the air table saves.

Whole processes (``python -m orbit_env.cli lifetime ...``), as a user runs them, for a 3U
cubesat (4 kg, 0.03 m^2, c_x 2.2) on four orbits whose lives are about 50 days, 1.2, 4.9 and
6.2 years. Each is timed in a disk cache of its own (a temporary folder):

- **cold**: the cache empty (every bin's universal curves integrated, every day's air
  computed by NRLMSIS);
- **air cold**: the curves on disk, the real Sun's air table (`orbit_env.decay.daily_air`,
  files ``airdays-*``) removed: NRLMSIS computed for every day the decay crosses, which
  is what every run paid before the table existed: the reference of the ratio;
- **warm**: everything on disk, a new process;
- **compute**: in that warm process, the time of `orbit_env.lifetime` itself (import,
  argument parsing and printing excluded), and of a second call on the same orbit
  (everything in memory).

The issue's targets: <= 0.1 s of compute warm for lives up to 5 years, <= 2 s cold for
lives up to 2 years. ``--repeats`` takes the median of warm runs.

Then, since the cold cost depends on the Sun a life crosses more than on its length (storm
days take NRLMSIS eight times over, a changing 81-day mean more solar bins), the same
cubesat at 51.6 deg on lives of 1.5-2.3 years from epochs in every phase of the cycle
(`PHASES`), cold, ``--cold-runs`` runs each (``--no-phases`` skips them).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SATELLITE = ["--mass", "4", "--area", "0.03", "--cx", "2.2", "--atmosphere", "msis"]
#: (perigee km, apogee km, inclination deg, epoch): lives of about 50 days, 1.2, 4.9 and 6.2 years.
CASES = [
    ("300", "350", "51.6", "2024-01-01"),
    ("400", "420", "51.6", "2015-01-01"),
    ("460", "480", "97.5", "2019-01-01"),
    ("500", "520", "97.5", "2019-01-01"),
]
#: (epoch, phase, perigee km, apogee km) at 51.6 deg: lives of 1.5-2.3 years across the solar cycle.
PHASES = [
    ("2003-01-01", "declining, the Halloween storms", "420", "440"),
    ("2009-01-01", "minimum", "380", "400"),
    ("2012-01-01", "rising", "420", "440"),
    ("2015-01-01", "declining, many storms", "410", "430"),
    ("2015-01-01", "declining, many storms", "415", "435"),
    ("2019-01-01", "minimum", "380", "400"),
    ("2022-01-01", "rising", "440", "460"),
]
COMPUTE = """
import sys, time
from orbit_env import Satellite, lifetime
from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.scenario import Scenario
from orbit_env.decay.solar import unix_days
from orbit_env.decay.solar_record import load_record
hp, ha, inc, epoch = sys.argv[1:]
satellite = Satellite(drag_coefficient=2.2, mass_kg=4.0, area_m2=0.03)
scenario = Scenario(MsisAir(load_record(), unix_days(epoch)))  # co-rotating air, as the command
times = []
for _ in range(2):
    start = time.perf_counter()
    result = lifetime(float(hp), float(ha), satellite=satellite, scenario=scenario, inclination_deg=float(inc))
    times.append(time.perf_counter() - start)
print(*times)
"""


def run(command: list[str], cache_dir: str, timeout: float | None = None) -> tuple[float, str]:
    """Wall time [s] and standard output of a whole process in the cache ``cache_dir``.

    Raises:
        subprocess.TimeoutExpired: the process ran over ``timeout`` seconds (it is stopped).
    """
    env = {**os.environ, "ORBIT_ENV_CACHE_DIR": cache_dir}
    start = time.perf_counter()
    done = subprocess.run(command, check=True, capture_output=True, text=True, env=env, timeout=timeout)
    return time.perf_counter() - start, done.stdout


def case_row(hp: str, ha: str, inc: str, epoch: str, folder: str, repeats: int) -> str:
    """The table's row of one orbit: cold, air cold, warm and compute, in the cache ``folder``."""
    command = [sys.executable, "-m", "orbit_env.cli", "lifetime", "--perigee", hp, "--apogee", ha]
    command += ["--inclination", inc, "--epoch", epoch, *SATELLITE]
    cold, out = run(command, folder)
    life = next(line for line in out.splitlines() if line.startswith("lifetime "))
    for table in Path(folder).glob("v-*/airdays-*"):
        table.unlink()
    air_cold, _ = run(command, folder)
    warm = statistics.median(run(command, folder)[0] for _ in range(repeats))
    _, out = run([sys.executable, "-c", COMPUTE, hp, ha, inc, epoch], folder)
    first, again = (float(x) for x in out.split())
    return (
        f"| {hp} x {ha} km, {inc} deg, {epoch} | {life.split(maxsplit=1)[1].strip()} | {cold:.2f} s "
        f"| {air_cold:.2f} s | {warm:.2f} s | {warm / air_cold:.2f} | {first:.3f} s | {again:.3f} s |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3, help="warm runs per case (median; default 3)")
    parser.add_argument("--cold-runs", type=int, default=2, help="cold runs per phase case (default 2)")
    parser.add_argument("--no-phases", action="store_true", help="skip the lives across the solar cycle")
    args = parser.parse_args()
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores, Python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as folder:
        baseline, _ = run([sys.executable, "-c", "import numpy"], folder)
    print(f"python -c 'import numpy': {baseline:.2f} s\n")
    print("| orbit | life | cold | air cold (reference) | warm | warm / air cold | compute | again in memory |")
    print("|---|---|---|---|---|---|---|---|")
    for hp, ha, inc, epoch in CASES:
        with tempfile.TemporaryDirectory(prefix="orbit-env-bench-dated-") as folder:
            print(case_row(hp, ha, inc, epoch, folder, args.repeats))
    if args.no_phases:
        return
    print("\n| epoch (phase) | orbit | life | cold |")
    print("|---|---|---|---|")
    for epoch, phase, hp, ha in PHASES:
        command = [sys.executable, "-m", "orbit_env.cli", "lifetime", "--perigee", hp, "--apogee", ha]
        command += ["--inclination", "51.6", "--epoch", epoch, *SATELLITE]
        colds = []
        for _ in range(args.cold_runs):
            with tempfile.TemporaryDirectory(prefix="orbit-env-bench-dated-") as folder:
                seconds, out = run(command, folder)
            colds.append(seconds)
        life = next(line for line in out.splitlines() if line.startswith("lifetime ")).split(maxsplit=1)[1].strip()
        cold = " / ".join(f"{seconds:.2f}" for seconds in colds)
        print(f"| {epoch} ({phase}) | {hp} x {ha} km | {life} | {cold} s |")


if __name__ == "__main__":
    main()
