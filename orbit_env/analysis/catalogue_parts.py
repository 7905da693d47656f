"""A catalogue computed in chunks over processes, each chunk kept in a part file until the results file is whole.

The rows are cut into chunks of a fixed number of rows (`chunk_rows`, set by the
catalogue's size and cost, never by the number of workers). Each chunk's records go to
``OUT.parts/<fingerprint>-<chunk>.csv``, written atomically (`atomic_text`); once every
chunk has its part, the parts are joined into OUT in chunk order (atomically too) and the
folder is removed. A run stopped by Ctrl-C, a crash or a killed worker leaves its finished
parts: the same command computes only the missing chunks and ends with the same OUT, byte
for byte. Chunks run in a `concurrent.futures.ProcessPoolExecutor` (spawned processes,
each handed the computation once), at most two per worker waiting, so memory holds a few
chunks, not the catalogue's results; or, given a Ray address, as Ray tasks on that cluster
(the computation put in its object store once). Where a chunk ran does not change its records.

The fingerprint (`fingerprint`) is a SHA-256 of the command's inputs: the files' bytes,
the options that change a result, the package's source code and the chunk size. Parts of
another fingerprint in the folder are refused (`run_in_parts` with ``restart=False``), or
deleted to start over (``restart=True``, the command's ``--force``): a changed command
never reuses stale parts.
"""

from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import math
import re
import signal
import threading
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from orbit_env.analysis.catalogue_io import atomic_text, write_records
from orbit_env.cache import fcntl
from orbit_env.workers import spawned_pool

if TYPE_CHECKING:
    from concurrent.futures import Future

#: A chunk's rows at most: on the time-stepped path (a dated air, 1000 samples of a 13-year life take
#: about 36 s a row), so a stopped run loses minutes, not hours; on a fixed profile (milliseconds a row).
MAX_CHUNK_ROWS_STEPPED = 10
MAX_CHUNK_ROWS_FIXED = 2000
#: A catalogue is cut into at least this many chunks where its rows allow (so that workers share it).
MIN_CHUNKS = 16
#: Chunks waiting per worker.
QUEUED_PER_WORKER = 2
#: A chunk's records, the function that computes rows ``start`` to ``stop``, and where a chunk's records go.
Records = list[dict[str, Any]]
Compute = Callable[[int, int], Records]
Keep = Callable[[int, Records], None]
_PART = re.compile(r"^(?P<fingerprint>[0-9a-f]{16})-(?P<chunk>\d{6})\.csv$")

#: The computation of a worker process, set once by `_start_worker`.
_compute: Compute | None = None


@dataclass(frozen=True)
class JoinedParts:
    """What the results file holds: rows, rows with a lifetime, the first other status, the longest life [days]."""

    rows: int
    ok: int
    first_status: str | None
    max_days: float


def chunk_rows(n_rows: int, stepped: bool) -> int:
    """Rows per chunk: ``n_rows`` in `MIN_CHUNKS` chunks, at most the cap of the path (``stepped``: time-stepped)."""
    cap = MAX_CHUNK_ROWS_STEPPED if stepped else MAX_CHUNK_ROWS_FIXED
    return max(1, min(cap, math.ceil(n_rows / MIN_CHUNKS)))


def parts_folder(out: str | Path) -> Path:
    """The folder of the parts of ``out``: ``OUT.parts`` beside it."""
    path = Path(out)
    return path.with_name(path.name + ".parts")


def fingerprint(files: Iterable[str | Path], options: dict[str, Any]) -> str:
    """SHA-256 (16 hex digits) of the files' bytes and the options (JSON values), in the order given."""
    digest = hashlib.sha256()
    for path in files:
        digest.update(hashlib.sha256(Path(path).read_bytes()).digest())
    digest.update(json.dumps(options, sort_keys=True, allow_nan=True).encode())
    return digest.hexdigest()[:16]


def run_in_parts(
    out: str | Path,
    key: str,
    n_rows: int,
    rows_per_chunk: int,
    compute: Compute,
    *,
    workers: int,
    address: str | None = None,
    progress: bool = True,
    restart: bool = False,
    report: Callable[[str], None] = print,
) -> JoinedParts:
    """Compute rows ``[0, n_rows)`` in chunks by ``compute(start, stop)``, keep their parts, join them into ``out``.

    Args:
        out: The results file.
        key: The run's `fingerprint`.
        n_rows: Rows of the catalogue.
        rows_per_chunk: Rows per chunk (`chunk_rows`).
        compute: The records of rows ``start`` to ``stop``, in order; picklable (it is sent to the workers once).
        workers: Processes (1: this one); not used with ``address``.
        address: Run the chunks as Ray tasks on the cluster at this address (``local``: a
            local Ray, started for the run) instead of processes of this machine.
        progress: Show a progress bar of rows, their rate and the time left.
        restart: Delete the parts of another fingerprint instead of refusing them.
        report: Where the line on chunks found and workers goes.

    Raises:
        ValueError: the parts folder holds parts of another fingerprint (and not ``restart``),
            or files that are not parts.
        ImportError: ``address`` without Ray installed (the ``cluster`` extra).
    """
    folder = parts_folder(out)
    folder.mkdir(exist_ok=True)
    with _owned(folder, out):
        bounds = [(start, min(start + rows_per_chunk, n_rows)) for start in range(0, n_rows, rows_per_chunk)]
        done, deleted = _found_parts(folder, key, len(bounds), restart)
        missing = [k for k in range(len(bounds)) if k not in done]
        processes = max(1, min(workers, len(missing)))
        report(
            f"{n_rows} rows in {len(bounds)} chunks of up to {rows_per_chunk}"
            + (f", {len(done)} already in {folder}" if done else "")
            + (f" ({deleted} part{'s' if deleted > 1 else ''} of another run deleted)" if deleted else "")
            + (f"; Ray at {address}" if address else f"; {processes} worker{'s' if processes > 1 else ''}")
        )
        rows_done = sum(bounds[k][1] - bounds[k][0] for k in done)
        from tqdm import tqdm  # here, not at the top: a command that runs no catalogue does not import it

        with tqdm(total=n_rows, initial=rows_done, disable=not progress, unit="row", desc="lifetimes") as bar:

            def keep(k: int, records: Records) -> None:
                write_records(_part_path(folder, key, k), records)
                bar.update(len(records))

            chunks = [(k, *bounds[k]) for k in missing]
            if address:
                _run_ray(compute, chunks, address, keep)
            elif processes == 1:
                for k, start, stop in chunks:
                    keep(k, compute(start, stop))
            else:
                _run_pool(compute, chunks, processes, keep)
        joined = _join(out, [_part_path(folder, key, k) for k in range(len(bounds))], replace=restart)
        for k in range(len(bounds)):
            _part_path(folder, key, k).unlink()
        (folder / LOCK_NAME).unlink(missing_ok=True)
        folder.rmdir()
        return joined


#: The lock file of a parts folder: held by the command computing into it.
LOCK_NAME = ".lock"


@contextlib.contextmanager
def _owned(folder: Path, out: str | Path) -> Iterator[None]:
    """Hold ``folder``'s lock while a command computes into it; another command's hold is an error.

    Two commands on one results file had both computed every chunk, and the second ended in "no such file"
    when the first had joined the parts and removed the folder. (No lock where the platform has no flock.)
    """
    if fcntl is None:
        yield
        return
    with open(folder / LOCK_NAME, "a") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)  # released when the file is closed
        except BlockingIOError:
            raise ValueError(
                f"another command is computing the parts of {out} in {folder} now; wait for it to end (or stop "
                "it), then run this one again"
            ) from None
        yield


def _run_pool(
    compute: Compute,
    chunks: list[tuple[int, int, int]],
    processes: int,
    keep: Keep,
) -> None:
    """Run ``chunks`` (index, start, stop) on ``processes`` spawned workers; ``keep`` each chunk's records."""
    from concurrent.futures import FIRST_COMPLETED, wait

    def finished(futures: list[Future[Records]]) -> list[tuple[Any, Records]]:
        done, _ = wait(futures, return_when=FIRST_COMPLETED)
        return [(future, future.result()) for future in done]

    # Ctrl-C or a failed chunk stops the workers now; the parts kept so far stay for the next run.
    with spawned_pool(processes, initializer=_start_worker, initargs=(compute,)) as executor:
        _drain(
            chunks,
            lambda start, stop: executor.submit(_compute_chunk, start, stop),
            finished,
            QUEUED_PER_WORKER * processes,
            keep,
        )


def _drain(
    chunks: list[tuple[int, int, int]],
    submit: Callable[[int, int], Any],
    finished: Callable[[list[Any]], list[tuple[Any, Records]]],
    at_once: int,
    keep: Keep,
) -> None:
    """Submit ``chunks``, ``at_once`` at most waiting; ``keep`` each one's records as ``finished`` returns them."""
    pending: dict[Any, int] = {}
    queue = iter(chunks)
    while True:
        for k, start, stop in queue:
            pending[submit(start, stop)] = k
            if len(pending) >= at_once:
                break
        if not pending:
            return
        for handle, records in finished(list(pending)):
            keep(pending.pop(handle), records)


def require_ray() -> Any:
    """The ``ray`` module.

    Raises:
        ImportError: Ray is not installed; names the ``cluster`` extra.
    """
    try:
        import ray
    except ImportError as error:
        raise ImportError("--address runs the chunks on Ray: pip install 'orbit-env[cluster]'") from error
    return ray


def _run_ray(
    compute: Compute,
    chunks: list[tuple[int, int, int]],
    address: str,
    keep: Keep,
) -> None:
    """Run ``chunks`` as Ray tasks on the cluster at ``address`` (``local``: a local Ray), two per CPU waiting."""
    ray = require_ray()
    ray.init(
        address=None if address == "local" else address,
        include_dashboard=False,
        log_to_driver=False,
        ignore_reinit_error=True,
    )
    try:
        at_once = QUEUED_PER_WORKER * max(1, int(ray.cluster_resources().get("CPU", 1)))
        task = ray.remote(_compute_with)
        job = ray.put(compute)  # sent to the cluster once, not with every chunk

        def finished(refs: list[Any]) -> list[tuple[Any, Records]]:
            done, _ = ray.wait(refs, num_returns=1)
            return [(ref, ray.get(ref)) for ref in done]

        _drain(chunks, lambda start, stop: task.remote(job, start, stop), finished, at_once, keep)
    finally:
        ray.shutdown()  # on Ctrl-C too: the parts kept so far stay for the next run


def _compute_with(compute: Compute, start: int, stop: int) -> Records:
    return compute(start, stop)


def _start_worker(compute: Compute) -> None:
    """A worker's start: Ctrl-C is the parent's to handle; keep the computation.

    tqdm's lock is a thread lock here: its default, a multiprocessing lock, would be a
    semaphore that a worker stopped by the parent leaves behind (and Python warns of it).
    """
    from tqdm import tqdm

    global _compute
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    tqdm.set_lock(threading.RLock())
    _compute = compute


def _compute_chunk(start: int, stop: int) -> Records:
    assert _compute is not None, "a worker runs chunks after _start_worker"
    return _compute(start, stop)


def _part_path(folder: Path, key: str, chunk: int) -> Path:
    return folder / f"{key}-{chunk:06d}.csv"


def _found_parts(folder: Path, key: str, chunks: int, restart: bool) -> tuple[set[int], int]:
    """The chunks whose parts of this fingerprint are in ``folder``, and how many of another run ``restart`` deleted.

    Temporary files of a stopped write are removed.
    """
    done = set()
    deleted = 0
    for path in sorted(folder.iterdir()):
        match = _PART.match(path.name)
        if path.name == LOCK_NAME:
            continue
        if path.name.startswith(".") and path.name.endswith(".tmp"):
            path.unlink()  # a part whose write was stopped
        elif match is None:
            raise ValueError(f"{folder} holds {path.name}, which is not a part of a results file; move it away")
        elif match["fingerprint"] != key or int(match["chunk"]) >= chunks:
            if not restart:
                raise ValueError(
                    f"{folder} holds the parts of another run (other inputs or options, or another version of this "
                    "package: its code is part of a run's fingerprint); run that command again to finish it, or "
                    "give --force to delete its parts and start this one"
                )
            path.unlink()
            deleted += 1
        else:
            done.add(int(match["chunk"]))
    return done, deleted


def _join(out: str | Path, parts: list[Path], *, replace: bool) -> JoinedParts:
    """Write the parts' rows under one header into ``out`` (atomically, `atomic_text`'s ``replace``); count them."""
    rows = ok = 0
    first_status = None
    max_days = 0.0
    header = None
    with atomic_text(out, replace=replace) as handle:
        for part in parts:
            text = part.read_text(encoding="utf-8")
            head, _, body = text.partition("\n")
            assert header in (None, head), f"{part}: another header than the first part's"
            if header is None:
                header = head
                handle.write(head + "\n")
            handle.write(body)
            for record in csv.DictReader(text.splitlines()):
                rows += 1
                if record["status"] == "ok":
                    ok += 1
                elif first_status is None:
                    first_status = record["status"]
                if record["days"]:
                    max_days = max(max_days, float(record["days"]))
    return JoinedParts(rows, ok, first_status, max_days)
