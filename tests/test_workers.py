"""`orbit_env.workers`: work split with a forked child (`in_two_processes`), and the worker pools."""

from __future__ import annotations

import multiprocessing
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from tqdm import tqdm

from orbit_env import workers
from orbit_env.physics.atmosphere import msis

POINTS = workers.FORK_MIN_POINTS + 11  # odd: the halves differ by one point


def squares(part: slice) -> np.ndarray:
    """The square of each point's index."""
    return np.arange(part.start, part.stop, dtype=np.float64) ** 2


def pids(part: slice) -> np.ndarray:
    """The id of the process that computed each point."""
    return np.full(part.stop - part.start, float(os.getpid()))


@pytest.mark.usefixtures("forking")
def test_the_second_half_is_computed_by_a_child_and_the_whole_is_the_one_calls_result() -> None:
    np.testing.assert_array_equal(workers.in_two_processes(squares, POINTS), squares(slice(0, POINTS)))
    by = workers.in_two_processes(pids, POINTS)
    assert np.all(by[: POINTS // 2] == os.getpid())
    assert np.all(by[POINTS // 2 :] != os.getpid()), "the second half was not computed by a child"


@pytest.mark.usefixtures("forking")
def test_a_failing_child_leaves_its_half_to_this_process() -> None:
    parent = os.getpid()

    def fails_in_a_child(part: slice) -> np.ndarray:
        if os.getpid() != parent:
            raise RuntimeError("child failure")
        return pids(part)

    assert np.all(workers.in_two_processes(fails_in_a_child, POINTS) == parent)


@pytest.mark.usefixtures("forking")
def test_a_fork_refused_by_the_system_leaves_the_work_to_this_process(monkeypatch: pytest.MonkeyPatch) -> None:
    def refused() -> int:
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(os, "fork", refused)
    before = set(workers._children)  # an air table's child that an earlier test left running may be there
    np.testing.assert_array_equal(workers.in_two_processes(squares, POINTS), squares(slice(0, POINTS)))
    assert workers._children == before


@pytest.mark.usefixtures("forking")
def test_rows_of_several_values_are_split_as_rows() -> None:
    """``row_shape``: each row (here a point's pid and its square, twice) is computed whole on one side."""

    def rows(part: slice) -> np.ndarray:
        index = np.arange(part.start, part.stop, dtype=np.float64)
        pid = np.full(index.size, float(os.getpid()))
        values = np.stack([index**2, pid], axis=1)  # (rows, 2)
        return np.stack([values, values], axis=1)  # (rows, 2, 2)

    by = workers.in_two_processes(rows, 9, row_shape=(2, 2), min_size=2)
    assert by.shape == (9, 2, 2)
    np.testing.assert_array_equal(by[:, :, 0], np.repeat(np.arange(9.0)[:, None] ** 2, 2, axis=1))
    assert np.all(by[:4, :, 1] == os.getpid()) and np.all(by[4:, :, 1] != os.getpid())


def test_small_work_stays_in_this_process() -> None:
    size = workers.FORK_MIN_POINTS - 1
    np.testing.assert_array_equal(workers.in_two_processes(squares, size), squares(slice(0, size)))
    assert np.all(workers.in_two_processes(pids, size) == os.getpid())


def test_no_fork_beside_another_python_thread_but_tqdms_monitor() -> None:
    """A thread of the user's forbids the fork; tqdm's monitor, which outlives its progress bars, does not."""
    from tqdm.std import TMonitor

    before = workers._other_threads()
    stop = threading.Event()
    thread = threading.Thread(target=stop.wait)
    thread.start()
    try:
        assert workers._other_threads() == before + 1
        assert not workers.can_fork()
    finally:
        stop.set()
        thread.join()
    monitor = TMonitor(tqdm, 10.0)  # started by its constructor, as tqdm does
    try:
        assert workers._other_threads() == before
    finally:
        monitor.exit()


@pytest.mark.usefixtures("forking")
def test_nrlmsis_split_over_two_processes_is_bit_for_bit_the_one_call(monkeypatch: pytest.MonkeyPatch) -> None:
    """The split changes nothing: NRLMSIS is pointwise, each half keeps the points' order."""
    pytest.importorskip("pymsis")
    heights = np.linspace(150e3, 700e3, 40)
    args = (heights, 140.0 + np.arange(30.0), np.full(30, 150.0), np.full(30, 12.0), np.arange(30.0) * 12 + 1, 51.6)
    split = msis.orbit_mean_density_by_day_kg_m3(*args)  # 30 days x 144 samples x 40 heights: above the threshold
    assert 30 * 144 * 40 >= workers.FORK_MIN_POINTS
    monkeypatch.setattr(workers, "FORK_MIN_POINTS", 10**9)
    np.testing.assert_array_equal(msis.orbit_mean_density_by_day_kg_m3(*args), split)


def test_a_containers_cpu_quota_is_read_from_cgroups_v2_and_v1(tmp_path: Path) -> None:
    assert workers.cgroup_cpu_limit(tmp_path) is None  # no cgroup files: no quota
    (tmp_path / "cpu.max").write_text("max 100000\n")
    assert workers.cgroup_cpu_limit(tmp_path) is None
    (tmp_path / "cpu.max").write_text("150000 100000\n")  # docker --cpus=1.5
    assert workers.cgroup_cpu_limit(tmp_path) == 1.5
    v1 = tmp_path / "v1"
    (v1 / "cpu").mkdir(parents=True)
    (v1 / "cpu" / "cpu.cfs_quota_us").write_text("-1\n")
    (v1 / "cpu" / "cpu.cfs_period_us").write_text("100000\n")
    assert workers.cgroup_cpu_limit(v1) is None
    (v1 / "cpu" / "cpu.cfs_quota_us").write_text("100000\n")
    assert workers.cgroup_cpu_limit(v1) == 1.0
    (tmp_path / "cpu.max").write_text("garbled")
    assert workers.cgroup_cpu_limit(tmp_path) is None


def test_one_cpu_of_quota_or_the_switch_keeps_the_work_here(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(workers, "_other_threads", lambda: 0)  # as the forking fixture: earlier tests' threads
    monkeypatch.setattr(workers, "cgroup_cpu_limit", lambda: 1.0)
    assert workers._cores() == 1 and not workers.can_fork()
    monkeypatch.setattr(workers, "cgroup_cpu_limit", lambda: None)
    monkeypatch.setenv(workers.FORK_ENV_VAR, "off")
    assert not workers.can_fork()
    assert np.all(workers.in_two_processes(pids, POINTS) == os.getpid())


@pytest.mark.usefixtures("forking")
def test_a_failure_in_a_pools_block_stops_its_workers_at_once() -> None:
    """Ctrl-C (here an error) while a worker runs a long task: the workers are terminated, not waited for."""
    start = time.monotonic()
    with pytest.raises(RuntimeError, match="stop"), workers.worker_pool(1) as pool:
        future = pool.submit(time.sleep, 60.0)
        time.sleep(0.2)  # the worker has started the long task
        raise RuntimeError("stop")
    assert time.monotonic() - start < 20.0
    assert not future.done() or future.cancelled() or future.exception() is not None
    assert not multiprocessing.active_children()
