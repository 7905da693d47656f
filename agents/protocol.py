"""Stable-Baselines3's prediction protocol, written once: the hand-coded policies, the DP's policy and the planner.

``predict(observation, state=None, episode_start=None, deterministic=True) -> (action, state)``, for
one observation or a batch, as SB3's models take them: `orbit_env.agents.evaluate` scores a policy
and a trained model alike through it.
"""

from __future__ import annotations

from typing import Any

import numpy as np


class Predicts:
    """SB3's ``predict`` from `actions_of`, which a policy implements for a batch of observations.

    A policy has no recurrent state: ``state`` comes back as given; its actions are deterministic.
    """

    def actions_of(self, observation: Any) -> Any:
        """The actions of one observation or a batch of n (subclasses): (n,) indices, or (n, 1) Box values."""
        raise NotImplementedError

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[Any, Any]:
        """Actions for one observation or a batch (n, components); SB3's signature and return."""
        actions = self.actions_of(observation)
        return (actions[0] if np.ndim(observation) == 1 else actions), state
