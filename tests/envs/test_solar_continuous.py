"""``OrbitRaisingSolarContinuous-v0``: the solar task with any burn size (its continuous twin)."""

import dataclasses

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import orbit_env  # noqa: F401  (registers the ids)
from orbit_env.agents.solar import evaluate_solar
from orbit_env.agents.solar_dp import CONTINUOUS_DP_STEP_M_S, dp_task
from orbit_env.envs import SOLAR_CONTINUOUS_ENV_ID, SOLAR_ENV_ID
from orbit_env.envs.solar_task import SolarTask


def test_the_twin_is_a_gymnasium_env_with_a_box_of_burns():
    env = gym.make(SOLAR_CONTINUOUS_ENV_ID)
    assert env.action_space == gym.spaces.Box(-1.0, 1.0, (1,), np.float32)
    check_env(env.unwrapped, skip_render_check=True)
    envs = gym.make_vec(SOLAR_CONTINUOUS_ENV_ID, num_envs=3)
    assert envs.action_space.shape == (3, 1)
    with pytest.raises(ValueError, match="continuous=1 is invalid"):
        gym.make(SOLAR_ENV_ID, continuous=1)


def test_a_burn_of_the_twin_is_the_discrete_tasks_burn_of_that_size():
    # a = 0.5 asks for 20 m/s x 0.5 = 10 m/s, the discrete env's action 2; a <= 0 coasts as action 0.
    twin, discrete = gym.make(SOLAR_CONTINUOUS_ENV_ID), gym.make(SOLAR_ENV_ID)
    start = {"perigee_km": 420.0, "apogee_km": 430.0, "start_date": "1990-03-01"}
    a, _ = twin.reset(seed=0, options=start)
    b, _ = discrete.reset(seed=0, options=start)
    assert np.array_equal(a, b)
    for continuous, index in [(0.5, 2), (-0.3, 0), (1.0, 3), (0.25, 1)] * 3:
        a, ra, ta, _, ia = twin.step(np.array([continuous], dtype=np.float32))
        b, rb, tb, _, ib = discrete.step(index)
        assert np.array_equal(a, b) and ra == rb and ta == tb and ia["burn_m_s"] == ib["burn_m_s"]


def test_the_twins_dp_burns_on_a_finer_grid():
    twin = SolarTask(continuous=True)
    sizes = dp_task(twin).config.burn_sizes_m_s
    assert sizes[1] == CONTINUOUS_DP_STEP_M_S and sizes[-1] == twin.config.max_burn_m_s and len(sizes) == 9
    assert dp_task(SolarTask()) == SolarTask()  # the discrete task's DP is its own
    assert dataclasses.replace(dp_task(twin).config, burn_sizes_m_s=twin.config.burn_sizes_m_s) == twin.config


@pytest.mark.slow  # two evaluations with a DP per mission: about a minute
def test_the_twins_dp_flies_at_least_the_discrete_dps_return():
    # On the same missions the finer grid's optimum holds every burn of the coarse one: it flies at least
    # as well up to the grid's interpolation (a day, the certificate's scale) and the rules are the same.
    twin_eval = evaluate_solar(3, 5, workers=1, continuous=True)
    coarse = evaluate_solar(3, 5, workers=1)
    for name in ("never", "life_threshold"):
        assert np.array_equal(twin_eval.flown[name].returns, coarse.flown[name].returns)
    assert twin_eval.flown["dp"].returns.mean() >= coarse.flown["dp"].returns.mean() - 1.0


def test_the_shipped_twin_agent_loads_and_flies_its_missions():
    from orbit_env.agents.evaluate import load_model
    from orbit_env.agents.solar import fly_model

    algorithm, model = load_model(SOLAR_CONTINUOUS_ENV_ID)
    assert algorithm == "ppo" and model.action_space.shape == (1,)
    assert model.orbit_env["env_id"] == SOLAR_CONTINUOUS_ENV_ID
    flown = fly_model(model, 3, 777, {"solar_split": "test"}, SOLAR_CONTINUOUS_ENV_ID)
    # Five-year missions that it keeps up and disposes of within the rule (a trained agent, not a coin).
    assert flown.complies.all() and (flown.days_in_orbit > 1000.0).all()
