"""A decay scenario: the air (`orbit_env.analysis.air`) and how it is stepped, shared by lifetimes, batches and fits.

SI units inside. A `Scenario` turns the user's choice of air into lifetimes of arrays
of satellites through the fast paths: the universal curves of one fixed profile, or,
when the air follows a date, the chunked curves of `orbit_env.decay.chunked`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.analysis.air import Air, PaperAir
from orbit_env.checks import check_array, check_number
from orbit_env.constants import DAYS_PER_YEAR, REENTRY_ALTITUDE_M
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.chunked import DEFAULT_CHUNK_DAYS, DEFAULT_MAX_YEARS, SolarDecayModel, propagate
from orbit_env.decay.curves import UniversalCurves, days_from_weighted_s
from orbit_env.decay.solar import SolarActivity, iso_date
from orbit_env.physics.atmosphere import Atmosphere
from orbit_env.physics.atmosphere.paper import RHO100_CALIBRATED_KG_M3
from orbit_env.physics.satellite_bounds import check_drag_parameter

FloatArray = NDArray[np.float64]
#: Bounds of a density scale factor, and why.
DENSITY_SCALE_RANGE = (1e-3, 1e3, "the models are off by a factor of a few at most; 1000 is another atmosphere")


#: Densest air at 100 km the universal curves are built for [kg/m^3]: 20 times the paper's
#: calibrated law. The curves step through nu on a fixed grid, and in denser air the perigee moves
#: too far per step near re-entry (at 30 times the family no longer closes, measured at 300 x 3000 km).
CURVES_MAX_RHO100_KG_M3 = 20.0 * RHO100_CALIBRATED_KG_M3


def check_scenario(value: object) -> Scenario:
    """``value`` if it is a `Scenario` (a parameter ``scenario``'s check).

    Raises:
        TypeError: anything else (an air model's name, None), named by its type.
    """
    if not isinstance(value, Scenario):
        raise TypeError(f"scenario must be a Scenario (orbit_env.analysis.scenario), got {type(value).__name__}")
    return value


def check_curves_density(atmosphere: Atmosphere) -> None:
    """Refuse, in the user's terms, an atmosphere too dense at 100 km for the universal curves.

    Raises:
        ValueError: its density at 100 km exceeds `CURVES_MAX_RHO100_KG_M3`.
    """
    rho = float(np.asarray(atmosphere.density_kg_m3(REENTRY_ALTITUDE_M)))
    if not rho <= CURVES_MAX_RHO100_KG_M3:
        raise ValueError(
            f"the air at 100 km is {rho:.3g} kg/m^3 with these options, {rho / RHO100_CALIBRATED_KG_M3:.3g} times "
            f"the paper's; the universal curves are built up to 20 times (a lower --rho100 or --density-scale, "
            "or --method averaged for a single orbit)"
        )


@dataclass(frozen=True, eq=False)
class Scenario:
    """Which air a decay runs in, and how the time-stepped path steps (everything but the satellite and its orbit).

    Args:
        air: The atmosphere model (`orbit_env.analysis.air`; default: the paper's law).
        density_scale: Multiplier on any model's density.
        rotating_atmosphere: Let the air co-rotate with the Earth (None: the model's
            default, `orbit_env.analysis.air.Air.corotates`).
        chunk_days: Time step of the time-stepped path (a dated air).
        max_years: The time-stepped path stops there (a satellite still up is reported so).
    """

    air: Air = field(default_factory=PaperAir)
    density_scale: float = 1.0
    rotating_atmosphere: bool | None = None
    chunk_days: float = DEFAULT_CHUNK_DAYS
    max_years: float = DEFAULT_MAX_YEARS

    def __post_init__(self) -> None:
        if not isinstance(self.air, Air):
            raise TypeError(f"air must be an orbit_env.analysis.air.Air, got {type(self.air).__name__}")
        low, high, why = DENSITY_SCALE_RANGE
        check_number(self.density_scale, "density_scale", low=low, high=high, why=why)
        if self.rotating_atmosphere is None:
            object.__setattr__(self, "rotating_atmosphere", self.air.corotates)

    @property
    def corotating(self) -> bool:
        """Whether the air co-rotates with the Earth (the model's default unless told)."""
        return bool(self.rotating_atmosphere)

    @property
    def time_varying(self) -> bool:
        """True when lifetimes take the time-stepped path (the air follows a date)."""
        return self.air.dated

    @property
    def epoch_days(self) -> float | None:
        """The start date [unix days] of a dated air (else None)."""
        return self.air.epoch_days

    @property
    def activity(self) -> SolarActivity | None:
        """The air's solar activity as given (None: none)."""
        return self.air.activity

    @property
    def depends_on_inclination(self) -> bool:
        """True when a lifetime depends on the inclination: the air's profile does, or the air co-rotates."""
        return self.air.depends_on_inclination or self.corotating

    def fixed_atmosphere(self, inclination_deg: float) -> Atmosphere:
        """The one density profile of a scenario that does not change in time (scale excluded)."""
        if self.time_varying:
            raise ValueError("this scenario changes in time; it has no single profile")
        return self.air.profile(inclination_deg)

    def decay_model(self, inclination_deg: float) -> DecayModel:
        """The fixed-profile decay model (see `fixed_atmosphere`)."""
        return DecayModel(self.fixed_atmosphere(inclination_deg), self.corotating, inclination_deg)

    def curves(self, inclination_deg: float) -> UniversalCurves:
        """The universal curves of the fixed profile (cached per profile).

        Raises:
            ValueError: the profile is too dense at 100 km for the curves (`check_curves_density`).
        """
        model = self.decay_model(inclination_deg)
        check_curves_density(model.atmosphere)
        return self.air.curves(model)

    def solar_model(self, inclination_deg: float, max_years: float | None = None) -> SolarDecayModel:
        """The time-stepped model (a dated air), stopped after ``max_years`` (default: the scenario's)."""
        return self.air.solar_model(
            inclination_deg,
            rotating_atmosphere=self.corotating,
            chunk_days=self.chunk_days,
            max_years=self.max_years if max_years is None else max_years,
        )

    def at_epoch(self, epoch_days: float) -> Scenario:
        """The same dated air from another date [unix days] (each object of a batch of element sets from its own).

        Raises:
            ValueError: the air has no date.
        """
        if not self.time_varying:
            raise ValueError("only a dated air starts at another date")
        return replace(self, air=replace(self.air, epoch_days=float(epoch_days)))

    def in_sphere_heights(self, reference: str, inclination_deg: float) -> Scenario:
        """The scenario for heights above the 6371 km sphere when the user's are above ``reference``."""
        air = self.air.in_sphere_heights(reference, inclination_deg)
        return self if air is self.air else replace(self, air=air)

    def describe(self, inclination_deg: float) -> str:
        """One line for the CLI."""
        details = (
            f", from {iso_date(self.epoch_days)} in {self.chunk_days:g}-day steps"
            if self.epoch_days is not None
            else ""
        )
        details += f" x {self.density_scale:g}" if self.density_scale != 1.0 else ""
        if self.corotating:
            details += ", co-rotating air"
        elif self.air.corotates:
            details += ", still air"
        return self.air.describe(inclination_deg, details)

    def lifetime_days(
        self,
        perigee_m: ArrayLike,
        apogee_m: ArrayLike,
        drag_parameter_m2_kg: ArrayLike,
        inclination_deg: float,
        *,
        density_scale: ArrayLike = 1.0,
        max_days: float | None = None,
        own_inclination_deg: ArrayLike | None = None,
        progress: Callable[[float], None] | None = None,
        start_days: ArrayLike | None = None,
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Days to re-entry of many satellites (one inclination), and whether they re-enter.

        Fixed profiles: one lookup on the universal curves. Time-varying: the
        chunked curves, stopped after ``max_days`` if given (else ``max_years``);
        with ``own_inclination_deg``, each satellite's inclination on the curves of
        ``inclination_deg`` (`orbit_env.decay.chunked.propagate`), and ``progress``
        called with the share of them re-entered after each chunk. ``start_days``: each
        satellite's start, days after the epoch (its own element set's; time-stepped only): the days
        (and ``max_days``) count from it.

        Raises:
            ValueError: heights invalid or outside the universal curves' domain, a drag parameter or
                density scale out of range, or ``own_inclination_deg`` or ``start_days`` on a fixed
                profile (the catalogue's one-family path serves the former; the latter has no date).
        """
        hp, ha = UniversalCurves.check_domain(perigee_m, apogee_m)
        c = check_drag_parameter(drag_parameter_m2_kg)
        s = check_array(density_scale, "density_scale", low=0.0, low_inclusive=False)
        hp, ha, c, s = np.broadcast_arrays(hp, ha, c, s)
        s = s * self.density_scale
        if not self.time_varying:
            if own_inclination_deg is not None or start_days is not None:
                raise ValueError("own_inclination_deg and start_days apply to the time-stepped path only")
            point = self.curves(inclination_deg).locate(hp, ha)
            days = days_from_weighted_s(point.weighted_s, c, s)
            return days, np.ones(days.shape, dtype=bool)
        model = self.solar_model(
            inclination_deg, None if max_days is None else max(max_days, self.chunk_days) / DAYS_PER_YEAR
        )
        own, start = (
            None if x is None else np.broadcast_to(x, hp.shape).ravel() for x in (own_inclination_deg, start_days)
        )
        result = propagate(
            hp.ravel(),
            ha.ravel(),
            c.ravel(),
            model,
            density_scale=s.ravel(),
            inclination_deg=own,
            progress=progress,
            start_days=start,
        )
        return result.days.reshape(hp.shape), result.reentered.reshape(hp.shape)
