"""The single orbit-raising environment: one satellite, the task model on Python floats.

The decision problem (burn, coast, reward, observation) is `orbit_env.envs.task`;
this module adds what Gymnasium asks of an environment: spaces, seeding, the
reset options, rendering. Its class docstring is the user's manual.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import EnvSpec
from numpy.typing import NDArray

from orbit_env.envs import ENDED_WARNING
from orbit_env.envs import task as task_model
from orbit_env.envs.config import DEFAULT_HORIZON_STEPS, DensityConfig, OrbitRaisingConfig, resolve_task_arguments
from orbit_env.envs.task import Task, TaskState, TaskView

__all__ = ["DEFAULT_HORIZON_STEPS", "DensityConfig", "OrbitRaisingConfig", "OrbitRaisingEnv"]


class OrbitRaisingEnv(TaskView, gym.Env[np.ndarray, Any]):
    r"""Keep a satellite in orbit against drag with perigee burns.

    ## Description

    A satellite on an elliptic orbit decays under air drag as computed by
    Okhotsimsky, Eneev and Taratynova (1957): every decay is one point moving along
    the paper's universal curves (Fig. 2) at the rate dnu/dN = g c s per revolution
    (Eq. 4.1), c = c_x F / m. Each step is a block of K revolutions. At the start of
    a step the agent may fire its engine at perigee: the tangential burn keeps the
    perigee and raises the apogee (exact vis-viva), the paper's cheap way to a long
    life (section 4: 360 x 700 km -> 360 x 1000 km costs 78 m/s and multiplies the
    lifetime by 2.2).
    The propellant is finite and the burn spends mass by the rocket equation, which
    raises c and so shortens the life per unit nu. A satellite that never burns
    lives exactly as long as the curves say.

    ## Action Space

    ``OrbitRaising-v0``: ``Discrete(4)``, the index of a burn in
    ``config.burn_sizes_m_s`` = (0, 10, 30, 100) m/s; 0 coasts.
    ``OrbitRaisingContinuous-v0``: ``Box(-1, 1, (1,))``; a burn of
    ``max_burn_m_s * max(a, 0)`` (100 m/s at +1), so half the range coasts. An
    action outside [-1, 1] is clipped to it, as Gymnasium's LunarLander clips (2.0
    burns 100 m/s, -3.0 coasts); a NaN action is a ``ValueError``.
    Every burn is cut to the propellant on board and to the 4000 km apogee where
    the universal curves end; the burn made is ``info["burn_m_s"]``.

    ## Observation Space

    ``Box(low, high, (7,), float32)``, the same in every variant:

    | Num | Observation        | Unit and scaling                                                         | Min | Max |
    |-----|--------------------|--------------------------------------------------------------------------|-----|-----|
    | 0   | perigee height     | m / ``HEIGHT_SCALE_M`` (1000 km)                                         | 0.1 | 1.2 |
    | 1   | apogee height      | m / ``HEIGHT_SCALE_M`` (1000 km)                                         | 0.1 | 5   |
    | 2   | delta-v left       | m/s / ``DV_SCALE_M_S`` (1 km/s), rocket eq.                              | 0   | 3   |
    | 3   | mission clock      | steps taken / ``horizon_steps``                                          | 0   | 1   |
    | 4   | predicted lifetime | L / (L + 365 d), L in days, no burns, at ``DensityConfig.nominal_scale`` | 0   | 1   |
    | 5   | apogee drop        | d / (d + 10 km), d = drop over the last coast                            | 0   | 1   |
    | 6   | perigee drop       | d / (d + 1 km), d = drop over the last coast                             | 0   | 1   |

    This is what a ground station knows: the tracked orbit, the propellant, the
    time, its own prediction of the lifetime from the paper's tables, and the decay
    it has observed. With the default, known density the prediction is exact; in
    ``OrbitRaisingUncertain-v0`` the true density scale is not observed and only
    the observed decay (5, 6) against the prediction (4) reveals it. "Min" is the
    least value the env produces; the Box's low is 0 for every component. The
    clock is held at 1 past ``horizon_steps``. ``env.unwrapped.state`` is the
    simulator's state (for tests and plots).

    ## Rewards

    The days the satellite spends in orbit during the step, minus
    ``propellant_cost_per_m_s`` (0.4 day per m/s) times the burn made. In the step
    of re-entry only the exact fraction of the step before re-entry counts.

    ## Starting State

    Perigee uniform in ``start_perigee_km`` (160-500 km), apogee uniform between
    the perigee and ``start_apogee_max_km`` (1600 km): the range of the paper's
    Table II. Full tank. In ``OrbitRaisingUncertain-v0`` the density scale s0 is
    drawn log-uniform in [0.1, 10] and the cycle phase uniform.
    ``reset(options=...)`` pins any of: ``perigee_km``, ``apogee_km``,
    ``density_scale``, ``density_phase_rad`` and the satellite's
    ``drag_coefficient``, ``area_m2``, ``dry_mass_kg``, ``propellant_mass_kg``,
    ``isp_s``. A missing height is drawn; an invalid option raises ``ValueError``.
    Instead of the heights, ``curve_label`` and ``curve_tau`` (together) pin the orbit's
    point on the universal curves, the state's ``label`` and ``tau``.

    Replaying a start: ``env.unwrapped.start_options`` is the dict of options that
    gives the episode's start back bit for bit (``curve_label``, ``curve_tau``, the
    density's two and the satellite's five), and ``reset(options=start_options)`` then
    gives the same returns for the same actions. The heights the state reports do not
    replay a start: they are table B's heights at the point table A located for the
    drawn heights, and table A locates them up to 30 m of perigee and 0.5 km of apogee
    away (some 0.3 day of return). The vector environment's ``start_options`` holds
    each sub-environment's (automatic resets included) as arrays; row i restarts its
    mission in a single environment too (returns equal to about 1e-12 day).

    ## Episode End

    Terminated (``terminated=True``) at re-entry, perigee at 100 km (the paper's end of
    integration), and at the mission's end, after ``horizon_steps`` steps (365): the
    mission's length is part of the task, not a time limit outside it, so ``truncated`` is
    never set and no value lies past the horizon (`orbit_env.envs`, "The mission's end is
    terminal"); ``info["reentered"]`` tells the two apart. The environment ends the mission
    itself: ``horizon_steps`` alone sets the mission's length and clock, so the ids
    are registered without ``max_episode_steps`` and ``gymnasium.make`` adds no
    ``TimeLimit``. ``env.spec.max_episode_steps`` reports the horizon all the same:
    365, or the ``horizon_steps`` given (``gymnasium.make(id, horizon_steps=100)``
    says 100), the length of a mission that does not re-enter. An environment made
    again from its spec (``gymnasium.make(env.spec)``, as ``check_env`` does) gets a
    ``TimeLimit`` at that same step, which adds ``truncated=True`` to the step that
    terminates (Gymnasium's libraries read that as terminated). (A different
    ``max_episode_steps`` given to ``gymnasium.make`` adds Gymnasium's ``TimeLimit``
    outside the environment, which cannot see it, and the spec then reports that
    limit: pass ``horizon_steps`` instead.)

    ## Info

    ``step`` returns ``info["burn_m_s"]``, the burn made in the step [m/s] (after the
    cuts above); ``step`` and ``reset`` return the episode so far:

    | Key               | Meaning                                                         |
    |-------------------|-----------------------------------------------------------------|
    | ``reentered``     | bool: the satellite has re-entered (``terminated`` at re-entry or the horizon) |
    | ``days_in_orbit`` | days in orbit since the start (the mission time; at re-entry,   |
    |                   | the exact life); the return is this less the propellant's cost |
    | ``dv_used_m_s``   | delta-v burnt since the start [m/s], the sum of ``burn_m_s``    |

    At ``reset`` they are False, 0 and 0. The vector environment returns the same keys
    as arrays with Gymnasium's ``_key`` masks.

    ## Arguments

    Every field of `OrbitRaisingConfig` and `DensityConfig` is a
    flat keyword, as LunarLander's ``gravity=``:
    ``gymnasium.make("OrbitRaising-v0", horizon_steps=100, area_m2=2.0)``,
    ``gymnasium.make("OrbitRaisingUncertain-v0", scale_range=(0.5, 2.0))``. A
    config object or a dict of its fields works too (``config=OrbitRaisingConfig(...)``,
    ``config={"horizon_steps": 100}``, ``density=DensityConfig(...)``); flat keywords
    then replace single fields. An unknown keyword is a ``ValueError`` that names it
    and lists the valid ones. Besides: ``continuous=False`` and ``render_mode=None``.
    ``reset(options=...)`` takes the options of ``Starting State``
    (`orbit_env.envs.reset_options.RESET_OPTIONS`; ``start_options`` gives a start's).
    The same keywords for ``gymnasium.make_vec(id, num_envs=N)``, the numpy-batched
    version (`orbit_env.envs.vector.OrbitRaisingVectorEnv`), which also takes
    ``autoreset_mode``.
    ``render_mode``: "human" and "rgb_array" draw the (apogee, perigee) plane of
    the paper's Fig. 2 with the track and the burns (needs ``orbit-env[plot]``);
    "ansi" returns one line of text. Where "human" can open no window (no display,
    or a matplotlib backend that draws none) it warns once and draws nothing, so
    Gymnasium's ``check_env`` passes on headless machines.

    ## Why these defaults

    A 46 kg satellite of 1 m^2 (c = c_x F / m = 0.048 m^2/kg; the paper's example
    sphere has 0.039) coasts 16 revolutions (about a day) per step through a
    365-step mission (about a year). Over the paper's start range its lifetime
    without burns runs from hours (160 km perigee) to centuries (500 km): about
    45% of starts outlive the mission anyway, a quarter re-enter within half of it
    even with the whole tank burned, and in between a burn pays if it is sized to
    the need. The tank (300 m/s) raises a 250 km circular orbit to 250 x 1380 km;
    a burn costs 0.4 day per m/s, so the whole tank is worth 120 mission days.
    Never burning loses the days after re-entry; burning everything at once pays
    for margin beyond the horizon. Measured on 4000 starts (seed 0), choosing per
    start the best single burn at the first step returns 17% more than never
    burning and 19% more than burning the whole tank at once, a lower bound on what
    the optimal policy gains. With the density known, a burn buys the most life per
    m/s while the perigee is still high, so the question is whether and how much;
    with the density unknown (``OrbitRaisingUncertain-v0``) it is also when enough
    decay has been seen to size the burn.

    ## Version History

    Nothing is released yet; from the first release on, any change to the returns
    bumps the id's version (Gymnasium's convention: ``-v0`` becomes ``-v1``). See
    CHANGELOG.md.

    * v0: initial version.
    * v0, dynamics changed 2026-12-03 (the burn relocation fix; unreleased, so the id
      stayed): a burn moves the orbit from its point on the universal curves by table
      A's difference, where it had been placed where table A puts the new heights (a
      burn of 1e-9 m/s then changed a year's return by +0.02 to +0.14 day), and
      ``decode`` inverts table B exactly (it was up to 0.1% off in nu). Returns of
      policies that burn differ from those measured before that date.
    * v0, episode end changed 2026-12-06 (unreleased, so the id stayed): the mission's
      end is ``terminated``, as re-entry is; it was ``truncated``. Rewards and dynamics
      are unchanged.

    Examples:
        >>> import gymnasium as gym
        >>> from orbit_env.envs import register_envs
        >>> register_envs()
        >>> env = gym.make("OrbitRaising-v0")
        >>> obs, info = env.reset(seed=0, options={"perigee_km": 360.0, "apogee_km": 700.0})
        >>> obs.shape, obs.dtype
        ((7,), dtype('float32'))
        >>> obs, reward, terminated, truncated, info = env.step(3)  # a 100 m/s burn
        >>> round(info["burn_m_s"]), terminated
        (100, False)
        >>> bool(obs[1] > 0.9)  # the apogee went from 700 km to about 1100 km
        True
        >>> start = env.unwrapped.start_options  # replays the start bit for bit
        >>> _ = env.reset(options=start)
        >>> env.unwrapped.start_options == start
        True
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array", "ansi"], "render_fps": 8}
    _spec: EnvSpec | None = None

    def __init__(
        self,
        config: OrbitRaisingConfig | dict[str, Any] | None = None,
        *,
        continuous: bool = False,
        density: DensityConfig | dict[str, Any] | None = None,
        render_mode: str | None = None,
        **keywords: Any,
    ) -> None:
        config, density = resolve_task_arguments(
            config, density, keywords, env_keywords=("config", "continuous", "density", "render_mode")
        )
        self.task = Task.of(config, density, continuous)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode={render_mode!r} is invalid; allowed: {self.metadata['render_modes']} or None"
            )
        self.render_mode = render_mode
        self.observation_space = self.task.observation_space
        self.action_space = self.task.action_space
        self._state: TaskState | None = None
        self._start_options: dict[str, float] = {}
        self._track: list[tuple[float, float, float]] = []  # (perigee, apogee, burn) for render()
        self._last_burn_m_s = 0.0
        self._dv_used_m_s = 0.0  # the burns of the episode so far, for info["dv_used_m_s"]
        self._renderer: Any = None
        self._ended = False  # the episode has ended: a step now warns, as CartPole's does

    @property
    def spec(self) -> EnvSpec | None:
        """Gymnasium's spec of the environment, ``max_episode_steps`` the horizon (see Episode End)."""
        return self._spec

    @spec.setter
    def spec(self, spec: EnvSpec | None) -> None:
        # gymnasium.make sets a spec without max_episode_steps (no TimeLimit: the env ends its
        # missions itself); readers of the spec (wrappers, researchers) still learn the episode's length.
        if spec is not None and spec.max_episode_steps is None:
            spec = dataclasses.replace(spec, max_episode_steps=self.config.horizon_steps)
        self._spec = spec

    # The universal curves are not an attribute: universal_curves() is the process's
    # one cached table, so a pickled env carries only its own state. Neither does it
    # carry its figure, which is drawn again on the next render().
    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state

    @property
    def state(self) -> dict[str, float]:
        """The simulator state: curve coordinates, heights [m], mass [kg], time [days], density scale."""
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        s = self._state
        return {
            "label": s.label,
            "tau": s.tau,
            "perigee_m": s.perigee_m,
            "apogee_m": s.apogee_m,
            "mass_kg": s.mass_kg,
            "time_days": s.time_days,
            "density_scale": s.density_scale,
        }

    @property
    def start_options(self) -> dict[str, float]:
        """The reset options that give this episode's start back bit for bit (a new dict).

        ``reset(options=env.unwrapped.start_options)`` restarts the same mission: the
        orbit's point on the universal curves (``curve_label``, ``curve_tau``), the density
        (``density_scale``, ``density_phase_rad``) and the satellite; the same actions then
        give the same returns. See ``Starting State``.
        """
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return dict(self._start_options)

    @property
    def task_state(self) -> TaskState:
        """The task model's state of the satellite (`orbit_env.envs.task.TaskState`; live, not a copy)."""
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return self._state

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start a new mission; ``options`` may pin the orbit and the satellite (see the class)."""
        super().reset(seed=seed)
        self._state, self._start_options = task_model.start_and_options(self.task, self.np_random, None, options)
        state = self._state
        self._last_burn_m_s = 0.0
        self._dv_used_m_s = 0.0
        self._ended = False
        if self.render_mode is not None:
            self._track = [(state.perigee_m, state.apogee_m, 0.0)]
            if self.render_mode == "human":
                self.render()
        return task_model.observe(self.task, state), self._outcome()

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        """Burn (maybe), then coast ``revolutions_per_step`` revolutions."""
        state = self._state
        if state is None:
            raise RuntimeError("call reset() before step()")
        if self._ended:
            gym.logger.warn(ENDED_WARNING)
        task = self.task
        requested = task.requested_dv(action)
        result = task_model.step(task, state, requested)
        self._dv_used_m_s += result.burn_m_s
        if self.render_mode is not None:
            if result.burn_m_s > 0.0:
                # The orbit the burn made, before the coast: the heights less the coast's drops.
                self._track.append(
                    (state.perigee_m + state.perigee_drop_m, state.apogee_m + state.apogee_drop_m, result.burn_m_s)
                )
            self._last_burn_m_s = result.burn_m_s
            self._track.append((state.perigee_m, state.apogee_m, 0.0))
            if self.render_mode == "human":
                self.render()
        # The mission's end is a terminal state of the task, as re-entry is (`orbit_env.envs`).
        self._ended = bool(result.terminated or result.truncated)
        return (
            task_model.observe(task, state),
            result.reward,
            self._ended,
            False,
            {"burn_m_s": result.burn_m_s, **self._outcome()},
        )

    def _outcome(self) -> dict[str, Any]:
        """The episode so far, for ``info``: re-entered, days in orbit, delta-v burnt."""
        state = self._state
        return {"reentered": state.tau <= 0.0, "days_in_orbit": state.time_days, "dv_used_m_s": self._dv_used_m_s}

    def render(self) -> Any:
        """Draw the (apogee, perigee) plane with the track (rgb_array, human) or one text line (ansi)."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode to gymnasium.make")
            return None
        state = self._state
        if state is None:
            raise RuntimeError("call reset() before render()")
        from orbit_env.envs import render as render_module

        if self.render_mode == "ansi":
            return render_module.render_ansi(
                step=int(state.steps),
                time_days=state.time_days,
                perigee_m=state.perigee_m,
                apogee_m=state.apogee_m,
                dv_left_m_s=state.dv_left_m_s,
                burn_m_s=self._last_burn_m_s,
                reentered=state.tau <= 0.0,
            )
        if self._renderer is None:
            self._renderer = render_module.TrackRenderer(
                human=self.render_mode == "human", fps=self.metadata["render_fps"]
            )
        return self._renderer.draw(self._track, time_days=state.time_days, dv_left_m_s=state.dv_left_m_s)

    def close(self) -> None:
        """Close the render window, if any."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
