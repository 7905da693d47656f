"""Worker processes: a pool of spawned processes that stops its workers at once on Ctrl-C or a failure."""

from __future__ import annotations

import multiprocessing
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager
from typing import Any


@contextmanager
def spawned_pool(processes: int, **kwargs: Any) -> Iterator[ProcessPoolExecutor]:
    """A `ProcessPoolExecutor` of ``processes`` spawned processes (``kwargs``: its other arguments).

    Spawned, not forked: a worker starts from a clean interpreter (no copy of the parent's
    threads or open files). On any exception in the block (Ctrl-C, a failed task) the workers
    are terminated and the queued tasks cancelled, rather than waited for; else the pool is
    shut down when its tasks are done.
    """
    executor = ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context("spawn"), **kwargs)
    try:
        yield executor
    except BaseException:
        for process in list((getattr(executor, "_processes", None) or {}).values()):
            process.terminate()
        executor.shutdown(cancel_futures=True)
        raise
    executor.shutdown()
