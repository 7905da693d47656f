"""The disk cache of long-built tables (orbit_env.cache): keyed by their inputs, atomic, movable, can be disabled."""

import os
import time
from pathlib import Path

import numpy as np
import pytest

from orbit_env import cache
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import UniversalCurves
from orbit_env.physics.atmosphere import ExponentialAtmosphere, FunctionAtmosphere, PaperAtmosphere


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    return tmp_path


def test_descriptions_name_every_input_and_refuse_what_has_none():
    assert cache.describe(DecayModel()) == cache.describe(DecayModel(PaperAtmosphere()))
    assert cache.describe(DecayModel(PaperAtmosphere(scale=2.0))) != cache.describe(DecayModel())
    assert cache.describe(DecayModel(rotating_atmosphere=True)) != cache.describe(DecayModel())
    assert cache.describe((1.0, None, 2)) == "(1.0, None, 2)"
    # A user's function has no stable description: such a model is never cached.
    assert cache.describe(DecayModel(FunctionAtmosphere(lambda h: np.exp(-h / 8e3)))) is None
    assert cache.describe(np.zeros(3)) is None


def test_curves_are_stored_once_and_read_back_identical(folder):
    model = DecayModel(ExponentialAtmosphere(1e-11, 400e3, 60e3))
    built = UniversalCurves(model)
    # The curves are a folder of .npy files (mapped, not read, on loading).
    (stored,) = folder.glob("v-*/curves-*")
    assert sorted(f.name for f in stored.iterdir()) == ["a.npy", "b.npy", "check.json", "q.npy"]
    assert not list(folder.glob("v-*/*.tmp"))
    loaded = UniversalCurves(model)
    assert not loaded.table_a.corners.flags.writeable  # mapped from the file
    np.testing.assert_array_equal(loaded.table_a.cells, built.table_a.cells)
    np.testing.assert_array_equal(loaded.table_b.cells, built.table_b.cells)
    hp, ha = np.array([300e3, 250e3]), np.array([400e3, 2500e3])
    np.testing.assert_array_equal(loaded.locate(hp, ha).weighted_s, built.locate(hp, ha).weighted_s)
    # Another model is another folder.
    UniversalCurves(DecayModel(ExponentialAtmosphere(2e-11, 400e3, 60e3)))
    assert len(list(folder.glob("v-*/curves-*"))) == 2


def test_a_damaged_file_is_built_again(folder):
    model = DecayModel(ExponentialAtmosphere(1e-11, 400e3, 50e3))
    built = UniversalCurves(model)
    (stored,) = folder.glob("v-*/curves-*")
    (stored / "b.npy").write_bytes(b"not an array")
    assert cache.load("curves", cache.describe(model), mapped=True) is None  # unreadable: as if not cached
    again = UniversalCurves(model)
    np.testing.assert_array_equal(again.table_b.cells, built.table_b.cells)
    # Rewritten whole.
    np.testing.assert_array_equal(np.load(stored / "b.npy"), built.table_b.corners)
    assert not list(folder.glob("v-*/*.tmp"))
    # A table in one file likewise.
    cache.store("dp", "a test table", {"values": np.arange(3.0)})
    (path,) = folder.glob("v-*/dp-*.npz")
    path.write_bytes(b"not a zip file")
    assert cache.load("dp", "a test table") is None


@pytest.mark.parametrize("damage", ["zeros", "noise", "nan", "short"])
def test_a_mapped_table_whose_arrays_were_overwritten_is_built_again(folder, damage):
    # The arrays' bytes after the header zeroed (a power cut after the rename), random or NaN: the lookups
    # had read them as they were, every run after ("lifetime 0.00 days", "days": -0.0, exit status 0).
    model = DecayModel(ExponentialAtmosphere(1e-11, 400e3, 45e3))
    built = UniversalCurves(model)
    (stored,) = folder.glob("v-*/curves-*")
    path = stored / "q.npy"
    data = bytearray(path.read_bytes())
    header = 128
    body = len(data) - header
    if damage == "zeros":
        data[header:] = bytes(body)
    elif damage == "noise":
        data[header:] = np.random.default_rng(0).bytes(body)
    elif damage == "nan":
        data[header:] = np.full(body // 8, np.nan).tobytes()
    else:
        del data[len(data) // 2 :]
    path.write_bytes(bytes(data))
    assert cache.load("curves", cache.describe(model), mapped=True) is None
    again = UniversalCurves(model)
    hp, ha = np.array([300e3, 250e3]), np.array([400e3, 2500e3])
    np.testing.assert_array_equal(again.locate(hp, ha).weighted_s, built.locate(hp, ha).weighted_s)
    assert cache.load("curves", cache.describe(model), mapped=True) is not None  # rewritten whole


def test_the_cache_can_be_disabled(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, "off")
    assert cache.cache_dir() is None
    UniversalCurves(DecayModel(ExponentialAtmosphere(1e-11, 400e3, 45e3)))
    assert not list(tmp_path.iterdir())
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    monkeypatch.setattr(cache, "_disabled", True)  # what orbit-env --no-cache sets
    assert cache.cache_dir() is None


def test_no_cache_flag_writes_nothing(folder, monkeypatch, capsys):
    from orbit_env.cli import main

    monkeypatch.setattr(cache, "_disabled", False)  # restored after the test: --no-cache sets it for the process
    args = ["lifetime", "--perigee", "300", "--apogee", "400", "--atmosphere", "exponential"]
    args += ["--rho0", "2e-11", "--h0-km", "350", "--scale-height-km", "55", "--method", "curves"]
    assert main([*args, "--no-cache"]) == 0
    assert not list(folder.iterdir())
    # The worker processes a batch starts read the cache's setting from the environment: it says off too.
    assert os.environ[cache.ENV_VAR] == "off"
    monkeypatch.setenv(cache.ENV_VAR, str(folder))
    monkeypatch.setattr(cache, "_disabled", False)
    args[args.index("2e-11")] = "3e-11"  # another atmosphere: not in this process's memory either
    assert main(args) == 0
    assert len(list(folder.glob("v-*/curves-*"))) == 1
    capsys.readouterr()


def test_the_default_curves_are_one_table_in_a_process():
    from orbit_env.decay.curves import universal_curves

    assert universal_curves() is universal_curves(DecayModel()) is universal_curves(DecayModel(PaperAtmosphere()))


def test_old_generations_and_flat_tables_are_pruned_and_nothing_else(folder):
    """The first write of a process keeps its generation, the two others used last and any in use; a user's stay."""
    hour = 3600.0
    now = time.time()

    def aged(path, hours):
        os.utime(path, (now - hours * hour, now - hours * hour))
        return path

    used_hours = [1 / 12, 1 / 3, 2 / 3, 2.0, 3.0]  # five other versions' folders, by when they were last used
    others = []
    for k, hours in enumerate(used_hours):
        generation = folder / f"v-{k:016x}"
        generation.mkdir()
        (generation / "curves-0123.npz").write_bytes(b"x")
        (generation / ".used").touch()
        aged(generation / ".used", hours)
        others.append(generation)
    # Kept: the two used last (5 and 20 minutes ago), and the one used 40 minutes ago (in use: a long run).
    kept_others, stale = others[:3], others[3:]
    week = 24 * 8
    flat = [folder / f"dp-{'a' * 24}.npz", folder / f"curves-{'b' * 24}", folder / f"msis-{'c' * 24}.lock"]
    flat[0].write_bytes(b"x")
    flat[1].mkdir()
    (flat[1] / "a.npy").write_bytes(b"x")
    flat[2].write_bytes(b"")
    for path in flat:
        aged(path, week)
    recent_flat = folder / f"dp-{'d' * 24}.npz"  # written by a checkout of the old layout this week: kept
    recent_flat.write_bytes(b"x")
    mine = [folder / "notes.txt", folder / "v-not-a-generation", folder / "dp-123.npz"]
    mine += [folder / f"user-{'e' * 24}", folder / f"curves-{'f' * 24}", folder / f"v-{'1' * 16}"]
    mine[0].write_text("a user's file")
    mine[1].mkdir()
    mine[2].write_bytes(b"x")
    mine[3].mkdir()  # a name like a table's but no kind of this package's
    mine[4].mkdir()  # a kind's name, but a folder holding what no table holds
    (mine[4] / "important.json").write_text("{}")
    mine[5].mkdir()  # a generation's name without this module's marker
    for path in mine:
        aged(path, week)
    cache.store("dp", "a pruning test", {"values": np.arange(3.0)})  # the first write into this (new) folder
    kept = sorted(p.name for p in folder.iterdir())
    own = cache.generation_dir().name
    expected = [own, *(p.name for p in kept_others), recent_flat.name, *(p.name for p in mine)]
    assert kept == sorted(expected)
    assert (mine[4] / "important.json").is_file()
    assert cache.load("dp", "a pruning test")["values"].tolist() == [0.0, 1.0, 2.0]
    # Once a process: a later write does not prune again.
    stale[0].mkdir()
    (stale[0] / ".used").touch()
    aged(stale[0] / ".used", week)
    cache.store("dp", "another table", {"values": np.arange(2.0)})
    assert stale[0].is_dir()


def test_a_table_that_cannot_be_deleted_does_not_cost_the_write(folder, monkeypatch):
    flat = folder / f"dp-{'a' * 24}.npz"
    flat.write_bytes(b"x")
    os.utime(flat, (0.0, 0.0))
    original = Path.unlink

    def refuse(path, *args, **kwargs):
        if path == flat:
            raise PermissionError("another user's file")
        return original(path, *args, **kwargs)

    monkeypatch.setattr(Path, "unlink", refuse)
    cache.store("dp", "a table beside an undeletable one", {"values": np.arange(2.0)})
    assert flat.is_file()
    assert cache.load("dp", "a table beside an undeletable one")["values"].tolist() == [0.0, 1.0]


def test_what_a_killed_write_left_is_pruned_once_stale(folder):
    # A DP's write killed half way left dp-....tmp (33 MB of 127) in the generation for good (a review).
    own = cache.generation_dir()
    other = folder / f"v-{1:016x}"  # another version's, used a minute ago: kept, and cleaned too
    for generation in (own, other):
        generation.mkdir()
        (generation / ".used").touch()
    old = time.time() - 2 * 3600.0
    stale = [own / "dp-abc123.tmp", other / "curves-def.tmp"]
    for path in stale:
        path.write_bytes(b"half a table")
        os.utime(path, (old, old))
    stale_folder = own / "curves-0123abc.tmp"  # a mapped table's temporary folder
    stale_folder.mkdir()
    os.utime(stale_folder, (old, old))
    live = own / "dp-def456.tmp"  # another process writing now: kept
    live.write_bytes(b"being written")
    cache.store("dp", "a table beside what a killed write left", {"values": np.arange(2.0)})
    assert not any(path.exists() for path in [*stale, stale_folder])
    assert live.is_file() and other.is_dir()


def test_a_results_file_another_command_wrote_meanwhile_is_kept(tmp_path):
    # A batch's --out checked before the computing had been replaced after it: two commands on one file lost one's.
    from orbit_env.analysis.catalogue_io import atomic_text, write_records

    out = tmp_path / "out.csv"
    with pytest.raises(ValueError, match="appeared while this command ran") as error:
        with atomic_text(out, replace=False) as handle:
            handle.write("ours\n")
            out.write_text("theirs\n")
    assert out.read_text() == "theirs\n"
    (kept,) = tmp_path.glob("out.csv.*.new")
    assert kept.read_text() == "ours\n" and str(kept) in str(error.value)
    write_records(out, [{"a": 1}])  # replace=True (--force, or a file of this command's own): replaced
    assert out.read_text() == "a\n1\n"
    fresh = tmp_path / "fresh.csv"
    write_records(fresh, [{"a": 2}], replace=False)
    assert fresh.read_text() == "a\n2\n" and sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["out.csv", kept.name, "fresh.csv"]
    )


def test_a_write_error_names_the_file(tmp_path):
    import errno

    from orbit_env.analysis.catalogue_io import atomic_text

    out = tmp_path / "out.csv"
    with pytest.raises(OSError) as error:
        with atomic_text(out):
            raise OSError(errno.ENOSPC, "No space left on device")  # as a full disk's write raises it: no name
    assert error.value.filename == str(out) and error.value.errno == errno.ENOSPC
    assert list(tmp_path.iterdir()) == []


def test_a_cache_that_cannot_be_written_is_said_once(tmp_path, monkeypatch, capsys):
    # Every command had run cold (2.9 s against 0.4 s warm) with no word of why.
    from orbit_env.cli import main

    (tmp_path / "file").write_text("")
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path / "file" / "cache"))  # under a file: cannot be made
    monkeypatch.setattr(cache, "_warned", set())
    argv = ["lifetime", "--perigee", "300", "--apogee", "400", "--rotating-atmosphere", "--inclination", "28.7"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count("orbit-env: warning: the disk cache") == 1 and "cannot be written" in err
    assert "ORBIT_ENV_CACHE_DIR=DIR moves it" in err and "Traceback" not in err


def test_a_results_file_is_kept_on_a_file_system_without_links_and_a_dangling_link_is_replaced(tmp_path, monkeypatch):
    import errno

    from orbit_env.analysis.catalogue_io import write_records

    out = tmp_path / "out.csv"
    out.write_text("theirs\n")

    def no_links(*args):
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    with pytest.raises(ValueError, match="appeared while this command ran"):
        write_records(out, [{"a": 1}], replace=False)
    (kept,) = tmp_path.glob("out.csv.*.new")  # the results had been deleted on this path
    assert out.read_text() == "theirs\n" and kept.read_text() == "a\n1\n"
    fresh = tmp_path / "fresh.csv"
    write_records(fresh, [{"a": 2}], replace=False)  # no file there: renamed
    assert fresh.read_text() == "a\n2\n"
    monkeypatch.undo()
    dangling = tmp_path / "link.csv"
    dangling.symlink_to(tmp_path / "nowhere" / "x.csv")
    write_records(dangling, [{"a": 3}], replace=False)  # it had been called "another command's file"
    assert dangling.read_text() == "a\n3\n" and not dangling.is_symlink()


def test_a_file_system_that_cannot_sync_still_caches(folder, monkeypatch):
    import errno

    def cannot(descriptor):
        raise OSError(errno.EINVAL, "Invalid argument")

    monkeypatch.setattr(os, "fsync", cannot)
    cache.store("dp", "a test table", {"values": np.arange(3.0)})
    np.testing.assert_array_equal(cache.load("dp", "a test table")["values"], np.arange(3.0))
    model = DecayModel(ExponentialAtmosphere(1e-11, 400e3, 55e3))
    UniversalCurves(model)
    assert cache.load("curves", cache.describe(model), mapped=True) is not None
