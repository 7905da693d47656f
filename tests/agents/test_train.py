"""Training options of ``orbit-env train``: the log features, the learning-rate schedule, config checks."""

import json
import math

import numpy as np
import pytest
import torch

from orbit_env.agents.features import LogFeatures
from orbit_env.agents.train import linear_decay, load_config
from orbit_env.envs.task import LIFETIME_SCALE_DAYS, Task, observation


def test_log_features_append_log_lifetime_and_log_time_left():
    # A satellite predicted to live 10 days, 100 steps into a 365-step mission.
    obs = np.array(observation(300e3, 500e3, 250.0, 100 / 365, 10.0, 2e3, 0.2e3), dtype=np.float32)[None, :]
    features = LogFeatures(Task().observation_space)(torch.as_tensor(obs)).numpy()
    assert features.shape == (1, 9)
    np.testing.assert_array_equal(features[:, :7], obs)  # the observation passes unchanged
    assert features[0, 7] == pytest.approx(math.log(10.0 / LIFETIME_SCALE_DAYS), abs=1e-4)
    assert features[0, 8] == pytest.approx(math.log(1 - 100 / 365), abs=1e-5)
    # The ends of the observation space give finite features.
    ends = torch.as_tensor(np.stack([Task().observation_space.low, Task().observation_space.high]))
    assert torch.isfinite(LogFeatures(Task().observation_space)(ends)).all()


def test_linear_decay_holds_the_rate_then_falls_to_zero():
    schedule = linear_decay(1e-3, start=0.6)  # SB3 passes the progress left, 1 -> 0
    assert schedule(1.0) == schedule(0.4) == pytest.approx(1e-3)
    assert schedule(0.2) == pytest.approx(0.5e-3)
    assert schedule(0.0) == 0.0
    assert linear_decay(2e-3)(0.25) == pytest.approx(0.5e-3)  # start 0: over the whole run


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ('shaping = "never_burn_value"\nend_decided = 1.5', "end_decided = 1.5 is invalid"),
        ("end_decided = 0.5", 'end_decided > 0 needs shaping = "never_burn_value"'),
        ("learning_rate_decay_start = 1.0", "learning_rate_decay_start = 1.0 is invalid"),
    ],
)
def test_training_config_checks_name_the_bad_value(tmp_path, extra, message):
    lines = [
        'env_id = "OrbitRaising-v0"',
        "seed = 0",
        "num_envs = 4",
        "total_timesteps = 8",
        extra,
        "[ppo]",
        "[policy]",
    ]
    path = tmp_path / "config.toml"
    path.write_text("\n".join(lines))
    with pytest.raises(ValueError, match=message):
        load_config(path)


def test_shipped_config_is_accepted():
    config = load_config()
    assert config["env_id"] == "OrbitRaising-v0" and config["total_timesteps"] > 0


# --------------------------------------------------------------------------------------
# Strict configs: every key checked, one line naming the file, the key and what is allowed
# --------------------------------------------------------------------------------------

TINY = """\
env_id = "OrbitRaising-v0"
seed = 0
num_envs = 8
total_timesteps = 100
checkpoint_every = 128
eval_every = 128
eval_episodes = 8
shaping = "never_burn_value"
end_decided = 1.0
bootstrap_at_horizon = false
[env]
horizon_steps = 30
[ppo]
n_steps = 16
batch_size = 64
n_epochs = 1
gamma = 1.0
[policy]
net_arch = [16]
initial_coast_logit = 2.0
[normalize]
reward = true
"""


def write(tmp_path, text, name="config.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "n_epochs = 1",
            "n_epochs = 1\nlearning_rat = 1e-3",
            r"unknown key ppo\.'learning_rat'; valid.*learning_rate",
        ),
        ("num_envs = 8", "num_env = 8", r"unknown key 'num_env'; valid keys: env_id, seed, num_envs"),
        ('shaping = "never_burn_value"', 'shapng = "never_burn_value"', r"unknown key 'shapng'"),
        (
            "net_arch = [16]",
            'net_arch = [16]\nactivation = "swish"',
            r"activation = 'swish' is invalid; allowed: tanh",
        ),
        ("num_envs = 8", 'num_envs = "8"', r"num_envs = '8' is invalid; allowed: an integer"),
        ("n_epochs = 1", "n_epochs = 1.5", r"ppo\.n_epochs = 1\.5 is invalid; allowed: an integer"),
        ("gamma = 1.0", "gamma = 1.5", r"ppo\.gamma = 1\.5 is invalid; allowed: a number in \[0, 1\]"),
        ("net_arch = [16]", "net_arch = [16, 0]", r"policy\.net_arch = \[16, 0\] is invalid"),
        ("seed = 0\n", "", r"the key 'seed' is missing"),
        (
            'env_id = "OrbitRaising-v0"',
            'env_id = "CartPole-v1"',
            r"'CartPole-v1' is not an orbit_env environment",
        ),
        (
            "horizon_steps = 30",
            "horizn_steps = 30",
            r"\[env\] unknown keyword 'horizn_steps'; valid.*horizon_steps",
        ),
        ("horizon_steps = 30", "horizon_steps = 0", r"\[env\] horizon_steps=0 is out of range"),
        ("reward = true", "reward = 1", r"normalize\.reward = 1 is invalid; allowed: true or false"),
    ],
)
def test_bad_training_configs_are_one_line_errors_naming_the_file_and_key(tmp_path, old, new, message):
    assert old in TINY
    path = write(tmp_path, TINY.replace(old, new))
    with pytest.raises(ValueError, match=message) as raised:
        load_config(path)
    assert str(raised.value).startswith(str(path)) and "\n" not in str(raised.value)


def test_toml_syntax_errors_name_the_file_and_line(tmp_path):
    path = write(tmp_path, TINY.replace("seed = 0", "seed = = 0"))
    with pytest.raises(ValueError, match=rf"^{path}: not valid TOML: .*line 2"):
        load_config(path)
    with pytest.raises(ValueError, match=r"cannot read the training config .*nowhere\.toml"):
        load_config(tmp_path / "nowhere.toml")


def test_the_cli_says_a_bad_config_in_one_line(tmp_path, capsys):
    from orbit_env.cli import main

    path = write(tmp_path, TINY.replace("num_envs = 8", "num_env = 8"))
    assert main(["train", "--config", str(path), "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown key 'num_env'" in err and "Traceback" not in err


@pytest.mark.parametrize("name", ["ppo.toml", "ppo_uncertain.toml", "ppo_continuous.toml"])
def test_shipped_configs_pass_the_strict_check(name):
    from importlib import resources

    config = load_config(resources.files("orbit_env.agents").joinpath(name))
    assert config["total_timesteps"] > 0


def test_the_docs_recipe_paths_read_the_shipped_recipes_outside_the_repository(tmp_path, monkeypatch):
    # The docs write `--config agents/ppo_uncertain.toml`; from another folder (an installed wheel) no such file
    # exists, and the command had failed "cannot read the training config" (the packaging review, 2026-12-06).
    monkeypatch.chdir(tmp_path)
    with pytest.warns(UserWarning, match="reading the shipped recipe ppo_uncertain.toml"):
        config = load_config("agents/ppo_uncertain.toml")
    assert config["env_id"] == "OrbitRaisingUncertain-v0"
    with pytest.warns(UserWarning):
        assert load_config("ppo_solar.toml")["env_id"] == "OrbitRaisingSolar-v0"
    # A path of another folder (even one named agents), or a name no recipe has, is not replaced: the user's
    # file is missing.
    for missing in ("mine/ppo.toml", "agents/mine.toml", str(tmp_path / "elsewhere" / "agents" / "ppo.toml")):
        with pytest.raises(ValueError, match="cannot read the training config"):
            load_config(missing)
    # A file of that name in the working folder is read, not the shipped recipe.
    (tmp_path / "agents").mkdir()
    from importlib import resources

    own = resources.files("orbit_env.agents").joinpath("ppo.toml").read_text()  # OrbitRaising-v0's recipe
    (tmp_path / "agents" / "ppo_uncertain.toml").write_text(own)
    assert load_config("agents/ppo_uncertain.toml")["env_id"] == "OrbitRaising-v0"


def test_budgets_round_up_to_whole_rollouts():
    from orbit_env.agents.train import timesteps_to_train

    config = {"ppo": {"n_steps": 512}, "num_envs": 64}  # 32768 transitions per update
    assert timesteps_to_train(40_000, config) == 65_536
    assert timesteps_to_train(32_768, config) == 32_768
    assert timesteps_to_train(1, {"ppo": {}, "num_envs": 2}) == 4096  # SB3's default n_steps 2048


# --------------------------------------------------------------------------------------
# orbit-env train: monitor, evaluation callback, --out kept, --resume, overrides
# --------------------------------------------------------------------------------------


def scalars(log_dir):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    tags = set()
    for run in log_dir.iterdir():
        accumulator = EventAccumulator(str(run))
        accumulator.Reload()
        tags |= set(accumulator.Tags()["scalars"])
    return tags


def test_train_logs_episodes_keeps_the_best_resumes_and_keeps_a_finished_run(tmp_path, capsys):
    from stable_baselines3 import PPO

    from orbit_env.agents.train import train
    from orbit_env.cli import main

    path = write(tmp_path, TINY)
    out = tmp_path / "run"
    result = train(path, out, progress=False)
    assert result.trained == result.timesteps == 128  # 100 rounded up to one rollout of 16 x 8
    assert {"rollout/ep_rew_mean", "eval/mean_reward"} <= scalars(result.log_dir)
    assert result.best_model_path == out / "best_model.zip" and result.best_model_path.is_file()
    evaluations = json.loads((out / "evaluations.json").read_text())
    assert [e["timesteps"] for e in evaluations] == [128]
    model = PPO.load(result.model_path, device="cpu")
    assert model.orbit_env == {"env_id": "OrbitRaising-v0", "env": {"horizon_steps": 30}}
    checkpoint = out / "checkpoints" / "rl_model_128_steps.zip"
    assert checkpoint.is_file() and (out / "checkpoints" / "rl_model_vecnormalize_128_steps.pkl").is_file()
    # A finished run is kept: one line, exit 2, and the model untouched.
    stamp = result.model_path.stat().st_mtime_ns
    assert main(["train", "--config", str(path), "--out", str(out), "--no-progress"]) == 2
    assert "exists: a finished run is kept; pass --force" in capsys.readouterr().err
    assert result.model_path.stat().st_mtime_ns == stamp
    # Resume from the checkpoint up to a larger budget: the timesteps continue (it replaces the finished run,
    # so only with force).
    with pytest.raises(ValueError, match="would replace a finished run; pass --force"):
        train(path, out, total_timesteps=384, resume=checkpoint, progress=False)
    resumed = train(path, out, total_timesteps=384, resume=checkpoint, force=True, progress=False)
    assert resumed.trained == 256 and resumed.timesteps == 384
    assert PPO.load(resumed.model_path, device="cpu").num_timesteps == 384
    assert [e["timesteps"] for e in json.loads((out / "evaluations.json").read_text())] == [128, 256, 384]
    with pytest.raises(ValueError, match="no checkpoint at"):
        train(path, out, resume=out / "missing.zip", progress=False)
    # --force overwrites, and the overrides reach the run.
    overrides = ["--seed", "3", "--n-envs", "4", "--env", "OrbitRaisingContinuous-v0", "--timesteps", "64"]
    status = main(["train", "--config", str(path), "--out", str(out), "--force", "--no-progress", *overrides])
    assert status == 0
    assert "trained 64 timesteps" in capsys.readouterr().out
    model = PPO.load(out / "model.zip", device="cpu")
    assert model.orbit_env["env_id"] == "OrbitRaisingContinuous-v0" and model.n_envs == 4 and model.seed == 3


# --------------------------------------------------------------------------------------
# make_sb3_vec_env is monitored, and nothing monitors twice
# --------------------------------------------------------------------------------------


def monitors(venv):
    """The number of VecMonitor wrappers in an SB3 VecEnv's chain."""
    from stable_baselines3.common.vec_env import VecEnvWrapper, VecMonitor

    count = 0
    while isinstance(venv, VecEnvWrapper):
        count += isinstance(venv, VecMonitor)
        venv = venv.venv
    return count


def test_make_sb3_vec_env_is_monitored_for_ep_rew_mean_and_evaluate_policy(tmp_path):
    import warnings

    from stable_baselines3 import PPO
    from stable_baselines3.common.evaluation import evaluate_policy

    from orbit_env.envs.sb3 import make_sb3_vec_env

    venv = make_sb3_vec_env("OrbitRaising-v0", num_envs=8, seed=0, horizon_steps=10)
    assert monitors(venv) == 1
    model = PPO(
        "MlpPolicy", venv, n_steps=16, batch_size=64, n_epochs=1, seed=0, device="cpu", tensorboard_log=str(tmp_path)
    )
    model.learn(total_timesteps=128)
    assert "rollout/ep_rew_mean" in scalars(tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        evaluate_policy(model, venv, n_eval_episodes=8)
    assert not [w for w in caught if "Monitor" in str(w.message)], [str(w.message) for w in caught]
    plain = make_sb3_vec_env("OrbitRaising-v0", num_envs=2, monitor=False)
    assert monitors(plain) == 0


@pytest.mark.parametrize("bootstrap", [False, True])
def test_bootstrap_at_horizon_marks_only_the_missions_that_reach_it_as_truncated(tmp_path, bootstrap):
    # The environments end every mission terminated; `bootstrap_at_horizon = true` has SB3 bootstrap past the
    # horizon (TimeLimit.truncated) where a mission ended in orbit, never where it re-entered.
    from orbit_env.agents.train import load_config, training_env

    text = TINY.replace('shaping = "never_burn_value"', 'shaping = "none"').replace(
        "end_decided = 1.0", "end_decided = 0.0"
    )
    text = text.replace("bootstrap_at_horizon = false", f"bootstrap_at_horizon = {str(bootstrap).lower()}")
    config = load_config(write(tmp_path, text))
    assert config["bootstrap_at_horizon"] is bootstrap and config["shaping"] == "none"
    venv = training_env(config)
    venv.reset()
    seen = {True: 0, False: 0}
    for _ in range(2 * config["env"].get("horizon_steps", 30)):
        _, _, dones, infos = venv.step(np.zeros(venv.num_envs, dtype=np.int64))
        for i in np.flatnonzero(dones):
            assert infos[i]["TimeLimit.truncated"] is (bootstrap and not infos[i]["reentered"])
            seen[infos[i]["reentered"]] += 1
    assert seen[True] > 0 and seen[False] > 0, seen


def test_training_and_sweep_envs_monitor_once(monkeypatch, tmp_path):
    from orbit_env.agents import sweep as sweep_module
    from orbit_env.agents.train import load_config, training_env

    config = load_config(write(tmp_path, TINY))
    assert monitors(training_env(config)) == 1
    seen = []
    monkeypatch.setattr("stable_baselines3.PPO.learn", lambda self, **kwargs: seen.append(monitors(self.get_env())))
    sweep_module.train_trial("OrbitRaising-v0", "ppo", seed=0, timesteps=8, out_dir=tmp_path / "trial", num_envs=2)
    assert seen == [1]


# --------------------------------------------------------------------------------------
# orbit-env train logs the shaped return and the mission's, named apart
# --------------------------------------------------------------------------------------


def scalar_values(log_dir, tag):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    values = []
    for run in log_dir.iterdir():
        accumulator = EventAccumulator(str(run))
        accumulator.Reload()
        if tag in accumulator.Tags()["scalars"]:
            values += [event.value for event in accumulator.Scalars(tag)]
    return values


def test_train_logs_the_missions_return_beside_the_shaped_one(tmp_path):
    from orbit_env.agents.train import train

    # TINY: shaping, decided episodes ended, a 30-step mission; two rollouts.
    result = train(
        write(tmp_path, TINY.replace("eval_every = 128", "eval_every = 0")),
        tmp_path / "run",
        total_timesteps=256,
        progress=False,
    )
    mission = scalar_values(result.log_dir, "mission/return")
    shaped = scalar_values(result.log_dir, "rollout/shaped_return")
    assert len(mission) == len(shaped) == 2
    # The mission's return is days of a 30-step mission less the propellant's cost; the shaped one is
    # that less the start's potential (the days coasting earns), which is > 0 for every start here.
    assert all(0.0 < m <= 30.0 for m in mission)
    assert all(m > s for m, s in zip(mission, shaped, strict=True))
    np.testing.assert_allclose(shaped, scalar_values(result.log_dir, "rollout/ep_rew_mean"), rtol=1e-6)
    # Without shaping the two are one: only mission/return, equal to SB3's ep_rew_mean.
    plain = TINY.replace('shaping = "never_burn_value"', 'shaping = "none"').replace("end_decided = 1.0", "")
    plain = plain.replace("eval_every = 128", "eval_every = 0")
    result = train(write(tmp_path, plain, "plain.toml"), tmp_path / "plain", total_timesteps=256, progress=False)
    assert scalar_values(result.log_dir, "rollout/shaped_return") == []
    np.testing.assert_allclose(
        scalar_values(result.log_dir, "mission/return"), scalar_values(result.log_dir, "rollout/ep_rew_mean"), rtol=1e-6
    )
