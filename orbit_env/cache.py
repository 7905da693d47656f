"""A disk cache for the tables that take long to build: universal curves, NRLMSIS profiles, DP solutions.

Each entry is one ``.npz`` file (compressed unless its arrays are already) of named arrays, or a folder of ``.npy``
files that are mapped rather than read (the universal curves: ``store(..., mapped=True)``), in the user's cache folder
(``platformdirs.user_cache_dir("orbit-env")``, e.g. ``~/.cache/orbit-env`` on Linux). Each
version of the package has a folder there of its own, its *generation* (``v-`` and a hash of
the package's source code, every module: the physics under a table changes with any of them,
its version and `FORMAT_VERSION`), so a stale table is never read; in it a table's name is a hash
of its kind and a description of its inputs (the ``repr`` of frozen dataclasses of plain numbers).

Old generations do not pile up: the first write of a process deletes the generations other
than its own and the `KEEP_GENERATIONS` - 1 used last, but never one used within `IN_USE_S` (a
process marks its generation used as it reads and writes, at most once a minute: a long run, or
two installed versions taking turns, keep their tables), and the tables of the layout before
generations (``<kind>-<hash>`` at the folder's top, of this package's kinds) not written within
`FLAT_KEPT_S`. Nothing else in the folder is touched: a generation is deleted only if it holds
the marker this module writes; what cannot be deleted stays (`prune`).

Writes are atomic: a table is written to a temporary file in the same folder, flushed to
the disk, and renamed over its name, so processes that race build the same table twice at most
and never read a half-written one. A cache that cannot be read or written (a
read-only home, a full disk) is passed over: the table is built in memory.

Reads are checked: a ``.npz`` by the CRC-32 of each array that the zip format keeps; a mapped folder
by its ``check.json``, each file's size and the CRC-32 of `CHECK_SLICES` slices of `CHECK_BYTES`
spread over it (a file read whole would cost milliseconds of the few pages a lookup maps). A table
that does not match (zeroed by a power cut, overwritten) is built again and rewritten, never used:
its lookups had given lifetimes of 0 days with no word. A change between two checked slices
escapes the mapped folder's check.

Control:

* the environment variable ``ORBIT_ENV_CACHE_DIR``: a folder to use instead, or
  ``off`` to disable the cache;
* `disable` (what ``orbit-env --no-cache`` calls) for the current process.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import functools
import hashlib
import json
import math
import os
import re
import shutil
import tempfile
import time
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

fcntl: ModuleType | None
try:
    import fcntl
except ImportError:  # not POSIX: `locked` does not lock
    fcntl = None

#: The environment variable that moves (a folder) or disables (``off``) the cache.
ENV_VAR = "ORBIT_ENV_CACHE_DIR"
#: Bumped when the layout of a cached table changes.
FORMAT_VERSION = 1
#: Generations kept in the cache folder by `prune`: this process's and those used last.
KEEP_GENERATIONS = 3
#: A generation used this recently [s] is in use (a process marks its own at most a minute apart): never pruned.
IN_USE_S = 3600.0
#: Tables of the layout before generations written this recently [s] are kept (a checkout of then may still run).
FLAT_KEPT_S = 7 * 86400.0
#: A process marks its generation used at most this often [s].
MARK_EVERY_S = 60.0
#: The kinds of table this package caches: a flat table's name starts with one.
KINDS = ("airdays", "curves", "dp", "fit", "msis", "record")
#: A generation's folder, and a table of the layout before generations (a file, its lock or a folder of arrays).
_GENERATION_NAME = re.compile(r"v-[0-9a-f]{16}")
_FLAT_TABLE_NAME = re.compile(rf"({'|'.join(KINDS)})-[0-9a-f]{{24}}(\.npz|\.lock)?")
#: A generation's marker file, touched as a process reads and writes it: its time is the generation's last use.
_USED = ".used"

#: Values of an ``ORBIT_ENV_*`` setting (this one, `orbit_env.workers.FORK_ENV_VAR`) that turn it off.
OFF_SETTINGS = ("off", "0", "false", "no")

_disabled = False
_marked: dict[Path, float] = {}  # generation folders this process has marked used, and when
_pruned: set[Path] = set()  # cache folders this process has pruned


def disable() -> None:
    """Neither read nor write the cache in this process (``orbit-env --no-cache``)."""
    global _disabled
    _disabled = True


def cache_dir() -> Path | None:
    """The cache folder, or None when the cache is disabled."""
    setting = os.environ.get(ENV_VAR, "").strip()
    if _disabled or setting.lower() in OFF_SETTINGS:
        return None
    if setting:
        return Path(setting).expanduser()
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("orbit-env", appauthor=False))


def describe(value: Any) -> str | None:
    """A stable description of a table's inputs, or None if there is none (then nothing is cached).

    Frozen dataclasses whose fields are numbers, strings, None or such dataclasses
    (and tuples of them) describe themselves by their ``repr``; anything else (a
    user's function, an array) has no stable description.
    """
    if value is None or isinstance(value, (bool, int, float, str)):
        return repr(value)
    if isinstance(value, tuple):
        parts = [describe(v) for v in value]
        return None if None in parts else "(" + ", ".join(parts) + ")"  # type: ignore[arg-type]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        parts = []
        for item in dataclasses.fields(value):
            if not item.repr:
                continue
            text = describe(getattr(value, item.name))
            if text is None:
                return None
            parts.append(f"{item.name}={text}")
        return f"{type(value).__qualname__}({', '.join(parts)})"
    return None


@functools.cache
def source_digest() -> str:
    """A hash of the package's Python source (read once per process: a few milliseconds)."""
    import importlib.util

    roots = [Path(__file__).parent]
    agents = importlib.util.find_spec("orbit_env.agents")
    if agents is not None and agents.submodule_search_locations:
        roots += [Path(p) for p in agents.submodule_search_locations]
    digest = hashlib.sha256()
    for root in roots:
        for path in sorted(root.rglob("*.py")):
            digest.update(path.read_bytes())
    return digest.hexdigest()


@functools.cache
def _generation() -> str:
    from orbit_env import __version__

    return hashlib.sha256(f"{FORMAT_VERSION}|{__version__}|{source_digest()}".encode()).hexdigest()[:16]


def generation_dir() -> Path | None:
    """This version's folder in the cache folder (its tables), or None when the cache is disabled."""
    folder = cache_dir()
    return None if folder is None else folder / f"v-{_generation()}"


def prune(folder: Path, keep: int = KEEP_GENERATIONS) -> list[Path]:
    """Delete from a cache folder old generations and flat tables (the module docstring says which); return them.

    A generation (``v-`` and 16 hex digits, a folder with this module's marker) goes when it is
    neither this version's, nor among the ``keep`` - 1 others used last, nor used within `IN_USE_S`.
    A flat table (the layout's before generations: one of `KINDS`, a hyphen and 24 hex digits, a
    file, its lock, or a folder of ``.npy`` arrays) goes when not written within `FLAT_KEPT_S`. In
    the generations kept, what a killed write left (a ``.tmp`` file or folder) goes when not written
    within `IN_USE_S`.
    Anything else stays, and so does what cannot be deleted (in use elsewhere, no permission).
    """
    own = f"v-{_generation()}"
    now = time.time()
    older: list[tuple[float, Path]] = []
    doomed: list[Path] = []
    try:
        entries = list(folder.iterdir())
    except OSError:
        return doomed
    for entry in entries:
        try:
            if entry.is_symlink():
                continue
            if _GENERATION_NAME.fullmatch(entry.name) and entry.name != own and (entry / _USED).is_file():
                older.append((_last_used(entry), entry))
            elif _FLAT_TABLE_NAME.fullmatch(entry.name) and now - entry.stat().st_mtime > FLAT_KEPT_S:
                arrays = not entry.is_dir() or all(f.suffix == ".npy" for f in entry.iterdir())
                if arrays:
                    doomed.append(entry)
        except OSError:
            continue
    older.sort(reverse=True)
    doomed += [entry for used, entry in older[max(keep - 1, 0) :] if now - used > IN_USE_S]
    # What a killed write left (`store`'s temporary file or folder, ``.tmp``) in the generations kept: stale
    # once no write has touched it within IN_USE_S (a live one is written continuously).
    for _, entry in [(0.0, folder / own), *older[: max(keep - 1, 0)]]:
        with contextlib.suppress(OSError):
            doomed += [left for left in entry.glob("*.tmp") if now - left.stat().st_mtime > IN_USE_S]
    removed = []
    for entry in doomed:
        with contextlib.suppress(OSError):
            if entry.is_dir():
                shutil.rmtree(entry)
            else:
                entry.unlink()
            removed.append(entry)
    return removed


def _last_used(generation: Path) -> float:
    """When a generation folder was last read or written (its marker's time)."""
    try:
        return (generation / _USED).stat().st_mtime
    except OSError:
        return 0.0


def _mark_used(generation: Path) -> None:
    """Touch a generation's marker, at most every `MARK_EVERY_S` in a process (`prune` keeps those in use)."""
    now = time.monotonic()
    if now - _marked.get(generation, -math.inf) < MARK_EVERY_S or not generation.is_dir():
        return
    _marked[generation] = now
    with contextlib.suppress(OSError):
        (generation / _USED).touch()


def _path(kind: str, description: str) -> Path | None:
    generation = generation_dir()
    if generation is None:
        return None
    _mark_used(generation)
    key = f"{kind}|{description}"
    return generation / f"{kind}-{hashlib.sha256(key.encode()).hexdigest()[:24]}.npz"


def _make_folder(path: Path) -> None:
    """The table's generation folder, made if need be and marked used; the cache folder pruned once a process."""
    path.parent.mkdir(parents=True, exist_ok=True)
    _mark_used(path.parent)
    folder = path.parent.parent
    if folder not in _pruned:
        _pruned.add(folder)
        prune(folder)


def load(kind: str, description: str | None, *, mapped: bool = False) -> dict[str, np.ndarray] | None:
    """The cached arrays of a table, or None (not cached, no description, cache disabled or unreadable).

    Args:
        kind: The kind of table (``"curves"``, ``"msis"``, ``"dp"``): the file's prefix.
        description: What shapes the table (`describe`); None: not cacheable.
        mapped: Map the arrays of a table stored with ``mapped=True`` (read-only) instead of
            reading them: a caller that looks up a few cells of a large table reads only
            their pages (a dated decay looks up tens of bins' 5 MB curves a few times each).
    """
    path = None if description is None else _path(kind, description)
    if path is None:
        return None
    try:
        if mapped:
            folder = path.with_suffix("")
            files = sorted(folder.glob("*.npy"))
            if not files or _checks(files) != json.loads((folder / CHECK_FILE).read_text()):
                return None  # damaged, or written before the check: built again
            # Read-only views of the mapped files, without memmap's slower methods (take).
            return {f.stem: np.load(f, mmap_mode="r").view(np.ndarray) for f in files}
        if not path.is_file():
            return None
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError):
        return None  # unreadable (truncated by a crash, another format): built again and rewritten


def store(
    kind: str, description: str | None, arrays: dict[str, np.ndarray], *, compress: bool = True, mapped: bool = False
) -> None:
    """Write a table's arrays to the cache, atomically; a cache that cannot be written is passed over.

    ``compress=False`` for arrays that are compressed already (deflating them again costs
    seconds and saves nothing). ``mapped=True``: a folder of ``.npy`` files instead of one
    ``.npz``, for `load` to map (the arrays aligned as numpy writes them).
    """
    path = None if description is None else _path(kind, description)
    if path is None:
        return
    try:
        _make_folder(path)
        if mapped:
            _store_folder(path.with_suffix(""), arrays)
            return
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.stem, suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as file:
                (np.savez_compressed if compress else np.savez)(file, **arrays)
                _flush(file)
            os.replace(temporary, path)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise
    except OSError as error:
        _unwritable(path.parent, error)


class CacheWarning(UserWarning):
    """The disk cache cannot be written: tables are built again in every run (said once a process)."""


_warned: set[Path] = set()


def _unwritable(folder: Path, error: OSError) -> None:
    """Say once a process that the cache folder cannot be written, and what that costs."""
    if folder in _warned:
        return
    _warned.add(folder)
    import warnings

    warnings.warn(
        f"the disk cache {folder} cannot be written ({error.strerror or error}): its tables are built again in "
        f"every run; {ENV_VAR}=DIR moves it",
        CacheWarning,
        stacklevel=3,
    )


def stamp(kind: str, description: str | None) -> tuple[int, int] | None:
    """The stored table's file identity (inode, modification time [ns]), None if there is none.

    Every write replaces the file (a new inode), so an unchanged stamp says no process has
    written the table since: a process that merges before it writes (`locked`) need not read it.
    """
    path = None if description is None else _path(kind, description)
    if path is None:
        return None
    try:
        status = path.stat()
    except OSError:
        return None
    return status.st_ino, status.st_mtime_ns


@contextlib.contextmanager
def locked(kind: str, description: str | None) -> Iterator[None]:
    """Hold a table's lock file (``<name>.lock`` beside it) for a block: for a read, merge and write of one table.

    An exclusive ``flock`` where the platform has one (POSIX); elsewhere, or where the lock file
    cannot be made (no cache, a read-only folder), the block runs unlocked: the write stays atomic,
    and the worst case is a table that misses the rows of a process that wrote at the same moment.
    """
    path = None if description is None else _path(kind, description)
    with contextlib.ExitStack() as stack:
        if path is not None and fcntl is not None:
            try:
                _make_folder(path)
                handle = stack.enter_context(path.with_suffix(".lock").open("a"))
                fcntl.flock(handle, fcntl.LOCK_EX)  # released when the file is closed
            except OSError:
                pass  # unlocked (see above)
        yield


#: A mapped table's check file, and the slices of each of its files that the check reads.
CHECK_FILE = "check.json"
CHECK_SLICES = 32
CHECK_BYTES = 2048


def _checks(files: list[Path]) -> dict[str, list[int]]:
    """Each file's size and the CRC-32 of `CHECK_SLICES` slices of `CHECK_BYTES` spread evenly over it."""
    checks = {}
    for path in files:
        size = path.stat().st_size
        crc = 0
        with open(path, "rb") as handle:
            for k in range(CHECK_SLICES):
                handle.seek(k * max(size - CHECK_BYTES, 0) // (CHECK_SLICES - 1))
                crc = zlib.crc32(handle.read(CHECK_BYTES), crc)
        checks[path.stem] = [size, crc]
    return checks


def _flush(file: Any) -> None:
    """A written file's bytes to the disk before it is renamed into place (a power cut then leaves it whole).

    A file system that cannot sync (EINVAL, ENOTSUP: some network and FUSE mounts) is written as before.
    """
    file.flush()
    try:
        os.fsync(file.fileno())
    except OSError as error:
        if error.errno not in (errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP):
            raise


def _store_folder(folder: Path, arrays: dict[str, np.ndarray]) -> None:
    """The arrays as ``.npy`` files in ``folder``, written in a temporary folder renamed to it (atomic)."""
    temporary = Path(tempfile.mkdtemp(dir=folder.parent, prefix=folder.name, suffix=".tmp"))
    try:
        for name, array in arrays.items():
            with open(temporary / f"{name}.npy", "wb") as file:
                np.save(file, array, allow_pickle=False)
                _flush(file)
        check = _checks(sorted(temporary.glob("*.npy")))
        with open(temporary / CHECK_FILE, "w") as file:
            json.dump(check, file)
            _flush(file)
        if folder.exists():  # unreadable (`load` gave None): replaced (a rename onto a folder with files fails)
            shutil.rmtree(folder, ignore_errors=True)
        try:
            os.replace(temporary, folder)
        except OSError:  # another process wrote the folder in between: its copy stays
            pass
    finally:
        if temporary.exists():
            for file in temporary.iterdir():
                file.unlink()
            temporary.rmdir()
