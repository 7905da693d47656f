"""Log features of the observation for PPO's networks (``[policy] log_features = true``).

The burn decision turns on the predicted lifetime L against the mission's time left.
The observation carries them as L / (L + 365 d) (component 4) and the clock t
(component 3): of order 1, but the short lives where a burn no longer pays (a day
to a few weeks) all lie in 0 to 0.08. This extractor passes the observation on
and appends ln(L / 365 d) = logit(component 4) and ln(1 - t), so that a linear
layer already forms ln(L / time left). It has no parameters and needs nothing
but the observation: the environment is unchanged, and a saved model carries
the class by name (``orbit_env.agents.features``). The components it reads and the
clamp are `orbit_env.envs.wrappers`' (``CLOCK``, ``LIFETIME``, ``LOG_FLOOR``), whose
observation wrappers append the same features outside the network for other libraries.
"""

from __future__ import annotations

import gymnasium
import torch
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from orbit_env.envs.wrappers import CLOCK, LIFETIME, LOG_FLOOR

__all__ = ["CLOCK", "LIFETIME", "LOG_FLOOR", "LogFeatures"]


class LogFeatures(BaseFeaturesExtractor):
    """The observation, then ln(L / 365 d) and ln(1 - clock), each of order 1 to 10."""

    def __init__(self, observation_space: gymnasium.spaces.Box) -> None:
        super().__init__(observation_space, features_dim=int(observation_space.shape[0]) + 2)

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        """Append the two logarithms to a batch of observations (n, 7) -> (n, 9)."""
        life = observations[:, LIFETIME].clamp(LOG_FLOOR, 1.0 - LOG_FLOOR)
        left = (1.0 - observations[:, CLOCK]).clamp_min(LOG_FLOOR)
        return torch.cat([observations, torch.logit(life)[:, None], torch.log(left)[:, None]], dim=1)
