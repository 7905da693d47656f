"""A decay scenario: the atmosphere and the solar activity, shared by single lifetimes, batches and fits.

SI units inside. A `Scenario` turns the user's choice (the paper's law, an
exponential law, or NRLMSIS under constant, tabulated or cyclic activity) into
lifetimes of arrays of satellites through the fast paths: the universal curves of
one fixed profile, or, when the activity changes over the lifetime (or the season
is to be followed), the chunked curves of `orbit_env.decay.chunked`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number
from orbit_env.constants import G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.chunked import DEFAULT_CHUNK_DAYS, DEFAULT_MAX_YEARS, SolarDecayModel, cached_curves, propagate
from orbit_env.decay.curves import UniversalCurves, universal_curves
from orbit_env.decay.solar import ConstantActivity, CycleActivity, SolarActivity, TableActivity, iso_date
from orbit_env.physics.atmosphere import Atmosphere, ExponentialAtmosphere, PaperAtmosphere
from orbit_env.physics.atmosphere.exponential import ORBITAL_LAW
from orbit_env.physics.atmosphere.paper import RHO100_CALIBRATED_KG_M3

FloatArray = NDArray[np.float64]
AtmosphereKind = Literal["paper", "exponential", "msis"]
ATMOSPHERES: tuple[str, ...] = ("paper", "exponential", "msis")
#: Bounds of a density scale factor, and why.
DENSITY_SCALE_RANGE = (1e-3, 1e3, "the models are off by a factor of a few at most; 1000 is another atmosphere")


#: Densest air at 100 km the universal curves are built for [kg/m^3]: 20 times the paper's
#: calibrated law. The curves step through nu on a fixed grid, and in denser air the perigee moves
#: too far per step near re-entry (at 30 times the family no longer closes, measured at 300 x 3000 km).
CURVES_MAX_RHO100_KG_M3 = 20.0 * RHO100_CALIBRATED_KG_M3


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
    """Which atmosphere and activity a decay runs in (everything but the satellite and its orbit).

    Args:
        atmosphere: ``paper``, ``exponential`` or ``msis``.
        rho100_kg_m3: Paper law: density at 100 km (None: calibrated value).
        density_scale: Multiplier on any model's density.
        rho0_kg_m3: Exponential law: density at ``h0_m`` (default: the orbital-height law
            `ORBITAL_LAW`).
        h0_m: Exponential law: reference height.
        scale_height_m: Exponential law: scale height.
        activity: NRLMSIS: indices against time (default: F10.7 = 150, Ap = 15, constant).
        epoch_days: Unix days of the orbit's epoch. With NRLMSIS it switches on the
            time-stepped path, which follows the season and any change in activity.
        rotating_atmosphere: Let the air co-rotate with the Earth.
        ascending_node_local_time_h: NRLMSIS, Sun-synchronous orbits: local time of the node.
        chunk_days: Time step of the time-stepped path.
        max_years: The time-stepped path stops there (a satellite still up is reported so).
    """

    atmosphere: AtmosphereKind = "paper"
    rho100_kg_m3: float | None = None
    density_scale: float = 1.0
    rho0_kg_m3: float = ORBITAL_LAW[0]
    h0_m: float = ORBITAL_LAW[1]
    scale_height_m: float = ORBITAL_LAW[2]
    activity: SolarActivity | None = None
    epoch_days: float | None = None
    rotating_atmosphere: bool = False
    ascending_node_local_time_h: float | None = None
    chunk_days: float = DEFAULT_CHUNK_DAYS
    max_years: float = DEFAULT_MAX_YEARS

    def __post_init__(self) -> None:
        if self.atmosphere not in ATMOSPHERES:
            raise ValueError(f"atmosphere must be one of {', '.join(ATMOSPHERES)}, got {self.atmosphere!r}")
        low, high, why = DENSITY_SCALE_RANGE
        check_number(self.density_scale, "density_scale", low=low, high=high, why=why)
        if self.atmosphere != "msis" and (self.activity is not None or self.epoch_days is not None):
            raise ValueError("solar activity and epoch apply to the msis atmosphere only (use --atmosphere msis)")
        if self.atmosphere != "paper" and self.rho100_kg_m3 is not None:
            raise ValueError("rho100 applies to the paper atmosphere only")
        if self.atmosphere == "msis" and self.epoch_days is None and self.activity is not None:
            if not isinstance(self.activity, ConstantActivity):
                raise ValueError("activity that changes with time needs an epoch (a start date)")

    @property
    def solar(self) -> SolarActivity:
        """The activity (NRLMSIS default: constant F10.7 = 150 sfu, Ap = 15)."""
        return self.activity if self.activity is not None else ConstantActivity(150.0, 150.0, 15.0)

    @property
    def time_varying(self) -> bool:
        """True when lifetimes take the time-stepped path."""
        return self.atmosphere == "msis" and self.epoch_days is not None

    def fixed_atmosphere(self, inclination_deg: float) -> Atmosphere:
        """The one density profile of a scenario that does not change in time (scale excluded)."""
        if self.time_varying:
            raise ValueError("this scenario changes in time; it has no single profile")
        if self.atmosphere == "paper":
            return PaperAtmosphere() if self.rho100_kg_m3 is None else PaperAtmosphere(self.rho100_kg_m3)
        if self.atmosphere == "exponential":
            return ExponentialAtmosphere(self.rho0_kg_m3, self.h0_m, self.scale_height_m)
        from orbit_env.physics.atmosphere.msis import MsisAtmosphere

        solar = self.solar
        assert isinstance(solar, ConstantActivity)
        return MsisAtmosphere(
            solar.f107_sfu,
            solar.f107a_sfu,
            solar.ap,
            inclination_deg,
            None,
            self.ascending_node_local_time_h,
        )

    def decay_model(self, inclination_deg: float) -> DecayModel:
        """The fixed-profile decay model (see `fixed_atmosphere`)."""
        return DecayModel(self.fixed_atmosphere(inclination_deg), self.rotating_atmosphere, inclination_deg)

    def curves(self, inclination_deg: float) -> UniversalCurves:
        """The universal curves of the fixed profile (cached per profile).

        Raises:
            ValueError: the profile is too dense at 100 km for the curves (`check_curves_density`).
        """
        model = self.decay_model(inclination_deg)
        check_curves_density(model.atmosphere)
        if self.atmosphere == "msis":
            return cached_curves(model)  # the larger cache: batches may hold many inclinations
        return universal_curves(model)

    def solar_model(self, inclination_deg: float) -> SolarDecayModel:
        """The time-stepped model (needs an epoch)."""
        assert self.epoch_days is not None
        return SolarDecayModel(
            self.solar,
            self.epoch_days,
            inclination_deg,
            follow_season=True,
            rotating_atmosphere=self.rotating_atmosphere,
            ascending_node_local_time_h=self.ascending_node_local_time_h,
            chunk_days=self.chunk_days,
            max_years=self.max_years,
        )

    def describe(self, inclination_deg: float) -> str:
        """One line for the CLI."""
        scale = f" x {self.density_scale:g}" if self.density_scale != 1.0 else ""
        if self.atmosphere == "paper":
            rho = self.fixed_atmosphere(inclination_deg)
            assert isinstance(rho, PaperAtmosphere)
            return f"paper, rho(100 km) = {rho.rho100_kg_m3:.4g} kg/m^3{scale}"
        if self.atmosphere == "exponential":
            law = (self.rho0_kg_m3, self.h0_m, self.scale_height_m)
            default = " (the default law for orbital heights: Vallado 2013, Table 8-4)" if law == ORBITAL_LAW else ""
            return (
                f"exponential, {self.rho0_kg_m3:.4g} kg/m^3 at {self.h0_m / 1e3:g} km, "
                f"scale height {self.scale_height_m / 1e3:g} km{scale}{default}"
            )
        solar = self.solar
        if isinstance(solar, ConstantActivity):
            what = f"F10.7 {solar.f107_sfu:g}, 81-day mean {solar.f107a_sfu:g} sfu, Ap {solar.ap:g}"
        elif hasattr(solar, "describe"):
            what = solar.describe()  # the space-weather record names its source and its eras
        elif isinstance(solar, TableActivity):
            what = f"solar table {solar.source} ({iso_date(solar.start_days)} to {iso_date(solar.end_days)})"
        elif isinstance(solar, CycleActivity):
            what = (
                f"smooth solar cycle, F10.7 {solar.f107_min_sfu:g}-{solar.f107_max_sfu:g} sfu, "
                f"minimum {iso_date(solar.minimum_days)}"
            )
        else:
            what = type(solar).__name__
        when = f", from {iso_date(self.epoch_days)} in {self.chunk_days:g}-day steps" if self.time_varying else ""
        where = f"inclination {inclination_deg:g} deg"
        if self.ascending_node_local_time_h is not None:
            where += f", node at {self.ascending_node_local_time_h:g} h local time"
        return f"NRLMSIS 2.1, {what}, {where}{when}{scale}"

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
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Days to re-entry of many satellites (one inclination), and whether they re-enter.

        Fixed profiles: one lookup on the universal curves. Time-varying: the
        chunked curves, stopped after ``max_days`` if given (else ``max_years``);
        with ``own_inclination_deg``, each satellite's inclination on the curves of
        ``inclination_deg`` (`orbit_env.decay.chunked.propagate`).

        Raises:
            ValueError: heights invalid or outside the universal curves' domain, or
                ``own_inclination_deg`` on a fixed profile (the catalogue's one-family
                path serves those).
        """
        hp, ha = UniversalCurves.check_domain(perigee_m, apogee_m)
        hp, ha, c, s = np.broadcast_arrays(
            hp, ha, np.asarray(drag_parameter_m2_kg, dtype=np.float64), np.asarray(density_scale, dtype=np.float64)
        )
        s = s * self.density_scale
        if not self.time_varying:
            if own_inclination_deg is not None:
                raise ValueError("own_inclination_deg applies to the time-stepped path only")
            point = self.curves(inclination_deg).locate(hp, ha)
            days = np.asarray(point.weighted_s / (G0_M_S2 * c * s) / SECONDS_PER_DAY, dtype=np.float64)
            return days, np.ones(days.shape, dtype=bool)
        model = self.solar_model(inclination_deg)
        if max_days is not None:
            model = SolarDecayModel(
                model.activity,
                model.start_days,
                model.inclination_deg,
                follow_season=model.follow_season,
                rotating_atmosphere=model.rotating_atmosphere,
                ascending_node_local_time_h=model.ascending_node_local_time_h,
                chunk_days=model.chunk_days,
                max_years=max(max_days / 365.25, model.chunk_days / 365.25),
            )
        own = None if own_inclination_deg is None else np.broadcast_to(own_inclination_deg, hp.shape).ravel()
        result = propagate(hp.ravel(), ha.ravel(), c.ravel(), model, density_scale=s.ravel(), inclination_deg=own)
        return result.days.reshape(hp.shape), result.reentered.reshape(hp.shape)
