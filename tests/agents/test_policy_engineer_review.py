"""What an engineer scoring a hand-coded policy on the solar tasks found (2026-12-06): each failed before its fix."""

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the ids)
from orbit_env.agents.certify import Certificate, certify, format_certificate
from orbit_env.agents.evaluate import predicted_actions
from orbit_env.agents.solar import fly, starts
from orbit_env.envs import SOLAR_CONTINUOUS_ENV_ID, SOLAR_ENV_ID
from orbit_env.envs.solar_task import SolarMission, SolarTask


class BurnAll:
    def predict(self, obs, state=None, episode_start=None, deterministic=True):
        return np.ones((len(obs), 1), np.float32), state


def test_the_solar_certificate_refuses_a_policy_it_would_not_certify():
    # It searched against each mission's DP and printed the result under the policy's name.
    for env_id in (SOLAR_ENV_ID, SOLAR_CONTINUOUS_ENV_ID):
        with pytest.raises(ValueError, match="searches plans against each mission's DP policy only"):
            certify(env_id, episodes=1, policy=BurnAll(), workers=1)


@pytest.mark.parametrize(
    ("continuous", "burn", "allowed"),
    [
        (False, 7.0, r"the burn sizes \(0.0, 5.0, 10.0, 20.0\) m/s"),
        (False, 50.0, "the burn sizes"),
        (True, 50.0, "0 to 20 m/s"),
        (True, np.nan, "0 to 20 m/s"),
        (True, -1.0, "0 to 20 m/s"),
    ],
)
def test_fly_refuses_burns_the_environment_would_not_fly(continuous, burn, allowed):
    task = SolarTask(mission=SolarMission(solar_split="test"), continuous=continuous)
    options = starts(task, 2, 12345)
    with pytest.raises(ValueError, match=f"a burn of {float(burn)!r} m/s asked for; allowed: {allowed}"):
        fly(task, options, lambda states: np.where(states.steps == 0, burn, 0.0))
    # The twin flies any burn in its range (7.5 m/s is no size of the discrete task).
    if continuous:
        flown = fly(task, options, lambda states: np.where(states.steps == 0, 7.5, 0.0))
        assert np.all(flown.dv_m_s >= 7.5 - 1e-9)


def test_booleans_are_no_actions():
    twin = gym.make(SOLAR_CONTINUOUS_ENV_ID)
    twin.reset(seed=0)
    with pytest.raises(ValueError, match="action=True is invalid"):
        twin.step(True)

    class Yes:
        def predict(self, obs, state=None, episode_start=None, deterministic=True):
            return np.ones(len(obs), dtype=bool), state

    with pytest.raises(ValueError, match=r"Yes\.predict returned booleans as actions"):
        predicted_actions(Yes(), np.zeros((3, 11), np.float32), gym.spaces.Discrete(4))


def test_the_solar_vector_env_gives_every_missions_start_back():
    envs = gym.make_vec(SOLAR_CONTINUOUS_ENV_ID, num_envs=3, horizon_steps=4)
    with pytest.raises(RuntimeError, match="no state before reset"):
        envs.unwrapped.start_options  # noqa: B018
    envs.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(6):  # past the end of the first missions: rows restarted automatically
        envs.step(rng.uniform(-1.0, 1.0, (3, 1)).astype(np.float32))
    start = envs.unwrapped.start_options
    first, _ = envs.reset(options=start)
    single = gym.make(SOLAR_CONTINUOUS_ENV_ID, horizon_steps=4)
    for i in range(3):
        obs, _ = single.reset(options={k: float(v[i]) for k, v in start.items()})
        assert np.array_equal(obs, first[i])


def test_a_certificate_without_a_better_plan_names_no_worst_start():
    zeros = np.zeros(2)
    summary = Certificate(
        SOLAR_ENV_ID, 1, zeros + 1800.0, zeros + 1800.0, zeros + 400.0, zeros + 410.0, 1.0, 10
    ).summary()
    assert "on no start a better plan" in format_certificate(summary) and "episode 0" not in format_certificate(summary)
