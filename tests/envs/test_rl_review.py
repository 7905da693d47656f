"""What an RL researcher's review found (2026-12-06): each case failed before its fix.

Gymnasium's vector API seeds with a list; the solar env's errors name what the user gave; the log
features serve the solar task too; the evaluation refuses options that would do nothing, and its
JSON keys mean the same for every env; sweeps and curves refuse what would count a seed twice; a
resumed training run does not score the same timesteps twice.
"""

import json
import tomllib
from importlib import resources

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the ids)
from orbit_env.agents import VALIDATION_SEED, solar, train
from orbit_env.agents.evaluate import load_model
from orbit_env.cli import main
from orbit_env.envs import SOLAR_ENV_ID
from orbit_env.envs.wrappers import LogFeaturesObservation, LogFeaturesVectorObservation


@pytest.mark.parametrize("env_id", ["OrbitRaising-v0", SOLAR_ENV_ID])
def test_a_vector_env_takes_a_list_of_seeds(env_id):
    envs = gym.make_vec(env_id, num_envs=3)
    first = envs.reset(seed=[7, 8, 9])[0]
    assert np.array_equal(first, envs.reset(seed=[7, 8, 9])[0])  # the same list, the same missions
    assert not np.array_equal(first, envs.reset(seed=[7, 8, 10])[0])
    for bad in ([1, 2], [1, 2, -3], [1.5, 2, 3]):
        with pytest.raises(ValueError, match="allowed: None, an integer, or a list of 3 integers >= 0"):
            envs.reset(seed=bad)


def test_the_solar_envs_errors_name_what_was_given():
    env = gym.make(SOLAR_ENV_ID)
    with pytest.raises(RuntimeError, match="no state before reset"):
        env.unwrapped.start_options  # noqa: B018
    with pytest.raises(ValueError, match=r"^start_date='2020-01-01' is invalid; allowed: dates \(1958-10-01 to "):
        env.reset(seed=0, options={"start_date": "2020-01-01"})
    # A pinned perigee carries the apogee with it (up to start_span_km above), as a pinned apogee the perigee.
    env.reset(seed=0, options={"perigee_km": 540.0})
    state = env.unwrapped.task_state
    assert 540e3 - 1e3 < state.perigee_m[0] <= state.apogee_m[0] < 560e3 + 1e3  # read back from the curves
    with pytest.raises(ValueError, match="perigee_km=3000 is out of range"):
        env.reset(seed=0, options={"perigee_km": 3000.0})


def test_the_log_features_serve_the_solar_task():
    env = LogFeaturesObservation(gym.make(SOLAR_ENV_ID))
    obs, _ = env.reset(seed=0)
    assert obs.shape == (13,) and env.observation_space.contains(obs)
    for _ in range(70):
        obs, _, terminated, _, _ = env.step(1)
        assert env.observation_space.contains(obs)
        if terminated:
            break
    envs = LogFeaturesVectorObservation(gym.make_vec(SOLAR_ENV_ID, num_envs=2))
    assert envs.reset(seed=0)[0].shape == (2, 13)


def test_evaluate_refuses_options_of_the_other_kind_of_env(capsys):
    cases = [
        (["--env", "OrbitRaising-v0", "--disposal-years", "100"], "--disposal-years applies to the solar task only"),
        (["--env", "OrbitRaising-v0", "--workers", "2", "--solar-split", "train"], "--solar-split, --workers apply"),
        (["--env", SOLAR_ENV_ID, "--dp-lookahead", "2"], "--dp-lookahead applies to the known-density envs"),
    ]
    for argv, message in cases:
        quick = [] if "--dp-lookahead" in argv else ["--no-dp"]  # (--no-dp refuses a DP option itself)
        assert main(["evaluate", *argv, "--episodes", "2", *quick]) == 2
        assert capsys.readouterr().err.startswith(f"orbit-env: error: {message}")


def test_a_model_trained_with_env_settings_is_named_as_such(tmp_path):
    _, model = load_model("OrbitRaising-v0")
    model.orbit_env = {"env_id": "OrbitRaising-v0", "env": {"horizon_steps": 100, "area_m2": 3.0}}
    path = tmp_path / "m.zip"
    model.save(path)
    warnings: list[str] = []
    load_model("OrbitRaising-v0", path, warn=warnings.append)
    assert warnings == [
        f"{path} was trained with the env settings {{'horizon_steps': 100, 'area_m2': 3.0}}; it is scored here on "
        "OrbitRaising-v0 as registered, the task the yardsticks solve"
    ]


def test_sweeps_and_curves_refuse_a_seed_counted_twice(tmp_path):
    # Checked before Ray is imported: without the cluster extra the error is this one, not an ImportError.
    from orbit_env.agents.curves import curves
    from orbit_env.agents.sweep import sweep

    with pytest.raises(ValueError, match="algorithms a2c given twice"):
        sweep("OrbitRaising-v0", ["a2c", "a2c"], 1, 64, tmp_path / "s", episodes=5, include_dp=False)
    with pytest.raises(ValueError, match="algorithms ppo given twice"):
        curves("OrbitRaising-v0", ["ppo", "ppo"], 1, 64, 64, tmp_path / "c")


def test_a_sweep_refuses_a_folder_of_other_or_unrecorded_settings(tmp_path):
    pytest.importorskip("ray")
    from orbit_env.agents.sweep import sweep

    legacy = tmp_path / "legacy"
    (legacy / "ray" / "sweep").mkdir(parents=True)  # a sweep from before the settings were recorded
    with pytest.raises(ValueError, match="holds a sweep that does not record its settings"):
        sweep("OrbitRaising-v0", ["a2c"], 1, 64, legacy, episodes=5, include_dp=False)
    folder = tmp_path / "old"
    folder.mkdir()
    kept = {"env": "OrbitRaising-v0", "algos": ["a2c"], "seeds": 1, "timesteps": 64, "episodes": 5}
    (folder / "settings.json").write_text(json.dumps(kept))
    with pytest.raises(ValueError, match="holds a sweep of other settings"):
        sweep("OrbitRaisingUncertain-v0", ["a2c", "ppo"], 3, 128, folder, episodes=5, include_dp=False)


def test_a_resumed_run_scores_no_timestep_twice(tmp_path):
    scores = [{"timesteps": t, "mean_return": r} for t, r in ((2048, 10.0), (4096, 12.0), (5120, 11.0))]
    (tmp_path / "evaluations.json").write_text(json.dumps(scores))
    (tmp_path / "best_model.zip").write_text("the 4096-step model")
    callback = train.BestModelCallback("OrbitRaising-v0", {}, 1, 5, VALIDATION_SEED, tmp_path, resume=2048)
    assert callback.evaluations == scores[:1]
    # The best model was the replaced branch's: kept aside, not passed off as this branch's; no file holds the
    # kept 2048-step score's model (the run overwrote it), so this branch's first score makes best_model.zip.
    assert not (tmp_path / "best_model.zip").exists() and callback.best_mean == -float("inf")
    assert (tmp_path / "best_model_replaced.zip").read_text() == "the 4096-step model"
    with pytest.raises(ValueError, match="resume=True is invalid"):
        train.BestModelCallback("OrbitRaising-v0", {}, 1, 5, VALIDATION_SEED, tmp_path, resume=True)
    # Without a replaced best, the kept scores stand: the best model on disk is theirs.
    (tmp_path / "evaluations.json").write_text(json.dumps(scores))
    (tmp_path / "best_model.zip").write_text("the 4096-step model")
    kept = train.BestModelCallback("OrbitRaising-v0", {}, 1, 5, VALIDATION_SEED, tmp_path, resume=4096)
    assert kept.best_mean == 12.0 and (tmp_path / "best_model.zip").exists()


def test_the_solar_recipe_is_validated_on_the_missions_the_rules_are_tuned_on():
    text = resources.files("orbit_env.agents").joinpath("ppo_solar.toml").read_text()
    config = tomllib.loads(text)
    assert config["eval_episodes"] == solar.TUNE_EPISODES
