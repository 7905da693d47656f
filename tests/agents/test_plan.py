"""The continuous variant's yardstick (agents/plan.py): the DP's plans refined by a search, played open loop.

On the DP tests' short task (tests/agents/test_dp.py: 60 steps from low perigees, cheap
propellant), in the continuous variant, with the DP on burns 10 m/s apart.
"""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents.dp import DPPolicy, solve
from orbit_env.agents.evaluate import ContinuousFromDiscrete, continuous_dp_burns
from orbit_env.agents.plan import PlanPolicy
from orbit_env.envs.config import OrbitRaisingConfig

CONFIG = OrbitRaisingConfig(
    horizon_steps=60, start_perigee_km=(160.0, 260.0), start_apogee_max_km=900.0, propellant_cost_per_m_s=0.05
)
SIZES = continuous_dp_burns(CONFIG.max_burn_m_s)
EPISODES = 48


@pytest.fixture(scope="module")
def base():
    return DPPolicy(solution=solve(dataclasses.replace(CONFIG, burn_sizes_m_s=SIZES), grid=(48, 1, 1)))


def play(policy):
    """Returns and burns of seeded episodes of the continuous variant, the policy acting on the running ones."""
    env = gym.make_vec("OrbitRaisingContinuous-v0", num_envs=EPISODES, config=CONFIG)
    obs, _ = env.reset(seed=5)
    returns = np.zeros(EPISODES)
    burns = np.zeros((EPISODES, CONFIG.horizon_steps))
    running = np.ones(EPISODES, dtype=bool)
    for t in range(CONFIG.horizon_steps):
        actions = np.zeros((EPISODES, 1), dtype=np.float32)
        actions[running] = policy.predict(obs[running])[0]
        obs, reward, terminated, truncated, info = env.step(actions)
        returns += np.where(running, reward, 0.0)
        burns[:, t] = np.where(running, info["burn_m_s"], 0.0)
        running &= ~(terminated | truncated)
    env.close()
    return returns, burns


def test_the_plans_earn_at_least_the_dp_policy_and_are_followed(base):
    dp_returns, _ = play(ContinuousFromDiscrete(base, SIZES, CONFIG.max_burn_m_s))
    policy = PlanPolicy(base)
    plan_returns, burns = play(policy)
    # The search keeps only gains over the DP's own plan, played from the state decoded from the
    # observation; the env plays it from its own state, which decode recovers up to the observation's
    # float32 rounding (some 0.1 m of apogee, tests/envs/test_task.py): 0.01 day is a wide allowance for it.
    assert np.all(plan_returns >= dp_returns - 0.01), (plan_returns - dp_returns).min()
    assert plan_returns.mean() > dp_returns.mean() + 0.01, (plan_returns.mean(), dp_returns.mean())
    # Burns off the DP's 10 m/s sizes: the search refines them.
    made = burns[burns > 0.0]
    assert np.any(np.abs(made / 10.0 - np.round(made / 10.0)) > 1e-3)
    # Every satellite planned at the start followed its plan's track to the end of the mission:
    # the plan covers the whole 60-step mission, so one batch of plans was made, no re-plans.
    assert len(policy._batches) == 1
    first = policy._batches[0]
    assert first.burns.shape[1] == CONFIG.horizon_steps
    np.testing.assert_array_equal(first.start, 0)


def test_predict_gives_box_actions_and_checks_its_arguments(base):
    policy = PlanPolicy(base)
    env = gym.make_vec("OrbitRaisingContinuous-v0", num_envs=4, config=CONFIG)
    obs, _ = env.reset(seed=1)
    actions, state = policy.predict(obs)
    assert actions.shape == (4, 1) and actions.dtype == np.float32 and state is None
    assert np.all((actions >= 0.0) & (actions <= 1.0))
    # One observation: the plan made for the batch is found again (same step and state).
    np.testing.assert_array_equal(policy.predict(obs[0])[0], actions[0])
    for kwargs, match in (({"window": 0}, "window=0"), ({"steps_m_s": (5.0, -1.0)}, "steps_m_s")):
        with pytest.raises(ValueError, match=match):
            PlanPolicy(base, **kwargs)
