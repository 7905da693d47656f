"""Stable-Baselines3 on the numpy-batched vector environment, without a wrapper per satellite.

SB3 trains on its own ``VecEnv`` interface; `SB3VecEnv` presents a Gymnasium
vector environment that resets finished episodes in the same step
(``AutoresetMode.SAME_STEP``, which `make_sb3_vec_env` asks of
`orbit_env.envs.vector.OrbitRaisingVectorEnv`) through it: one numpy step
for all satellites instead of ``DummyVecEnv``'s Python loop over single environments;
it comes wrapped in SB3's ``VecMonitor``, so training logs the episodes' returns.
Needs ``pip install 'orbit-env[train]'``.

Examples:
    >>> from orbit_env.envs.sb3 import make_sb3_vec_env
    >>> venv = make_sb3_vec_env("OrbitRaising-v0", num_envs=8, seed=0)
    >>> venv.reset().shape
    (8, 7)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium
import numpy as np
from gymnasium.vector import AutoresetMode

from orbit_env.envs.vector import OUTCOME_KEYS
from orbit_env.optional import TRAIN_EXTRA

try:
    from stable_baselines3.common.vec_env import VecEnv, VecMonitor
    from stable_baselines3.common.vec_env.base_vec_env import VecEnvIndices, VecEnvStepReturn
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError(f"orbit_env.envs.sb3 needs stable-baselines3; install it with: {TRAIN_EXTRA}") from error


class SB3VecEnv(VecEnv):
    """A Gymnasium vector environment (same-step autoreset) as a Stable-Baselines3 ``VecEnv``.

    Finished episodes follow SB3's convention: the returned observation starts the
    next episode, ``infos[i]["terminal_observation"]`` is the last one of the
    finished episode and ``infos[i]["TimeLimit.truncated"]`` tells truncation from
    termination (for value bootstrapping: False for this package's environments, whose
    missions end terminated, `orbit_env.envs`), and the finished episode's ``final_info`` as the
    single environment's info: ``reentered``, ``days_in_orbit``, ``dv_used_m_s`` (see
    `OrbitRaisingEnv`), and for the solar task ``date`` and, at the mission's end,
    ``disposal_dv_m_s`` and ``complies`` (only at the episode's end, so that a step builds no
    dicts for the others). Attributes and methods act on the whole
    batch, so ``get_attr`` returns the batch's value once per index.

    Seeding: ``seed(s)`` then ``reset()`` seeds the batch's one generator with
    ``s`` (SB3 asks for s, s+1, ... per environment; the batch draws every
    satellite from the first).

    Args:
        env: A Gymnasium ``VectorEnv`` whose ``metadata["autoreset_mode"]`` is
            ``AutoresetMode.SAME_STEP``.
    """

    def __init__(self, env: gymnasium.vector.VectorEnv) -> None:
        mode = env.metadata.get("autoreset_mode")
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(
                f"env has autoreset_mode={mode!r}; SB3VecEnv needs AutoresetMode.SAME_STEP "
                "(gymnasium.make_vec(id, num_envs, autoreset_mode=AutoresetMode.SAME_STEP) of an orbit_env id)"
            )
        self.env = env
        self.render_mode = None
        super().__init__(env.num_envs, env.single_observation_space, env.single_action_space)
        self._actions: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        """Reset every environment (with the seed and options set by ``seed`` / ``set_options``)."""
        obs, _ = self.env.reset(seed=self._seeds[0], options=self._batched_options())
        self.reset_infos = [{} for _ in range(self.num_envs)]
        self._reset_seeds()
        self._reset_options()
        return obs

    def _batched_options(self) -> dict[str, Any] | None:
        """SB3 keeps one options dict per environment; the batch takes arrays per key."""
        options = self._options
        if not any(options):
            return None
        keys = set(options[0])
        if any(set(o) != keys for o in options):
            raise ValueError("set_options: every environment must set the same option keys")
        return {key: np.array([o[key] for o in options]) for key in keys}

    def step_async(self, actions: np.ndarray) -> None:
        """Store the actions for `step_wait`."""
        self._actions = actions

    def step_wait(self) -> VecEnvStepReturn:
        """Step all environments; returns (obs, rewards, dones, infos) in SB3's convention."""
        obs, rewards, terminated, truncated, info = self.env.step(self._actions)
        dones = terminated | truncated
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if dones.any():
            final_obs, final_info = info["final_obs"], info["final_info"]
            keys = [key for key in final_info if not key.startswith("_") and f"_{key}" in final_info]
            for i in np.flatnonzero(dones):
                infos[i]["terminal_observation"] = final_obs[i]
                infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
                for key in keys:  # the finished episode's outcome, e.g. for VecMonitor's info_keywords
                    if final_info[f"_{key}"][i]:
                        infos[i][key] = final_info[key][i].item()
        return obs, rewards.astype(np.float32), dones, infos

    def close(self) -> None:
        """Close the vector environment."""
        self.env.close()

    def get_images(self) -> Sequence[np.ndarray | None]:
        """No pictures: the batched environment does not render."""
        return [None] * self.num_envs

    def _count(self, indices: VecEnvIndices) -> int:
        return len(list(self._get_indices(indices)))

    def get_attr(self, attr_name: str, indices: VecEnvIndices = None) -> list[Any]:
        """The batch's attribute, once per index."""
        return [getattr(self.env, attr_name)] * self._count(indices)

    def set_attr(self, attr_name: str, value: Any, indices: VecEnvIndices = None) -> None:
        """Set an attribute of the whole batch (only for all indices)."""
        if self._count(indices) != self.num_envs:
            raise ValueError("set_attr acts on the whole batch; pass indices=None")
        setattr(self.env, attr_name, value)

    def env_method(
        self, method_name: str, *method_args: Any, indices: VecEnvIndices = None, **method_kwargs: Any
    ) -> list[Any]:
        """Call a method of the batch once; its result is repeated per index."""
        result = getattr(self.env, method_name)(*method_args, **method_kwargs)
        return [result] * self._count(indices)

    def env_is_wrapped(self, wrapper_class: type[gymnasium.Wrapper], indices: VecEnvIndices = None) -> list[bool]:
        """The batch holds no per-environment Gymnasium wrappers."""
        return [False] * self._count(indices)


def make_sb3_vec_env(
    env_id: str = "OrbitRaising-v0", num_envs: int = 64, seed: int | None = None, monitor: bool = True, **kwargs: Any
) -> VecEnv:
    """``gymnasium.make_vec`` of a registered orbit_env id, ready for Stable-Baselines3.

    Wrapped in SB3's ``VecMonitor`` (as SB3's own ``make_vec_env`` monitors), so a
    model logs ``rollout/ep_rew_mean`` and ``evaluate_policy`` counts whole episodes;
    the monitor also keeps each finished episode's outcome (`OUTCOME_KEYS`) in its
    episode info.

    Args:
        env_id: A registered id (see `orbit_env.envs`).
        num_envs: Number of satellites stepped together.
        seed: Seed of the first reset (None: unseeded).
        monitor: Wrap in ``VecMonitor``. False gives the bare `SB3VecEnv`, for a
            chain that changes the rewards or the episodes (reward shaping) and puts
            its own monitor above them.
        **kwargs: Passed to the environment (``config``, ``density``, ...).
    """
    from orbit_env.envs import register_envs

    register_envs()
    env = gymnasium.make_vec(
        env_id,
        num_envs=num_envs,
        vectorization_mode="vector_entry_point",
        autoreset_mode=AutoresetMode.SAME_STEP,  # SB3's convention: the next episode's first observation
        **kwargs,
    )
    venv: VecEnv = SB3VecEnv(env)
    if seed is not None:
        venv.seed(seed)
    if monitor:
        venv = VecMonitor(venv, info_keywords=OUTCOME_KEYS)
    return venv
