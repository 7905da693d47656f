"""Worker processes: pools of spawned (or forked) processes, and forked children for work beside this process.

`spawned_pool` and `worker_pool` stop their workers at once on Ctrl-C or a failure. `Forked` has a forked child
fill an array in shared memory while this process goes on; `in_two_processes` splits a large
pointwise computation (NRLMSIS at many points) over this process and a forked child.
"""

from __future__ import annotations

import atexit
import math
import mmap
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager, contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.cache import OFF_SETTINGS

if TYPE_CHECKING:  # imported where a pool is made: a command that makes none does not import them
    from concurrent.futures import ProcessPoolExecutor

#: Points below which `in_two_processes` computes in this process alone: a fork costs a few milliseconds
#: (measured 5-15 ms for a process with numpy and pymsis loaded), NRLMSIS 0.5-1 us a point.
FORK_MIN_POINTS = 50_000


def spawned_pool(processes: int, **kwargs: Any) -> AbstractContextManager[ProcessPoolExecutor]:
    """A `ProcessPoolExecutor` of ``processes`` spawned processes (``kwargs``: its other arguments).

    Spawned, not forked: a worker starts from a clean interpreter (no copy of the parent's
    threads or open files). On any exception in the block (Ctrl-C, a failed task) the workers
    are terminated and the queued tasks cancelled, rather than waited for; else the pool is
    shut down when its tasks are done.
    """
    return _stopped_on_error(_pool(processes, "spawn", **kwargs))


def worker_pool(processes: int) -> AbstractContextManager[ProcessPoolExecutor]:
    """`spawned_pool`, but forked where `can_fork` says so: workers with this process's modules and tables.

    For a few tasks of a second or so (the uncertainty's solar nodes), where a spawned worker's
    start (the interpreter, the imports, the curves and the air read again) is a good part of
    the wall time. The pool forks its workers at its first task, before its management thread
    starts; a forked worker forks no further, and ends without this process's exit handlers
    (nothing written to the disk cache twice).
    """
    return _stopped_on_error(_pool(processes, "fork" if can_fork() else "spawn"))


def _pool(processes: int, method: str, **kwargs: Any) -> ProcessPoolExecutor:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context(method), **kwargs)


@contextmanager
def _stopped_on_error(executor: ProcessPoolExecutor) -> Iterator[ProcessPoolExecutor]:
    """``executor`` for a block: its workers terminated at once on an exception, else shut down at its end."""
    try:
        yield executor
    except BaseException:
        for process in list((getattr(executor, "_processes", None) or {}).values()):
            process.terminate()
        executor.shutdown(cancel_futures=True)
        raise
    executor.shutdown()


#: Set to "off" (or 0, false, no: `orbit_env.cache.OFF_SETTINGS`) to keep every computation in its process.
FORK_ENV_VAR = "ORBIT_ENV_FORK"


def _cores() -> int:
    """The cores this process may run on: its CPU affinity, within a container's CPU quota (cgroups)."""
    affinity = getattr(os, "sched_getaffinity", None)
    cores = len(affinity(0)) if affinity is not None else os.cpu_count() or 1
    quota = cgroup_cpu_limit()
    return cores if quota is None else max(1, min(cores, math.ceil(quota)))


def cgroup_cpu_limit(root: Path = Path("/sys/fs/cgroup")) -> float | None:
    """The CPUs a container's quota allows (cgroup v2 ``cpu.max``, or v1 ``cpu.cfs_quota_us``), None if none."""
    try:
        v2 = root / "cpu.max"
        if v2.is_file():
            quota, period = v2.read_text().split()[:2]
            return None if quota == "max" else int(quota) / int(period)
        v1 = root / "cpu" / "cpu.cfs_quota_us"
        if v1.is_file():
            quota_us = int(v1.read_text())
            return None if quota_us <= 0 else quota_us / int((root / "cpu" / "cpu.cfs_period_us").read_text())
    except (OSError, ValueError):
        return None
    return None


def can_fork() -> bool:
    """Whether a computation may be handed to a forked child here.

    Not where `FORK_ENV_VAR` says off. Linux only (fork elsewhere is unsafe or absent), at
    least two cores (`_cores`: a container's CPU quota counts), and only in a
    process that is neither a pool's worker nor a forked child, runs no other Python
    thread (a fork copies one thread: a lock another thread holds would never be released
    in the child; tqdm's monitor thread excepted, `_other_threads`) and has no worker
    process or forked child still running (a second process beside busy ones would only
    compete for the same cores).
    """
    return (
        not _in_child
        and os.environ.get(FORK_ENV_VAR, "").strip().lower() not in OFF_SETTINGS
        and sys.platform.startswith("linux")
        and _cores() >= 2
        and not _other_threads()
        and not any(child.running() for child in list(_children))
        and not _in_pool()
    )


def _in_pool() -> bool:
    """Whether this process is a pool's worker or has pool workers running (multiprocessing not imported: neither)."""
    multiprocessing = sys.modules.get("multiprocessing")
    if multiprocessing is None:
        return False
    return multiprocessing.parent_process() is not None or bool(multiprocessing.active_children())


def _other_threads() -> int:
    """Python threads beside this one, tqdm's monitor left out.

    The monitor (a daemon thread that a progress bar starts and that outlives it) only wakes
    to refresh bars, and a forked child draws none: its locks are never the child's.
    """
    current = threading.current_thread()
    return sum(thread is not current and type(thread).__name__ != "TMonitor" for thread in threading.enumerate())


class Forked:
    """An array filled by a forked child process, in memory shared with this one.

    The child calls ``fill(out, mark)``: it writes the array ``out`` (of ``shape`` and
    ``dtype``) and may call ``mark(k)`` once its first k rows are final, so that `stop` can
    keep them. It exits at once when done (``os._exit``: no ``atexit`` handlers, no buffers
    flushed twice). Make one only where `can_fork` says yes. A child still running when
    this process exits is killed.
    """

    def __init__(
        self,
        fill: Callable[[NDArray[Any], Callable[[int], None]], None],
        shape: tuple[int, ...],
        dtype: type[np.generic] = np.float64,
    ) -> None:
        self._shape, self._dtype = shape, np.dtype(dtype)
        self._count = math.prod(shape)
        # The count of final rows (8 bytes), then the array.
        self._shared = mmap.mmap(-1, 8 + self._count * self._dtype.itemsize)
        self._status: int | None = None
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child leaves by os._exit, invisible to coverage
            global _in_child
            _in_child = True
            status = 1
            try:
                fill(self._view(), self._mark)
                self._mark(shape[0])
                status = 0
            finally:
                os._exit(status)
        self.pid = pid
        _children.add(self)

    def _view(self) -> NDArray[Any]:
        return np.frombuffer(self._shared, dtype=self._dtype, count=self._count, offset=8).reshape(self._shape)

    def _mark(self, rows: int) -> None:
        np.frombuffer(self._shared, dtype=np.int64, count=1)[0] = rows

    def running(self) -> bool:
        """Whether the child is still computing (without waiting for it)."""
        if self._status is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self._status = status
        return self._status is None

    def result(self) -> NDArray[Any] | None:
        """Wait for the child: its array, or None if it failed."""
        if self._status is None:
            self._status = os.waitpid(self.pid, 0)[1]
        out, _ = self._release()
        return out if self._status == 0 else None

    def stop(self) -> tuple[NDArray[Any], int]:
        """The array and the count of its leading rows that are final, without waiting (a running child is stopped)."""
        if self.running():
            os.kill(self.pid, signal.SIGKILL)
            self._status = os.waitpid(self.pid, 0)[1]
        return self._release()

    def _release(self) -> tuple[NDArray[Any], int]:
        """The array and its count of final rows, copied out of the shared memory, which is then freed."""
        _children.discard(self)
        rows = int(np.frombuffer(self._shared, dtype=np.int64, count=1)[0])
        out = self._view().copy()
        self._shared.close()
        return out, rows


def in_two_processes(
    compute: Callable[[slice], NDArray[Any]],
    size: int,
    dtype: type[np.generic] = np.float64,
    *,
    row_shape: tuple[int, ...] = (),
    min_size: int = FORK_MIN_POINTS,
) -> NDArray[Any]:
    """``compute(slice(0, size))``: an array (size, *row_shape) of ``dtype``, its second half by a forked child.

    For work whose rows are independent (each depends only on its own inputs: NRLMSIS at a list
    of points, a universal curve), so the two halves put together are the one call's result,
    bit for bit. Below ``min_size`` rows (`FORK_MIN_POINTS`), where `can_fork` says no or the
    fork fails, one call here. Should the child fail, this process computes its half too; on
    Ctrl-C or an error here the child is stopped.
    """
    if size < min_size or not can_fork():
        return compute(slice(0, size))
    half = size // 2

    def fill(out: NDArray[Any], _: Callable[[int], None]) -> None:
        out[...] = compute(slice(half, size))

    try:
        child = Forked(fill, (size - half, *row_shape), dtype)
    except OSError:  # no fork to be had (process or memory limits): all here
        return compute(slice(0, size))
    try:
        first = compute(slice(0, half))
    except BaseException:
        child.stop()
        raise
    second = child.result()
    return np.concatenate([first, compute(slice(half, size)) if second is None else second])


#: This process's forked children not yet collected (`Forked`).
_children: set[Forked] = set()
#: True in a forked child: it forks no further.
_in_child = False


@atexit.register
def _stop_children() -> None:
    for child in list(_children):
        child.stop()
