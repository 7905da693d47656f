"""Gymnasium environments: perigee burns against drag, registered in one place.

| id                            | actions                | density                                   |
|-------------------------------|------------------------|-------------------------------------------|
| ``OrbitRaising-v0``           | Discrete: burn sizes   | the paper's, known                        |
| ``OrbitRaisingContinuous-v0`` | Box [-1, 1]: burn size | the paper's, known                        |
| ``OrbitRaisingUncertain-v0``  | Discrete: burn sizes   | scale drawn per episode, hidden, drifting |

Each has a single environment (``gymnasium.make``) and a numpy-batched vector
environment (``gymnasium.make_vec(id, num_envs=N)``, autoreset ``NEXT_STEP`` by default);
`orbit_env.envs.sb3` hands the latter to Stable-Baselines3. The user's manual
is the docstring of `OrbitRaisingEnv`.
"""

from __future__ import annotations

import gymnasium

from orbit_env.envs.config import UNCERTAIN_DENSITY, DensityConfig, OrbitRaisingConfig
from orbit_env.envs.orbit_raising import OrbitRaisingEnv

__all__ = ["ENV_IDS", "DensityConfig", "OrbitRaisingConfig", "OrbitRaisingEnv", "register_envs"]

_ENTRY_POINT = "orbit_env.envs.orbit_raising:OrbitRaisingEnv"
_VECTOR_ENTRY_POINT = "orbit_env.envs.vector:OrbitRaisingVectorEnv"

#: Every registered id and the keyword arguments that make the variant.
_VARIANTS: dict[str, dict[str, object]] = {
    "OrbitRaising-v0": {},
    "OrbitRaisingContinuous-v0": {"continuous": True},
    "OrbitRaisingUncertain-v0": {"density": UNCERTAIN_DENSITY},
}
ENV_IDS = tuple(_VARIANTS)


def register_envs() -> None:
    """Register the orbit-raising environments with Gymnasium (safe to call twice).

    No ``max_episode_steps``: both environments truncate themselves after
    ``horizon_steps`` (a flat keyword of ``gymnasium.make``), the one owner of the
    truncation and of the observed clock.
    """
    for env_id, kwargs in _VARIANTS.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(
            id=env_id,
            entry_point=_ENTRY_POINT,
            vector_entry_point=_VECTOR_ENTRY_POINT,
            kwargs=dict(kwargs),
        )
