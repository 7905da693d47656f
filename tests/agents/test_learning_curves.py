"""``orbit-env curves``: the benchmark protocol's learning curves, on one-rollout runs of the recipe."""

import json

import numpy as np
import pytest

from orbit_env.agents import curves as curves_module
from orbit_env.agents.curves import aggregate, curves, plot_curves
from orbit_env.agents.evaluate import EVAL_SEED, run_episodes
from orbit_env.agents.policies import NeverBurn


def test_aggregate_takes_the_iqm_over_seeds_at_every_point():
    runs = [
        {"algo": "ppo", "seed": s, "points": [[0, 0.0, 0.0], [100 + s, 0.0, 0.1 * s]], "wall_s": 1.0} for s in range(5)
    ] + [{"algo": "ppo_recipe", "seed": 0, "points": [[0, 0.0, 0.5]], "wall_s": 1.0}]
    out = aggregate(runs)
    assert out["ppo"]["timesteps"] == [0.0, 102.0]  # the seeds' median step
    assert out["ppo"]["iqm_capture"] == pytest.approx([0.0, np.mean([0.1, 0.2, 0.3])])  # the middle half of 0..0.4
    assert out["ppo"]["ci95_low"][1] <= out["ppo"]["iqm_capture"][1] <= out["ppo"]["ci95_high"][1]
    assert out["ppo_recipe"]["iqm_capture"] == [0.5] and out["ppo_recipe"]["seeds"] == [1.0]


def test_the_recipes_curves_start_at_never_and_resume_without_training(tmp_path, monkeypatch):
    out = tmp_path / "curves"
    # One rollout per run (the recipe's 64 envs x 512 steps): points at step 0 and after its update.
    result = curves("OrbitRaising-v0", ["ppo_recipe"], 2, 1, 1, out, episodes=20)
    never = run_episodes("OrbitRaising-v0", NeverBurn(), 20, EVAL_SEED).returns.mean()
    assert result["never_return"] == pytest.approx(never, rel=1e-12)
    for run in result["runs"]:
        steps = [point[0] for point in run["points"]]
        assert steps == [0.0, 32768.0]
        # Untrained, the recipe coasts (its initial coast logit): exactly never's return, capture 0.
        assert run["points"][0][1] == pytest.approx(never, rel=1e-12) and run["points"][0][2] == pytest.approx(0.0)
    assert (out / "curves" / "ppo_recipe_seed1.json").is_file()
    # The same command again trains nothing: the written runs are read back.
    monkeypatch.setattr(curves_module, "train_trial", lambda *a, **k: pytest.fail("a written run was trained again"))
    again = curves("OrbitRaising-v0", ["ppo_recipe"], 2, 1, 1, out, episodes=20)
    assert again["runs"] == result["runs"] and again["curves"] == result["curves"]
    assert json.loads((out / "results.json").read_text())["curves"] == result["curves"]
    # Other settings in the same folder are refused, not mixed.
    with pytest.raises(ValueError, match="holds curves of other settings"):
        curves("OrbitRaising-v0", ["ppo_recipe"], 2, 1, 2, out, episodes=20)
    plot_curves(result, tmp_path / "curves.png")
    assert (tmp_path / "curves.png").stat().st_size > 10_000


def test_curves_refuse_unknown_algorithms_and_counts(tmp_path):
    with pytest.raises(ValueError, match="unknown algorithm 'dqn'"):
        curves("OrbitRaising-v0", ["dqn"], 1, 1, 1, tmp_path)
    with pytest.raises(ValueError, match=">= 1"):
        curves("OrbitRaising-v0", ["ppo"], 0, 1, 1, tmp_path)


def test_the_shipped_curves_are_the_statistics_of_their_runs():
    from importlib import resources

    folder = resources.files("orbit_env.agents").joinpath("baselines", "curves")
    names = sorted(p.name for p in folder.iterdir() if p.name.endswith(".json"))
    assert "OrbitRaising-v0.json" in names
    for name in names:
        result = json.loads(folder.joinpath(name).read_text())
        assert result["env"] + ".json" == name
        assert {run["algo"] for run in result["runs"]} == set(result["curves"]) == {"ppo", "ppo_recipe"}
        assert sorted(run["seed"] for run in result["runs"] if run["algo"] == "ppo") == [0, 1, 2, 3, 4]
        for run in result["runs"]:
            steps = [point[0] for point in run["points"]]
            assert steps[0] == 0 and steps == sorted(steps) and steps[-1] >= result["timesteps"]
        assert aggregate(result["runs"]) == result["curves"]  # the curves are their runs' IQM and intervals
