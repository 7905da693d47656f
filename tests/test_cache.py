"""The disk cache of long-built tables (orbit_env.cache): keyed by their inputs, atomic, movable, can be disabled."""

import os

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
    (stored,) = folder.glob("curves-*")
    assert sorted(f.name for f in stored.iterdir()) == ["a.npy", "b.npy", "q.npy"] and not list(folder.glob("*.tmp"))
    loaded = UniversalCurves(model)
    assert not loaded.table_a.corners.flags.writeable  # mapped from the file
    np.testing.assert_array_equal(loaded.table_a.cells, built.table_a.cells)
    np.testing.assert_array_equal(loaded.table_b.cells, built.table_b.cells)
    hp, ha = np.array([300e3, 250e3]), np.array([400e3, 2500e3])
    np.testing.assert_array_equal(loaded.locate(hp, ha).weighted_s, built.locate(hp, ha).weighted_s)
    # Another model is another folder.
    UniversalCurves(DecayModel(ExponentialAtmosphere(2e-11, 400e3, 60e3)))
    assert len(list(folder.glob("curves-*"))) == 2


def test_a_damaged_file_is_built_again(folder):
    model = DecayModel(ExponentialAtmosphere(1e-11, 400e3, 50e3))
    built = UniversalCurves(model)
    (stored,) = folder.glob("curves-*")
    (stored / "b.npy").write_bytes(b"not an array")
    assert cache.load("curves", cache.describe(model), mapped=True) is None  # unreadable: as if not cached
    again = UniversalCurves(model)
    np.testing.assert_array_equal(again.table_b.cells, built.table_b.cells)
    # Rewritten whole.
    np.testing.assert_array_equal(np.load(stored / "b.npy"), built.table_b.corners)
    assert not list(folder.glob("*.tmp"))
    # A table in one file likewise.
    cache.store("dp", "a test table", {"values": np.arange(3.0)})
    (path,) = folder.glob("dp-*.npz")
    path.write_bytes(b"not a zip file")
    assert cache.load("dp", "a test table") is None


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
    assert len(list(folder.glob("curves-*"))) == 1
    capsys.readouterr()


def test_the_default_curves_are_one_table_in_a_process():
    from orbit_env.decay.curves import universal_curves

    assert universal_curves() is universal_curves(DecayModel()) is universal_curves(DecayModel(PaperAtmosphere()))
