import os
import sys
from pathlib import Path

from hypothesis import HealthCheck, settings

# tests/ mirrors the package's folders; the helpers at its root (benchmark_scripts) are imported from any of them.
sys.path.insert(0, str(Path(__file__).resolve().parent))

# CI machines are shared and noisy: no deadline; fewer examples keep the default run short.
settings.register_profile("ci", deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, max_examples=100)
settings.load_profile("ci" if os.environ.get("CI") else "dev")


def pytest_configure(config):
    # The tests read and write a disk cache of their own (the universal curves, NRLMSIS
    # profiles, DP solutions), not the user's: a run is not changed by what an earlier one
    # left, and leaves the user's cache as it was.
    if "ORBIT_ENV_CACHE_DIR" not in os.environ:
        import tempfile

        os.environ["ORBIT_ENV_CACHE_DIR"] = tempfile.mkdtemp(prefix="orbit-env-tests-")
