"""An installation without the [train] extra (no torch, no stable-baselines3): what needs them says so first.

The packaging review of 2026-12-06 installed the wheel without extras: ``orbit-env evaluate`` (the README's
main job, whose every row but the shipped PPO's needs only the core) ended in "No module named 'torch'", and
``orbit-env curves`` computed its references for 4 s and left two files before "No module named
'stable_baselines3'". Here the libraries are made to look absent (`missing_learning_libraries`).
"""

import pytest

from orbit_env.agents import curves as curves_module
from orbit_env.agents import evaluate


@pytest.fixture
def no_torch(monkeypatch):
    monkeypatch.setattr(evaluate, "missing_learning_libraries", lambda: ["torch", "stable_baselines3"])


def test_the_shipped_agents_row_is_left_out_with_a_warning(no_torch):
    warned = []
    assert evaluate.load_model("OrbitRaising-v0", None, warned.append) is None
    assert len(warned) == 1 and "torch and stable_baselines3" in warned[0] and "orbit-env[train]" in warned[0]
    policies = evaluate.all_policies("OrbitRaising-v0", include_dp=False, warn=warned.append)
    assert "ppo" not in policies and "never" in policies


def test_a_model_asked_for_names_the_extra(no_torch, tmp_path):
    model = tmp_path / "mine.zip"
    model.write_bytes(b"PK")
    with pytest.raises(ValueError, match=r"needs torch and stable_baselines3: pip install 'orbit-env\[train\]'"):
        evaluate.load_model("OrbitRaising-v0", model)


def test_learning_curves_refuse_before_any_work(no_torch, tmp_path):
    out = tmp_path / "curves"
    with pytest.raises(ImportError, match=r"orbit-env\[train\]"):
        curves_module.curves("OrbitRaising-v0", ["ppo"], 1, 100, 100, out)
    assert not out.exists()
