"""Training options of ``orbit-env train``: the log features, the learning-rate schedule, config checks."""

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
        ('shaping = "never_burn_value"\nend_decided = 1.5', "end_decided=1.5 is invalid"),
        ("end_decided = 0.5", 'end_decided > 0 needs shaping = "never_burn_value"'),
        ("learning_rate_decay_start = 1.0", "learning_rate_decay_start=1.0 is invalid"),
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
