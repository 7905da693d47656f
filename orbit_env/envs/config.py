"""Parameters of the orbit-raising task: the satellite, the mission and the density knowledge.

Frozen dataclasses checked at construction (``ValueError`` naming the field and the
allowed range); derived quantities (wet mass, exhaust velocity, delta-v capacity)
are properties. SI units except where a name says otherwise (``_km``, ``_days``,
``_s`` for the specific impulse in seconds). The decision problem built on them is
`orbit_env.envs.task`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from orbit_env.checks import check_array, check_int, check_number
from orbit_env.constants import G0_M_S2, REENTRY_ALTITUDE_M
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M
from orbit_env.physics.satellite_bounds import (
    AREA_RANGE_M2,
    DRAG_COEFFICIENT_RANGE,
    MASS_PER_AREA_RANGE_KG_M2,
    MASS_RANGE_KG,
)

#: Largest delta-v a satellite may carry [m/s]. More is beyond escape from low orbit,
#: never an orbit-raising budget; the bound keeps the observation space bounded.
MAX_DV_CAPACITY_M_S = 3000.0
#: Default mission length in steps (``OrbitRaisingConfig.horizon_steps``): the mission's end and the clock.
DEFAULT_HORIZON_STEPS = 365


def _pair(value: Any, name: str, unit: str = "") -> tuple[float, float]:
    """A (low, high) pair of numbers, low <= high; ValueError naming it otherwise."""
    if not (isinstance(value, (tuple, list)) and len(value) == 2):
        raise ValueError(f"{name}={value!r} is invalid; allowed: (low, high), two numbers")
    low = check_number(value[0], f"{name}[0]", unit=unit)
    return low, check_number(value[1], f"{name}[1]", unit=unit, low=low, low_name=f"{name}[0]")


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
        low, high = _pair(self.scale_range, "scale_range")
        check_number(low, "scale_range[0]", low=0.0, low_inclusive=False, why="a density scale")
        object.__setattr__(self, "scale_range", (low, high))
        check_number(self.cycle_amplitude, "cycle_amplitude", low=0.0, high=5.0, why="a natural-log amplitude")
        check_number(self.cycle_period_days, "cycle_period_days", unit="days", low=0.0, low_inclusive=False)

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
    (see `OrbitRaisingEnv`, "Why these defaults").

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
        horizon_steps: Mission length in steps (365: about a year). It alone sets
            the mission's end and the observation's mission clock.
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
        sizes = self.burn_sizes_m_s
        if not (isinstance(sizes, (tuple, list)) and len(sizes) >= 1):
            raise ValueError(f"burn_sizes_m_s={sizes!r} is invalid; allowed: a non-empty tuple of delta-v values")
        dv_cap = {"unit": "m/s", "high": MAX_DV_CAPACITY_M_S, "why": "the most delta-v a satellite may carry"}
        object.__setattr__(
            self,
            "burn_sizes_m_s",
            tuple(check_number(v, f"burn_sizes_m_s[{i}]", low=0.0, **dv_cap) for i, v in enumerate(sizes)),
        )
        check_number(self.max_burn_m_s, "max_burn_m_s", low=0.0, low_inclusive=False, **dv_cap)
        check_number(self.revolutions_per_step, "revolutions_per_step", low=0.0, low_inclusive=False)
        check_int(self.horizon_steps, "horizon_steps", low=1)
        check_number(self.propellant_cost_per_m_s, "propellant_cost_per_m_s", unit="days per m/s", low=0.0)
        domain = "the universal curves' domain"
        low_km, high_km = _pair(self.start_perigee_km, "start_perigee_km", "km")
        check_number(
            low_km, "start_perigee_km[0]", unit="km", low=REENTRY_ALTITUDE_M / 1e3, low_inclusive=False, why=domain
        )
        check_number(high_km, "start_perigee_km[1]", unit="km", high=CURVES_MAX_PERIGEE_M / 1e3, why=domain)
        object.__setattr__(self, "start_perigee_km", (low_km, high_km))
        check_number(
            self.start_apogee_max_km,
            "start_apogee_max_km",
            unit="km",
            low=high_km,
            low_name="start_perigee_km[1]",
            high=CURVES_MAX_APOGEE_M / 1e3,
            why=domain,
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
    """Check a satellite (scalars or arrays); ValueError names the first bad value and its range.

    The drag properties within the bounds of `orbit_env.physics.satellite_bounds`, the ones
    `orbit_env.analysis.lifetime.Satellite` checks: the mass at both ends of the mission (dry
    and wet) and the load of both.
    """
    positive = {"low": 0.0, "low_inclusive": False}
    for value, name, unit, (low, high, why) in (
        (drag_coefficient, "drag_coefficient", "", DRAG_COEFFICIENT_RANGE),
        (area_m2, "area_m2", "m^2", AREA_RANGE_M2),
        (dry_mass_kg, "dry_mass_kg", "kg", MASS_RANGE_KG),
    ):
        check_array(value, name, unit=unit, low=low, high=high, low_inclusive=False, why=why)
    check_array(isp_s, "isp_s", unit="s", **positive)
    propellant = check_array(propellant_mass_kg, "propellant_mass_kg", unit="kg", low=0.0)
    dry = np.asarray(dry_mass_kg, dtype=np.float64)
    wet = dry + propellant
    low, high, why = MASS_RANGE_KG
    check_array(wet, "dry_mass_kg + propellant_mass_kg", unit="kg", high=high, why=why)
    low, high, why = MASS_PER_AREA_RANGE_KG_M2
    area = np.asarray(area_m2, dtype=np.float64)
    check_array(dry / area, "dry_mass_kg / area_m2", unit="kg/m^2", low=low, why=why)
    check_array(wet / area, "(dry_mass_kg + propellant_mass_kg) / area_m2", unit="kg/m^2", high=high, why=why)
    capacity = np.asarray(isp_s, dtype=np.float64) * G0_M_S2 * np.log1p(propellant / dry)
    bad = capacity > MAX_DV_CAPACITY_M_S
    if bad.any():
        raise ValueError(
            f"the satellite carries {np.broadcast_to(capacity, bad.shape)[bad].flat[0]:.0f} m/s of delta-v "
            f"(isp_s, propellant_mass_kg, dry_mass_kg); allowed: up to {MAX_DV_CAPACITY_M_S:g} m/s"
        )


#: The flat keywords of ``gymnasium.make`` and ``gymnasium.make_vec``: every field of
#: `OrbitRaisingConfig` and of `DensityConfig` (their names do not overlap).
CONFIG_FIELDS = tuple(f.name for f in fields(OrbitRaisingConfig))
DENSITY_FIELDS = tuple(f.name for f in fields(DensityConfig))


def from_fields(cls: type, value: Any, name: str, overrides: Mapping[str, Any], default: Any = None) -> Any:
    """``value`` (None, an instance of ``cls`` or a mapping of its fields) with ``overrides`` applied.

    ``default``: an instance of ``cls`` whose fields stand where ``value`` is None or a mapping does
    not give them (else the class's defaults).

    Raises:
        ValueError: ``value`` of another type, or a mapping with a key that is not a field (named, with the valid ones).
    """
    valid = [f.name for f in fields(cls)]
    start = {} if default is None else {key: getattr(default, key) for key in valid}
    if value is None:
        base: dict[str, Any] = start
    elif isinstance(value, cls):
        base = {key: getattr(value, key) for key in valid}
    elif isinstance(value, Mapping):
        unknown = [key for key in value if key not in valid]
        if unknown:
            raise ValueError(f"{name} has the unknown key {unknown[0]!r}; valid keys: {', '.join(valid)}")
        base = {**start, **value}
    else:
        raise ValueError(f"{name}={value!r} is invalid; allowed: a {cls.__name__}, a dict of its fields, or None")
    given = default if value is None else value
    if not overrides and isinstance(given, cls):
        return given
    return cls(**{**base, **overrides})


def resolve_task_arguments(
    config: Any = None, density: Any = None, keywords: Mapping[str, Any] | None = None, *, env_keywords: tuple = ()
) -> tuple[OrbitRaisingConfig, DensityConfig]:
    """The config and density of an environment's arguments, Gymnasium's way.

    ``config`` and ``density`` may be None (the defaults), the dataclasses or dicts of
    their fields (as read from a TOML or YAML file); each flat keyword (``horizon_steps=100``,
    ``scale_range=(0.1, 10)``) then replaces that field.

    Args:
        config: An `OrbitRaisingConfig`, a dict of its fields, or None.
        density: A `DensityConfig`, a dict of its fields, or None.
        keywords: Flat keywords, each a field of either.
        env_keywords: The environment's other keywords, listed in the error message.

    Raises:
        ValueError: an unknown keyword or key (named, with the valid ones), or a bad value.
    """
    keywords = dict(keywords or {})
    unknown = [key for key in keywords if key not in CONFIG_FIELDS and key not in DENSITY_FIELDS]
    if unknown:
        valid = sorted((*env_keywords, *CONFIG_FIELDS, *DENSITY_FIELDS))
        raise ValueError(f"unknown keyword {unknown[0]!r}; valid keywords: {', '.join(valid)}")
    config_overrides = {key: value for key, value in keywords.items() if key in CONFIG_FIELDS}
    density_overrides = {key: value for key, value in keywords.items() if key in DENSITY_FIELDS}
    return (
        from_fields(OrbitRaisingConfig, config, "config", config_overrides),
        from_fields(DensityConfig, density, "density", density_overrides),
    )
