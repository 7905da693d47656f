"""The log-feature observation wrappers: the SB3 extractor's features, as Gymnasium wrappers."""

import math
import pickle

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.envs.task import LIFETIME_SCALE_DAYS, Task, observation
from orbit_env.envs.wrappers import (
    LOG_FLOOR,
    LogFeaturesObservation,
    LogFeaturesVectorObservation,
    log_features,
    log_features_space,
)


def random_rollout(steps=400, num_envs=16, seed=0):
    """Observations (steps + 1, num_envs, 7) of random actions, restarts included."""
    env = gymnasium.make_vec("OrbitRaising-v0", num_envs=num_envs)
    env.action_space.seed(seed)
    obs, _ = env.reset(seed=seed)
    seen = [obs]
    for _ in range(steps):
        obs, *_ = env.step(env.action_space.sample())
        seen.append(obs)
    env.close()
    return np.stack(seen)


def test_features_are_the_log_lifetime_and_the_log_time_left():
    # A satellite predicted to live 10 days, 100 steps into a 365-step mission.
    obs = np.array(observation(300e3, 500e3, 250.0, 100 / 365, 10.0, 2e3, 0.2e3), dtype=np.float32)
    features = log_features(obs)
    assert features.shape == (9,) and features.dtype == np.float32
    np.testing.assert_array_equal(features[:7], obs)
    assert features[7] == pytest.approx(math.log(10.0 / LIFETIME_SCALE_DAYS), abs=1e-4)
    assert features[8] == pytest.approx(math.log(1 - 100 / 365), abs=1e-5)


def test_space_bounds_are_the_clamped_logs():
    space = log_features_space(Task().observation_space)
    np.testing.assert_array_equal(space.low[:7], Task().observation_space.low)
    np.testing.assert_array_equal(space.high[:7], Task().observation_space.high)
    floor = math.log(LOG_FLOOR)  # -13.8: logit(1e-6) = ln(1e-6 / (1 - 1e-6))
    assert space.low[7] == pytest.approx(floor, abs=1e-3) and space.high[7] == pytest.approx(-floor, abs=0.1)
    assert space.low[8] == pytest.approx(floor, rel=1e-6) and space.high[8] == 0.0
    assert space.dtype == np.float32 and space.is_bounded("both")
    with pytest.raises(ValueError, match=r"Box of shape \(7,\)"):
        log_features_space(gymnasium.spaces.Box(0.0, 1.0, (3,)))


def test_wrapper_equals_the_sb3_extractor():
    torch = pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    from orbit_env.agents.features import LogFeatures

    obs = random_rollout().reshape(-1, 7)
    space = Task().observation_space
    # The ends of the space too, where the clamps act: lifetime 0 and 1, clock 1.
    obs = np.concatenate([obs, np.stack([space.low, space.high])])
    with torch.no_grad():
        expected = LogFeatures(space)(torch.as_tensor(obs)).numpy()
    vector = LogFeaturesVectorObservation(gymnasium.make_vec("OrbitRaising-v0", num_envs=1)).observations(obs)
    single = LogFeaturesObservation(gymnasium.make("OrbitRaising-v0"))
    single = np.stack([single.observation(o) for o in obs])
    for mine in (vector, single):
        assert mine.dtype == np.float32
        np.testing.assert_array_equal(mine[:, :7], obs)
        # float32 round-off: numpy's and torch's float32 logarithms differ by an ulp here and there.
        np.testing.assert_allclose(mine, expected, rtol=1e-6, atol=1e-6)


def test_single_wrapper_passes_the_env_checker():
    env = LogFeaturesObservation(gymnasium.make("OrbitRaising-v0"))
    with pytest.warns(UserWarning, match="different from the unwrapped version"):
        check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (9,) and obs.dtype == np.float32 and env.observation_space.contains(obs)
    env = pickle.loads(pickle.dumps(env))  # a module-level class: it pickles
    assert env.observation_space.contains(env.step(3)[0])


def test_single_wrapper_matches_the_unwrapped_env_step_by_step():
    plain, wrapped = gymnasium.make("OrbitRaising-v0"), LogFeaturesObservation(gymnasium.make("OrbitRaising-v0"))
    start = {"perigee_km": 300.0, "apogee_km": 600.0}
    obs, _ = plain.reset(seed=3, options=start)
    mine, _ = wrapped.reset(seed=3, options=start)
    for action in [3, 0, 0, 1, 0, 2] + [0] * 20:
        np.testing.assert_array_equal(mine, log_features(obs))
        obs, reward, *_ = plain.step(action)
        mine, mine_reward, *_ = wrapped.step(action)
        assert mine_reward == reward


def test_vector_wrapper_on_make_vec():
    envs = LogFeaturesVectorObservation(gymnasium.make_vec("OrbitRaising-v0", num_envs=4))
    assert envs.single_observation_space == log_features_space(Task().observation_space)
    assert envs.observation_space.shape == (4, 9)
    envs.action_space.seed(1)
    obs, _ = envs.reset(seed=1)
    plain = gymnasium.make_vec("OrbitRaising-v0", num_envs=4)
    plain_obs, _ = plain.reset(seed=1)
    for _ in range(400):  # past the horizon: automatic resets (NEXT_STEP) included
        assert obs.shape == (4, 9) and obs.dtype == np.float32
        assert envs.observation_space.contains(obs)
        np.testing.assert_array_equal(obs, log_features(plain_obs))
        actions = envs.action_space.sample()
        obs, *_ = envs.step(actions)
        plain_obs, *_ = plain.step(actions)


def test_vector_wrapper_refuses_same_step_autoreset():
    # As Gymnasium's own vector observation wrappers: info["final_obs"] would stay unwrapped.
    with pytest.raises(ValueError, match="NEXT_STEP or DISABLED"):
        LogFeaturesVectorObservation(gymnasium.make_vec("OrbitRaising-v0", num_envs=2, autoreset_mode="SameStep"))


def test_space_contains_a_random_rollout():
    features = log_features(random_rollout(steps=800, num_envs=64, seed=7))
    space = log_features_space(Task().observation_space)
    assert features.shape == (801, 64, 9)
    assert all(space.contains(f) for f in features.reshape(-1, 9))
    # The rollout reaches short lives and the mission's end, where the logarithms are large.
    assert features[..., 7].min() < -5.0 and features[..., 8].min() < -5.0


def test_docstring_examples_run():
    import doctest

    from orbit_env.envs import wrappers

    result = doctest.testmod(wrappers)
    assert result.attempted > 0 and result.failed == 0
