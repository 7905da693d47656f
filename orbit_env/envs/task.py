"""The orbit-raising decision problem, written once: parameters, state, start, step, observe, decode.

SI units inside (m, kg, s, m/s); days only in the reward and in the mission's clock,
km only in the reset options (the user's edge). In the manner of gymnax's
``step_env(key, state, action, params)``: a frozen `Task` holds the
parameters, a `TaskState` the mutable state, and module functions move it:

* `start`: draw (or pin) new missions (`start_and_options`: and the reset options
  that give them back bit for bit);
* `step`: burn at perigee (maybe), relocate the orbit on the universal curves,
  update the drag rates, coast K revolutions, and reward;
* `observe`: the scaled observation of a state;
* `decode`: the state a planner recovers from an observation;
* `lookahead`: burn now, then coast for a number of steps in one jump (the value
  of never burning again: the greedy look-ahead's score, the shaping's potential, the
  DP's satellites that outlive the mission).

Every consumer calls these: the single env (`orbit_env.envs.orbit_raising`)
on a state of Python floats, the vector env (`orbit_env.envs.vector`) on a
state of arrays of shape (num_envs,), and the DP, the hand-coded policies and the
reward shaping in `orbit_env.agents` on arrays of planned or decoded states.
Nothing else composes burn, coast and reward.

Its parts live by concern beside it: the state's fields and storage in `orbit_env.envs.state`,
the rocket equation and the burn in `orbit_env.envs.rocket`, the reset options' checks in
`orbit_env.envs.reset_options`, the continuous action space in `orbit_env.envs.spaces`, and
the compiled step of a batch in `orbit_env.envs.kernel`.

The dynamics are the paper's universal curves (`orbit_env.decay.curves`): K
revolutions move the universal variable nu by K g c s (Eq. 4.1), and the time is the
drop of W = Int P dnu over g c s. A perigee burn keeps the perigee and raises the
apogee (exact vis-viva, `orbit_env.physics.orbit`) and spends mass by the
rocket equation, which raises c = c_x F / m.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from functools import cached_property, lru_cache
from typing import Any, NamedTuple

import numpy as np
from gymnasium import spaces
from numpy.typing import ArrayLike, NDArray

from orbit_env.constants import G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY, TWO_PI
from orbit_env.decay.curves import (
    CURVES_MAX_APOGEE_M,
    CURVES_MAX_PERIGEE_M,
    CurvePoint,
    UniversalCurves,
    nu_per_revolution,
    universal_curves,
)
from orbit_env.envs import kernel
from orbit_env.envs.config import (
    MAX_DV_CAPACITY_M_S,
    DensityConfig,
    OrbitRaisingConfig,
)
from orbit_env.envs.reset_options import START_OPTIONS, resolve_options
from orbit_env.envs.rocket import delta_v_left_m_s, mass_from_delta_v_left_kg, perigee_burn
from orbit_env.envs.spaces import UniformBox
from orbit_env.envs.state import STALE_SEGMENT, AnyState, BatchState, TaskState

FloatArray = NDArray[np.float64]

# Observation scales: each feature is divided by (or squashed with) one of these,
# so that every component is of order 1.
#: Heights are observed in units of 1000 km: the paper's orbits span 0.1 to 4.
HEIGHT_SCALE_M = 1000e3
#: Delta-v is observed in km/s: a perigee burn from the lowest circular orbit to the
#: 4000 km apogee cap of the curves is about 0.8 km/s.
DV_SCALE_M_S = 1000.0
#: Predicted lifetime L is observed as L / (L + 365 d): 0.5 at one year, where the
#: missions of the default config end, and resolved from days to decades.
LIFETIME_SCALE_DAYS = 365.0
#: Observed apogee drop d over the last step, as d / (d + 10 km).
APOGEE_DROP_SCALE_M = 10e3
#: Observed perigee drop d over the last step, as d / (d + 1 km): the perigee moves
#: about ten times less than the apogee (the paper's section 4).
PERIGEE_DROP_SCALE_M = 1e3

#: Names of the observation components, in order.
OBS_NAMES = (
    "perigee",
    "apogee",
    "delta_v_left",
    "mission_clock",
    "predicted_lifetime",
    "apogee_drop",
    "perigee_drop",
)
#: Index of each observation component by name.
OBS_INDEX = {name: i for i, name in enumerate(OBS_NAMES)}
#: Observation bounds. Heights come from the tabulated curves, which reach 1140 km
#: in perigee and 5000 km in apogee (the cap of 4000 km plus the curves' margin).
OBS_LOW = np.zeros(len(OBS_NAMES), dtype=np.float32)
OBS_HIGH = np.array([1.2, 5.0, MAX_DV_CAPACITY_M_S / DV_SCALE_M_S, 1.0, 1.0, 1.0, 1.0], dtype=np.float32)

_UNSIGNED = {1: np.uint8, 2: np.uint16, 4: np.uint32, 8: np.uint64}  # by item size: the actions' range check


@dataclass(frozen=True)
class Task:
    """The parameters of one orbit-raising task: satellite and mission, density knowledge, action kind.

    Args:
        config: Satellite, mission and start distribution (default ``OrbitRaisingConfig()``).
        density: What is known of the density (default: the paper's atmosphere, known).
        continuous: Burn sizes from a ``Box(-1, 1)`` action instead of the discrete sizes.

    Raises:
        ValueError: a config or density of another type.
    """

    config: OrbitRaisingConfig = field(default_factory=OrbitRaisingConfig)
    density: DensityConfig = field(default_factory=DensityConfig)
    continuous: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.config, OrbitRaisingConfig):
            raise ValueError(f"config={self.config!r} is invalid; allowed: an OrbitRaisingConfig")
        if not isinstance(self.density, DensityConfig):
            raise ValueError(f"density={self.density!r} is invalid; allowed: a DensityConfig")
        if not isinstance(self.continuous, (bool, np.bool_)):  # a truthy "false" would make the Box variant
            raise ValueError(f"continuous={self.continuous!r} is invalid; allowed: True or False")
        object.__setattr__(self, "continuous", bool(self.continuous))

    def __getstate__(self) -> dict[str, Any]:
        # The fields only: the cached properties (the curves' table, 20 MB) rebuild from the
        # process's cache (universal_curves()) on first use, so a pickled env carries its state alone.
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def of(
        cls, config: OrbitRaisingConfig | None = None, density: DensityConfig | None = None, continuous: bool = False
    ) -> Task:
        """The task of an environment's arguments (None: the defaults)."""
        return cls(config or OrbitRaisingConfig(), density or DensityConfig(), continuous)

    @cached_property
    def burn_sizes_m_s(self) -> FloatArray:
        """The discrete actions' burns [m/s]."""
        return np.array(self.config.burn_sizes_m_s, dtype=np.float64)

    @cached_property
    def curves(self) -> UniversalCurves:
        """The universal curves the task steps on (the paper's atmosphere; the density scale multiplies g c)."""
        return universal_curves()

    @cached_property
    def planning(self) -> Task:
        """This task with the density known and constant at its nominal scale: what a planner assumes."""
        scale = self.density.nominal_scale
        return Task(self.config, DensityConfig(scale_range=(scale, scale)), self.continuous)

    @property
    def observation_space(self) -> spaces.Box:
        """The observation space, the same in every variant (see `OrbitRaisingEnv`)."""
        return spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)

    @property
    def action_space(self) -> spaces.Space:
        """Discrete(len(burn_sizes_m_s)), or Box([-1], [1]) for the continuous variant."""
        if self.continuous:
            return UniformBox(-1.0, 1.0, shape=(1,), dtype=np.float32)
        return spaces.Discrete(len(self.config.burn_sizes_m_s))

    def requested_dv(self, action: Any) -> float:
        """The burn [m/s] one action asks for; ValueError for an action outside the action space.

        A continuous action outside [-1, 1] is clipped to it, as Gymnasium's LunarLander
        clips; NaN is a ValueError.
        """
        sizes = self.config.burn_sizes_m_s
        if not self.continuous:
            if isinstance(action, (int, np.integer)) and not isinstance(action, bool):
                if 0 <= action < len(sizes):
                    return sizes[action]
            elif isinstance(action, np.ndarray) and action.shape in ((), (1,)) and action.dtype.kind in "iu":
                return self.requested_dv(int(action.reshape(())))
            raise ValueError(
                f"action={action!r} is invalid; allowed: an integer in [0, {len(sizes) - 1}] (burns of {sizes} m/s)"
            )
        if isinstance(action, np.ndarray) and action.shape == (1,) and action.dtype.kind == "f":
            one = action.item()  # the action space's own form, without numpy calls on a 1-element array
            if one == one:  # False for NaN
                return self.config.max_burn_m_s * min(max(one, 0.0), 1.0)
        typed = np.asarray(action).dtype.kind not in "iuf"  # text, bools, complex (a cast drops the imaginary part)
        value = np.array(np.nan) if typed else np.asarray(action, dtype=np.float64)
        if value.shape not in ((), (1,)) or np.isnan(value).any():
            raise ValueError(f"action={action!r} is invalid; allowed: one real number, not NaN (clipped to [-1, 1])")
        return self.config.max_burn_m_s * min(max(float(value.reshape(())), 0.0), 1.0)

    def requested_dvs(self, actions: Any, n: int) -> FloatArray:
        """The burns [m/s] a batch of ``n`` actions asks for; ValueError outside the batched action space.

        Continuous actions are clipped to [-1, 1] as in `requested_dv`; NaN is a ValueError.
        """
        a = np.asarray(actions)
        sizes = self.burn_sizes_m_s
        if not self.continuous:
            if a.shape != (n,) or a.dtype.kind not in "iu":
                raise ValueError(
                    f"actions of shape {a.shape} and dtype {a.dtype} are invalid; allowed: integers of shape ({n},)"
                )
            # One reduction: viewed as unsigned, negative actions are huge.
            unsigned = a.view(_UNSIGNED[a.dtype.itemsize]) if a.dtype.kind == "i" else a
            if unsigned.max() >= sizes.size:
                bad = (a < 0) | (a >= sizes.size)
                raise ValueError(f"action {a[bad][0].item()!r} is invalid; allowed: integers in [0, {sizes.size - 1}]")
            return sizes.take(a)
        if a.shape not in ((n, 1), (n,)) or a.dtype.kind not in "iuf":
            raise ValueError(
                f"actions of shape {a.shape} and dtype {a.dtype} are invalid; "
                f"allowed: real numbers of shape ({n}, 1) or ({n},)"
            )
        a = a.reshape(n).astype(np.float64)
        if np.isnan(a).any():
            raise ValueError("action nan is invalid; allowed: numbers, not NaN (clipped to [-1, 1])")
        return self.config.max_burn_m_s * np.clip(a, 0.0, 1.0)

    def encode(self, dv_m_s: FloatArray) -> Any:
        """Actions for requested burns: the largest discrete size not above each, or the Box value."""
        if self.continuous:
            return np.clip(dv_m_s / self.config.max_burn_m_s, 0.0, 1.0).astype(np.float32)[:, None]
        index = np.searchsorted(self.burn_sizes_m_s, dv_m_s + 1e-9, side="right") - 1
        return np.maximum(index, 0).astype(np.int64)


class TaskView:
    """The task's parts as attributes of an environment that holds a `Task` as ``self.task``."""

    task: Task

    @property
    def config(self) -> OrbitRaisingConfig:
        """The satellite and the mission."""
        return self.task.config

    @property
    def density(self) -> DensityConfig:
        """The density knowledge."""
        return self.task.density

    @property
    def continuous(self) -> bool:
        """Whether the action is the continuous burn size."""
        return self.task.continuous


def density_scale_at(
    base_scale: ArrayLike, amplitude: float, period_days: float, phase_rad: ArrayLike, time_days: ArrayLike
) -> FloatArray:
    """Density scale s(t) = s0 exp(A sin(2 pi t / T + phi)) of `DensityConfig`."""
    if isinstance(base_scale, float) and isinstance(phase_rad, float) and isinstance(time_days, float):
        return base_scale * math.exp(amplitude * math.sin(TWO_PI * time_days / period_days + phase_rad))
    return np.asarray(base_scale) * np.exp(amplitude * np.sin(TWO_PI * np.asarray(time_days) / period_days + phase_rad))


def observation(
    perigee_m: ArrayLike,
    apogee_m: ArrayLike,
    dv_left_m_s: ArrayLike,
    mission_clock: ArrayLike,
    lifetime_days: ArrayLike,
    apogee_drop_m: ArrayLike,
    perigee_drop_m: ArrayLike,
) -> tuple[Any, ...]:
    """The seven scaled observation components (see `OrbitRaisingEnv`), float64.

    Plain arithmetic only, so that it costs nothing on floats and broadcasts on arrays.
    """
    return (
        perigee_m * (1.0 / HEIGHT_SCALE_M),  # multiplications: half the cost of divisions on arrays
        apogee_m * (1.0 / HEIGHT_SCALE_M),
        dv_left_m_s * (1.0 / DV_SCALE_M_S),
        mission_clock,
        lifetime_days / (lifetime_days + LIFETIME_SCALE_DAYS),
        apogee_drop_m / (apogee_drop_m + APOGEE_DROP_SCALE_M),
        perigee_drop_m / (perigee_drop_m + PERIGEE_DROP_SCALE_M),
    )


# ---------------------------------------------------------------------------------
# Start.
# ---------------------------------------------------------------------------------


def sample_start(
    rng: np.random.Generator, config: OrbitRaisingConfig, density: DensityConfig, size: int | None = None
) -> dict[str, Any]:
    """Draw start orbits and density from the config's distributions (floats if ``size`` is None).

    Perigee uniform in ``start_perigee_km``, apogee uniform between it and
    ``start_apogee_max_km``, density scale log-uniform in ``density.scale_range``,
    cycle phase uniform in [0, 2 pi).
    """
    low_km, high_km = config.start_perigee_km
    perigee_km = rng.uniform(low_km, high_km, size)
    apogee_km = rng.uniform(perigee_km, config.start_apogee_max_km)
    low_s, high_s = density.scale_range
    scale = low_s * np.exp(rng.uniform(0.0, math.log(high_s / low_s), size))
    phase = rng.uniform(0.0, TWO_PI, size)
    if size is None:
        return {
            "perigee_km": float(perigee_km),
            "apogee_km": float(apogee_km),
            "density_scale": float(scale),
            "density_phase_rad": float(phase),
        }
    return {"perigee_km": perigee_km, "apogee_km": apogee_km, "density_scale": scale, "density_phase_rad": phase}


def _new_state(size: int | None) -> AnyState:
    return TaskState() if size is None else BatchState(size)


def start(
    task: Task, rng: np.random.Generator, size: int | None = None, options: Mapping[str, Any] | None = None
) -> AnyState:
    """New missions: drawn from the task's start distribution, pinned where ``options`` say.

    Args:
        task: The task.
        rng: The generator to draw from (the env's ``np_random``).
        size: None for one satellite (a `TaskState` of floats), else the
            number of satellites (a `BatchState`).
        options: Reset options (`orbit_env.envs.reset_options.RESET_OPTIONS`), numbers or arrays of shape (size,).

    Raises:
        ValueError: an unknown or invalid option.
    """
    return start_and_options(task, rng, size, options)[0]


def start_and_options(
    task: Task, rng: np.random.Generator, size: int | None = None, options: Mapping[str, Any] | None = None
) -> tuple[AnyState, dict[str, Any]]:
    """`start`, and the reset options that give these missions back bit for bit.

    The options (`orbit_env.envs.reset_options.START_OPTIONS`, floats, or arrays of shape
    (size,)) pin the orbit by its point on the curves, not by its heights: a start's
    heights are table B's at the point table A locates for the drawn heights, and
    locating those through table A again gives another point (up to 30 m of perigee,
    0.5 km of apogee and 0.3 day of return away).
    """
    drawn = sample_start(rng, task.config, task.density, size)
    values = resolve_options(options, drawn, task.config, size, task.curves)
    state = _new_state(size)
    state.dry_mass_kg = values["dry_mass_kg"]
    state.mass_kg = values["dry_mass_kg"] + values["propellant_mass_kg"]
    state.exhaust_m_s = values["isp_s"] * G0_M_S2
    state.drag_area_m2 = values["drag_coefficient"] * values["area_m2"]
    state.density_base = values["density_scale"]
    state.density_phase_rad = values["density_phase_rad"]
    state.time_days = state.steps = state.start_day = 0.0
    state.perigee_drop_m = state.apogee_drop_m = 0.0
    update_satellite(task, state)
    if "curve_label" in values:
        label, tau = values["curve_label"], values["curve_tau"]
        if size is not None:
            label, tau = np.broadcast_to(label, (size,)), np.broadcast_to(tau, (size,))
        _put_point(state, *task.curves.segments_at(label, tau))
    else:
        perigee_m, apogee_m = values["perigee_km"] * 1e3, values["apogee_km"] * 1e3
        if size is not None:
            perigee_m, apogee_m = np.broadcast_to(perigee_m, (size,)), np.broadcast_to(apogee_m, (size,))
        place(task, state, perigee_m, apogee_m)
    return state, _start_options(state, values, size)


def _start_options(state: AnyState, values: dict[str, Any], size: int | None) -> dict[str, Any]:
    """The `START_OPTIONS` of new missions: their point on the curves, their density and satellite."""
    values = {**values, "curve_label": state.label, "curve_tau": state.tau}
    if size is None:
        return {name: float(values[name]) for name in START_OPTIONS}
    return {name: np.array(np.broadcast_to(values[name], (size,)), dtype=np.float64) for name in START_OPTIONS}


def _satellite_states(task: Task, dv_left_m_s: ArrayLike, steps: ArrayLike, size: int) -> BatchState:
    """States of the config's satellite with ``dv_left_m_s`` left after ``steps`` steps, not yet placed."""
    config = task.config
    state = BatchState(size)
    state.dry_mass_kg = config.dry_mass_kg
    state.exhaust_m_s = config.exhaust_velocity_m_s
    state.mass_kg = mass_from_delta_v_left_kg(dv_left_m_s, config.dry_mass_kg, config.exhaust_velocity_m_s)
    state.drag_area_m2 = config.drag_coefficient * config.area_m2
    state.density_base = task.density.nominal_scale
    state.density_phase_rad = state.time_days = state.start_day = 0.0
    state.steps = steps
    state.perigee_drop_m = state.apogee_drop_m = 0.0
    update_satellite(task, state)
    return state


def states_at_orbits(
    task: Task, perigee_m: ArrayLike, apogee_m: ArrayLike, dv_left_m_s: ArrayLike, steps: ArrayLike
) -> BatchState:
    """Planning states of the task's satellite at given orbits (1-d arrays that broadcast).

    The satellite is the config's with ``dv_left_m_s`` of delta-v left (its mass by
    the rocket equation), ``steps`` taken, the density at the nominal scale (phase 0,
    time 0): what the DP, the policies and `decode` plan on. The orbits are
    located on the curves (`place`).
    """
    perigee_m, apogee_m, dv_left_m_s, steps = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=np.float64)) for v in (perigee_m, apogee_m, dv_left_m_s, steps))
    )
    state = _satellite_states(task, dv_left_m_s, steps, perigee_m.size)
    place(task, state, perigee_m, apogee_m)
    return state


def states_on_curves(
    task: Task, label: ArrayLike, tau: ArrayLike, dv_left_m_s: ArrayLike, steps: ArrayLike
) -> BatchState:
    """`states_at_orbits` at curve coordinates (label, tau) instead of heights (the DP's grid)."""
    label, tau, dv_left_m_s, steps = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=np.float64)) for v in (label, tau, dv_left_m_s, steps))
    )
    state = _satellite_states(task, dv_left_m_s, steps, label.size)
    place_on_curves(task, state, label, tau)
    return state


# ---------------------------------------------------------------------------------
# Step.
# ---------------------------------------------------------------------------------


def update_satellite(task: Task, state: AnyState) -> None:
    """Recompute what depends on the mass: the delta-v left, the nominal and the current g c s."""
    dv_left = delta_v_left_m_s(state.mass_kg, state.dry_mass_kg, state.exhaust_m_s)
    drag_parameter = state.drag_area_m2 / state.mass_kg
    if isinstance(state, TaskState):
        state.dv_left_m_s = max(float(dv_left), 0.0)
    else:
        state.dv_left_m_s = np.maximum(dv_left, 0.0)
    state.nominal_w_per_day = nu_per_revolution(drag_parameter, task.density.nominal_scale * SECONDS_PER_DAY)
    update_density(task, state, drag_parameter)


def update_density(task: Task, state: AnyState, drag_parameter: Any = None) -> None:
    """Set the density scale s(t) of the coming step and g c s per revolution."""
    density = task.density
    scale = state.density_base
    if density.varies:
        scale = density_scale_at(
            scale, density.cycle_amplitude, density.cycle_period_days, state.density_phase_rad, state.time_days
        )
        if isinstance(state, TaskState):
            scale = float(scale)
    if drag_parameter is None:
        drag_parameter = state.drag_area_m2 / state.mass_kg
    state.density_scale = scale
    state.nu_per_rev = nu_per_revolution(drag_parameter, scale)


def place(task: Task, state: AnyState, perigee_m: Any, apogee_m: Any) -> None:
    """Locate new orbits (a start) on the curves and take their heights as the curves give them.

    The heights then come from the same table before and after every coast, so the
    observed decay of a step is never the locate-and-read-back round trip's
    interpolation error (``UniversalCurves.locate_heights``).
    """
    if isinstance(state, TaskState):
        perigee_m, apogee_m = float(perigee_m), float(apogee_m)
    _put_point(state, *task.curves.locate_segments(perigee_m, apogee_m))


def place_burnt(task: Task, state: AnyState, apogee_after_m: Any) -> None:
    """Move orbits whose apogee a perigee burn raised to ``apogee_after_m`` onto their new curve.

    From their point on the curves, continuously in the burn
    (``UniversalCurves.relocate_segments``: a tiny burn is nearly no burn, not a
    jump to where table A locates the heights).
    """
    if isinstance(state, TaskState):
        apogee_after_m = float(apogee_after_m)
    moved = task.curves.relocate_segments(state.label, state.tau, state.perigee_m, state.apogee_m, apogee_after_m)
    _put_point(state, *moved)


def _put_point(state: AnyState, point: CurvePoint, perigee_m: Any, apogee_m: Any, segments: Any) -> None:
    """Set a state's place on the curves, its heights and its cell of table B."""
    state.perigee_m, state.apogee_m, state.segments = perigee_m, apogee_m, segments
    state.label = point.label
    state.tau = point.tau
    state.nu = point.nu
    state.period_s = point.mean_period_s
    if isinstance(state, TaskState):
        state.point = point


def place_on_curves(task: Task, state: BatchState, label: FloatArray, tau: FloatArray) -> None:
    """Put orbits at curve coordinates (label, tau), with the heights and the mean period there (``at``).

    Their cells of the curves' table are marked stale, so the first coast makes them.
    """
    perigee_m, apogee_m, period = task.curves.at(label, tau)
    point = CurvePoint(label, tau, period)
    state.label = label
    state.tau = tau
    state.nu = point.nu
    state.period_s = period
    state.perigee_m = perigee_m
    state.apogee_m = apogee_m
    state.segments[0] = STALE_SEGMENT


def burn(task: Task, state: AnyState, requested_dv_m_s: Any) -> Any:
    """Fire at perigee where asked and able: spend the mass, relocate the orbit; return the burns made [m/s].

    A request is cut to the propellant on board and to the 4000 km apogee cap of the
    curves (`perigee_burn`); an orbit whose burn comes to 0 is left untouched.
    """
    if isinstance(state, TaskState):
        if not (requested_dv_m_s > 0.0 and state.dv_left_m_s > 0.0):
            return 0.0
        dv, apogee_m, mass_kg = perigee_burn(
            state.perigee_m, state.apogee_m, state.mass_kg, state.dry_mass_kg, state.exhaust_m_s, requested_dv_m_s
        )
        dv = float(dv)
        if dv > 0.0:
            state.mass_kg = float(mass_kg)
            update_satellite(task, state)
            place_burnt(task, state, apogee_m)
        return dv
    asked = np.flatnonzero(np.minimum(requested_dv_m_s, state.dv_left_m_s) > 0.0)  # asked to burn, and able to
    compiled = None
    if asked.size:
        compiled = kernel.burn_rows(state.data, asked, requested_dv_m_s, kernel_parameters(task), task.curves)
    if compiled is not None:
        return compiled  # the same burns, one compiled loop (orbit_env.envs.kernel)
    made = np.zeros(state.size)
    if asked.size:
        requested = requested_dv_m_s[asked] if np.ndim(requested_dv_m_s) else requested_dv_m_s
        # The few that burn, gathered once, moved as a batch of their own, and written back once.
        firing = state.take(asked)
        dv, apogee_m, mass_kg = perigee_burn(
            firing.perigee_m, firing.apogee_m, firing.mass_kg, firing.dry_mass_kg, firing.exhaust_m_s, requested
        )
        fired = dv > 0.0
        if not fired.all():
            asked, dv, apogee_m, mass_kg = asked[fired], dv[fired], apogee_m[fired], mass_kg[fired]
            firing = firing.take(fired)
        if asked.size:
            made[asked] = dv
            firing.mass_kg = mass_kg
            update_satellite(task, firing)
            place_burnt(task, firing, apogee_m)
            state.put(asked, firing)
    return made


class StepResult(NamedTuple):
    """What `step` returns besides the updated state (floats or arrays)."""

    reward: Any  # days in orbit during the step minus the propellant's cost [days]
    terminated: Any  # re-entered (perigee at 100 km)
    truncated: Any  # the mission's horizon reached
    burn_m_s: Any  # the burn made [m/s]


def coast(task: Task, state: AnyState, steps: Any = 1.0) -> Any:
    """Coast ``steps`` steps of K revolutions along the curves; return the days lived.

    K revolutions move nu by K g c s (Eq. 4.1), at the g c s of now; the time is the
    drop of W = Int P dnu over g c s. At re-entry the curves clamp nu, and so W, at 0,
    so the same formula gives the exact fraction lived before re-entry. Several steps
    in one jump are the sum of single steps' days (nu falls by the same K g c s each
    step), up to round-off. The drops are those of the whole coast.
    """
    single = isinstance(state, TaskState)
    weighted_s = state.period_s * state.nu  # W = q nu, as CurvePoint.weighted_s (not cached: cheaper)
    revolutions = task.config.revolutions_per_step * steps
    # The state's place on the curves, nu known (no expm1 of tau).
    point = state.point if single else CurvePoint.with_nu(state.label, state.tau, state.period_s, state.nu)
    after, perigee_m, apogee_m = task.curves.advance_heights(point, revolutions * state.nu_per_rev, state.segments)
    days = (weighted_s - after.mean_period_s * after.nu) / (state.nu_per_rev * SECONDS_PER_DAY)
    # The drops: heights before less heights after (on a batch's rows, written in place).
    if single:
        state.perigee_drop_m = state.perigee_m - perigee_m
        state.apogee_drop_m = state.apogee_m - apogee_m
        state.point = after
    else:
        np.subtract(state.perigee_m, perigee_m, out=state.perigee_drop_m)
        np.subtract(state.apogee_m, apogee_m, out=state.apogee_drop_m)
    state.perigee_m = perigee_m
    state.apogee_m = apogee_m
    state.tau = after.tau
    state.nu = after.nu
    state.period_s = after.mean_period_s
    state.time_days += days  # in place on a batch's rows
    state.steps += steps
    return days


def step(task: Task, state: AnyState, requested_dv_m_s: Any) -> StepResult:
    """One step of the task, in place: burn (maybe), then coast ``revolutions_per_step`` revolutions.

    Args:
        task: The task.
        state: One satellite's state (floats) or a batch's (arrays); updated in place.
        requested_dv_m_s: The burn asked for [m/s] (`Task.requested_dv`), a
            number or an array of the batch's shape.

    Returns:
        The reward (days in orbit during the step minus ``propellant_cost_per_m_s``
        times the burn made), termination (re-entry), truncation (the horizon) and
        the burn made.
    """
    dv = burn(task, state, requested_dv_m_s)
    if task.density.varies:
        update_density(task, state)
    days = coast(task, state)
    cost = task.config.propellant_cost_per_m_s
    reward = days - cost * dv if cost else days
    return StepResult(reward, state.tau <= 0.0, state.steps >= task.config.horizon_steps, dv)


@lru_cache(maxsize=16)
def kernel_parameters(task: Task) -> FloatArray:
    """The numbers of a task that the compiled loops (`orbit_env.envs.kernel`) read: `kernel.KernelParameters`."""
    config, density = task.config, task.density
    parameters = kernel.KernelParameters(
        revolutions_per_step=config.revolutions_per_step,
        propellant_cost_per_m_s=config.propellant_cost_per_m_s,
        horizon_steps=config.horizon_steps,
        nominal_scale_s_per_day=density.nominal_scale * SECONDS_PER_DAY,
        density_varies=density.varies,
        cycle_amplitude=density.cycle_amplitude,
        cycle_period_days=density.cycle_period_days,
        per_height_scale_m=1.0 / HEIGHT_SCALE_M,
        per_dv_scale_m_s=1.0 / DV_SCALE_M_S,
        lifetime_scale_days=LIFETIME_SCALE_DAYS,
        apogee_drop_scale_m=APOGEE_DROP_SCALE_M,
        perigee_drop_scale_m=PERIGEE_DROP_SCALE_M,
    )
    return np.array(parameters, dtype=np.float64)


def step_and_observe(
    task: Task, state: BatchState, requested_dv_m_s: FloatArray
) -> tuple[StepResult, NDArray[np.float32]]:
    """`step`, then `observe`, of a batch: what a vector environment's step does.

    The coast, reward and observation after the burns run as compiled loops where
    numba is there (`orbit_env.envs.kernel.coast_and_observe`, the same formulas in
    the same order, tested equal to round-off), else as `step` and `observe`.
    """
    if kernel.compiled() is None:
        result = step(task, state, requested_dv_m_s)
        return result, observe(task, state)
    dv = burn(task, state, requested_dv_m_s)
    reward, terminated, truncated, obs = kernel.coast_and_observe(state.data, dv, kernel_parameters(task), task.curves)
    return StepResult(reward, terminated, truncated, dv), obs


# ---------------------------------------------------------------------------------
# Observe, decode, look ahead.
# ---------------------------------------------------------------------------------


def observe(task: Task, state: AnyState) -> NDArray[np.float32]:
    """The observation of a state: shape (7,) for one satellite, (n, 7) for a batch (column-major).

    The clock is held at 1 past ``horizon_steps``; the predicted lifetime is the
    curves' W over g c s at the nominal density (no burns).
    """
    clock = state.steps * (1.0 / task.config.horizon_steps)
    single = isinstance(state, TaskState)
    if single:
        clock = min(clock, 1.0)
    columns = observation(
        state.perigee_m,
        state.apogee_m,
        state.dv_left_m_s,
        clock,
        state.period_s * state.nu / state.nominal_w_per_day,
        state.apogee_drop_m,
        state.perigee_drop_m,
    )
    if single:
        return np.array(columns, dtype=np.float32)
    # A (7, n) array and its transpose: three times faster than a row-major stack (CartPoleVectorEnv's layout).
    return np.array(columns, dtype=np.float32).T


def observation_batch(observation: Any, width: int = len(OBS_NAMES)) -> FloatArray:
    """One observation (width,) or a batch (n, width) as a finite float64 batch (n, width): 7, or the solar task's 11.

    Raises:
        ValueError: another shape, or a value that is not finite.
    """
    obs = np.asarray(observation, dtype=np.float64)
    if obs.ndim not in (1, 2) or obs.shape[-1:] != (width,):
        raise ValueError(f"observation must have shape ({width},) or (n, {width}), got shape {obs.shape}")
    if not np.all(np.isfinite(obs)):
        raise ValueError(f"observation must be finite, got {obs[~np.isfinite(obs)][0]} in it")
    return np.atleast_2d(obs)


def decode(task: Task, observation: Any) -> BatchState:
    """The states a planner recovers from observations (7,) or (n, 7), as a ground station would.

    The orbit from the observed heights (the point of the curves whose heights they
    are, `UniversalCurves.locate_exactly`), the mass from the
    delta-v left and the config's satellite (rocket equation), the steps taken from
    the mission clock, and the nominal density of ``task`` (see
    `Task.planning`). Heights are clipped into the curves' domain.

    Raises:
        ValueError: an observation of another shape, or not finite.
    """
    obs = observation_batch(observation)
    perigee_m = np.clip(obs[:, OBS_INDEX["perigee"]] * HEIGHT_SCALE_M, REENTRY_ALTITUDE_M, CURVES_MAX_PERIGEE_M)
    apogee_m = np.clip(obs[:, OBS_INDEX["apogee"]] * HEIGHT_SCALE_M, perigee_m, CURVES_MAX_APOGEE_M)
    dv_left = np.maximum(obs[:, OBS_INDEX["delta_v_left"]] * DV_SCALE_M_S, 0.0)
    horizon = task.config.horizon_steps
    steps = np.rint(np.clip(obs[:, OBS_INDEX["mission_clock"]], 0.0, 1.0) * horizon)
    # The point whose table-B heights the env showed, not table A's point of them (see locate_exactly).
    label, tau = task.curves.locate_exactly(perigee_m, apogee_m)
    return states_on_curves(task, label, tau, dv_left, steps)


def outlives(task: Task, state: AnyState, steps: ArrayLike) -> Any:
    """Whether each satellite is still in orbit after coasting ``steps`` more steps at the g c s of now."""
    return state.nu > np.asarray(steps, dtype=np.float64) * task.config.revolutions_per_step * state.nu_per_rev


def lookahead(task: Task, state: AnyState, requested_dv_m_s: Any, steps: ArrayLike) -> tuple[Any, Any]:
    """The return of burning now, then coasting ``steps`` steps, at the density of now.

    The burn's cost plus the days in orbit during the steps: with no burn, the value
    of never burning again (the shaping's potential); with one, the greedy
    look-ahead's score. The state is not changed.

    Returns:
        (return [days], the burn made [m/s]).
    """
    after = state.copy()
    dv = burn(task, after, requested_dv_m_s)
    days = coast(task, after, np.maximum(np.asarray(steps, dtype=np.float64), 0.0))
    return days - task.config.propellant_cost_per_m_s * dv, dv
