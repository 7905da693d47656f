"""A training run stopped or started again loses nothing (a review of long jobs killed at any moment, 2026-12-06).

Each test failed before its fix: an unfinished run's folder was trained over from zero, Ctrl-C saved nothing
and said nothing, --resume replaced a finished model and continued under other settings, SIGTERM left no
checkpoint.
"""

import json
import os
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")

from stable_baselines3 import PPO

from orbit_env.agents.train import TrainingInterrupted, newest_checkpoint, train
from orbit_env.cli import main

TINY = """\
env_id = "OrbitRaising-v0"
seed = 0
num_envs = 8
total_timesteps = 256
checkpoint_every = 128
eval_every = 0
shaping = "none"
[env]
horizon_steps = 30
[ppo]
n_steps = 16
batch_size = 64
n_epochs = 1
gamma = 1.0
[policy]
net_arch = [16]
[normalize]
reward = true
"""


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def test_an_interrupted_run_keeps_its_last_whole_rollout_and_resumes(config, tmp_path, ctrl_c_at):
    out = tmp_path / "run"
    with pytest.raises(TrainingInterrupted) as stop:
        train(config, out, progress=False, extra_callbacks=[ctrl_c_at(20)])  # 160 timesteps collected
    assert stop.value.timesteps == 128 and stop.value.checkpoint == out / "checkpoints" / "rl_model_128_steps.zip"
    assert PPO.load(stop.value.checkpoint, device="cpu").num_timesteps == 128
    assert (out / "checkpoints" / "rl_model_vecnormalize_128_steps.pkl").is_file()
    assert not list((out / "checkpoints" / ".partial").iterdir())  # each file moved in whole
    # Started again as it was, the folder is refused (it had been trained over from zero) ...
    with pytest.raises(ValueError, match=r"holds an unfinished run; continue it with --resume .*rl_model_128_steps"):
        train(config, out, progress=False)
    # ... resumed under other settings too, and resumed as it was, it finishes.
    with pytest.raises(ValueError, match=r"is of a run trained with other settings \(seed differ"):
        train(config, out, seed=5, resume=stop.value.checkpoint, progress=False)
    done = train(config, out, resume=stop.value.checkpoint, progress=False)
    assert done.timesteps == 256 and done.trained == 128 and newest_checkpoint(out).name == "rl_model_256_steps.zip"


def test_a_resumed_runs_tensorboard_curves_do_not_double_back(config, tmp_path):
    # A run resumed from a checkpoint older than its last logs (SIGKILL, a crash, an older checkpoint chosen)
    # had logged 384 and 512 twice: TensorBoard drew each curve back to 256 and on again.
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    config.write_text(TINY.replace("total_timesteps = 256", "total_timesteps = 512"))
    out = tmp_path / "run"
    train(config, out, progress=False)
    train(config, out, resume=out / "checkpoints" / "rl_model_256_steps.zip", force=True, progress=False)
    assert [p.name for p in (out / "tensorboard").iterdir()] == ["ppo_1"]  # the run's one folder, continued
    logs = EventAccumulator(str(out / "tensorboard" / "ppo_1"))
    logs.Reload()
    for tag in logs.Tags()["scalars"]:  # each curve once along the timesteps
        steps = [event.step for event in logs.Scalars(tag)]
        assert steps == sorted(set(steps)), tag
    for tag in ("rollout/ep_rew_mean", "mission/return"):  # logged after every rollout, by both runs
        assert [event.step for event in logs.Scalars(tag)] == [128, 256, 384, 512], tag


def test_force_starts_over_without_the_old_runs_files(config, tmp_path):
    out = tmp_path / "run"
    train(config, out, progress=False)
    assert newest_checkpoint(out).name == "rl_model_256_steps.zip"
    train(config, out, total_timesteps=64, force=True, progress=False)  # one rollout: 128 timesteps
    # The first run's checkpoint at 256 would have stood beside this one's, the newest of the folder.
    assert sorted(p.name for p in (out / "checkpoints").glob("rl_model_*.zip")) == ["rl_model_128_steps.zip"]
    assert PPO.load(out / "model.zip", device="cpu").num_timesteps == 128


def test_the_command_line_says_how_to_continue(config, tmp_path, capsys, monkeypatch):
    checkpoint = tmp_path / "run" / "checkpoints" / "rl_model_128_steps.zip"

    def interrupted(*args, **kwargs):
        raise TrainingInterrupted(checkpoint, 128)

    monkeypatch.setattr("orbit_env.agents.train.train", interrupted)
    status = main(["train", "--config", str(config), "--out", str(tmp_path / "run"), "--seed", "2", "--no-progress"])
    assert status == 130
    err = capsys.readouterr().err
    assert f"interrupted at 128 timesteps (the last whole rollout), saved in {checkpoint}" in err
    again = shlex.split(err.strip().splitlines()[-1])
    run = str(tmp_path / "run")
    assert again == [
        "orbit-env",
        "train",
        "--config",
        str(config),
        "--seed",
        "2",
        "--out",
        run,
        "--resume",
        str(checkpoint),
    ]
    # A finished run's resume, interrupted: continuing it replaces the model again, so the command says --force.
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "model.zip").write_bytes(b"a finished run's model")
    assert main(["train", "--out", run, "--resume", str(checkpoint), "--force", "--no-progress"]) == 130
    assert shlex.split(capsys.readouterr().err.strip().splitlines()[-1])[-1] == "--force"


def test_sigterm_stops_training_as_ctrl_c_does(config, tmp_path):
    # A session's end (SIGTERM) had killed the run with no checkpoint beyond the last periodic one, silently.
    out = tmp_path / "run"
    config.write_text(TINY.replace("total_timesteps = 256", "total_timesteps = 1000000"))
    command = [sys.executable, "-m", "orbit_env.cli", "train", "--config", str(config), "--out", str(out)]
    process = subprocess.Popen([*command, "--no-progress"], stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while newest_checkpoint(out) is None and time.monotonic() < deadline and process.poll() is None:
            time.sleep(0.2)
        assert newest_checkpoint(out) is not None, "training never wrote its first checkpoint"
        os.kill(process.pid, signal.SIGTERM)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:  # a failed test leaves no run training towards a million steps
            process.kill()
            process.wait()
    assert process.returncode == 130, err
    assert "interrupted at" in err and "--resume" in err
    saved = Path(shlex.split(err.strip().splitlines()[-1])[-1])
    assert PPO.load(saved, device="cpu").num_timesteps % 128 == 0  # whole rollouts, a loadable file
    settings = json.loads((out / "config.json").read_text())
    assert settings["total_timesteps"] == 1000000


def test_a_resume_continues_its_runs_budget_and_settings_whatever_out_is(config, tmp_path, ctrl_c_at):
    # A plain --resume had trained on to the TOML's budget (256 here) instead of the run's (--timesteps 384), and
    # the settings were those of --out's folder, not of the checkpoint's run.
    out = tmp_path / "run"
    with pytest.raises(TrainingInterrupted) as stop:
        train(config, out, total_timesteps=384, progress=False, extra_callbacks=[ctrl_c_at(20)])
    with pytest.raises(ValueError, match=r"is of a run trained with other settings \(seed differ"):
        train(config, tmp_path / "elsewhere", seed=5, resume=stop.value.checkpoint, progress=False)
    done = train(config, out, resume=stop.value.checkpoint, progress=False)
    assert done.timesteps == 384


def test_an_interrupt_while_the_model_is_written_leaves_a_checkpoint_not_half_a_model(config, tmp_path, monkeypatch):
    import orbit_env.agents.train as train_module

    written = train_module._save_whole

    def interrupted(model, path):
        if path.name == "model.zip":
            raise KeyboardInterrupt
        written(model, path)

    monkeypatch.setattr(train_module, "_save_whole", interrupted)
    out = tmp_path / "run"
    with pytest.raises(TrainingInterrupted) as stop:
        train(config, out, progress=False)
    assert stop.value.timesteps == 256 and not (out / "model.zip").exists()
    import pickle  # raised in a worker process (curves, sweeps), it reaches the parent whole

    again = pickle.loads(pickle.dumps(stop.value))
    assert (again.checkpoint, again.timesteps) == (stop.value.checkpoint, 256)


def test_a_run_stopped_in_its_final_evaluation_resumes_to_that_evaluation(config, tmp_path, monkeypatch):
    # The checkpoint at the budget resumed with nothing to train: the final evaluation then ran on a callback
    # learn had never set up (AttributeError: no attribute 'model'), so the printed command failed.
    import orbit_env.agents.train as train_module

    config.write_text(TINY.replace("eval_every = 0", "eval_every = 128\neval_episodes = 4"))
    scored = train_module.BestModelCallback.evaluate

    def stopped_at_the_end(self):
        if self.model.num_timesteps == 256:
            raise KeyboardInterrupt
        return scored(self)

    monkeypatch.setattr(train_module.BestModelCallback, "evaluate", stopped_at_the_end)
    out = tmp_path / "run"
    with pytest.raises(TrainingInterrupted) as stop:
        train(config, out, progress=False)
    monkeypatch.setattr(train_module.BestModelCallback, "evaluate", scored)
    done = train(config, out, resume=stop.value.checkpoint, progress=False)
    assert done.trained == 0 and done.timesteps == 256
    assert [e["timesteps"] for e in json.loads((out / "evaluations.json").read_text())] == [128, 256]


def test_the_settings_a_resume_checks_are_its_runs_wherever_the_checkpoint_file_is(config, tmp_path):
    # A checkpoint copied out of checkpoints/ had escaped the check (and overwritten the run's config.json); a
    # config.json two folders up that was no run's had crashed the command with a KeyError.
    out = tmp_path / "run"
    train(config, out, total_timesteps=128, progress=False)
    elsewhere = tmp_path / "copies" / "sub"
    elsewhere.mkdir(parents=True)
    copy = elsewhere / "rl_model_128_steps.zip"
    copy.write_bytes((out / "checkpoints" / "rl_model_128_steps.zip").read_bytes())
    with pytest.raises(ValueError, match=r"other settings \(num_envs, seed differ"):
        train(config, out, seed=5, num_envs=4, resume=copy, force=True, progress=False)
    (tmp_path / "copies" / "checkpoints").mkdir()
    (tmp_path / "copies" / "config.json").write_text('{"name": "not a run"}')
    inside = tmp_path / "copies" / "checkpoints" / copy.name
    inside.write_bytes(copy.read_bytes())
    with pytest.raises(ValueError, match="is not a training run's settings"):
        train(config, tmp_path / "other", resume=inside, progress=False)


def test_an_interrupt_during_a_files_write_waits_for_the_file_then_stops_the_run(tmp_path):
    # A SIGTERM inside torch's zip writer had been replaced by the writer's own error ("unexpected pos") on
    # closing the cut file: the run ended with a traceback and status 1, not its checkpoint and 130 (seen in
    # CI, test_sigterm_stops_training_as_ctrl_c_does). The signal now waits for the write, then acts as before.
    import orbit_env.agents.train as train_module

    written = []

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    def write(file):
        os.kill(os.getpid(), signal.SIGTERM)  # arrives mid-write
        time.sleep(0.05)  # (delivered here, were it not held)
        file.write_text("whole")
        written.append(file)

    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        with pytest.raises(KeyboardInterrupt):
            train_module._written_whole(tmp_path / "model.zip", write)
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert written and (tmp_path / "model.zip").read_text() == "whole"
