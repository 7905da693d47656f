import os
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# tests/ mirrors the package's folders; the helpers at its root (benchmark_scripts) are imported from any of them.
sys.path.insert(0, str(Path(__file__).resolve().parent))

# CI machines are shared and noisy: no deadline; fewer examples keep the default run short.
settings.register_profile("ci", deadline=None, max_examples=60, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("dev", deadline=None, max_examples=100)
settings.load_profile("ci" if os.environ.get("CI") else "dev")


#: The disk cache folder this run made (removed when it ends).
_OWN_CACHE = pytest.StashKey[str]()


def pytest_configure(config):
    # The tests read and write a disk cache of their own (the universal curves, NRLMSIS
    # profiles, DP solutions), not the user's: a run is not changed by what an earlier one
    # left, and leaves the user's cache as it was.
    if "ORBIT_ENV_CACHE_DIR" not in os.environ:
        import tempfile

        os.environ["ORBIT_ENV_CACHE_DIR"] = tempfile.mkdtemp(prefix="orbit-env-tests-")
        config.stash[_OWN_CACHE] = os.environ["ORBIT_ENV_CACHE_DIR"]


def pytest_unconfigure(config):
    # The cache made for this run goes with it (hundreds of MB of curves and DP tables a run).
    folder = config.stash.get(_OWN_CACHE, None)
    if folder is not None:
        import shutil

        # Off first: tables still held write themselves at exit (orbit_env.decay.daily_air), after this hook.
        os.environ["ORBIT_ENV_CACHE_DIR"] = "off"
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture
def forking(monkeypatch):
    """Let this process hand work to forked children (`orbit_env.workers.can_fork`), or skip.

    Skipped off Linux or on one core. The idle Python threads that earlier tests leave behind
    (tensorboard's writers of the training tests) would forbid the fork; they never touch
    what a child computes, so they are let be here (the guard itself is tested in test_workers.py).
    A child that an earlier decay left computing the real Sun's air would forbid it too: the
    tables take in what their children finished (as at the process's end).
    """
    from orbit_env import workers
    from orbit_env.decay import daily_air

    monkeypatch.setattr(workers, "_other_threads", lambda: 0)
    for table in list(daily_air._TABLES):
        table.close()
    if not workers.can_fork():
        pytest.skip("needs Linux and two cores")
