"""The solar decision task: when to raise the apogee under the real Sun, with the disposal rule at the end.

A satellite of today (53 deg, NRLMSIS 2.1 in co-rotating air, the shipped space-weather
record) flies a five-year mission from a date drawn from its split of the record. Each step
is a month (`SolarMission.block_days`); at its start the agent may fire at perigee, which
raises the apogee and keeps the perigee low (the paper's burn); the orbit then decays along
the universal curves of a reference NRLMSIS profile by the drag clock of that month at its
perigee (`orbit_env.decay.drag_clock`). At the mission's end the orbit must comply with the
disposal rule: re-enter within ``disposal_years`` under the record's Sun after the end. The
task then makes the cheapest compliant disposal burn (retrograde at apogee, lowering the
perigee) and charges its propellant; where the propellant left cannot make the orbit comply,
it charges `SolarTask.penalty_days` instead.

The parts it shares with the known-density task (`orbit_env.envs.task`): the state's fields
and storage (`orbit_env.envs.state`), the perigee burn (`orbit_env.envs.task.burn`: the rocket
equation, the vis-viva burn, the move to the new curve) and the universal curves. What is its
own: the calendar (a mission's days are whole days of the record), the drag clock's coast, the
observation of the Sun, and the disposal rule. Every consumer (the single and the vector
environment, the hand-coded policies, the DP) calls these functions; the manual is
`orbit_env.envs.solar.OrbitRaisingSolarEnv`'s docstring and docs/solar-task.md.

SI units inside (m, kg, s, m/s); days for the calendar and the reward; km in the reset options.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from functools import cached_property, lru_cache
from typing import Any, NamedTuple

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from orbit_env.checks import check_number
from orbit_env.constants import DAYS_PER_YEAR, SECONDS_PER_DAY
from orbit_env.decay.curves import NU_REF, UniversalCurves, nu_per_revolution
from orbit_env.decay.drag_clock import DragClock, drag_clock
from orbit_env.decay.solar import iso_date, unix_days
from orbit_env.envs import DISPOSAL_YEARS, SOLAR_SPLITS, solar_kernel
from orbit_env.envs import task as task_model
from orbit_env.envs.config import OrbitRaisingConfig
from orbit_env.envs.reset_options import check_curve_point, option_array
from orbit_env.envs.state import STALE_SEGMENT, BatchState
from orbit_env.envs.task import (
    LIFETIME_SCALE_DAYS,
    OBS_HIGH,
    OBS_NAMES,
    Task,
    kernel_parameters,
    observation_batch,
    place,
    update_satellite,
)
from orbit_env.physics.orbit import dv_to_lower_perigee_m_s

FloatArray = NDArray[np.float64]

#: The day that splits the record: training missions end before it (solar cycles 19-23), test missions
#: begin on or after it (cycles 24-25, held out).
SPLIT_DATE = "2009-01-01"
#: Days of the record a mission's first day needs before it: the observation's trailing 365-day mean.
HISTORY_DAYS = 365
#: Candidate perigees of the disposal burn per pass (from 100 km to the perigee, searched by bisection; two
#: passes, the second between the last compliant candidate and the next: the cheapest compliant burn to
#: within (h_p - 100 km) / CANDIDATES^2, under 0.5 km of perigee, about 0.15 m/s).
DISPOSAL_CANDIDATES = 24

#: The satellite and the mission of ``OrbitRaisingSolar-v0`` (why each, measured: docs/solar-task.md).
#: A 210 kg smallsat of 1 m^2 (G/(c_x F) = 95 kg/m^2), a monopropellant tank of 10 kg (Isp 220 s:
#: 105 m/s), burns of 5-20 m/s a month, 61 months (1830 days, five years: half a solar cycle,
#: so the phase matters), released in near-circular orbits of 380-560 km (where ride-shares drop
#: satellites of today: without burns about half re-enter within the mission and a fifth to a
#: third need a disposal burn at its end). Propellant costs 3 days of mission per m/s (the tank
#: is worth a sixth of the mission: spent on a reboost it is not there for the disposal); at
#: 1 day per m/s the tuned life-threshold rule captured 93.6% of the optimum's gain on 40 test
#: missions, at 3 days 81.4%. ``revolutions_per_step`` is unused: a step is
#: `SolarMission.block_days` of the calendar.
SOLAR_CONFIG = OrbitRaisingConfig(
    drag_coefficient=2.2,
    area_m2=1.0,
    dry_mass_kg=200.0,
    propellant_mass_kg=10.0,
    isp_s=220.0,
    burn_sizes_m_s=(0.0, 5.0, 10.0, 20.0),
    max_burn_m_s=20.0,
    horizon_steps=61,
    propellant_cost_per_m_s=3.0,
    start_perigee_km=(380.0, 560.0),
    start_apogee_max_km=580.0,
)

#: The observation's components: the known-density task's seven, then the Sun as observed the day before.
SOLAR_OBS_NAMES = (*OBS_NAMES, "f107", "f107_mean_81d", "f107_mean_365d", "ap")
#: Index of each component by name.
SOLAR_OBS_INDEX = {name: i for i, name in enumerate(SOLAR_OBS_NAMES)}
#: The solar indices are observed in units of 100 (F10.7 in sfu, Ap).
SOLAR_INDEX_SCALE = 100.0
SOLAR_OBS_LOW = np.zeros(len(SOLAR_OBS_NAMES), dtype=np.float32)
SOLAR_OBS_HIGH = np.concatenate([OBS_HIGH, np.full(4, 5.0, dtype=np.float32)])
_BOUNDS = np.array([SOLAR_OBS_LOW, SOLAR_OBS_HIGH], dtype=np.float64)  # as the compiled observation reads them


@dataclass(frozen=True)
class SolarMission:
    """What makes the orbit-raising task a task of today: the calendar, the Sun's split, the rule.

    Args:
        solar_split: ``"train"`` (missions wholly before `SPLIT_DATE`: cycles 19-23) or ``"test"``
            (missions wholly from it, within the observed record: cycles 24-25).
        disposal_years: The rule: re-enter within this many years of the mission's end (`DISPOSAL_YEARS`,
            5: the FCC's rule of 2022 for low orbits; 25: the IADC guideline).
        block_days: Days of a step (30: a month, an operator's planning cycle).
        inclination_deg: The orbit's inclination (53 deg: the most populated shell of today).
        start_span_km: A start's apogee lies up to this far above its perigee (uniform).
    """

    solar_split: str = "train"
    disposal_years: float = DISPOSAL_YEARS
    block_days: int = 30
    inclination_deg: float = 53.0
    start_span_km: float = 20.0

    def __post_init__(self) -> None:
        if self.solar_split not in SOLAR_SPLITS:
            raise ValueError(f"solar_split={self.solar_split!r} is invalid; allowed: {', '.join(SOLAR_SPLITS)}")
        check_number(self.disposal_years, "disposal_years", unit="years", low=0.5, high=25.0)
        if not (isinstance(self.block_days, (int, np.integer)) and 1 <= self.block_days <= 365):
            raise ValueError(f"block_days={self.block_days!r} is invalid; allowed: a whole number of days in [1, 365]")
        check_number(self.inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
        check_number(self.start_span_km, "start_span_km", unit="km", low=0.0, high=500.0)

    @property
    def disposal_days(self) -> float:
        """The rule's time from the mission's end to re-entry, at most [days] (365.25-day years)."""
        return self.disposal_years * DAYS_PER_YEAR


@dataclass(frozen=True)
class SolarTask(Task):
    """The solar decision task's parameters: the satellite (``config``), the mission and the rule (``mission``).

    ``density`` and ``continuous`` are the known-density task's; the density is the drag
    clock's (`orbit_env.decay.drag_clock`), so ``density`` stays the default (scale 1).
    """

    config: OrbitRaisingConfig = field(default_factory=lambda: SOLAR_CONFIG)
    mission: SolarMission = field(default_factory=SolarMission)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.mission, SolarMission):
            raise ValueError(f"mission={self.mission!r} is invalid; allowed: a SolarMission")

    def __getstate__(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @cached_property
    def clock(self) -> DragClock:
        """The drag clock of the mission's orbit plane."""
        return drag_clock(self.mission.inclination_deg)

    @cached_property
    def tables(self) -> solar_kernel.SolarTables:
        """The tables the compiled loops read (the clock's curves and drag-days)."""
        return solar_kernel.solar_tables(self.clock)

    @cached_property
    def kernel_parameters(self) -> FloatArray:
        """The task's numbers as the compiled loops read them (`orbit_env.envs.task.kernel_parameters`)."""
        return kernel_parameters(self)

    @cached_property
    def curves(self) -> UniversalCurves:  # type: ignore[override]
        """The universal curves of the drag clock's reference NRLMSIS profile."""
        return self.clock.curves

    @property
    def mission_days(self) -> int:
        """The mission's length [days]."""
        return self.config.horizon_steps * self.mission.block_days

    @cached_property
    def penalty_days(self) -> float:
        """What an orbit that cannot comply at the end costs [days].

        The mission's days plus the cost of the whole tank: a non-compliant plan then returns at
        most minus the tank's cost, and a compliant one (save the tank, dispose at the end: always
        possible from the start distribution, `start_window` checks the worst) at least that.
        """
        return self.mission_days + self.config.propellant_cost_per_m_s * self.config.delta_v_capacity_m_s

    @cached_property
    def start_window(self) -> tuple[int, int]:
        """The first and the last clock day a mission of the split may start on."""
        clock, mission = self.clock, self.mission
        split = clock.day_of(unix_days(SPLIT_DATE))
        if mission.solar_split == "train":
            first, last = HISTORY_DAYS, split - self.mission_days
        else:
            first, last = split, clock.day_of(clock.record.observed_end_days) + 1 - self.mission_days
        judged_to = last + self.mission_days + math.ceil(mission.disposal_days) + mission.block_days
        if last < first or judged_to > clock.days:
            raise ValueError(
                f"a mission of {self.mission_days} days judged over {mission.disposal_years} years does not fit the "
                f"{mission.solar_split} split of the record ({iso_date(clock.start_days)} to "
                f"{iso_date(clock.start_days + clock.days)})"
            )
        return first, last

    @property
    def observation_space(self) -> spaces.Box:
        """Box of the 11 components of `SOLAR_OBS_NAMES`."""
        return spaces.Box(SOLAR_OBS_LOW, SOLAR_OBS_HIGH, dtype=np.float32)


class Coast(NamedTuple):
    """Orbits after `coast_block` (arrays of the orbits' shape)."""

    lived_days: FloatArray  # days lived in the span (its length, or the fraction before re-entry)
    nu: FloatArray
    tau: FloatArray
    perigee_m: FloatArray
    apogee_m: FloatArray
    period_s: FloatArray  # the mean period left at the new point
    ratio: FloatArray  # the span's mean multiplier at the perigee of its start


class SolarStep(NamedTuple):
    """What `step` returns besides the updated state (arrays over the batch)."""

    reward: FloatArray  # days in orbit minus the propellant's cost, the disposal's and the penalty [days]
    terminated: NDArray[np.bool_]  # re-entered during the mission
    truncated: NDArray[np.bool_]  # the mission's end reached (the rule judged)
    burn_m_s: FloatArray  # the perigee burn made [m/s]
    disposal_m_s: FloatArray  # the disposal burn made at the end [m/s] (0 elsewhere)
    complies: NDArray[np.bool_]  # at the end: the orbit complies (after its disposal burn); True elsewhere


# ---------------------------------------------------------------------------------
# Start.
# ---------------------------------------------------------------------------------

#: Reset options of the solar task: pinned starts (any subset) or the exact replay of one.
SOLAR_START_OPTIONS = ("perigee_km", "apogee_km", "start_date", "start_day", "curve_label", "curve_tau")


def start(task: SolarTask, rng: np.random.Generator, size: int, options: Mapping[str, Any] | None = None) -> BatchState:
    """New missions: start day, orbit drawn from the split and the config, pinned where ``options`` say.

    Options (numbers or arrays of shape (size,)): ``perigee_km``, ``apogee_km``, ``start_date``
    (ISO date) or ``start_day`` (days since the record's first); ``curve_label`` with
    ``curve_tau`` put the orbit at that point of the curves (the exact replay of a start, as
    `start_options` reports it).

    Raises:
        ValueError: an unknown option, or a start outside the split or the curves' domain.
    """
    options = dict(options or {})
    unknown = set(options) - set(SOLAR_START_OPTIONS)
    if unknown:
        raise ValueError(f"unknown reset option(s) {sorted(unknown)}; allowed: {', '.join(SOLAR_START_OPTIONS)}")
    if "start_date" in options and "start_day" in options:
        raise ValueError("reset options start_date and start_day both pin the start; give one")
    options.update({name: option_array(name, value, size) for name, value in options.items() if name != "start_date"})
    if "start_date" in options and np.shape(options["start_date"]) not in ((), (size,)):
        raise ValueError(
            f"reset option start_date={options['start_date']!r} must be a date or an array of shape {(size,)}"
        )
    config, mission = task.config, task.mission
    first, last = task.start_window
    day = rng.integers(first, last + 1, size).astype(np.float64)
    low_km, high_km = config.start_perigee_km
    perigee_km = rng.uniform(low_km, high_km, size)
    span_km = rng.uniform(0.0, mission.start_span_km, size)
    window = (
        f"({iso_date(task.clock.start_days + first)} to {iso_date(task.clock.start_days + last)}, "
        f"the {mission.solar_split} split)"
    )
    if "start_date" in options:
        given = options.pop("start_date")
        options["start_day"] = np.vectorize(lambda d: task.clock.day_of(unix_days(str(d))))(given)
        named = f"start_date={given!r}", f"dates {window}"
    else:
        named = f"start_day={options.get('start_day')!r}", f"whole days in [{first}, {last}] {window}"
    if "start_day" in options:
        day = np.broadcast_to(np.asarray(options["start_day"], dtype=np.float64), (size,)).copy()
        if not np.all((day == np.round(day)) & (day >= first) & (day <= last)):
            raise ValueError(f"{named[0]} is invalid; allowed: {named[1]}")
    # A pinned height carries the other with it: the apogee up to start_span_km above the perigee.
    if "perigee_km" in options and "apogee_km" not in options:
        perigee_km = np.broadcast_to(np.asarray(options["perigee_km"], dtype=np.float64), (size,))
        apogee_km = perigee_km + span_km
    elif "apogee_km" in options and "perigee_km" not in options:
        apogee_km = np.broadcast_to(np.asarray(options["apogee_km"], dtype=np.float64), (size,))
        perigee_km = apogee_km - span_km
    else:
        pinned = (options.get("perigee_km", perigee_km), options.get("apogee_km", perigee_km + span_km))
        perigee_km, apogee_km = (np.broadcast_to(np.asarray(h, dtype=np.float64), (size,)) for h in pinned)
    if "perigee_km" in options or "apogee_km" in options:  # drawn ones are in the domain: the config is checked
        task.curves.check_domain_km(perigee_km, apogee_km)
    state = BatchState(size)
    state.dry_mass_kg = config.dry_mass_kg
    state.mass_kg = config.wet_mass_kg
    state.exhaust_m_s = config.exhaust_velocity_m_s
    state.drag_area_m2 = config.drag_coefficient * config.area_m2
    state.density_base = 1.0
    state.density_phase_rad = state.time_days = state.steps = 0.0
    state.perigee_drop_m = state.apogee_drop_m = 0.0
    state.start_day = day
    update_satellite(task, state)
    if "curve_label" in options or "curve_tau" in options:
        if not ("curve_label" in options and "curve_tau" in options):
            given = "curve_label" if "curve_label" in options else "curve_tau"
            raise ValueError(f"reset option {given} needs ['curve_label', 'curve_tau'] together")
        if "perigee_km" in options or "apogee_km" in options:
            raise ValueError(
                "reset options ['curve_label', 'curve_tau'] and ['perigee_km', 'apogee_km'] both pin the orbit"
            )
        check_curve_point(options["curve_label"], options["curve_tau"], task.curves)
        label, tau = np.broadcast_arrays(options["curve_label"], options["curve_tau"], np.empty(size))[:2]
        hp, ha, period = task.curves.at(label, tau)
        state.label, state.tau, state.period_s = label, tau, period
        state.nu = NU_REF * np.expm1(tau)
        state.perigee_m, state.apogee_m = hp, ha
        state.segments[0] = STALE_SEGMENT
    else:
        place(task, state, perigee_km * 1e3, apogee_km * 1e3)
    # The multiplier observed over the month before the start.
    state.density_scale = task.clock.drag_days(state.perigee_m, day - task.mission.block_days, day) / (
        task.mission.block_days
    )
    return state


def start_options(state: BatchState) -> dict[str, FloatArray]:
    """The options that give these missions' starts back exactly (their point on the curves and day)."""
    return {
        "curve_label": state.label.copy(),
        "curve_tau": state.tau.copy(),
        "start_day": state.start_day.copy(),
    }


# ---------------------------------------------------------------------------------
# Step.
# ---------------------------------------------------------------------------------


def today(task: SolarTask, state: BatchState) -> FloatArray:
    """Each mission's current clock day (its next step's first)."""
    return state.start_day + state.steps * task.mission.block_days


def drag_rate(state: BatchState) -> FloatArray:
    """The rate g c of each satellite: W falls by g c times the drag clock [s] (Eq. 4.1)."""
    return nu_per_revolution(state.drag_area_m2 / state.mass_kg, 1.0)


def predicted_life_days(component: Any) -> FloatArray:
    """The predicted lifetime [days] an observation's ``predicted_lifetime`` component L / (L + 365) shows.

    The component is clipped into [1e-9, 1 - 1e-9]: a life of a few hundredths of a second at least, finite.
    """
    x = np.clip(np.asarray(component, dtype=np.float64), 1e-9, 1.0 - 1e-9)
    return LIFETIME_SCALE_DAYS * x / (1.0 - x)


def decode(task: SolarTask, observation: Any) -> BatchState:
    """The states a ground station recovers from observations (11,) or (n, 11), for a planner.

    The orbit, tank and steps as the known-density task recovers them (`orbit_env.envs.task.decode`),
    and the last month's multiplier (``density_scale``) from the predicted lifetime, which the
    observation computes from it (`observe`).

    Raises:
        ValueError: an observation of another shape, or not finite.
    """
    obs = observation_batch(observation, len(SOLAR_OBS_NAMES))
    state = task_model.decode(task, obs[:, : len(OBS_NAMES)])
    life_days = predicted_life_days(obs[:, SOLAR_OBS_INDEX["predicted_lifetime"]])
    state.density_scale = state.period_s * state.nu / (drag_rate(state) * life_days * SECONDS_PER_DAY)
    return state


def coast_block(
    clock: DragClock,
    label: FloatArray,
    nu: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    gc: FloatArray,
    first_day: FloatArray,
    days: float,
) -> Coast:
    """Decay orbits over ``days`` days from ``first_day`` (whole days) at the drag clock of their perigee.

    W = Int P dnu falls by g c x the drag-days of the span at the perigee of its start; an orbit
    whose W runs out re-enters at that fraction of the span (the span's mean rate). Compiled
    (`orbit_env.envs.solar_kernel`); arrays of the orbits' shape out.
    """
    shape = np.broadcast_shapes(*(np.shape(a) for a in (label, nu, perigee_m, apogee_m, gc, first_day)))
    rows = solar_kernel.coast_rows(clock, label, nu, perigee_m, apogee_m, gc, first_day, days)
    return Coast(*(row.reshape(shape) for row in rows))


def life_margin_days(
    task: SolarTask,
    label: FloatArray,
    nu: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    gc: FloatArray,
    first_day: FloatArray,
) -> FloatArray:
    """Re-entry day after ``first_day`` minus the rule's days: <= 0 complies (1-d over the broadcast orbits).

    The orbits decay by `coast_block` in the task's steps up to the rule's end; one still up
    then gets its W left over its last rate (days it would still live at that rate), > 0.
    """
    mission = task.mission
    return solar_kernel.life_margin_rows(
        task.clock, label, nu, perigee_m, apogee_m, gc, first_day, float(mission.block_days), mission.disposal_days
    )


def disposal(task: SolarTask, state: BatchState) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The cheapest compliant disposal burn of each orbit at its mission's end, and whether the tank allows it.

    The rule is judged from the day after the mission (`today`) by `life_margin_days`, at the
    mass before the disposal (its few kilograms of propellant would shorten the life a little:
    the judgement is on the safe side). The burn is retrograde at apogee and lowers the perigee
    (`orbit_env.physics.orbit.dv_to_lower_perigee_m_s`); the lowest candidate, 100 km, re-enters
    at once, so a compliant perigee always exists. Two passes of `DISPOSAL_CANDIDATES` candidate
    perigees, each searched by bisection, the second between the last compliant and the next
    (`orbit_env.envs.solar_kernel`).

    Returns:
        (the burn [m/s], 0 where the orbit complies as it is; whether the propellant left makes it).
    """
    mission = task.mission
    lowered = solar_kernel.disposal_perigee_rows(
        task.clock,
        state.label,
        state.nu,
        state.perigee_m,
        state.apogee_m,
        drag_rate(state),
        today(task, state),
        float(mission.block_days),
        mission.disposal_days,
        DISPOSAL_CANDIDATES,
    )
    dv = dv_to_lower_perigee_m_s(state.perigee_m, state.apogee_m, lowered)
    able = dv <= state.dv_left_m_s + 1e-9
    return dv, able


def step(task: SolarTask, state: BatchState, requested_dv_m_s: Any) -> SolarStep:
    """One step of the task, in place: burn at perigee (maybe), decay a month; at the mission's end, the rule.

    Returns:
        The reward (days in orbit during the step, minus ``propellant_cost_per_m_s`` times the
        burn, and at the end times the disposal burn, or the penalty), the ends and the burns.
    """
    moved = solar_kernel.step_rows(
        task.tables, state.data, requested_dv_m_s, task.kernel_parameters, float(task.mission.block_days)
    )
    return _rule_at_the_end(task, state, *moved)


def step_and_observe(
    task: SolarTask, state: BatchState, requested_dv_m_s: Any
) -> tuple[SolarStep, NDArray[np.float32]]:
    """`step`, then `observe`, in one compiled loop over the orbits: what an environment's step does."""
    *moved, ending, obs = solar_kernel.step_observe_rows(
        task.tables,
        state.data,
        requested_dv_m_s,
        task.kernel_parameters,
        float(task.mission.block_days),
        SOLAR_INDEX_SCALE,
        _BOUNDS,
    )
    result = _rule_at_the_end(task, state, *moved, ending)
    if ending:  # the disposal burn spent propellant: observed again
        rows = np.flatnonzero(result.truncated)
        obs[rows] = observe(task, state.take(rows))
    return result, obs


def step_and_observe_one(
    task: SolarTask, state: BatchState, requested_dv_m_s: float
) -> tuple[NDArray[np.float32], float, bool, bool, float, float, bool]:
    """`step_and_observe` of a batch of one, as the single environment reads it: numbers, not arrays.

    Returns:
        (the observation (11,), the reward, terminated, truncated, the burn made, the disposal
        burn made and whether the orbit complies: the last two as `SolarStep`'s off the mission's end).
    """
    obs, dv, reward, terminated, truncated = solar_kernel.step_observe_one(
        task.tables,
        state.data,
        float(requested_dv_m_s),
        task.kernel_parameters,
        float(task.mission.block_days),
        SOLAR_INDEX_SCALE,
        _BOUNDS,
    )
    if not truncated:
        return obs, reward, terminated, False, dv, 0.0, True
    moved = (np.array([dv]), np.array([reward]), np.array([terminated]), np.array([truncated]))
    result = _rule_at_the_end(task, state, *moved, 1)
    return (
        observe(task, state)[0],  # the disposal burn spent propellant: observed again
        float(result.reward[0]),
        terminated,
        True,
        dv,
        float(result.disposal_m_s[0]),
        bool(result.complies[0]),
    )


def _rule_at_the_end(
    task: SolarTask,
    state: BatchState,
    dv: FloatArray,
    reward: FloatArray,
    terminated: NDArray[np.bool_],
    truncated: NDArray[np.bool_],
    ending: int,
) -> SolarStep:
    """A step's result, the ``ending`` missions (the truncated) judged by the rule: disposal burn or penalty."""
    disposal_m_s = np.zeros(state.size)
    complies = np.ones(state.size, dtype=bool)
    if ending:
        rows = np.flatnonzero(truncated)
        ended = state.take(rows)
        need, able = disposal(task, ended)
        made = np.where(able, need, 0.0)
        ended.mass_kg = ended.mass_kg / np.exp(made / ended.exhaust_m_s)
        ended.mass_kg = np.maximum(ended.mass_kg, ended.dry_mass_kg)
        update_satellite(task, ended)
        state.put(rows, ended)
        disposal_m_s[rows] = made
        complies[rows] = able
        reward[rows] -= task.config.propellant_cost_per_m_s * made + np.where(able, 0.0, task.penalty_days)
    return SolarStep(reward, terminated, truncated, dv, disposal_m_s, complies)


# ---------------------------------------------------------------------------------
# Observe.
# ---------------------------------------------------------------------------------


def observe(task: SolarTask, state: BatchState) -> NDArray[np.float32]:
    """Observations (n, 11) of a batch: the orbit, the tank, the clock, the predicted life, the Sun.

    The Sun as observed up to the day before the step's first day (F10.7, its trailing 81-
    and 365-day means, Ap); the predicted lifetime is W over the last month's mean multiplier
    at the perigee (what the orbit's observed decay says), held at the mission's start by the
    month before it. Compiled (`orbit_env.envs.solar_kernel`).
    """
    return solar_kernel.observe_rows(
        task.tables, state.data, task.kernel_parameters, float(task.mission.block_days), SOLAR_INDEX_SCALE, _BOUNDS
    )


def date_of(task: SolarTask, day: float) -> str:
    """ISO date of a clock day (a whole day's from a list made once per clock: a step's ``info["date"]``)."""
    k = int(day)
    dates = _iso_dates(task.clock)
    if k == day and 0 <= k < len(dates):
        return dates[k]
    return iso_date(task.clock.start_days + float(day))


@lru_cache(maxsize=4)
def _iso_dates(clock: DragClock) -> list[str]:
    """`iso_date` of every whole day of a clock, in order."""
    first = np.datetime64(math.floor(clock.start_days), "D")
    return np.datetime_as_string(first + np.arange(clock.days)).tolist()


def dates_of(task: SolarTask, days: FloatArray) -> NDArray[np.datetime64]:
    """Dates (numpy ``datetime64[D]``) of clock days: a vector environment's ``info["date"]``."""
    unix = np.rint(task.clock.start_days + days).astype(np.int64)
    return np.datetime64("1970-01-01", "D") + unix.astype("timedelta64[D]")
