"""What a researcher reads from the environments on day one: spec, info, action clipping, headless checks.

Each test here pins one item of the interface as Gymnasium's own environments have it
(``spec.max_episode_steps``, LunarLander's clipped actions, ``check_env`` on a machine
without a display, outcome keys in ``info``).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers import TimeLimit

from orbit_env.envs import ENV_IDS, register_envs
from orbit_env.envs.config import DEFAULT_HORIZON_STEPS

if not all(env_id in gym.envs.registry for env_id in ENV_IDS):
    register_envs()

OUTLIVES = {"perigee_km": 500.0, "apogee_km": 1000.0}  # lives through any test's horizon


def wrappers(env: gym.Env) -> list[type]:
    """The classes of the wrappers around an environment, outermost first."""
    found = []
    while isinstance(env, gym.Wrapper):
        found.append(type(env))
        env = env.env
    return found


# --------------------------------------------------------------------------------------
# spec.max_episode_steps: the horizon, with the environment the one owner of the truncation
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_the_spec_reports_the_horizon_without_a_second_time_limit(env_id):
    env = gym.make(env_id)
    assert env.spec.max_episode_steps == DEFAULT_HORIZON_STEPS == 365
    assert TimeLimit not in wrappers(env)  # the environment truncates itself: one owner
    short = gym.make(env_id, horizon_steps=10)
    assert short.spec.max_episode_steps == 10  # follows the horizon keyword
    assert short.unwrapped.spec.max_episode_steps == 10
    short.reset(seed=0, options=OUTLIVES)
    ends = [short.step(short.action_space.sample())[3] for _ in range(10)]
    assert ends == [False] * 9 + [True]
    # Made again from its spec (as check_env does): the same horizon and the same episode length.
    again = gym.make(short.spec)
    assert again.spec.max_episode_steps == 10 and again.unwrapped.config.horizon_steps == 10
    again.reset(seed=0, options=OUTLIVES)
    assert [again.step(again.action_space.sample())[3] for _ in range(10)] == [False] * 9 + [True]


# --------------------------------------------------------------------------------------
# Continuous actions outside [-1, 1] are clipped, as LunarLander's; NaN is refused
# --------------------------------------------------------------------------------------


def test_continuous_actions_outside_the_box_are_clipped_and_nan_refused():
    start = {"perigee_km": 300.0, "apogee_km": 600.0}
    for outside, inside in ((1.5, 1.0), (7.0, 1.0), (-3.0, -1.0)):
        clipped, plain = gym.make("OrbitRaisingContinuous-v0"), gym.make("OrbitRaisingContinuous-v0")
        clipped.reset(seed=0, options=start)
        plain.reset(seed=0, options=start)
        a = clipped.step(np.array([outside], dtype=np.float32))
        b = plain.step(np.array([inside], dtype=np.float32))
        np.testing.assert_array_equal(a[0], b[0])
        assert a[1:] == b[1:]
    assert a[4]["burn_m_s"] == 0.0  # -3 clips to -1: a coast
    assert b[4]["burn_m_s"] == 0.0
    env = gym.make("OrbitRaisingContinuous-v0").unwrapped
    env.reset(seed=0, options=start)
    assert env.step(2.0)[4]["burn_m_s"] == 100.0  # a plain number clips too
    with pytest.raises(ValueError, match=r"action=array\(\[nan\]"):
        env.step(np.array([np.nan], dtype=np.float32))
    vec = gym.make_vec("OrbitRaisingContinuous-v0", num_envs=3, vectorization_mode="vector_entry_point")
    vec.reset(seed=0, options=start)
    *_, info = vec.step(np.array([[2.0], [-5.0], [0.5]]))
    np.testing.assert_array_equal(info["burn_m_s"], [100.0, 0.0, 50.0])
    with pytest.raises(ValueError, match=r"action nan is invalid; allowed: numbers, not NaN \(clipped to \[-1, 1\]\)"):
        vec.step(np.array([[0.0], [np.nan], [0.0]]))
