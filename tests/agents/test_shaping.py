"""Potential-based shaping of PPO's reward (agents/shaping.py): telescoping and Phi = 0 at the end."""

import gymnasium
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.agents.shaping import never_burn_value_shaping, period_gain_days_per_m_s
from orbit_env.agents.train import load_config
from orbit_env.envs import task as task_model
from orbit_env.envs.config import OrbitRaisingConfig
from orbit_env.envs.sb3 import make_sb3_vec_env


def _phi_of(env: gymnasium.Env, steps_left: float) -> float:
    """The potential of the single env's state: the shaping's look-ahead without a burn."""
    return float(task_model.lookahead(env.unwrapped.task, env.unwrapped.task_state, 0.0, steps_left)[0])


def test_shaped_returns_telescope_to_the_true_return_minus_phi_at_the_start():
    # Same seed, same actions: one copy shaped, one plain. Per episode the shaped rewards sum to
    # the true return minus Phi(s_0) (Ng et al. 1999 with gamma = 1 and Phi = 0 at the end).
    n = 16
    shaped_env = never_burn_value_shaping(make_sb3_vec_env("OrbitRaising-v0", num_envs=n, seed=7))
    plain_env = make_sb3_vec_env("OrbitRaising-v0", num_envs=n, seed=7)
    obs = shaped_env.reset()
    np.testing.assert_array_equal(obs, plain_env.reset())
    phi_start = shaped_env.phi.copy()
    assert np.all(phi_start >= 0.0) and np.any(phi_start > 100.0)
    rng = np.random.default_rng(0)
    shaped_sum, true_sum = np.zeros(n), np.zeros(n)
    running = np.ones(n, dtype=bool)
    ended_by = np.zeros(n, dtype=bool)  # True: re-entry before the horizon
    coast_rewards = []
    for step in range(OrbitRaisingConfig().horizon_steps):
        actions = np.where(rng.random(n) < 0.05, rng.integers(1, 4, n), 0)
        _, shaped, dones, infos = shaped_env.step(actions)
        _, reward, plain_dones, _ = plain_env.step(actions)
        np.testing.assert_array_equal(dones, plain_dones)
        np.testing.assert_allclose([info["unshaped_reward"] for info in infos], reward)
        shaped_sum += np.where(running, shaped, 0.0)
        true_sum += np.where(running, reward, 0.0)
        coast_rewards.extend(shaped[running & (actions == 0)])
        ended_by |= running & dones & (step < OrbitRaisingConfig().horizon_steps - 1)
        running &= ~dones
    assert not running.any()
    assert ended_by.any() and not ended_by.all()  # both re-entries and the horizon were met
    np.testing.assert_allclose(shaped_sum, true_sum - phi_start, atol=1e-3)
    # The point of the potential: coasting earns (almost exactly) nothing, only burns move the return.
    assert np.max(np.abs(coast_rewards)) < 1e-3


def test_phi_is_the_never_return_and_zero_at_the_terminal_states():
    env = gymnasium.make("OrbitRaising-v0")
    horizon = env.unwrapped.config.horizon_steps
    # A low orbit that re-enters within the mission: Phi(s_0) is what never burning earns.
    env.reset(seed=0, options={"perigee_km": 180.0, "apogee_km": 400.0})
    phi_start = _phi_of(env, horizon)
    total, steps, terminated = 0.0, 0, False
    while not terminated:
        _, reward, terminated, truncated, _ = env.step(0)
        total += reward
        steps += 1
        assert not truncated
    assert 0 < steps < horizon
    assert phi_start == pytest.approx(total, rel=1e-6)
    assert _phi_of(env, horizon - steps) == 0.0  # re-entered
    # A high orbit: Phi(s_0) is the mission's days, and 0 with no steps left.
    env.reset(seed=0, options={"perigee_km": 450.0, "apogee_km": 900.0})
    total = sum(env.step(0)[1] for _ in range(horizon))
    assert _phi_of(env, 0) == 0.0
    env.reset(seed=0, options={"perigee_km": 450.0, "apogee_km": 900.0})
    assert _phi_of(env, horizon) == pytest.approx(total, rel=1e-6)


def test_ending_decided_episodes_is_exact():
    # end_decided=1: an episode ends after the step from a state where the tank is empty or the
    # satellite outlives the mission. Its shaped return plus Phi(s_0) must be what the same actions,
    # then coasting, earn in the plain env: the cut-off tail is worth exactly 0 when shaped.
    n = 32
    shaped_env = never_burn_value_shaping(
        make_sb3_vec_env("OrbitRaising-v0", num_envs=n, seed=11, monitor=False), end_decided=1.0
    )
    plain_env = make_sb3_vec_env("OrbitRaising-v0", num_envs=n, seed=11)
    np.testing.assert_array_equal(shaped_env.reset(), plain_env.reset())
    phi_start = shaped_env.phi.copy()
    rng = np.random.default_rng(1)
    shaped_sum, true_sum = np.zeros(n), np.zeros(n)
    first = np.ones(n, dtype=bool)  # still in the shaped env's first episode
    plain_running = np.ones(n, dtype=bool)
    cut = np.zeros(n, dtype=bool)
    mission = np.full(n, np.nan)  # info["mission_return"] at the end of each first episode
    while plain_running.any():
        actions = np.where(first & (rng.random(n) < 0.1), rng.integers(1, 4, n), 0)
        _, shaped, dones, infos = shaped_env.step(actions)
        _, reward, plain_dones, _ = plain_env.step(actions)
        shaped_sum += np.where(first, shaped, 0.0)
        true_sum += np.where(plain_running, reward, 0.0)
        cut |= first & np.array([info.get("decided_end", False) for info in infos])
        for i in np.flatnonzero(first & dones):
            mission[i] = infos[i]["mission_return"]
        first &= ~dones
        plain_running &= ~plain_dones
    assert cut.sum() >= n // 4 and not cut.all()  # many ended early, some by re-entry
    np.testing.assert_allclose(shaped_sum + phi_start, true_sum, atol=1e-3)
    # What the wrapper reports as the mission's return (for `orbit-env train`'s mission/return) is the
    # plain env's return, on the episodes cut short too: float32 rewards, hence 1e-3 day.
    np.testing.assert_allclose(mission, true_sum, atol=1e-3)


def test_ending_decided_episodes_refuses_where_it_is_not_exact():
    # The default task: a burn adds at most 0.30 mission day per m/s by the longer period, its cost is 0.4.
    assert period_gain_days_per_m_s(OrbitRaisingConfig()) == pytest.approx(0.30, abs=0.01)
    cheap = OrbitRaisingConfig(propellant_cost_per_m_s=0.2)
    with pytest.raises(ValueError, match="not exact for this config"):
        never_burn_value_shaping(make_sb3_vec_env("OrbitRaising-v0", num_envs=2, config=cheap), end_decided=0.5)
    with pytest.raises(ValueError, match="known, constant density"):
        never_burn_value_shaping(make_sb3_vec_env("OrbitRaisingUncertain-v0", num_envs=2), end_decided=0.5)
    with pytest.raises(ValueError, match="probability"):
        never_burn_value_shaping(make_sb3_vec_env("OrbitRaising-v0", num_envs=2), end_decided=1.5)
    # Resetting under a VecMonitor would run its returns on into the next episode.
    with pytest.raises(ValueError, match=r"make_sb3_vec_env\(\.\.\., monitor=False\)"):
        never_burn_value_shaping(make_sb3_vec_env("OrbitRaising-v0", num_envs=2), end_decided=1.0)
    never_burn_value_shaping(make_sb3_vec_env("OrbitRaising-v0", num_envs=2), end_decided=0.0)  # no ends: fine


def test_config_rejects_an_unknown_shaping(tmp_path):
    lines = [
        'env_id = "OrbitRaising-v0"',
        "seed = 0",
        "num_envs = 4",
        "total_timesteps = 8",
        'shaping = "curiosity"',
        "[ppo]",
        "[policy]",
    ]
    (tmp_path / "good.toml").write_text("\n".join(lines).replace("curiosity", "never_burn_value"))
    assert load_config(tmp_path / "good.toml")["shaping"] == "never_burn_value"
    (tmp_path / "bad.toml").write_text("\n".join(lines))
    with pytest.raises(ValueError, match="shaping = 'curiosity' is invalid"):
        load_config(tmp_path / "bad.toml")
