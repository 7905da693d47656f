"""The solar task's operators' rules as policies: SB3's ``predict`` in either id's space, one registry of rules."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents import solar
from orbit_env.envs import SOLAR_CONTINUOUS_ENV_ID, SOLAR_ENV_ID, solar_task
from orbit_env.envs.solar_task import SolarMission, SolarTask

#: Fixed thresholds (the tuning itself is not what these tests check: it takes 30 s).
SETTINGS = {"perigee_threshold": (420.0, 40.0), "life_threshold": (1.0, 20.0)}


def _rules(task: SolarTask) -> list[solar.Never]:
    return [rule(task) if rule.grid is None else rule(task, *SETTINGS[rule.name]) for rule in solar.SOLAR_RULES]


@pytest.mark.parametrize("env_id", [SOLAR_ENV_ID, SOLAR_CONTINUOUS_ENV_ID])
def test_each_rule_flown_by_predict_in_the_environment_returns_what_fly_gives(env_id):
    """A rule's ``predict`` in the environment (one observation at a time) flies the mission `fly` flies.

    `fly` is the yardsticks' own loop (`evaluate_solar`'s rows); the environment is what a user's
    harness steps. Same missions, same burns: the returns agree to rounding (1e-9 day).
    """
    continuous = env_id == SOLAR_CONTINUOUS_ENV_ID
    task = SolarTask(mission=SolarMission(solar_split="test"), continuous=continuous)
    options = solar.starts(task, 2, seed=5)
    env = gymnasium.make(env_id, solar_split="test")
    for rule in _rules(task):
        flown = solar.fly(task, options, solar.by_observation(task, rule))
        for i in range(2):
            obs, _ = env.reset(options={key: float(value[i]) for key, value in options.items()})
            total, done = 0.0, False
            while not done:
                action, _ = rule.predict(obs)
                assert env.action_space.contains(action), (rule.name, action)
                obs, reward, done, _, _ = env.step(action)
                total += reward
            assert total == pytest.approx(flown.returns[i], abs=1e-9), rule.name


def test_predict_takes_a_batch_and_refuses_another_shape():
    task = SolarTask(mission=SolarMission(solar_split="test"))
    obs = solar_task.observe(task, solar_task.start(task, np.random.default_rng(3), 4))
    for rule in _rules(task):
        actions, state = rule.predict(obs)
        assert state is None
        np.testing.assert_array_equal(actions, rule.actions(obs))
    with pytest.raises(ValueError, match=r"shape \(11,\) or \(n, 11\), got shape \(4, 7\)"):
        solar.Never(task).predict(obs[:, :7])


def test_a_rule_added_to_the_registry_is_scored_beside_the_others(monkeypatch):
    """A new rule is its class and its entry in `SOLAR_RULES`: the evaluation's rows follow the registry."""

    class Half(solar.Never):
        name = "half"

        def actions(self, obs):
            return np.ones(len(obs), dtype=np.int64)

    monkeypatch.setattr(solar, "SOLAR_RULES", (*solar.SOLAR_RULES, Half))
    monkeypatch.setattr(solar, "SOLAR_HAND_CODED", (*solar.SOLAR_HAND_CODED, "half"))
    monkeypatch.setattr(solar, "tune", lambda task: SETTINGS)
    evaluation = solar.evaluate_solar(2, 11, include_dp=False)
    assert list(evaluation.flown) == [*solar.SOLAR_HAND_CODED]
    assert evaluation.flown["half"].dv_m_s.min() > 0.0  # it burned
