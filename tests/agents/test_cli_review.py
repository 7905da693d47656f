"""The agents' commands refuse what they cannot do, in one line naming the flag (a review of the command line).

Each test failed before its fix.
"""

import json
import re
import sys

import pytest

pytest.importorskip("stable_baselines3")

import torch
from stable_baselines3 import PPO

from orbit_env.agents.train import TrainingInterrupted, newest_checkpoint, train
from orbit_env.cli import main


def status(args) -> int:
    """The command's exit status, also where argparse exits (a flag's value refused by its type)."""
    try:
        return main(args)
    except SystemExit as exit:
        return exit.code


def one_line_error(capsys) -> str:
    """The error a command printed: one line on stderr, no traceback."""
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# --------------------------------------------------------------------------------------
# A negative seed, and a flag's value blamed on the flag
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env", ["OrbitRaising-v0", "OrbitRaisingSolar-v0"])
def test_evaluate_refuses_a_negative_seed_in_one_line(capsys, env):
    # Gymnasium's "Seed must be greater or equal to zero" had ended the command in a traceback.
    assert main(["evaluate", "--env", env, "--no-dp", "--episodes", "2", "--seed", "-1"]) == 2
    assert "--seed -1 is out of range; allowed: an integer at least 0" in one_line_error(capsys)
    assert main(["evaluate", "--certify", "--episodes", "2", "--seed", "-1"]) == 2
    assert "--seed -1 is out of range" in one_line_error(capsys)


def test_the_api_refuses_a_negative_seed_naming_it():
    from orbit_env.agents.evaluate import hand_coded_policies, run_episodes

    with pytest.raises(ValueError, match=r"^seed=-1 is out of range; allowed: an integer at least 0$"):
        run_episodes("OrbitRaising-v0", hand_coded_policies("OrbitRaising-v0")["never"], 2, -1)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--seed", "-1"], "--seed -1 is out of range; allowed: an integer 0 to 4294967295"),
        (["--env", "Nope-v0"], "--env Nope-v0 is not an orbit_env environment; allowed: OrbitRaising-v0"),
    ],
)
def test_train_blames_a_flags_value_on_the_flag_not_on_the_config_file(tmp_path, capsys, flags, message):
    out = tmp_path / "run"
    assert main(["train", "--out", str(out), "--no-progress", *flags]) == 2
    err = one_line_error(capsys)
    assert message in err and "ppo.toml" not in err
    assert not out.exists()


def test_train_names_its_arguments_as_the_caller_gave_them(tmp_path):
    with pytest.raises(ValueError, match=r"^seed=-1 is out of range"):
        train(out_dir=tmp_path / "run", seed=-1, progress=False)
    with pytest.raises(ValueError, match=r"^env_id='Nope-v0' is not an orbit_env environment"):
        train(out_dir=tmp_path / "run", env_id="Nope-v0", progress=False)
    assert not (tmp_path / "run").exists()


# --------------------------------------------------------------------------------------
# No NaN in what the commands write: an undefined number is JSON null
# --------------------------------------------------------------------------------------


def strict_json(text: str):
    """JSON as a strict parser reads it: NaN and Infinity are not JSON."""

    def refused(constant):
        raise AssertionError(f"{constant} in the JSON: {text[:200]}")

    return json.loads(text, parse_constant=refused)


def test_one_episode_has_no_standard_error_json_null_and_said_in_the_table(capsys):
    assert main(["evaluate", "--no-dp", "--episodes", "1", "--json"]) == 0
    paired = strict_json(capsys.readouterr().out)["paired_difference"]
    assert paired["stderr"] is None and paired["mean"] == pytest.approx(paired["mean"])
    assert main(["evaluate", "--no-dp", "--episodes", "1"]) == 0
    table = capsys.readouterr().out
    assert "nan" not in table and "(one episode: no standard error)" in table


def test_a_curve_point_without_a_capture_is_null_not_nan():
    from orbit_env.agents.curves import aggregate, format_curves

    # Never burning as good as the DP on the episodes: no capture at that point, for any run.
    runs = [{"algo": "ppo", "seed": s, "points": [[0, 1.0, None], [128, 1.0, 0.5]], "wall_s": 1.0} for s in (0, 1)]
    curve = aggregate(runs)["ppo"]
    assert curve["iqm_capture"][0] is curve["ci95_low"][0] is curve["ci95_high"][0] is None
    assert curve["iqm_capture"][1] == pytest.approx(0.5)
    strict_json(json.dumps({"curves": {"ppo": curve}}))
    text = format_curves({"env": "OrbitRaising-v0", "episodes": 2, "eval_seed": 1, "curves": {"ppo": curve}})
    assert "nan" not in text and "no capture" in text


# --------------------------------------------------------------------------------------
# train: every number of the config checked before anything is written to --out
# --------------------------------------------------------------------------------------

TINY = """\
env_id = "OrbitRaising-v0"
seed = 0
num_envs = 8
total_timesteps = 100
shaping = "none"
[env]
horizon_steps = 30
[ppo]
n_steps = 16
batch_size = 64
n_epochs = 1
[policy]
net_arch = [16]
initial_coast_logit = 2.0
"""


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # Stable-Baselines3's AssertionError, in a traceback
        ("batch_size = 64", "batch_size = 1", r"ppo\.batch_size = 1 is invalid; allowed: an integer >= 2"),
        ("num_envs = 8", "num_envs = 1", None),  # with n_steps = 1 below
        # torch's "Expected parameter logits ... found invalid values", after config.json and tensorboard/
        ("initial_coast_logit = 2.0", "initial_coast_logit = nan", r"policy\.initial_coast_logit = nan is invalid"),
        # trained on, without an error
        ("n_epochs = 1", "n_epochs = 1\nclip_range = -0.2", r"ppo\.clip_range = -0\.2 is invalid"),
        ("n_epochs = 1", "n_epochs = 1\nmax_grad_norm = -1.0", r"ppo\.max_grad_norm = -1\.0 is invalid"),
        ("n_epochs = 1", "n_epochs = 1\nent_coef = -0.1", r"ppo\.ent_coef = -0\.1 is invalid"),
        ("n_epochs = 1", "n_epochs = 1\nlearning_rate = inf", r"ppo\.learning_rate = inf is invalid"),
        ("n_epochs = 1", "n_epochs = 1\ntarget_kl = 'x'", r"ppo\.target_kl = 'x' is invalid; allowed: a number"),
        ("n_epochs = 1", "n_epochs = 1\nuse_sde = true", r"ppo\.use_sde = true is invalid for OrbitRaising-v0"),
        ("n_epochs = 1", "n_epochs = 1\nrollout_buffer_kwargs = {}", r"unknown key ppo\.'rollout_buffer_kwargs'"),
        ("initial_coast_logit = 2.0", "log_std_init = -100.0", r"policy\.log_std_init = -100\.0 is invalid"),
        ("seed = 0", "seed = 4294967296", r"seed = 4294967296 is invalid; allowed: an integer from 0 to 4294967295"),
    ],
)
def test_train_refuses_a_config_number_that_would_fail_or_mislead_before_writing_anything(
    tmp_path, capsys, old, new, message
):
    text = TINY.replace(old, new)
    if message is None:
        text = text.replace("n_steps = 16", "n_steps = 1")
        message = r"ppo\.n_steps x num_envs = 1 is invalid; allowed: at least 2"
    assert old in TINY and text != TINY
    config = tmp_path / "my.toml"
    config.write_text(text)
    out = tmp_path / "run"
    assert main(["train", "--config", str(config), "--out", str(out), "--no-progress"]) == 2
    err = one_line_error(capsys)
    assert re.search(message, err) and err.startswith(f"orbit-env: error: {config}: ")
    assert not out.exists()  # no config.json, no tensorboard/


def test_every_number_of_a_training_config_has_its_range():
    from orbit_env.agents.train import NUMBER_RANGES, POLICY_KEYS, TOP_KEYS, _ppo_schema

    def numbers(schema, table=""):
        kinds = {key: kind if isinstance(kind, tuple) else (kind,) for key, (kind, _) in schema.items()}
        return {table + key for key, kind in kinds.items() if int in kind or float in kind}

    every = numbers(TOP_KEYS) | numbers(_ppo_schema(), "ppo.") | numbers(POLICY_KEYS, "policy.")
    assert every == set(NUMBER_RANGES)


# --------------------------------------------------------------------------------------
# train: a checkpoint named N holds the policy trained on N timesteps
# --------------------------------------------------------------------------------------


def policy_of(path):
    """A saved model's policy parameters."""
    return PPO.load(path, device="cpu").policy.state_dict()


def test_checkpoints_are_taken_between_rollouts_and_named_by_the_steps_learned(tmp_path, ctrl_c_at):
    # Checkpoints every 64 timesteps in rollouts of 128: SB3's way had saved inside a rollout, a policy not
    # updated on the steps its name counted (a kill at 20 s of a 10M-step rollout left rl_model_4000000 of
    # an untrained policy, which the next command offered to resume, skipping 4M steps of training).
    config = tmp_path / "tiny.toml"
    config.write_text(TINY.replace("shaping", "checkpoint_every = 64\nshaping"))
    out = tmp_path / "run"
    train(config, out, total_timesteps=256, progress=False)
    names = sorted(p.name for p in (out / "checkpoints").glob("rl_model_*_steps.zip"))
    assert names == ["rl_model_128_steps.zip", "rl_model_256_steps.zip"]
    # The checkpoint at 128 is the policy after the first update: a run of 128 steps ends with it.
    one = train(config, tmp_path / "one", total_timesteps=128, progress=False)
    after_one, checkpoint = policy_of(one.model_path), policy_of(out / "checkpoints" / "rl_model_128_steps.zip")
    assert all(torch.equal(after_one[key], checkpoint[key]) for key in after_one)
    final, last = policy_of(out / "model.zip"), policy_of(out / "checkpoints" / "rl_model_256_steps.zip")
    assert all(torch.equal(final[key], last[key]) for key in final)
    # Stopped inside its first rollout, the run keeps step 0, and that is what the next command offers to resume.
    stopped = tmp_path / "stopped"
    with pytest.raises(TrainingInterrupted) as stop:
        train(config, stopped, total_timesteps=256, progress=False, extra_callbacks=[ctrl_c_at(12)])
    assert stop.value.timesteps == 0 and newest_checkpoint(stopped) == stop.value.checkpoint
    with pytest.raises(ValueError, match=r"continue it with --resume .*rl_model_0_steps\.zip"):
        train(config, stopped, total_timesteps=256, progress=False)


def test_validation_scores_the_policy_updated_on_the_steps_it_is_labelled_with(tmp_path):
    # Scored every 128 timesteps in rollouts of 128: the score at 128 had been taken at the rollout's last step,
    # before the update, and the final policy was then not scored (its label, 128, was taken).
    config = tmp_path / "tiny.toml"
    config.write_text(TINY.replace("shaping", "eval_every = 128\neval_episodes = 4\nshaping"))
    out = tmp_path / "run"
    train(config, out, total_timesteps=128, progress=False)
    assert [e["timesteps"] for e in json.loads((out / "evaluations.json").read_text())] == [128]
    final, best = policy_of(out / "model.zip"), policy_of(out / "best_model.zip")  # the one score's model
    assert all(torch.equal(final[key], best[key]) for key in final)
    # Two rollouts: the score at 128 is taken at the second rollout's start (after the first update), the
    # score at 256 at the end.
    again = tmp_path / "again"
    train(config, again, total_timesteps=256, progress=False)
    assert [e["timesteps"] for e in json.loads((again / "evaluations.json").read_text())] == [128, 256]


# --------------------------------------------------------------------------------------
# No flag silently ignored: refused in one line
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "message"),
    [
        # they set the DP policy that --no-dp leaves out
        (["evaluate", "--no-dp", "--dp-lookahead", "2"], "--no-dp leaves the DP policy out: it takes no --dp-lookah"),
        (["evaluate", "--no-dp", "--dp-rollout"], "--no-dp leaves the DP policy out: it takes no --dp-rollout"),
        (["evaluate", "--env", "OrbitRaisingSolar-v0", "--no-dp", "--dp-rollout"], "it takes no --dp-rollout"),
        # a row without a name (the algorithm's had been used)
        (["evaluate", "--no-dp", "--name", ""], "argument --name: a blank name (''); give the row a name"),
        (["evaluate", "--no-dp", "--name", " "], "argument --name: a blank name (' ')"),
        # the current folder, never meant
        (["train", "--out", ""], "argument --out: an empty path; give a folder"),
        (["curves", "--out", ""], "argument --out: an empty path; give a folder"),
        (["sweep", "--out", ""], "argument --out: an empty path; give a folder"),
        # an empty file name (it had been taken for no flag)
        (["evaluate", "--no-dp", "--returns", ""], "argument --returns: an empty file name"),
        (["evaluate", "--no-dp", "--plot", ""], "argument --plot: an empty file name"),
        (["curves", "--out", "curves", "--plot", ""], "argument --plot: an empty file name"),
        (["evaluate", "--certify", "--plot", ""], "argument --plot: an empty file name"),
        (["evaluate", "--certify", "--plot", "box.png"], "--certify searches plans against the DP policy: it takes no"),
    ],
)
def test_a_flag_that_would_do_nothing_is_refused(tmp_path, monkeypatch, capsys, args, message):
    from orbit_env.agents import curves as curves_module
    from orbit_env.agents import sweep as sweep_module
    from orbit_env.agents import train as train_module

    def ran(*args, **kwargs):
        raise AssertionError("the command ran")  # (a refused command returns before; this one would train)

    for module, name in ((train_module, "train"), (curves_module, "curves"), (sweep_module, "sweep")):
        monkeypatch.setattr(module, name, ran)
    monkeypatch.chdir(tmp_path)
    if args[0] == "evaluate":
        args = [*args, "--episodes", "2"]  # quick, if it ran
    assert status(args) == 2
    assert message in one_line_error(capsys)
    assert not list(tmp_path.iterdir())  # nothing written in the current folder


def test_the_api_refuses_a_blank_row_name():
    from orbit_env.agents.evaluate import all_policies

    with pytest.raises(ValueError, match=r"^learned_name='' is blank"):
        all_policies("OrbitRaising-v0", include_dp=False, learned_name="")


# --------------------------------------------------------------------------------------
# sweep --cpus: what is wrong with it, said so
# --------------------------------------------------------------------------------------


def test_sweep_takes_cpus_for_a_ray_it_starts_and_says_why_not_for_a_running_cluster(tmp_path, monkeypatch, capsys):
    # "--cpus 1 --address local" had been refused as "cpus=1 is invalid; allowed: an integer >= 1, for a local
    # Ray only": address "local" is Ray's word for starting a new local Ray, where num_cpus applies.
    monkeypatch.setitem(sys.modules, "ray", None)  # Ray absent (as here): the checks come before its import
    base = ["sweep", "--algos", "a2c", "--seeds", "1", "--timesteps", "64", "--episodes", "2", "--no-dp"]
    assert main([*base, "--cpus", "1", "--address", "local", "--out", str(tmp_path / "local")]) == 2
    assert "orbit-env sweep runs on Ray Tune: pip install 'orbit-env[cluster]'" in one_line_error(capsys)
    assert main([*base, "--cpus", "1", "--address", "ray://head:10001", "--out", str(tmp_path / "cluster")]) == 2
    err = one_line_error(capsys)
    assert "--cpus sets the CPUs of a Ray the sweep starts" in err and "--address ray://head:10001" in err
    assert "is invalid" not in err
    from orbit_env.agents.sweep import sweep

    with pytest.raises(ValueError, match=r"^cpus=1 sets the CPUs of a Ray the sweep starts .*address='auto'"):
        sweep("OrbitRaising-v0", ["a2c"], 1, 64, tmp_path / "api", address="auto", cpus=1, include_dp=False)
    with pytest.raises(ValueError, match=r"^cpus=0 is invalid; allowed: an integer >= 1$"):
        sweep("OrbitRaising-v0", ["a2c"], 1, 64, tmp_path / "api", cpus=0, include_dp=False)
