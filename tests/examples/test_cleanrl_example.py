"""The single-file PPO example runs end to end on a tiny budget (a smoke test, not a learning test)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "cleanrl_ppo.py"


def test_cleanrl_example_trains_saves_and_prints_its_capture(tmp_path):
    pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")  # orbit_env.agents.shaping, the example's potential
    weights = tmp_path / "ppo.pt"
    # A coarse DP (48 states, some 7 s to solve in the tests' empty cache, against 27 s for
    # orbit-env evaluate's) and 100 missions keep the run well under 30 s.
    command = [sys.executable, str(EXAMPLE), "--total-timesteps", "2048", "--num-envs", "4"]
    command += ["--eval-episodes", "100", "--dp-grid", "48", "--save", str(weights)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "iteration 1/1, step 2048:" in done.stdout
    assert re.search(r"^capture -?\d+\.\d%: 2048 timesteps, training \d+ s", done.stdout, re.MULTILINE), done.stdout
    assert re.search(r"^ppo +\d+\.\d \+- ", done.stdout, re.MULTILINE)  # the agent's row in the table
    torch = pytest.importorskip("torch")
    assert "actor.4.bias" in torch.load(weights)
