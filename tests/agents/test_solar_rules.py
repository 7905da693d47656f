"""The solar task's operators' rules as policies: SB3's ``predict`` in either id's space, one registry of rules."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents import solar
from orbit_env.envs import SOLAR_CONTINUOUS_ENV_ID, SOLAR_ENV_ID, solar_task
from orbit_env.envs.solar_task import SolarMission, SolarTask

#: Fixed thresholds (the tuning itself is not what these tests check: it takes 30 s), high enough that every
#: rule burns on the missions flown here (checked).
SETTINGS = {"perigee_threshold": (450.0, 0.0), "life_threshold": (3.0, 0.0)}


def _rules(task: SolarTask) -> list[solar.Never]:
    return [
        rule(task, *SETTINGS[rule.name]) if issubclass(rule, solar.Threshold) else rule(task)
        for rule in solar.SOLAR_RULES
    ]


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
        if rule.name != "never":  # every other rule burns on these missions: its predict is tested burning
            assert (flown.dv_m_s - flown.disposal_m_s).max() > 0.0, rule.name
        for i in range(2):
            obs, _ = env.reset(options={key: float(value[i]) for key, value in options.items()})
            total, done = 0.0, False
            while not done:
                action, _ = rule.predict(obs)
                assert env.action_space.contains(action), (rule.name, action)
                obs, reward, done, _, _ = env.step(action)
                total += reward
            assert total == pytest.approx(flown.returns[i], abs=1e-9), rule.name


@pytest.mark.parametrize("continuous", [False, True])
def test_predict_takes_one_observation_or_a_batch_as_sb3_does_and_refuses_another_shape(continuous):
    """SB3's shapes: a batch of n gives (n,) indices or (n, 1) Box values; one observation () or (1,)."""
    task = SolarTask(mission=SolarMission(solar_split="test"), continuous=continuous)
    obs = solar_task.observe(task, solar_task.start(task, np.random.default_rng(3), 4))
    sizes = np.asarray(task.config.burn_sizes_m_s)
    for rule in _rules(task):
        actions, _ = rule.predict(obs)
        single, _ = rule.predict(obs[0])
        assert actions.shape == ((4, 1) if continuous else (4,)) and single.shape == ((1,) if continuous else ())
        burns = task.requested_dvs(actions, 4)  # as the environment reads the actions
        np.testing.assert_array_equal(burns, sizes[rule.actions(obs)])
        np.testing.assert_array_equal(single, actions[0])
    with pytest.raises(ValueError, match=r"shape \(11,\) or \(n, 11\), got shape \(4, 7\)"):
        solar.Never(task).predict(obs[:, :7])


def test_a_rule_added_to_the_registry_is_scored_beside_the_others(monkeypatch):
    """A new rule is its class and its entry in `SOLAR_RULES`: the evaluation's rows follow the registry."""

    class Half(solar.Never):
        name = "half"

        def actions(self, obs):
            return np.ones(len(obs), dtype=np.int64)

    monkeypatch.setattr(solar, "SOLAR_RULES", (*solar.SOLAR_RULES, Half))
    monkeypatch.setattr(solar, "tune", lambda task: SETTINGS)
    evaluation = solar.evaluate_solar(2, 11, include_dp=False)
    assert list(evaluation.flown) == [*solar.SOLAR_HAND_CODED, "half"] == list(evaluation.rules)
    assert (evaluation.flown["half"].dv_m_s - evaluation.flown["half"].disposal_m_s).min() > 0.0  # it burned
    assert set(solar.solar_report(evaluation)["policies"]) == set(evaluation.flown)


def test_a_tuned_rule_added_to_the_registry_is_tuned(monkeypatch):
    """A `Threshold` rule added to `SOLAR_RULES` has its grid tuned (the tuning's cache keys on the rules)."""

    class Apogee(solar.Threshold):
        name = "apogee_threshold"
        grid = (500.0,)

        def actions(self, obs):
            return np.zeros(len(obs), dtype=np.int64)

    monkeypatch.setattr(solar, "SOLAR_RULES", (solar.Never, Apogee))
    monkeypatch.setattr(solar, "TUNE_EPISODES", 2)
    task = SolarTask(mission=SolarMission(solar_split="test"))
    assert solar.tune(task) == {"apogee_threshold": (500.0, 0.0)}  # every reserve ties: the first one kept
    assert isinstance(solar.hand_coded(task)["apogee_threshold"], Apogee)


def test_a_rule_without_its_own_name_or_grid_and_a_learned_agent_named_as_a_row_are_refused(monkeypatch):
    """A subclass inherits its parent's name: it had silently replaced the `never` row capture is measured from."""

    class Forgot(solar.Threshold):
        grid = (400.0,)

    monkeypatch.setattr(solar, "SOLAR_RULES", (*solar.SOLAR_RULES, Forgot))
    with pytest.raises(ValueError, match="rules Never, Forgot share the name 'never'"):
        solar.evaluate_solar(2, 11, include_dp=False)

    class NoGrid(solar.Threshold):
        name = "no_grid"

    monkeypatch.setattr(solar, "SOLAR_RULES", (solar.Never, NoGrid))
    with pytest.raises(ValueError, match="NoGrid is a Threshold rule without a grid"):
        solar.registered_rules()
    monkeypatch.undo()
    monkeypatch.setattr(solar, "tune", lambda task: SETTINGS)
    task = SolarTask(mission=SolarMission(solar_split="test"))
    for row in ("never", "dp"):
        with pytest.raises(ValueError, match=f"learned agent '{row}' has the name of a row"):
            solar.evaluate_solar(2, 11, include_dp=False, learned={row: solar.AllAtOnce(task)})
    with pytest.raises(ValueError, match="episodes=0 is out of range"):
        solar.evaluate_solar(0, 11, include_dp=False)


def test_float_actions_of_a_discrete_space_are_refused_as_the_environment_refuses_them():
    from orbit_env.agents.evaluate import predicted_actions

    task = SolarTask(mission=SolarMission(solar_split="test"))
    obs = solar_task.observe(task, solar_task.start(task, np.random.default_rng(3), 2))

    class Floats:
        def predict(self, observation, state=None, episode_start=None, deterministic=True):
            return np.full(len(observation), 3.0), state

    with pytest.raises(ValueError, match=r"Floats\.predict returned float64 actions for a discrete space \(3\.0"):
        predicted_actions(Floats(), obs, task.action_space)
    env = gymnasium.make(SOLAR_ENV_ID, solar_split="test")
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action=3\.0 is invalid"):
        env.step(3.0)
