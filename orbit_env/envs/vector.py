"""The orbit-raising environment batched over many satellites: the task model on arrays.

The same functions of `orbit_env.envs.task` as the single environment, called
on a `BatchState` of shape (num_envs,): one call of the
universal curves moves every satellite. The vector environment ends missions
(re-entry, or ``horizon_steps``: both ``terminated``, see `orbit_env.envs`) and restarts
finished satellites as Gymnasium 1.x's ``autoreset_mode`` says:

* ``AutoresetMode.NEXT_STEP`` (default, as ``SyncVectorEnv`` and ``CartPoleVectorEnv``):
  the step that ends an episode returns its last observation; the next step ignores
  that satellite's action and returns the first observation of a new episode, with
  reward 0, not terminated, not truncated, and no ``info["burn_m_s"]`` there (the
  outcome keys there describe the new episode, as its reset's info would).
* ``AutoresetMode.SAME_STEP``: the step that ends an episode returns the first
  observation of the new one; ``info["final_obs"]`` and ``info["final_info"]`` hold
  the last observation and info of the old, the outcome keys of the finished episode
  among them (the convention of Stable-Baselines3, see `orbit_env.envs.sb3`).
* ``AutoresetMode.DISABLED``: no restarts; reset finished satellites with
  ``reset(options={"reset_mask": mask})`` before stepping them again.
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from orbit_env.envs import task as task_model
from orbit_env.envs.config import DensityConfig, OrbitRaisingConfig, resolve_task_arguments
from orbit_env.envs.reset_options import START_OPTIONS
from orbit_env.envs.state import BatchState
from orbit_env.envs.task import Task, TaskView

FloatArray = NDArray[np.float64]

#: The keys of ``info`` that describe each episode so far (with their ``_key`` masks).
OUTCOME_KEYS = ("reentered", "days_in_orbit", "dv_used_m_s")


def batch_seed(seed: Any, num_envs: int) -> int | None:
    """The seed of a batched env's one generator from ``reset(seed=...)``: None, an int, or one int per env.

    Gymnasium's vector API takes a list of ``num_envs`` seeds, one per sub-environment; a batched env
    draws every mission from one generator, seeded here from the whole list (`numpy.random.SeedSequence`):
    the same list gives the same missions, but not those of single envs seeded with each element.

    Raises:
        ValueError: anything else (a list of another length, or not of whole numbers >= 0).
    """
    if seed is None or (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool)):
        return seed
    values = list(seed) if isinstance(seed, (list, tuple, np.ndarray)) else None
    if (
        values is None
        or len(values) != num_envs
        or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v >= 0 for v in values)
    ):
        raise ValueError(
            f"seed={seed!r} is invalid; allowed: None, an integer, or a list of {num_envs} integers >= 0 (one per env)"
        )
    return int(np.random.SeedSequence([int(v) for v in values]).generate_state(1, np.uint64)[0])


#: The keywords of the vector environment besides the config's and the density's fields.
_ENV_KEYWORDS = ("num_envs", "config", "continuous", "density", "max_episode_steps", "render_mode", "autoreset_mode")


class OrbitRaisingVectorEnv(TaskView, VectorEnv):
    """``num_envs`` independent orbit-raising missions stepped together with numpy.

    Observation, action, reward and episode end are those of
    `orbit_env.envs.orbit_raising.OrbitRaisingEnv` (read its docstring),
    batched: observations (num_envs, 7) float32, rewards float64, actions of shape
    (num_envs,) (discrete) or (num_envs, 1) (continuous). ``info`` holds the single
    environment's keys as arrays of shape (num_envs,), each with its boolean mask
    ``info["_key"]`` as in Gymnasium's vector API: ``burn_m_s`` after a step, and
    ``reentered``, ``days_in_orbit`` and ``dv_used_m_s`` (`OUTCOME_KEYS`, each
    episode so far) after every step and reset. The mission's end, after
    ``config.horizon_steps`` steps, is terminal (``terminated``), as re-entry is. Finished
    missions restart as ``autoreset_mode`` says (see the module; ``metadata["autoreset_mode"]``
    tells which).

    ``reset(options=...)`` takes the single environment's options, each a number
    or an array of shape (num_envs,); they pin only that reset, not the automatic
    ones. ``start_options`` gives back every current episode's start, automatic
    resets included. All randomness is drawn from ``self.np_random``, one stream for the
    batch: sub-environment i is not the single environment seeded with seed + i.

    Version History: that of `OrbitRaisingEnv` (the same ids and dynamics),
    including the dynamics change of 2026-12-03 (the burn relocation fix) and the
    mission's end terminated from 2026-12-06.

    Args:
        num_envs: Number of satellites.
        config: Satellite and task (default ``OrbitRaisingConfig()``).
        continuous: Continuous burn size instead of the discrete burns.
        density: Density knowledge (default: the paper's atmosphere, known).
        max_episode_steps: If given, must equal ``config.horizon_steps``, which
            alone sets the mission's length and the observation's clock.
        render_mode: Only None: render a single environment instead.
        autoreset_mode: ``AutoresetMode`` (or its value, e.g. ``"SameStep"``);
            default ``NEXT_STEP``.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        config: OrbitRaisingConfig | dict[str, Any] | None = None,
        *,
        continuous: bool = False,
        density: DensityConfig | dict[str, Any] | None = None,
        max_episode_steps: int | None = None,
        render_mode: str | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        **keywords: Any,
    ) -> None:
        if not (isinstance(num_envs, (int, np.integer)) and num_envs >= 1):
            raise ValueError(f"num_envs={num_envs!r} is invalid; allowed: an integer >= 1")
        config, density = resolve_task_arguments(
            config,
            density,
            keywords,
            env_keywords=_ENV_KEYWORDS,
        )
        self.task = Task.of(config, density, continuous)
        if max_episode_steps is not None and max_episode_steps != self.config.horizon_steps:
            raise ValueError(
                f"max_episode_steps={max_episode_steps} but horizon_steps={self.config.horizon_steps}; "
                f"pass horizon_steps={max_episode_steps}: it alone sets the mission's length and the clock"
            )
        if render_mode is not None:
            raise ValueError(f"render_mode={render_mode!r} is invalid; the vector environment does not render")
        try:
            self.autoreset_mode = AutoresetMode(autoreset_mode)
        except ValueError:
            allowed = ", ".join(f"AutoresetMode.{m.name} ({m.value!r})" for m in AutoresetMode)
            raise ValueError(f"autoreset_mode={autoreset_mode!r} is invalid; allowed: {allowed}") from None
        self.metadata = {**type(self).metadata, "autoreset_mode": self.autoreset_mode}
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
        # Each episode's START_OPTIONS as rows (copied with its state at a restart), and the pool's.
        self._start_rows = np.zeros((len(START_OPTIONS), self.num_envs))
        self._pool_start_rows = np.zeros((len(START_OPTIONS), 0))
        self._pool_next = self.num_envs
        self._last_obs = np.zeros((self.num_envs, 7), dtype=np.float32)  # for reset_mask
        self._everyone_mask = np.ones(self.num_envs, dtype=np.bool_)  # info["_burn_m_s"], read-only
        self._everyone_mask.flags.writeable = False
        self._finished = np.zeros(0, dtype=np.intp)  # ended in the last step (NEXT_STEP, DISABLED)
        self._dv_used_m_s = np.zeros(self.num_envs)  # the burns of each episode so far, for info

    @property
    def state(self) -> dict[str, FloatArray]:
        """The simulator state of every satellite (copies), as `OrbitRaisingEnv.state`."""
        s = self._state
        return {
            name: getattr(s, name).copy()
            for name in ("label", "tau", "perigee_m", "apogee_m", "mass_kg", "time_days", "density_scale")
        }

    @property
    def start_options(self) -> dict[str, FloatArray]:
        """The reset options that give every current episode's start back bit for bit (arrays of shape (num_envs,)).

        As `OrbitRaisingEnv.start_options`, for the episode each sub-environment is in,
        whether ``reset`` or an automatic reset began it: ``reset(options=env.start_options)``
        restarts all of them, and row i's values (``{k: v[i] for k, v in ...items()}``) restart
        sub-environment i's mission in a single environment.
        """
        if not self._has_state:
            raise RuntimeError("the environment has no state before reset()")
        return {name: row.copy() for name, row in zip(START_OPTIONS, self._start_rows, strict=True)}

    @property
    def task_state(self) -> BatchState:
        """The task model's state of every satellite (`orbit_env.envs.task.BatchState`; live, not a copy)."""
        return self._state

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start new missions (options as the single env's, per env; a list of seeds: `batch_seed`).

        ``options["reset_mask"]``, a boolean array of shape (num_envs,) as in
        Gymnasium's ``SyncVectorEnv``, restarts only the masked sub-environments;
        the other rows of the returned observation are their last observations.
        The other options then apply to the masked ones (arrays of shape
        (num_envs,) are read at the masked places).
        """
        super().reset(seed=batch_seed(seed, self.num_envs))
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
            fresh, start_options = task_model.start_and_options(self.task, self.np_random, idx.size, options or None)
            self._state.put(idx, fresh)
            self._start_rows[:, idx] = [start_options[name] for name in START_OPTIONS]
            self._dv_used_m_s[idx] = 0.0
            obs[idx] = task_model.observe(self.task, fresh)
        self._has_state = True
        self._last_obs = obs
        self._finished = np.setdiff1d(self._finished, idx, assume_unique=True) if mask is not None else idx[:0]
        reset = self._everyone_mask if mask is None else mask.copy()  # as SyncVectorEnv: the reset rows' info
        return obs, self._outcome(self._state.tau <= 0.0, reset)

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
        restart = self._finished
        if restart.size:
            if self.autoreset_mode is AutoresetMode.DISABLED:
                raise RuntimeError(
                    f"sub-environments {restart.tolist()} have finished and autoreset_mode is DISABLED; "
                    "restart them with reset(options={'reset_mask': mask}) before stepping them"
                )
            requested[restart] = 0.0  # NEXT_STEP: the action of a finished satellite is ignored
        (reward, terminated, truncated, dv), obs = task_model.step_and_observe(task, self._state, requested)
        infos: dict[str, Any] = {"burn_m_s": dv, "_burn_m_s": self._everyone_mask}
        if restart.size:
            # NEXT_STEP: the satellites that ended in the last step start anew instead.
            obs[restart] = self._restart(restart)
            reward[restart] = 0.0
            terminated[restart] = False
            truncated[restart] = False
            dv[restart] = 0.0
            stepped = np.ones(self.num_envs, dtype=np.bool_)
            stepped[restart] = False
            infos["_burn_m_s"] = stepped
        self._dv_used_m_s += dv
        done = terminated | truncated
        finished = np.flatnonzero(done)
        infos.update(self._outcome(terminated.copy(), self._everyone_mask))
        if self.autoreset_mode is not AutoresetMode.SAME_STEP:
            self._finished = finished
        elif finished.size:
            final_obs = np.empty(self.num_envs, dtype=object)
            final_obs[finished] = np.fromiter(obs[finished], dtype=object, count=finished.size)  # rows, as arrays
            infos["final_obs"] = final_obs
            infos["_final_obs"] = done
            # As SyncVectorEnv: the old episode's info moves to final_info, the new one's (empty) stays.
            final_info = {"burn_m_s": dv, "_burn_m_s": done}
            for key in OUTCOME_KEYS:
                final_info[key], final_info[f"_{key}"] = infos[key].copy(), done
                infos[key][finished] = 0  # the new episode's: not re-entered, 0 days, nothing burnt
            infos["final_info"] = final_info
            infos["_final_info"] = done
            infos["_burn_m_s"] = ~done
            obs[finished] = self._restart(finished)
        self._last_obs = obs
        # The mission's end is a terminal state of the task, as re-entry is (`orbit_env.envs`).
        return obs, reward, done.copy(), np.zeros(self.num_envs, dtype=np.bool_), infos

    def _outcome(self, reentered: NDArray[np.bool_], mask: NDArray[np.bool_]) -> dict[str, Any]:
        """The episodes so far, for ``info`` (`OUTCOME_KEYS`, each with its mask as Gymnasium's vector API)."""
        return {
            "reentered": reentered,
            "_reentered": mask,
            "days_in_orbit": self._state.time_days.copy(),
            "_days_in_orbit": mask,
            "dv_used_m_s": self._dv_used_m_s.copy(),
            "_dv_used_m_s": mask,
        }

    def _restart(self, idx: NDArray[np.intp]) -> NDArray[np.float32]:
        """Automatic reset of ``idx``: copy fresh missions from the pool; return their observations.

        A few dozen satellites finish per step out of thousands. Drawing and
        locating them one step at a time costs more in numpy's per-call overhead
        than the whole batch's step, so fresh missions are drawn ``num_envs`` at a
        time into a pool (with the same function as ``reset``) and handed out in order.
        """
        if self._pool is None or self._pool_next + idx.size > self.num_envs:
            self._pool, start_options = task_model.start_and_options(self.task, self.np_random, self.num_envs)
            self._pool_start_rows = np.array([start_options[name] for name in START_OPTIONS])
            self._pool_obs = task_model.observe(self.task, self._pool)
            self._pool_next = 0
        take = slice(self._pool_next, self._pool_next + idx.size)
        self._pool_next += idx.size
        self._state.put(idx, self._pool.data[:, take])
        self._start_rows[:, idx] = self._pool_start_rows[:, take]
        self._dv_used_m_s[idx] = 0.0
        return self._pool_obs[take]
