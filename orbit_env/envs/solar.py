"""``OrbitRaisingSolar-v0``: the orbit-raising decision under the real Sun, with the disposal rule at the end.

The single environment (`OrbitRaisingSolarEnv`, whose docstring is the user's manual) and the
vector environment (`OrbitRaisingSolarVectorEnv`) both step the solar task model
(`orbit_env.envs.solar_task`) on a `~orbit_env.envs.state.BatchState`: of one satellite, or of
``num_envs``.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import EnvSpec
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numpy.typing import NDArray

from orbit_env.envs import ENDED_WARNING, solar_task
from orbit_env.envs.config import OrbitRaisingConfig, from_fields
from orbit_env.envs.solar_task import SOLAR_CONFIG, SOLAR_OBS_NAMES, SolarMission, SolarTask
from orbit_env.envs.state import ROW, BatchState
from orbit_env.envs.vector import batch_seed

FloatArray = NDArray[np.float64]

#: The keys of ``info`` that describe each episode so far.
SOLAR_OUTCOME_KEYS = ("reentered", "days_in_orbit", "dv_used_m_s", "date")
#: The keys of ``info`` at a mission's end: the disposal burn made and whether the orbit complies.
SOLAR_END_KEYS = ("disposal_dv_m_s", "complies")


def solar_task_of(config: OrbitRaisingConfig | dict[str, Any] | None, keywords: dict[str, Any]) -> SolarTask:
    """The solar task of an environment's keywords: the mission's fields flat (``solar_split="test"``).

    Raises:
        ValueError: an unknown keyword (the valid ones named) or a bad value.
    """
    keywords = dict(keywords)
    continuous = keywords.pop("continuous", False)
    if not isinstance(continuous, (bool, np.bool_)):
        raise ValueError(f"continuous={continuous!r} is invalid; allowed: True or False")
    mission_fields = {f.name for f in dataclasses.fields(SolarMission)}
    config_fields = {f.name for f in dataclasses.fields(OrbitRaisingConfig)}
    unknown = [k for k in keywords if k not in mission_fields and k not in config_fields]
    if unknown:
        valid = sorted({"config", "continuous", "render_mode", *mission_fields, *config_fields})
        raise ValueError(f"unknown keyword {unknown[0]!r}; valid keywords: {', '.join(valid)}")
    overrides = {k: v for k, v in keywords.items() if k in config_fields}
    config = from_fields(OrbitRaisingConfig, config, "config", overrides, default=SOLAR_CONFIG)
    mission = SolarMission(**{k: v for k, v in keywords.items() if k in mission_fields})
    task = SolarTask(config=config, mission=mission, continuous=bool(continuous))
    _ = task.start_window  # the mission must fit its split of the record: a ValueError now, not at reset()
    return task


class OrbitRaisingSolarEnv(gym.Env[NDArray[np.float32], np.int64]):
    """When to raise the apogee under the real Sun, with the disposal rule at the end.

    ## Description
    A 210 kg satellite of today (1 m^2, c_x 2.2; a 10 kg monopropellant tank, Isp 220 s: 105 m/s)
    is released in a near-circular orbit of 380-560 km at 53 deg, on a date drawn from its split of
    the space-weather record, and flies a five-year mission. Each step is a month (30 days). At its
    start the agent may fire at perigee: the perigee stays, the apogee rises, and the orbit lives
    longer while its perigee stays low. The orbit then decays under NRLMSIS 2.1 in co-rotating air
    and the record's Sun of that month (the drag clock, `orbit_env.decay.drag_clock`). At the
    mission's end the orbit must comply with the disposal rule: re-enter within
    ``disposal_years`` (5: the FCC's rule of 2022) under the record's Sun after the end. The
    environment then makes the cheapest compliant disposal burn (retrograde at apogee, lowering
    the perigee) and charges its propellant; if the propellant left cannot make the orbit
    comply, it charges a penalty instead. The task: live through the mission, comply at its end,
    spend little.

    ## Action Space
    ``Discrete(4)``: a perigee burn of 0, 5, 10 or 20 m/s this month (cut to the propellant left).
    ``OrbitRaisingSolarContinuous-v0`` (``continuous=True``), the continuous twin: ``Box(-1, 1, (1,))``,
    a burn of 20 m/s x max(a, 0) (``max_burn_m_s``; a <= 0 coasts, as in ``OrbitRaisingContinuous-v0``).

    ## Observation Space
    ``Box(0, high, (11,), float32)``; only the past, never the future:

    | index | name | meaning |
    |---|---|---|
    | 0, 1 | perigee, apogee | heights / 1000 km |
    | 2 | delta_v_left | km/s the propellant left gives |
    | 3 | mission_clock | months flown / 61 |
    | 4 | predicted_lifetime | L / (L + 365 d), L the life left at last month's observed drag |
    | 5, 6 | apogee_drop, perigee_drop | last month's, d / (d + 10 km), d / (d + 1 km) |
    | 7 | f107 | F10.7 of the day before the step [sfu] / 100 |
    | 8, 9 | f107_mean_81d, f107_mean_365d | its trailing 81- and 365-day means / 100 |
    | 10 | ap | Ap of the day before / 100 |

    ## Rewards
    The days in orbit during the month, minus 3 days per m/s burnt. At the mission's end, minus
    3 days per m/s of the disposal burn, or minus the penalty (the mission's 1830 days plus the
    whole tank's cost: 2146 days) if the propellant left cannot make the orbit comply; a
    non-compliant plan then never returns more than a compliant one.

    ## Starting State
    A whole day drawn uniformly from the split (``solar_split="train"``: missions ending before
    2009-01-01, cycles 19-23; ``"test"``: missions from 2009-01-01 to the end of the observed
    record, cycles 24-25); perigee uniform in 380-560 km, apogee up to 20 km above. The rule's
    judgement after a test mission reaches into the record's forecast and then solar cycle 24
    repeated (`orbit_env.decay.solar_record.RecordActivity`). ``reset(options=...)`` pins
    ``start_date`` (ISO) or ``start_day``, ``perigee_km``, ``apogee_km``; ``start_options``
    gives back the exact start (``curve_label``, ``curve_tau``, ``start_day``).

    ## Episode End
    Terminated at re-entry (perigee 100 km) and after 61 steps, with the rule judged: the mission's
    end is part of the task (its disposal is charged there), so ``truncated`` is never set
    (`orbit_env.envs`, "The mission's end is terminal"); ``info["reentered"]`` tells the two apart.
    A shorter mission is ``horizon_steps``; ``gymnasium.make``'s own ``max_episode_steps`` wraps the
    environment in Gymnasium's ``TimeLimit``, which cuts the mission off (``truncated``, no rule judged).
    ``info``: ``burn_m_s``, ``reentered``, ``days_in_orbit``, ``dv_used_m_s``, ``date`` (the
    next step's first day, ISO); at the end also ``disposal_dv_m_s`` and ``complies``.

    ## Arguments
    ``continuous`` (the twin's action space), ``solar_split`` ("train" or "test"), ``disposal_years``
    (0.5-25), ``block_days``, ``inclination_deg``, ``start_span_km``, and any field of
    `OrbitRaisingConfig` (the satellite, the burn sizes, ``horizon_steps``, ``propellant_cost_per_m_s``,
    ``start_perigee_km``).
    ``render_mode``: "rgb_array" and "human" draw the (apogee, perigee) plane with the track, a
    month with a burn in red, over the paper's curves as the other environments draw them (needs
    ``orbit-env[plot]``; Stable-Baselines3's ``make_vec_env`` asks for "rgb_array"); "ansi" returns
    one line of text.

    ## Version History
    * v0: initial version (2026-12-04).
    * v0, episode end changed 2026-12-06 (unreleased, so the id stayed): the mission's end is
      ``terminated``, as re-entry is; it was ``truncated``. Rewards and dynamics are unchanged.
    * ``OrbitRaisingSolarContinuous-v0``: v0, initial version (2026-12-06).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array", "ansi"], "render_fps": 4}
    _spec: EnvSpec | None = None

    def __init__(
        self,
        config: OrbitRaisingConfig | dict[str, Any] | None = None,
        *,
        render_mode: str | None = None,
        **keywords: Any,
    ) -> None:
        self.task = solar_task_of(config, keywords)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode={render_mode!r} is invalid; allowed: {self.metadata['render_modes']} or None"
            )
        self.render_mode = render_mode
        self.observation_space = self.task.observation_space
        self.action_space = self.task.action_space
        self._state: BatchState | None = None
        self._dv_used_m_s = 0.0
        self._last: dict[str, Any] = {}
        self._ended = False  # the episode has ended: a step now warns, as CartPole's does
        # Pictures ("human", "rgb_array"): the (apogee, perigee) plane with the track, as the known-density envs
        # draw it (`orbit_env.envs.render.TrackRenderer`); (perigee [m], apogee [m], the month's burn [m/s]).
        self._drawn = render_mode in ("human", "rgb_array")
        self._track: list[tuple[float, float, float]] = []
        self._renderer: Any = None

    # A pickled env carries no figure: it is drawn again on the next render().
    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state

    @property
    def spec(self) -> EnvSpec | None:
        """Gymnasium's spec, ``max_episode_steps`` the mission's steps."""
        return self._spec

    @spec.setter
    def spec(self, spec: EnvSpec | None) -> None:
        if spec is not None and spec.max_episode_steps is None:
            spec = dataclasses.replace(spec, max_episode_steps=self.task.config.horizon_steps)
        self._spec = spec

    @property
    def task_state(self) -> BatchState:
        """The task model's state (a batch of one; live, not a copy)."""
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return self._state

    @property
    def start_options(self) -> dict[str, float]:
        """The reset options that give this episode's start back exactly (a new dict)."""
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return {k: float(v[0]) for k, v in self._start.items()}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start a new mission; ``options`` may pin its day and orbit (see the class)."""
        super().reset(seed=seed)
        self._state = solar_task.start(self.task, self.np_random, 1, options)
        self._start = solar_task.start_options(self._state)
        self._dv_used_m_s = 0.0
        self._ended = False
        if self._drawn:
            self._track = [(float(self._state.perigee_m[0]), float(self._state.apogee_m[0]), 0.0)]
            if self.render_mode == "human":
                self.render()
        return solar_task.observe(self.task, self._state)[0], self._outcome()

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        """Burn (maybe), then decay a month; at the mission's end, the rule."""
        state = self._state
        if state is None:
            raise RuntimeError("call reset() before step()")
        if self._ended:
            gym.logger.warn(ENDED_WARNING)
        obs, reward, terminated, truncated, burn, disposal, complies = solar_task.step_and_observe_one(
            self.task, state, self.task.requested_dv(action)
        )
        self._dv_used_m_s += burn
        info: dict[str, Any] = {"burn_m_s": burn, **self._outcome()}
        if truncated:
            info["disposal_dv_m_s"] = disposal
            info["complies"] = complies
            self._dv_used_m_s += disposal
            info["dv_used_m_s"] = self._dv_used_m_s
        self._last = info
        if self._drawn:
            self._track.append((float(state.perigee_m[0]), float(state.apogee_m[0]), burn))
            if self.render_mode == "human":
                self.render()
        # The mission's end is a terminal state of the task, as re-entry is (`orbit_env.envs`).
        self._ended = terminated or truncated
        return obs, reward, self._ended, False, info

    def _outcome(self) -> dict[str, Any]:
        data = self._state.data  # a batch of one: column 0 (read directly, as the step is timed against CartPole's)
        today = data[ROW.start_day, 0] + data[ROW.steps, 0] * self.task.mission.block_days
        return {
            "reentered": bool(data[ROW.nu, 0] <= 0.0),
            "days_in_orbit": float(data[ROW.time_days, 0]),
            "dv_used_m_s": self._dv_used_m_s,
            "date": solar_task.date_of(self.task, float(today)),
        }

    def render(self) -> Any:
        """The (apogee, perigee) plane with the track ("rgb_array", "human"), or one text line ("ansi").

        The text: the date, the orbit, the tank and the last burn.
        """
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode to gymnasium.make")
            return None
        state = self.task_state
        if self._drawn:
            from orbit_env.envs.render import TrackRenderer

            if self._renderer is None:
                self._renderer = TrackRenderer(human=self.render_mode == "human", fps=self.metadata["render_fps"])
            return self._renderer.draw(
                self._track, time_days=float(state.time_days[0]), dv_left_m_s=float(state.dv_left_m_s[0])
            )
        info = self._last
        return (
            f"{solar_task.date_of(self.task, float(solar_task.today(self.task, state)[0]))}  "
            f"step {int(state.steps[0]):2d}  perigee {state.perigee_m[0] / 1e3:7.1f} km  "
            f"apogee {state.apogee_m[0] / 1e3:7.1f} km  dv left {state.dv_left_m_s[0]:6.1f} m/s  "
            f"burn {info.get('burn_m_s', 0.0):4.1f} m/s"
        )

    def close(self) -> None:
        """Close the render window, if any."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


class OrbitRaisingSolarVectorEnv(VectorEnv):
    """``num_envs`` solar missions stepped together (see `OrbitRaisingSolarEnv` for the task).

    Batched as Gymnasium's vector API: observations (num_envs, 11), actions (num_envs,), ``info``
    the single environment's keys as arrays with their ``_key`` masks (``date`` as ``datetime64[D]``,
    where the single environment's is an ISO string and Gymnasium's own vector environments gather
    those strings in an object array). Finished missions restart
    as ``autoreset_mode`` says (``NEXT_STEP``, the default, or ``SAME_STEP`` with
    ``info["final_obs"]`` and ``info["final_info"]``).
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(
        self,
        num_envs: int = 1,
        config: OrbitRaisingConfig | dict[str, Any] | None = None,
        *,
        render_mode: str | None = None,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        max_episode_steps: int | None = None,
        **keywords: Any,
    ) -> None:
        if not (isinstance(num_envs, (int, np.integer)) and num_envs >= 1):
            raise ValueError(f"num_envs={num_envs!r} is invalid; allowed: a whole number >= 1")
        if render_mode is not None:
            raise ValueError("render_mode is invalid for the vector environment; allowed: None")
        self.task = solar_task_of(config, keywords)
        if max_episode_steps is not None and max_episode_steps != self.task.config.horizon_steps:
            raise ValueError(f"max_episode_steps={max_episode_steps} must equal horizon_steps")
        mode = AutoresetMode(autoreset_mode)
        if mode == AutoresetMode.DISABLED:
            raise ValueError("autoreset_mode=DISABLED is invalid here; allowed: NEXT_STEP, SAME_STEP")
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.num_envs = int(num_envs)
        self.single_observation_space = self.task.observation_space
        self.single_action_space = self.task.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._state: BatchState | None = None
        self._starts: dict[str, FloatArray] = {}  # the current missions' start options (`start_options`)
        self._needs_reset = np.zeros(self.num_envs, dtype=bool)
        self._dv_used = np.zeros(self.num_envs)

    @property
    def task_state(self) -> BatchState:
        """The task model's state of the batch (live)."""
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return self._state

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start ``num_envs`` new missions (``options`` as the single environment's, numbers or arrays).

        A list of seeds, one per env (Gymnasium's form), seeds the one generator (`batch_seed`).
        """
        if seed is not None:
            self._np_random, self._np_random_seed = gym.utils.seeding.np_random(batch_seed(seed, self.num_envs))
        self._state = solar_task.start(self.task, self.np_random, self.num_envs, options)
        self._starts = solar_task.start_options(self._state)
        self._needs_reset[:] = False
        self._dv_used[:] = 0.0
        return solar_task.observe(self.task, self._state), self._outcome(np.ones(self.num_envs, dtype=bool))

    def step(self, actions: Any) -> tuple[NDArray[np.float32], FloatArray, Any, Any, dict[str, Any]]:
        """Step every mission; restart the finished ones as ``autoreset_mode`` says."""
        state = self.task_state
        n = self.num_envs
        requested = self.task.requested_dvs(actions, n)
        restarting = np.flatnonzero(self._needs_reset)
        reward = np.zeros(n)
        terminated, truncated = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        burn_m_s, disposal_m_s, complies = np.zeros(n), np.zeros(n), np.ones(n, dtype=bool)
        if restarting.size:  # NEXT_STEP: these ignore the action and start a new mission
            stepping = np.flatnonzero(~self._needs_reset)
            sub = state.take(stepping)
            result, stepped_obs = solar_task.step_and_observe(self.task, sub, requested[stepping])
            state.put(stepping, sub)
            obs = np.empty((n, len(SOLAR_OBS_NAMES)), dtype=np.float32)
            obs[stepping] = stepped_obs
            obs[restarting] = self._restart(restarting)
        else:
            stepping = slice(None)
            result, obs = solar_task.step_and_observe(self.task, state, requested)
        reward[stepping], terminated[stepping], truncated[stepping] = result.reward, result.terminated, result.truncated
        burn_m_s[stepping], disposal_m_s[stepping], complies[stepping] = (
            result.burn_m_s,
            result.disposal_m_s,
            result.complies,
        )
        self._dv_used += burn_m_s + disposal_m_s
        stepped = ~self._needs_reset
        ends = terminated | truncated
        info = {"burn_m_s": burn_m_s, "_burn_m_s": stepped, **self._outcome(np.ones(n, dtype=bool))}
        info["disposal_dv_m_s"], info["_disposal_dv_m_s"] = disposal_m_s, truncated.copy()
        info["complies"], info["_complies"] = complies, truncated.copy()
        if self.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP:
            done = np.flatnonzero(ends)
            if done.size:
                # As SyncVectorEnv: final_obs an object array (the finished rows' observations, None elsewhere);
                # the finished episodes' info moves to final_info, and the new episodes' info has none of the
                # step's keys (their masks False there) and their outcome so far (nothing yet).
                final_obs = np.empty(n, dtype=object)
                final_obs[done] = np.fromiter(obs[done], dtype=object, count=done.size)
                final_info = {key: value & ends if key.startswith("_") else value.copy() for key, value in info.items()}
                obs[done] = self._restart(done)
                info = {**info, **self._outcome(np.ones(n, dtype=bool))}
                for key in ("burn_m_s", *SOLAR_END_KEYS):
                    info[f"_{key}"] = info[f"_{key}"] & ~ends
                info["final_obs"], info["_final_obs"] = final_obs, ends.copy()
                info["final_info"], info["_final_info"] = final_info, ends.copy()
        else:
            self._needs_reset = ends
        # The mission's end is a terminal state of the task, as re-entry is (`orbit_env.envs`).
        return obs, reward, ends.copy(), np.zeros(n, dtype=bool), info

    @property
    def start_options(self) -> dict[str, FloatArray]:
        """The reset options that give every current mission's start back exactly (arrays of shape (num_envs,)).

        For the mission each sub-environment is in, whether ``reset`` or an automatic reset began it:
        ``reset(options=envs.start_options)`` restarts all of them, and row i's values
        (``{k: v[i] for k, v in ...items()}``) restart mission i in a single environment.
        """
        if self._state is None:
            raise RuntimeError("the environment has no state before reset()")
        return {name: row.copy() for name, row in self._starts.items()}

    def _restart(self, rows: NDArray[np.intp]) -> NDArray[np.float32]:
        fresh = solar_task.start(self.task, self.np_random, rows.size)
        self.task_state.put(rows, fresh)
        for name, row in solar_task.start_options(fresh).items():
            self._starts[name][rows] = row
        self._dv_used[rows] = 0.0
        return solar_task.observe(self.task, fresh)

    def _outcome_values(self, key: str) -> Any:
        state = self.task_state
        if key == "reentered":
            return state.nu <= 0.0
        if key == "days_in_orbit":
            return state.time_days.copy()
        if key == "dv_used_m_s":
            return self._dv_used.copy()
        return solar_task.dates_of(self.task, solar_task.today(self.task, state))

    def _outcome(self, mask: NDArray[np.bool_]) -> dict[str, Any]:
        info: dict[str, Any] = {}
        for key in SOLAR_OUTCOME_KEYS:
            info[key] = self._outcome_values(key)
            info[f"_{key}"] = mask.copy()
        return info
