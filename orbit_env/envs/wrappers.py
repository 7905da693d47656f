"""Observation wrappers: the observation followed by the log features of the burn decision.

The burn decision turns on the predicted lifetime L against the mission's time left.
The observation carries them as L / (L + 365 d) (component 4, ``predicted_lifetime``)
and the clock t (component 3, ``mission_clock``): of order 1, but the short lives
where a burn no longer pays (a day to a few weeks) all lie in 0 to 0.08. The log
features are ln(L / 365 d) = logit(component 4) and ln(1 - t), so that a linear
layer already forms ln(L / time left). `LogFeaturesObservation` (a single
environment) and `LogFeaturesVectorObservation` (a vector environment) append them
to the observation: (7,) -> (9,), float32; the solar task's (11,) -> (13,) (its first
seven components are these). Stable-Baselines3's
``orbit_env.agents.features.LogFeatures`` computes the same inside the network
from the constants defined here.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import VectorEnv, VectorObservationWrapper
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from orbit_env.envs.solar_task import SOLAR_OBS_NAMES
from orbit_env.envs.task import OBS_INDEX, OBS_NAMES

__all__ = [
    "CLOCK",
    "LIFETIME",
    "LOG_FEATURE_NAMES",
    "LOG_FLOOR",
    "LogFeaturesObservation",
    "LogFeaturesVectorObservation",
    "log_features",
    "log_features_space",
]

#: Observation components the log features read (the task model's layout, `orbit_env.envs.task.OBS_INDEX`).
CLOCK, LIFETIME = OBS_INDEX["mission_clock"], OBS_INDEX["predicted_lifetime"]
#: The observations the log features read: the known-density task's (7,), the solar task's (11,) (the same
#: seven first, then the Sun).
OBSERVATION_SHAPES = ((len(OBS_NAMES),), (len(SOLAR_OBS_NAMES),))
#: Clamp before the logarithms: a lifetime of about 30 s, a clock a step before 1 of a 365-step mission.
LOG_FLOOR = 1e-6
#: Names of the two components appended to the observation, in order.
LOG_FEATURE_NAMES = ("log_lifetime", "log_time_left")


def log_features(observations: Any) -> NDArray[np.float32]:
    """The observation(s), then ln(L / 365 d) and ln(1 - clock): (..., 7) -> (..., 9) (or 11 -> 13), float32.

    ln(L / 365 d) is logit(``predicted_lifetime``) with the component clamped to
    [`LOG_FLOOR`, 1 - `LOG_FLOOR`]; ln(1 - clock) has 1 - clock clamped below at
    `LOG_FLOOR`. The arithmetic is float32, as the torch extractor's.
    """
    obs = np.asarray(observations, dtype=np.float32)
    life = np.clip(obs[..., LIFETIME], np.float32(LOG_FLOOR), np.float32(1.0 - LOG_FLOOR))
    left = np.maximum(np.float32(1.0) - obs[..., CLOCK], np.float32(LOG_FLOOR))
    logit = np.log(life / (np.float32(1.0) - life))
    return np.concatenate([obs, logit[..., None], np.log(left)[..., None]], axis=-1)


def log_features_space(space: gymnasium.spaces.Box) -> gymnasium.spaces.Box:
    """The Box of `log_features` of the observations in ``space`` (the task model's (7,) Box).

    The two logarithms are monotone in their components, so their bounds are the
    features of the space's two corners: [-13.8, 13.8] for ln(L / 365 d) and
    [ln(`LOG_FLOOR`), 0] = [-13.8, 0] for ln(1 - clock), computed by `log_features`
    itself so that every observation it returns lies in the Box.
    """
    if not (isinstance(space, gymnasium.spaces.Box) and space.shape in OBSERVATION_SHAPES):
        raise ValueError(
            "log features need an orbit-raising observation space, a Box of shape (7,) (the solar task's: (11,), "
            f"the same seven first); got {space}"
        )
    ends = log_features(np.stack([space.low, space.high]))
    return gymnasium.spaces.Box(ends.min(axis=0), ends.max(axis=0), dtype=np.float32)


class LogFeaturesObservation(
    gymnasium.ObservationWrapper[NDArray[np.float32], Any, NDArray[np.float32]], gymnasium.utils.RecordConstructorArgs
):
    """A single orbit-raising environment whose observation is followed by the log features (9,).

    Examples:
        >>> import gymnasium as gym
        >>> import orbit_env
        >>> from orbit_env.envs.wrappers import LogFeaturesObservation
        >>> env = LogFeaturesObservation(gym.make("OrbitRaising-v0"))
        >>> obs, info = env.reset(seed=0, options={"perigee_km": 360.0, "apogee_km": 700.0})
        >>> obs.shape, obs.dtype, bool(obs[8] == 0.0)  # ln(1 - clock) at the start
        ((9,), dtype('float32'), True)
    """

    def __init__(self, env: gymnasium.Env[NDArray[np.float32], Any]) -> None:
        gymnasium.utils.RecordConstructorArgs.__init__(self)
        gymnasium.ObservationWrapper.__init__(self, env)
        self.observation_space = log_features_space(env.observation_space)

    def observation(self, observation: NDArray[np.float32]) -> NDArray[np.float32]:
        """The observation (7,) followed by ln(L / 365 d) and ln(1 - clock)."""
        return log_features(observation)


class LogFeaturesVectorObservation(VectorObservationWrapper, gymnasium.utils.RecordConstructorArgs):
    """A vector orbit-raising environment whose observations are followed by the log features (n, 9).

    As Gymnasium's vector observation wrappers, it takes a vector environment whose
    ``autoreset_mode`` is ``NEXT_STEP`` (the default) or ``DISABLED``.

    Examples:
        >>> import gymnasium as gym
        >>> import orbit_env
        >>> from orbit_env.envs.wrappers import LogFeaturesVectorObservation
        >>> envs = LogFeaturesVectorObservation(gym.make_vec("OrbitRaising-v0", num_envs=4))
        >>> obs, info = envs.reset(seed=0)
        >>> obs.shape, envs.single_observation_space.shape
        ((4, 9), (9,))
    """

    def __init__(self, env: VectorEnv) -> None:
        gymnasium.utils.RecordConstructorArgs.__init__(self)
        VectorObservationWrapper.__init__(self, env)
        self.single_observation_space = log_features_space(env.single_observation_space)
        self.observation_space = batch_space(self.single_observation_space, env.num_envs)

    def observations(self, observations: NDArray[np.float32]) -> NDArray[np.float32]:
        """The observations (n, 7) followed by ln(L / 365 d) and ln(1 - clock), (n, 9)."""
        return log_features(observations)
