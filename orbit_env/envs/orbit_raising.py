"""Orbit raising against drag: the single environment and the pure functions it shares.

SI units inside (m, kg, s, m/s); days only in the reward and km only in the
config and the reset options, the user's edge. The dynamics are the paper's
universal curves (:mod:`orbit_env.decay.curves`) and the vis-viva burn of
:mod:`orbit_env.physics.orbit`; this module adds the spacecraft (rocket equation), the
task (reward, horizon) and the observation. The pure functions here broadcast
over numpy arrays and also take plain floats, so the single environment
(:class:`OrbitRaisingEnv`, floats) and the vector environment
(:class:`orbit_env.envs.vector.OrbitRaisingVectorEnv`, arrays) run the same code.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, NamedTuple

import gymnasium as gym
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
from orbit_env.physics.orbit import apogee_after_perigee_burn_m, elements_from_heights, perigee_velocity_m_s, period_s

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
#: Largest delta-v a satellite may carry [m/s]. More is beyond escape from low orbit,
#: never an orbit-raising budget; the bound keeps the observation space bounded.
MAX_DV_CAPACITY_M_S = 3000.0

#: Observation bounds. Heights come from the tabulated curves, which reach 1140 km
#: in perigee and 5000 km in apogee (the cap of 4000 km plus the curves' margin).
OBS_LOW = np.zeros(7, dtype=np.float32)
OBS_HIGH = np.array([1.2, 5.0, MAX_DV_CAPACITY_M_S / DV_SCALE_M_S, 1.0, 1.0, 1.0, 1.0], dtype=np.float32)
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

#: Reset options that pin the satellite (names of :class:`OrbitRaisingConfig` fields).
SATELLITE_OPTIONS = ("drag_coefficient", "area_m2", "dry_mass_kg", "propellant_mass_kg", "isp_s")
#: Reset options that pin the orbit and the atmosphere.
ORBIT_OPTIONS = ("perigee_km", "apogee_km", "density_scale", "density_phase_rad")
RESET_OPTIONS = ORBIT_OPTIONS + SATELLITE_OPTIONS

#: Default mission length in steps; also the registered ``max_episode_steps``.
DEFAULT_HORIZON_STEPS = 365


def _check(name: str, value: Any, ok: bool, allowed: str) -> None:
    if not ok:
        raise ValueError(f"{name}={value!r} is invalid; allowed: {allowed}")


def _finite_positive(name: str, value: Any) -> None:
    _check(name, value, isinstance(value, (int, float)) and math.isfinite(value) and value > 0, "a finite number > 0")


@dataclass(frozen=True)
class DensityConfig:
    """How well the environment's agent knows the upper-air density.

    The paper's Table 1 atmosphere times a scale s. The paper notes (section 1)
    that published upper-air densities differed by 1.5-2.5 orders of magnitude,
    and that the lifetime is about inversely proportional to the density near
    the perigee (section 4). Per episode, s0 is drawn log-uniform in
    ``scale_range``; during the episode s(t) = s0 exp(A sin(2 pi t / T + phi)),
    a solar-cycle-like factor with random phase phi, held constant over each step.

    Args:
        scale_range: (low, high) of the log-uniform s0. Equal ends: a known density.
        cycle_amplitude: A, the natural-log amplitude of the slow modulation (0: none).
        cycle_period_days: T, the modulation period [days] (default: the 11-year
            solar cycle).
    """

    scale_range: tuple[float, float] = (1.0, 1.0)
    cycle_amplitude: float = 0.0
    cycle_period_days: float = 4018.0

    def __post_init__(self) -> None:
        low_high = tuple(self.scale_range) if isinstance(self.scale_range, (tuple, list)) else ()
        _check(
            "scale_range",
            self.scale_range,
            len(low_high) == 2
            and all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in low_high)
            and low_high[0] <= low_high[1],
            "(low, high) with 0 < low <= high",
        )
        object.__setattr__(self, "scale_range", (float(low_high[0]), float(low_high[1])))
        _check(
            "cycle_amplitude",
            self.cycle_amplitude,
            isinstance(self.cycle_amplitude, (int, float)) and 0.0 <= self.cycle_amplitude <= 5.0,
            "0 to 5 (natural-log amplitude)",
        )
        _finite_positive("cycle_period_days", self.cycle_period_days)

    @property
    def nominal_scale(self) -> float:
        """Geometric mean of ``scale_range``: the scale a ground station would assume."""
        return math.sqrt(self.scale_range[0] * self.scale_range[1])

    @property
    def varies(self) -> bool:
        """Whether the density changes during an episode."""
        return self.cycle_amplitude > 0.0


#: The density of ``OrbitRaisingUncertain-v0``: s0 log-uniform over the two orders
#: of magnitude of the paper's section 1 (0.1 to 10 times its atmosphere), and a
#: solar-cycle factor of e^{+-0.5}: over a one-year mission it drifts by up to 30%.
UNCERTAIN_DENSITY = DensityConfig(scale_range=(0.1, 10.0), cycle_amplitude=0.5)


@dataclass(frozen=True)
class OrbitRaisingConfig:
    """Satellite, task and start distribution of the orbit-raising environments.

    All defaults are chosen together so that the decision depends on the state
    (see :class:`OrbitRaisingEnv`, "Why these defaults").

    Args:
        drag_coefficient: c_x, the drag coefficient (2.2, the usual value for a
            compact satellite in free-molecular flow; the paper's example uses 2).
        area_m2: F, the cross-section [m^2] (1 m^2: a small body with solar wings;
            with the masses below G/F = 46 kg/m^2, near the 51 kg/m^2 of the
            paper's example sphere).
        dry_mass_kg: Mass without propellant [kg] (40 kg).
        propellant_mass_kg: Propellant at the start [kg] (6 kg: with the Isp below
            300 m/s, enough to take a 250 km circular orbit to 250 x 1380 km).
        isp_s: Specific impulse [s] (220 s, a hydrazine monopropellant thruster).
        burn_sizes_m_s: Delta-v of each discrete action [m/s] (0, 10, 30, 100):
            coast, a trim (about +35 km of apogee), a medium burn (+100 km) and
            one of the class of the paper's 78 m/s manoeuvre (+350 km).
        max_burn_m_s: Delta-v of the continuous action at +1 [m/s] (100).
        revolutions_per_step: K, revolutions coasted per step (16: about one day).
        horizon_steps: Mission length in steps (365: about a year); the
            registered ``max_episode_steps``. Change both together.
        propellant_cost_per_m_s: Reward cost of a burn [days per m/s] (0.4: the
            whole tank is worth 120 days of mission, so burning without need costs,
            and a burn that saves a mission pays many times over).
        start_perigee_km: (low, high) of the uniform start perigee [km]
            ((160, 500), the paper's range).
        start_apogee_max_km: Upper end of the uniform start apogee, drawn between
            the start perigee and this value [km] (1600, the paper's range).
    """

    drag_coefficient: float = 2.2
    area_m2: float = 1.0
    dry_mass_kg: float = 40.0
    propellant_mass_kg: float = 6.0
    isp_s: float = 220.0
    burn_sizes_m_s: tuple[float, ...] = (0.0, 10.0, 30.0, 100.0)
    max_burn_m_s: float = 100.0
    revolutions_per_step: float = 16.0
    horizon_steps: int = DEFAULT_HORIZON_STEPS
    propellant_cost_per_m_s: float = 0.4
    start_perigee_km: tuple[float, float] = (160.0, 500.0)
    start_apogee_max_km: float = 1600.0

    def __post_init__(self) -> None:
        validate_satellite(
            drag_coefficient=self.drag_coefficient,
            area_m2=self.area_m2,
            dry_mass_kg=self.dry_mass_kg,
            propellant_mass_kg=self.propellant_mass_kg,
            isp_s=self.isp_s,
        )
        sizes = tuple(self.burn_sizes_m_s) if isinstance(self.burn_sizes_m_s, (tuple, list)) else ()
        _check(
            "burn_sizes_m_s",
            self.burn_sizes_m_s,
            len(sizes) >= 1
            and all(
                isinstance(v, (int, float)) and math.isfinite(v) and 0.0 <= v <= MAX_DV_CAPACITY_M_S for v in sizes
            ),
            f"a non-empty tuple of delta-v values in [0, {MAX_DV_CAPACITY_M_S:g}] m/s",
        )
        object.__setattr__(self, "burn_sizes_m_s", tuple(float(v) for v in sizes))
        _check(
            "max_burn_m_s",
            self.max_burn_m_s,
            isinstance(self.max_burn_m_s, (int, float)) and 0.0 < self.max_burn_m_s <= MAX_DV_CAPACITY_M_S,
            f"a delta-v in (0, {MAX_DV_CAPACITY_M_S:g}] m/s",
        )
        _finite_positive("revolutions_per_step", self.revolutions_per_step)
        _check(
            "horizon_steps",
            self.horizon_steps,
            isinstance(self.horizon_steps, (int, np.integer)) and self.horizon_steps >= 1,
            "an integer >= 1",
        )
        _check(
            "propellant_cost_per_m_s",
            self.propellant_cost_per_m_s,
            isinstance(self.propellant_cost_per_m_s, (int, float))
            and math.isfinite(self.propellant_cost_per_m_s)
            and self.propellant_cost_per_m_s >= 0.0,
            "a finite number of days per m/s >= 0",
        )
        lo_hi = tuple(self.start_perigee_km) if isinstance(self.start_perigee_km, (tuple, list)) else ()
        floor_km, top_km = REENTRY_ALTITUDE_M / 1e3, CURVES_MAX_PERIGEE_M / 1e3
        _check(
            "start_perigee_km",
            self.start_perigee_km,
            len(lo_hi) == 2
            and all(isinstance(v, (int, float)) and floor_km < v <= top_km for v in lo_hi)
            and lo_hi[0] <= lo_hi[1],
            f"(low, high) with {floor_km:g} < low <= high <= {top_km:g} km",
        )
        object.__setattr__(self, "start_perigee_km", (float(lo_hi[0]), float(lo_hi[1])))
        _check(
            "start_apogee_max_km",
            self.start_apogee_max_km,
            isinstance(self.start_apogee_max_km, (int, float))
            and lo_hi[1] <= self.start_apogee_max_km <= CURVES_MAX_APOGEE_M / 1e3,
            f"from the highest start perigee {lo_hi[1]:g} km to {CURVES_MAX_APOGEE_M / 1e3:g} km",
        )

    @property
    def wet_mass_kg(self) -> float:
        """Mass at the start [kg]."""
        return self.dry_mass_kg + self.propellant_mass_kg

    @property
    def exhaust_velocity_m_s(self) -> float:
        """Effective exhaust velocity Isp g0 [m/s]."""
        return self.isp_s * G0_M_S2

    @property
    def drag_parameter_m2_kg(self) -> float:
        """Drag parameter c = c_x F / m at the start [m^2/kg] (the paper's c of Eq. 4.1 over g)."""
        return self.drag_coefficient * self.area_m2 / self.wet_mass_kg

    @property
    def delta_v_capacity_m_s(self) -> float:
        """Delta-v of the full tank, Tsiolkovsky: Isp g0 ln(m_wet / m_dry) [m/s]."""
        return self.exhaust_velocity_m_s * math.log(self.wet_mass_kg / self.dry_mass_kg)


def validate_satellite(
    *,
    drag_coefficient: ArrayLike,
    area_m2: ArrayLike,
    dry_mass_kg: ArrayLike,
    propellant_mass_kg: ArrayLike,
    isp_s: ArrayLike,
) -> None:
    """Check a satellite (scalars or arrays); ValueError names the first bad value."""
    for name, value in (
        ("drag_coefficient", drag_coefficient),
        ("area_m2", area_m2),
        ("dry_mass_kg", dry_mass_kg),
        ("isp_s", isp_s),
    ):
        array = np.asarray(value, dtype=np.float64)
        bad = ~(np.isfinite(array) & (array > 0.0))
        if bad.any():
            raise ValueError(f"{name}={array[bad].flat[0].item()!r} is invalid; allowed: a finite number > 0")
    propellant = np.asarray(propellant_mass_kg, dtype=np.float64)
    bad = ~(np.isfinite(propellant) & (propellant >= 0.0))
    if bad.any():
        raise ValueError(
            f"propellant_mass_kg={propellant[bad].flat[0].item()!r} is invalid; allowed: a finite number >= 0"
        )
    dry = np.asarray(dry_mass_kg, dtype=np.float64)
    capacity = np.asarray(isp_s, dtype=np.float64) * G0_M_S2 * np.log1p(propellant / dry)
    bad = capacity > MAX_DV_CAPACITY_M_S
    if bad.any():
        raise ValueError(
            f"the satellite carries {np.broadcast_to(capacity, bad.shape)[bad].flat[0]:.0f} m/s of delta-v "
            f"(isp_s, propellant_mass_kg, dry_mass_kg); allowed: up to {MAX_DV_CAPACITY_M_S:g} m/s"
        )


# ---------------------------------------------------------------------------------
# Pure functions shared by the single and the vector environment.
# ---------------------------------------------------------------------------------


def delta_v_left_m_s(mass_kg: ArrayLike, dry_mass_kg: ArrayLike, exhaust_velocity_m_s: ArrayLike) -> FloatArray:
    """Delta-v the propellant on board still gives, Tsiolkovsky: v_e ln(m / m_dry) [m/s]."""
    return exhaust_velocity_m_s * np.log(np.divide(mass_kg, dry_mass_kg))


def perigee_burn(
    perigee_m: ArrayLike,
    apogee_m: ArrayLike,
    mass_kg: ArrayLike,
    dry_mass_kg: ArrayLike,
    exhaust_velocity_m_s: ArrayLike,
    requested_dv_m_s: ArrayLike,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Fire the engine at perigee: the burn actually made, the new apogee and the new mass.

    The burn is the request cut to the propellant on board (rocket equation) and to
    the burn that takes the apogee to the top of the universal curves,
    ``CURVES_MAX_APOGEE_M`` (4000 km); the perigee does not change.

    Returns:
        (dv [m/s], apogee after the burn [m], mass after the burn [kg]).
    """
    dv_fuel = delta_v_left_m_s(mass_kg, dry_mass_kg, exhaust_velocity_m_s)
    dv = np.maximum(np.minimum(requested_dv_m_s, dv_fuel), 0.0)
    apogee_after = apogee_after_perigee_burn_m(perigee_m, apogee_m, dv)
    # Beyond the cap (escape included: its apogee is unbounded): burn only up to the cap.
    # Rare, so the cap's burn is computed only when some burn needs it.
    over = apogee_after > CURVES_MAX_APOGEE_M
    if np.any(over):
        dv_cap = perigee_velocity_m_s(perigee_m, CURVES_MAX_APOGEE_M) - perigee_velocity_m_s(perigee_m, apogee_m)
        dv = np.where(over, np.maximum(np.minimum(dv, dv_cap), 0.0), dv)
        apogee_after = apogee_after_perigee_burn_m(perigee_m, apogee_m, dv)
    apogee_after = np.minimum(apogee_after, CURVES_MAX_APOGEE_M)
    mass_after = mass_kg / np.exp(dv / exhaust_velocity_m_s)
    # Emptying the tank leaves exactly the dry mass (the exponential rounds either way).
    mass_after = np.where(dv >= dv_fuel, dry_mass_kg, np.maximum(mass_after, dry_mass_kg))
    return dv, apogee_after, mass_after


def period_gain_days_per_m_s_per_step(revolutions_per_step: float) -> float:
    """The most days a step of K revolutions can gain per m/s of perigee burn, by the longer period alone.

    K times the largest dP/d(dv) of a perigee burn over the curves' domain, per day.
    P grows convexly with the perigee speed and fastest at the highest apogee, so
    the rate is taken at the 4000 km cap, for perigees 100-1100 km, by a 1 mm/s
    difference. A bound on what a burn buys a satellite that outlives the mission
    anyway (the DP's coasting stages, the training's decided episodes).
    """
    perigee_m = np.linspace(REENTRY_ALTITUDE_M, CURVES_MAX_PERIGEE_M, 101)
    step_m_s = 1e-3
    p, e = elements_from_heights(perigee_m, CURVES_MAX_APOGEE_M)
    p2, e2 = elements_from_heights(perigee_m, apogee_after_perigee_burn_m(perigee_m, CURVES_MAX_APOGEE_M, step_m_s))
    rate_s_per_m_s = float(np.max(period_s(p2, e2) - period_s(p, e)) / step_m_s)
    return revolutions_per_step * rate_s_per_m_s / SECONDS_PER_DAY


class Coast(NamedTuple):
    """What :func:`coast` returns (floats or arrays)."""

    point: CurvePoint
    perigee_m: FloatArray
    apogee_m: FloatArray
    days: FloatArray
    weighted_s: FloatArray


def coast(
    curves: UniversalCurves,
    point: CurvePoint,
    revolutions: ArrayLike,
    nu_per_rev: ArrayLike,
    segments: FloatArray | None = None,
) -> Coast:
    """Coast K revolutions along the universal curves.

    K revolutions move nu by K g c s (Eq. 4.1). The time is the drop of W = Int P dnu
    over g c s; at re-entry the curves clamp nu, and so W, at 0, so the same formula
    gives the exact fraction of the step lived before re-entry. ``segments``: the
    orbits' places on the curves' table, kept between steps by a vector simulator
    (``UniversalCurves.segments``), updated in place.

    Returns:
        The new point, its perigee and apogee heights [m], the days lived and the
        new point's W [s m^3/(kg s^2)].
    """
    after, perigee_m, apogee_m = curves.advance_heights(point, revolutions * nu_per_rev, segments)
    weighted_s = after.weighted_s
    days = (point.weighted_s - weighted_s) / (nu_per_rev * SECONDS_PER_DAY)
    return Coast(after, perigee_m, apogee_m, days, weighted_s)


def density_scale_at(
    base_scale: ArrayLike, amplitude: float, period_days: float, phase_rad: ArrayLike, time_days: ArrayLike
) -> FloatArray:
    """Density scale s(t) = s0 exp(A sin(2 pi t / T + phi)) of :class:`DensityConfig`."""
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
    """The seven scaled observation components (see :class:`OrbitRaisingEnv`), float64.

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


def resolve_options(
    options: Mapping[str, Any] | None, drawn: dict[str, Any], config: OrbitRaisingConfig, size: int | None = None
) -> dict[str, Any]:
    """Merge reset options over the drawn start and the config's satellite, and validate.

    Options may be scalars or, for the vector environment, arrays of shape (num_envs,).

    Raises:
        ValueError: an unknown option, or a value out of range (named, with the range).
    """
    options = dict(options or {})
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ValueError(f"unknown reset option(s) {unknown}; allowed: {list(RESET_OPTIONS)}")
    merged: dict[str, Any] = {name: getattr(config, name) for name in SATELLITE_OPTIONS}
    merged.update(drawn)
    shape = () if size is None else (size,)
    for name, value in options.items():
        array = np.asarray(value, dtype=np.float64) if not isinstance(value, (str, bytes)) else None
        if array is None or (array.shape != () and array.shape != shape):
            raise ValueError(f"reset option {name}={value!r} must be a number or an array of shape {shape}")
        if not np.all(np.isfinite(array)):
            raise ValueError(f"reset option {name}={value!r} must be finite")
        merged[name] = float(array) if size is None else np.broadcast_to(array, shape).copy()
    if "perigee_km" in options and "apogee_km" not in options:
        # A pinned perigee above the drawn apogee makes the drawn orbit circular.
        merged["apogee_km"] = np.maximum(merged["apogee_km"], merged["perigee_km"])
        if size is None:
            merged["apogee_km"] = float(merged["apogee_km"])
    if "apogee_km" in options and "perigee_km" not in options:
        merged["perigee_km"] = np.minimum(merged["perigee_km"], merged["apogee_km"])
        if size is None:
            merged["perigee_km"] = float(merged["perigee_km"])
    validate_satellite(**{name: merged[name] for name in SATELLITE_OPTIONS})
    perigee_m = np.asarray(merged["perigee_km"]) * 1e3
    apogee_m = np.asarray(merged["apogee_km"]) * 1e3
    UniversalCurves.check_domain(perigee_m, apogee_m)
    scale = np.asarray(merged["density_scale"])
    bad = ~(scale > 0.0)
    if bad.any():
        raise ValueError(f"reset option density_scale={scale[bad].flat[0].item()!r} is invalid; allowed: > 0")
    return merged


def resolve_task(
    config: OrbitRaisingConfig | None, density: DensityConfig | None
) -> tuple[OrbitRaisingConfig, DensityConfig]:
    """The config and density of an environment (defaults for None); ValueError for other types."""
    config = OrbitRaisingConfig() if config is None else config
    density = DensityConfig() if density is None else density
    if not isinstance(config, OrbitRaisingConfig):
        raise ValueError(f"config={config!r} is invalid; allowed: an OrbitRaisingConfig")
    if not isinstance(density, DensityConfig):
        raise ValueError(f"density={density!r} is invalid; allowed: a DensityConfig")
    return config, density


def observation_space() -> spaces.Box:
    """The observation space shared by all variants (see :class:`OrbitRaisingEnv`)."""
    return spaces.Box(OBS_LOW, OBS_HIGH, dtype=np.float32)


def action_space(config: OrbitRaisingConfig, continuous: bool) -> spaces.Space:
    """Discrete(len(burn_sizes_m_s)), or Box([-1], [1]) for the continuous variant."""
    if continuous:
        return spaces.Box(-1.0, 1.0, shape=(1,), dtype=np.float32)
    return spaces.Discrete(len(config.burn_sizes_m_s))


@dataclass
class _Episode:
    """Mutable per-episode satellite and atmosphere of the single environment (floats)."""

    mass_kg: float = 0.0
    dry_mass_kg: float = 1.0
    exhaust_velocity_m_s: float = 1.0
    drag_area_m2: float = 0.0
    density_base: float = 1.0
    density_phase_rad: float = 0.0
    density_scale: float = 1.0
    nu_per_rev: float = 0.0
    nominal_w_per_day: float = 0.0
    dv_left_m_s: float = 0.0
    last_burn_m_s: float = 0.0
    track: list[tuple[float, float, float]] = field(default_factory=list)


class OrbitRaisingEnv(gym.Env[np.ndarray, Any]):
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
    ``max_burn_m_s * max(a, 0)`` (100 m/s at +1), so half the range coasts.
    Every burn is cut to the propellant on board and to the 4000 km apogee where
    the universal curves end; the burn made is ``info["burn_m_s"]``.

    ## Observation Space

    ``Box(low, high, (7,), float32)``, the same in every variant:

    | Num | Observation         | Unit and scaling                               | Min | Max |
    |-----|---------------------|------------------------------------------------|-----|-----|
    | 0   | perigee height      | m / ``HEIGHT_SCALE_M`` (1000 km)               | 0.1 | 1.2 |
    | 1   | apogee height       | m / ``HEIGHT_SCALE_M`` (1000 km)               | 0.1 | 5   |
    | 2   | delta-v left        | m/s / ``DV_SCALE_M_S`` (1 km/s), rocket eq.    | 0   | 3   |
    | 3   | mission clock       | steps taken / ``horizon_steps``                | 0   | 1   |
    | 4   | predicted lifetime  | L / (L + 365 d), L in days, no burns, nominal  | 0   | 1   |
    |     |                     | density (``DensityConfig.nominal_scale``)      |     |     |
    | 5   | apogee drop         | d / (d + 10 km), d = drop over the last coast  | 0   | 1   |
    | 6   | perigee drop        | d / (d + 1 km), d = drop over the last coast   | 0   | 1   |

    This is what a ground station knows: the tracked orbit, the propellant, the
    time, its own prediction of the lifetime from the paper's tables, and the decay
    it has observed. With the default, known density the prediction is exact; in
    ``OrbitRaisingUncertain-v0`` the true density scale is not observed and only
    the observed decay (5, 6) against the prediction (4) reveals it. "Min" is the
    least value the env produces; the Box's low is 0 for every component. The
    clock is held at 1 past ``horizon_steps``. ``info["burn_m_s"]`` is the burn
    made, and ``env.unwrapped.state`` the simulator's state (for tests and plots).

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

    ## Episode End

    Termination: re-entry, perigee at 100 km (the paper's end of integration).
    Truncation: after ``horizon_steps`` steps (365), owned by the registered
    ``max_episode_steps`` (Gymnasium's ``TimeLimit``). For another horizon pass
    both: ``gymnasium.make(id, config=cfg, max_episode_steps=cfg.horizon_steps)``
    (the vector environment refuses a mismatch; the single one cannot see its
    ``TimeLimit``, so it warns once stepped past ``horizon_steps`` and holds
    the clock at 1).

    ## Arguments

    ``gymnasium.make("OrbitRaising-v0", config=OrbitRaisingConfig(...),
    continuous=False, density=DensityConfig(...), render_mode=None)``; the same
    keywords for ``gymnasium.make_vec(id, num_envs=N,
    vectorization_mode="vector_entry_point")``, the numpy-batched version
    (:class:`orbit_env.envs.vector.OrbitRaisingVectorEnv`).
    ``render_mode``: "human" and "rgb_array" draw the (apogee, perigee) plane of
    the paper's Fig. 2 with the track and the burns (needs ``orbit-env[plot]``);
    "ansi" returns one line of text.

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

    * v0: initial version.

    ## Example

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
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["human", "rgb_array", "ansi"], "render_fps": 8}

    def __init__(
        self,
        config: OrbitRaisingConfig | None = None,
        *,
        continuous: bool = False,
        density: DensityConfig | None = None,
        render_mode: str | None = None,
    ) -> None:
        self.config, self.density = resolve_task(config, density)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode={render_mode!r} is invalid; allowed: {self.metadata['render_modes']} or None"
            )
        self.continuous = bool(continuous)
        self.render_mode = render_mode
        self.observation_space = observation_space()
        self.action_space = action_space(self.config, self.continuous)
        self._burn_sizes = self.config.burn_sizes_m_s
        self._revolutions = float(self.config.revolutions_per_step)
        self._cost = float(self.config.propellant_cost_per_m_s)
        self._horizon = int(self.config.horizon_steps)
        self._point: CurvePoint | None = None
        self._perigee_m = 0.0
        self._apogee_m = 0.0
        self._time_days = 0.0
        self._steps = 0
        self._last_obs: NDArray[np.float32] | None = None
        self._ep = _Episode()
        self._renderer: Any = None

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
        point = self._point
        if point is None:
            raise RuntimeError("the environment has no state before reset()")
        return {
            "label": float(point.label),
            "tau": float(point.tau),
            "perigee_m": self._perigee_m,
            "apogee_m": self._apogee_m,
            "mass_kg": self._ep.mass_kg,
            "time_days": self._time_days,
            "density_scale": self._ep.density_scale,
        }

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        """Start a new mission; ``options`` may pin the orbit and the satellite (see the class)."""
        super().reset(seed=seed)
        start = resolve_options(options, sample_start(self.np_random, self.config, self.density), self.config)
        ep = self._ep
        ep.dry_mass_kg = float(start["dry_mass_kg"])
        ep.mass_kg = ep.dry_mass_kg + float(start["propellant_mass_kg"])
        ep.exhaust_velocity_m_s = float(start["isp_s"]) * G0_M_S2
        ep.drag_area_m2 = float(start["drag_coefficient"]) * float(start["area_m2"])
        ep.density_base = float(start["density_scale"])
        ep.density_phase_rad = float(start["density_phase_rad"])
        ep.track = []
        ep.last_burn_m_s = 0.0
        self._time_days = 0.0
        self._steps = 0
        self._update_satellite()
        self._set_point(float(start["perigee_km"]) * 1e3, float(start["apogee_km"]) * 1e3)
        self._last_obs = self._observe(self._point.weighted_s, 0.0, 0.0)
        if self.render_mode is not None:
            ep.track.append((self._perigee_m, self._apogee_m, 0.0))
            if self.render_mode == "human":
                self.render()
        return self._last_obs, {}

    def step(self, action: Any) -> tuple[NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        """Burn (maybe), then coast ``revolutions_per_step`` revolutions."""
        if self._point is None:
            raise RuntimeError("call reset() before step()")
        dv = self._requested_dv(action)
        ep = self._ep
        if dv > 0.0 and ep.mass_kg > ep.dry_mass_kg:
            dv = self._burn(dv)
        else:
            dv = 0.0
        if self.density.varies:
            self._update_density()
        start = self._point
        perigee_m, apogee_m = self._perigee_m, self._apogee_m
        after, self._perigee_m, self._apogee_m, days, weighted_s = coast(
            universal_curves(), start, self._revolutions, ep.nu_per_rev
        )
        self._point = after
        self._time_days += days
        self._steps += 1
        if self._steps == self._horizon + 1:
            gym.logger.warn(
                f"stepped past config.horizon_steps={self._horizon}: the mission clock stays at 1. "
                "Truncation belongs to gymnasium.make's TimeLimit; for another horizon pass "
                "config=cfg and max_episode_steps=cfg.horizon_steps together."
            )
        obs = self._observe(weighted_s, perigee_m - self._perigee_m, apogee_m - self._apogee_m)
        self._last_obs = obs
        if self.render_mode is not None:
            ep.last_burn_m_s = dv
            ep.track.append((self._perigee_m, self._apogee_m, 0.0))
            if self.render_mode == "human":
                self.render()
        return obs, days - self._cost * dv, after.tau <= 0.0, False, {"burn_m_s": dv}

    def _requested_dv(self, action: Any) -> float:
        """The requested burn [m/s]; ValueError for an action outside the action space."""
        if not self.continuous:
            if isinstance(action, (int, np.integer)) and not isinstance(action, bool):
                if 0 <= action < len(self._burn_sizes):
                    return self._burn_sizes[action]
            elif isinstance(action, np.ndarray) and action.shape in ((), (1,)) and action.dtype.kind in "iu":
                return self._requested_dv(int(action.reshape(())))
            raise ValueError(
                f"action={action!r} is invalid; allowed: an integer in [0, {len(self._burn_sizes) - 1}] "
                f"(burns of {self._burn_sizes} m/s)"
            )
        value = np.asarray(action, dtype=np.float64) if not isinstance(action, (str, bytes)) else np.array(np.nan)
        if value.shape not in ((), (1,)) or not (np.isfinite(value).all() and (np.abs(value) <= 1.0).all()):
            raise ValueError(f"action={action!r} is invalid; allowed: one number in [-1, 1]")
        return self.config.max_burn_m_s * max(float(value.reshape(())), 0.0)

    def _burn(self, requested_dv_m_s: float) -> float:
        ep = self._ep
        dv, apogee_m, mass_kg = perigee_burn(
            self._perigee_m, self._apogee_m, ep.mass_kg, ep.dry_mass_kg, ep.exhaust_velocity_m_s, requested_dv_m_s
        )
        dv = float(dv)
        if dv > 0.0:
            ep.mass_kg = float(mass_kg)
            self._update_satellite()
            self._set_point(self._perigee_m, float(apogee_m))
            if self.render_mode is not None:
                ep.track.append((self._perigee_m, self._apogee_m, dv))
        return dv

    def _update_satellite(self) -> None:
        """Recompute what depends on the mass: g c s per revolution and the delta-v left."""
        ep = self._ep
        ep.dv_left_m_s = max(float(delta_v_left_m_s(ep.mass_kg, ep.dry_mass_kg, ep.exhaust_velocity_m_s)), 0.0)
        drag_parameter = ep.drag_area_m2 / ep.mass_kg
        ep.nominal_w_per_day = nu_per_revolution(drag_parameter, self.density.nominal_scale) * SECONDS_PER_DAY
        self._update_density()

    def _update_density(self) -> None:
        ep = self._ep
        scale = ep.density_base
        if self.density.varies:
            scale = float(
                density_scale_at(
                    scale,
                    self.density.cycle_amplitude,
                    self.density.cycle_period_days,
                    ep.density_phase_rad,
                    self._time_days,
                )
            )
        ep.density_scale = scale
        ep.nu_per_rev = nu_per_revolution(ep.drag_area_m2 / ep.mass_kg, scale)

    def _set_point(self, perigee_m: float, apogee_m: float) -> None:
        """Locate a new orbit (start or burn) and take its heights as the curves give them.

        The heights then come from the same table before and after every coast, so
        the observed decay of a step is never the locate-and-read-back round trip's
        interpolation error (``UniversalCurves.locate_heights``).
        """
        self._point, self._perigee_m, self._apogee_m = universal_curves().locate_heights(perigee_m, apogee_m)

    def _observe(self, weighted_s: float, perigee_drop_m: float, apogee_drop_m: float) -> NDArray[np.float32]:
        ep = self._ep
        lifetime_days = weighted_s / ep.nominal_w_per_day
        return np.array(
            observation(
                self._perigee_m,
                self._apogee_m,
                ep.dv_left_m_s,
                min(self._steps / self._horizon, 1.0),
                lifetime_days,
                apogee_drop_m,
                perigee_drop_m,
            ),
            dtype=np.float32,
        )

    def render(self) -> Any:
        """Draw the (apogee, perigee) plane with the track (rgb_array, human) or one text line (ansi)."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode to gymnasium.make")
            return None
        if self._point is None:
            raise RuntimeError("call reset() before render()")
        from orbit_env.envs import render as render_module

        ep = self._ep
        if self.render_mode == "ansi":
            return render_module.render_ansi(
                step=self._steps,
                time_days=self._time_days,
                perigee_m=self._perigee_m,
                apogee_m=self._apogee_m,
                dv_left_m_s=ep.dv_left_m_s,
                burn_m_s=ep.last_burn_m_s,
                reentered=float(self._point.tau) <= 0.0,
            )
        if self._renderer is None:
            self._renderer = render_module.TrackRenderer(
                human=self.render_mode == "human", fps=self.metadata["render_fps"]
            )
        return self._renderer.draw(ep.track, time_days=self._time_days, dv_left_m_s=ep.dv_left_m_s)

    def close(self) -> None:
        """Close the render window, if any."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
