"""The orbit-raising environment batched over many satellites: the task model on arrays.

The same functions of :mod:`orbit_env.envs.task` as the single environment, called
on a :class:`~orbit_env.envs.task.BatchState` of shape (num_envs,): one call of the
universal curves moves every satellite. The vector environment owns truncation
(``horizon_steps``) and resets finished satellites in the same step
(``AutoresetMode.SAME_STEP``): the step returns the first observation of the new
episode, and ``info["final_obs"]`` the last one of the old (the convention of
Stable-Baselines3, see :mod:`orbit_env.envs.sb3`).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from orbit_env.envs import task as task_model
from orbit_env.envs.config import DensityConfig, OrbitRaisingConfig
from orbit_env.envs.task import BatchState, Task, TaskView

FloatArray = NDArray[np.float64]


class OrbitRaisingVectorEnv(TaskView, VectorEnv):
    """``num_envs`` independent orbit-raising missions stepped together with numpy.

    Observation, action, reward and episode end are those of
    :class:`orbit_env.envs.orbit_raising.OrbitRaisingEnv` (read its docstring),
    batched: observations (num_envs, 7) float32, rewards float64, actions of shape
    (num_envs,) (discrete) or (num_envs, 1) (continuous). Truncation after
    ``config.horizon_steps`` steps. Finished missions restart in the same step
    (``metadata["autoreset_mode"]`` is ``SAME_STEP``); their last observation is
    in ``info["final_obs"]`` (masked by ``info["_final_obs"]``).

    ``reset(options=...)`` takes the single environment's options, each a number
    or an array of shape (num_envs,); they pin only that reset, not the automatic
    ones. All randomness is drawn from ``self.np_random``, one stream for the
    batch: sub-environment i is not the single environment seeded with seed + i.

    Args:
        num_envs: Number of satellites.
        config: Satellite and task (default ``OrbitRaisingConfig()``).
        continuous: Continuous burn size instead of the discrete burns.
        density: Density knowledge (default: the paper's atmosphere, known).
        max_episode_steps: Passed by ``gymnasium.make_vec`` from the registration;
            must equal ``config.horizon_steps`` (the observation's clock runs on it).
        render_mode: Only None: render a single environment instead.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [], "autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        config: OrbitRaisingConfig | None = None,
        *,
        continuous: bool = False,
        density: DensityConfig | None = None,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
    ) -> None:
        if not (isinstance(num_envs, (int, np.integer)) and num_envs >= 1):
            raise ValueError(f"num_envs={num_envs!r} is invalid; allowed: an integer >= 1")
        self.task = Task.of(config, density, continuous)
        if max_episode_steps is not None and max_episode_steps != self.config.horizon_steps:
            raise ValueError(
                f"max_episode_steps={max_episode_steps} but config.horizon_steps={self.config.horizon_steps}; "
                "pass max_episode_steps=config.horizon_steps to gymnasium.make_vec"
            )
        if render_mode is not None:
            raise ValueError(f"render_mode={render_mode!r} is invalid; the vector environment does not render")
        self.num_envs = int(num_envs)
        self.render_mode = None
        self.single_observation_space = self.task.observation_space
        self.single_action_space = self.task.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._state = BatchState(self.num_envs)
        self._has_state = False
        self._pool: BatchState | None = None
        self._pool_obs = np.zeros((0, 7), dtype=np.float32)
        self._pool_next = self.num_envs
        self._last_obs = np.zeros((self.num_envs, 7), dtype=np.float32)  # for reset_mask
        self._everyone_mask = np.ones(self.num_envs, dtype=np.bool_)  # info["_burn_m_s"], read-only
        self._everyone_mask.flags.writeable = False

    @property
    def state(self) -> dict[str, FloatArray]:
        """The simulator state of every satellite (copies), as :attr:`OrbitRaisingEnv.state`."""
        s = self._state
        return {
            name: getattr(s, name).copy()
            for name in ("label", "tau", "perigee_m", "apogee_m", "mass_kg", "time_days", "density_scale")
        }

    @property
    def task_state(self) -> BatchState:
        """The task model's state of every satellite (:class:`orbit_env.envs.task.BatchState`; live, not a copy)."""
        return self._state

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start new missions (options as the single env's, per env).

        ``options["reset_mask"]``, a boolean array of shape (num_envs,) as in
        Gymnasium's ``SyncVectorEnv``, restarts only the masked sub-environments;
        the other rows of the returned observation are their last observations.
        The other options then apply to the masked ones (arrays of shape
        (num_envs,) are read at the masked places).
        """
        super().reset(seed=seed)
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if mask is None or seed is not None:
            self._pool_next = self.num_envs  # empty: the next restart draws a fresh pool
        obs = self._last_obs.copy()
        if mask is None:
            idx = np.arange(self.num_envs)
        else:
            idx = self._masked(mask)
            options = {k: v[idx] if np.shape(v) == (self.num_envs,) else v for k, v in options.items()}
        if mask is not None and not options:
            obs[idx] = self._restart(idx)  # fresh draws, as an automatic reset's
        else:
            fresh = task_model.start(self.task, self.np_random, idx.size, options or None)
            self._state.put(idx, fresh)
            obs[idx] = task_model.observe(self.task, fresh)
        self._has_state = True
        self._last_obs = obs
        return obs, {}

    def _masked(self, mask: Any) -> NDArray[np.intp]:
        """The sub-environments a ``reset_mask`` names; ValueError as Gymnasium's for a bad mask."""
        if not self._has_state:
            raise RuntimeError("reset_mask needs a first reset() of every sub-environment")
        if not (isinstance(mask, np.ndarray) and mask.dtype == np.bool_ and mask.shape == (self.num_envs,)):
            raise ValueError(
                f"options['reset_mask']={mask!r} is invalid; allowed: a numpy bool array of shape ({self.num_envs},)"
            )
        if not mask.any():
            raise ValueError("options['reset_mask'] must contain at least one True value")
        return np.flatnonzero(mask)

    def step(
        self, actions: Any
    ) -> tuple[NDArray[np.float32], FloatArray, NDArray[np.bool_], NDArray[np.bool_], dict[str, Any]]:
        """Burn where asked, coast every satellite one block, restart the finished ones."""
        if not self._has_state:
            raise RuntimeError("call reset() before step()")
        task = self.task
        requested = task.requested_dvs(actions, self.num_envs)
        reward, terminated, truncated, dv = task_model.step(task, self._state, requested)
        obs = task_model.observe(task, self._state)
        # As Gymnasium's TimeLimit: at the horizon an episode is truncated even if it also terminated.
        infos: dict[str, Any] = {"burn_m_s": dv, "_burn_m_s": self._everyone_mask}
        done = terminated | truncated
        finished = np.flatnonzero(done)
        if finished.size:
            final_obs = np.empty(self.num_envs, dtype=object)
            final_obs[finished] = np.fromiter(obs[finished], dtype=object, count=finished.size)  # rows, as arrays
            infos["final_obs"] = final_obs
            infos["_final_obs"] = done
            infos["final_info"] = {}
            infos["_final_info"] = done
            obs[finished] = self._restart(finished)
        self._last_obs = obs
        return obs, reward, terminated, truncated, infos

    def _restart(self, idx: NDArray[np.intp]) -> NDArray[np.float32]:
        """Automatic reset of ``idx``: copy fresh missions from the pool; return their observations.

        A few dozen satellites finish per step out of thousands. Drawing and
        locating them one step at a time costs more in numpy's per-call overhead
        than the whole batch's step, so fresh missions are drawn ``num_envs`` at a
        time into a pool (with the same function as ``reset``) and handed out in order.
        """
        if self._pool is None or self._pool_next + idx.size > self.num_envs:
            self._pool = task_model.start(self.task, self.np_random, self.num_envs)
            self._pool_obs = task_model.observe(self.task, self._pool)
            self._pool_next = 0
        take = slice(self._pool_next, self._pool_next + idx.size)
        self._pool_next += idx.size
        self._state.data[:, idx] = self._pool.data[:, take]
        return self._pool_obs[take]
