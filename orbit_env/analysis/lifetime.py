"""The lifetime of one satellite: the Python API behind ``orbit-env lifetime``.

This is the public edge, so heights are in km and every input is checked here
(``ValueError`` naming the value and the allowed range); the physics below is SI.
"""

from __future__ import annotations

import datetime
import math
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from orbit_env.analysis.air import Air, MsisAir, PaperAir, ProfileAir
from orbit_env.analysis.disposal import RuleCheck, check_disposal_rule
from orbit_env.analysis.scenario import DENSITY_SCALE_RANGE, Scenario, check_curves_density, check_scenario
from orbit_env.checks import InputError, check_date, check_number
from orbit_env.constants import DAYS_PER_YEAR, G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.averaged import DecayModel, integrate_averaged
from orbit_env.decay.chunked import DEFAULT_CHUNK_DAYS, SolarDecayModel, propagate
from orbit_env.decay.curves import (
    CURVES_MAX_APOGEE_M,
    CURVES_MAX_PERIGEE_M,
    NU_REF,
    UniversalCurves,
    days_from_weighted_s,
    universal_curves,
)
from orbit_env.decay.reference_path import reference_path
from orbit_env.decay.solar import ConstantActivity, SolarActivity, SolarTableWarning, TableActivity, unix_days
from orbit_env.physics.atmosphere import Atmosphere, as_atmosphere
from orbit_env.physics.orbit import elements_from_heights, perigee_velocity_m_s, period_s, validate_heights_km
from orbit_env.physics.satellite_bounds import (
    AREA_RANGE_M2,
    DRAG_COEFFICIENT_RANGE,
    MASS_PER_AREA_RANGE_KG_M2,
    MASS_RANGE_KG,
)
from orbit_env.physics.satellite_bounds import (
    DRAG_PARAMETER_RANGE_M2_KG as DRAG_PARAMETER_RANGE_M2_KG,
)

FloatArray = NDArray[np.float64]
Method = Literal["averaged", "curves", "direct"]
METHODS: tuple[str, ...] = ("averaged", "curves", "direct")

#: The paper's example satellite (section 4): a 0.5 m sphere of 10 kg, c_x = 2.
PAPER_SPHERE_DIAMETER_M = 0.5
PAPER_SPHERE_MASS_KG = 10.0
PAPER_DRAG_COEFFICIENT = 2.0

#: Longest lifetime reported [years]; beyond it a number would claim more than any atmosphere
#: model (or the solar cycles it averages) can say.
MAX_LIFETIME_YEARS = 1e6


@dataclass(frozen=True)
class Satellite:
    """Drag properties of a satellite.

    Args:
        drag_coefficient: c_x of Eq. (3.2), referred to ``area_m2``.
        mass_kg: Mass (the paper's weight G in kgf is numerically the same).
        area_m2: Reference area F.
    """

    drag_coefficient: float = PAPER_DRAG_COEFFICIENT
    mass_kg: float = PAPER_SPHERE_MASS_KG
    area_m2: float = math.pi * (PAPER_SPHERE_DIAMETER_M / 2) ** 2

    def __post_init__(self) -> None:
        for value, name, unit, (low, high, why) in (
            (self.drag_coefficient, "drag_coefficient", "", DRAG_COEFFICIENT_RANGE),
            (self.mass_kg, "mass_kg", "kg", MASS_RANGE_KG),
            (self.area_m2, "area_m2", "m^2", AREA_RANGE_M2),
        ):
            check_number(value, name, unit=unit, low=low, high=high, low_inclusive=False, why=why)
        low, high, why = MASS_PER_AREA_RANGE_KG_M2
        check_number(self.mass_per_area_kg_m2, "mass_kg / area_m2", unit="kg/m^2", low=low, high=high, why=why)

    @classmethod
    def from_mass_per_area(
        cls, mass_per_area_kg_m2: float, drag_coefficient: float = PAPER_DRAG_COEFFICIENT
    ) -> Satellite:
        """A satellite given by its transverse load G/F [kg/m^2] (Eq. 4.1)."""
        low, high, why = MASS_PER_AREA_RANGE_KG_M2
        mass_kg = check_number(mass_per_area_kg_m2, "mass_per_area_kg_m2", unit="kg/m^2", low=low, high=high, why=why)
        return cls(drag_coefficient=drag_coefficient, mass_kg=mass_kg, area_m2=1.0)

    @property
    def mass_per_area_kg_m2(self) -> float:
        """Transverse load G/F [kg/m^2]."""
        return self.mass_kg / self.area_m2

    @property
    def drag_parameter_m2_kg(self) -> float:
        """Drag parameter c = c_x F / m [m^2/kg] of Eq. (3.4)."""
        return self.drag_coefficient * self.area_m2 / self.mass_kg

    @property
    def revolutions_per_nu(self) -> float:
        """The factor of Eq. (4.1): N = nu (G/F) / (g c_x)."""
        return self.mass_per_area_kg_m2 / (G0_M_S2 * self.drag_coefficient)


@dataclass(frozen=True)
class DecayHistory:
    """A decay from the start (index 0) to re-entry; arrays of equal length."""

    revolutions: FloatArray
    days: FloatArray
    perigee_km: FloatArray
    apogee_km: FloatArray
    nu_remaining: FloatArray

    def rows(self) -> list[dict[str, float]]:
        """The history as a list of records (for CSV)."""
        columns = asdict(self)
        return [{key: float(columns[key][i]) for key in columns} for i in range(self.revolutions.size)]


@dataclass(frozen=True)
class LifetimeResult:
    """The lifetime of one satellite on one orbit.

    Attributes:
        perigee_km: Initial perigee height.
        apogee_km: Initial apogee height.
        nu: The paper's universal lifetime nu [m^3/(kg s^2)] (Table II).
        revolutions: Revolutions to re-entry, N of Eq. (4.1).
        days: Time to re-entry, the sum of the periods (not N / 16).
        perigee_velocity_m_s: Initial speed at perigee (Table II's v_pi).
        method: ``averaged``, ``curves`` or ``direct``.
        history: The decay history.
        reentered: False when the satellite outlived the time-stepped propagation; ``days``,
            ``revolutions`` and ``nu`` are then those reached (``max_years``), not a lifetime.
        epoch_days: The start's unix days when the decay followed a date (else None).
    """

    perigee_km: float
    apogee_km: float
    nu: float
    revolutions: float
    days: float
    perigee_velocity_m_s: float
    method: str
    history: DecayHistory = field(repr=False, compare=False)  # equal results: equal numbers
    reentered: bool = True
    epoch_days: float | None = None

    @property
    def reentry_date(self) -> str | None:
        """The re-entry, UTC, ISO 8601 to the minute (None without an epoch or without a re-entry)."""
        if self.epoch_days is None or not self.reentered:
            return None
        return iso_datetime(self.epoch_days + self.days)

    @classmethod
    def from_si(
        cls,
        perigee_m: float,
        apogee_m: float,
        nu: float,
        revolutions: float,
        days: float,
        method: str,
        history: DecayHistory,
    ) -> LifetimeResult:
        """The result of a decay from SI start heights (the perigee velocity is derived)."""
        return cls(
            perigee_km=perigee_m / 1e3,
            apogee_km=apogee_m / 1e3,
            nu=nu,
            revolutions=revolutions,
            days=days,
            perigee_velocity_m_s=float(perigee_velocity_m_s(perigee_m, apogee_m)),
            method=method,
            history=history,
        )

    def to_dict(self) -> dict[str, Any]:
        """The result without the history, JSON-ready; its heights above the 6371 km sphere (``height_reference``).

        The command line reports the heights as they were typed, in their reference (``equatorial``
        for NRLMSIS and a date: above 6378.137 km), under the same key.
        """
        return {
            "perigee_km": self.perigee_km,
            "apogee_km": self.apogee_km,
            "nu": self.nu,
            "revolutions": self.revolutions,
            "days": self.days if self.reentered else None,
            "years": self.days / DAYS_PER_YEAR if self.reentered else None,
            "perigee_velocity_m_s": self.perigee_velocity_m_s,
            "method": self.method,
            "reentered": self.reentered,
            **({} if self.reentered else {"years_reached": self.days / DAYS_PER_YEAR}),
            **({} if self.epoch_days is None else {"epoch": iso_datetime(self.epoch_days)}),
            **({} if self.reentry_date is None else {"reentry_date": self.reentry_date}),
            "height_reference": "sphere",  # lifetime() takes heights above the sphere
        }


def iso_datetime(days: float) -> str:
    """ISO 8601 UTC date and time to the minute of unix days: ``2003-01-21T05:10Z``."""
    return str(np.datetime64(round(days * 1440.0), "m")) + "Z"


def make_satellite(
    cx: float = PAPER_DRAG_COEFFICIENT,
    mass_kg: float | None = None,
    area_m2: float | None = None,
    mass_per_area_kg_m2: float | None = None,
) -> Satellite:
    """Build a `Satellite` from the CLI's options (defaults: the paper's sphere)."""
    if mass_per_area_kg_m2 is not None:
        if mass_kg is not None or area_m2 is not None:
            raise ValueError("give either --mass-per-area or --mass and --area, not both")
        return Satellite.from_mass_per_area(mass_per_area_kg_m2, cx)
    if (mass_kg is None) != (area_m2 is None):
        raise ValueError("give --mass and --area together (or --mass-per-area alone)")
    if mass_kg is None or area_m2 is None:
        return Satellite(drag_coefficient=cx)
    return Satellite(drag_coefficient=cx, mass_kg=mass_kg, area_m2=area_m2)


def lifetime(
    perigee_km: float,
    apogee_km: float,
    *,
    satellite: Satellite | None = None,
    scenario: Scenario | None = None,
    method: Method | None = None,
    inclination_deg: float = 0.0,
    rho100_kg_m3: float | None = None,
    density_scale: float = 1.0,
    atmosphere: Atmosphere | None = None,
    rotating_atmosphere: bool | None = None,
    activity: SolarActivity | None = None,
    epoch: str | float | datetime.date | np.datetime64 | None = None,
    ascending_node_local_time_h: float | None = None,
    chunk_days: float | None = None,
    progress: Callable[[float], None] | None = None,
) -> LifetimeResult:
    """Lifetime of a satellite from perigee/apogee heights to re-entry (perigee 100 km).

    The air is a `Scenario` (``scenario``), or, as a shorthand, the keywords from
    ``rho100_kg_m3`` on, which build one (`scenario_from_keywords`); not both.

    Args:
        perigee_km: Initial perigee height above the spherical Earth.
        apogee_km: Initial apogee height.
        satellite: Drag properties (default: the paper's 0.5 m, 10 kg sphere, c_x 2).
        scenario: The air and how it is stepped (default: the paper's atmosphere).
        method: ``averaged`` integrates the orbit-averaged equations (the reference),
            ``curves`` interpolates the universal curves (fast), ``direct`` integrates
            the non-averaged equations of motion (slow; a check). None (default): the
            curves wherever the orbit lies on them (perigee up to 1100 km, apogee up to
            4000 km) for the package's own atmospheres and for every dated one; the
            averaged equations otherwise (above the curves, an exponential law, a user's
            profile). The curves agree with the averaged equations to 0.06% and answer in
            milliseconds once built and cached on disk.
        inclination_deg: Orbit inclination (matters with a rotating atmosphere,
            and sets the latitudes NRLMSIS is averaged over).
        rho100_kg_m3: The paper atmosphere's density at 100 km.
        density_scale: Multiply the density profile.
        atmosphere: Any density model of the user's (`ProfileAir`).
        rotating_atmosphere: Let the air co-rotate with the Earth (section 5; None: the
            model's default).
        activity: Use NRLMSIS 2.1 under this solar activity (`orbit_env.decay.solar`).
            Constant activity without an epoch is one fixed profile (every method);
            otherwise the satellite is stepped through time on the universal curves
            (``method="curves"``, `orbit_env.decay.chunked`) or, as a slow reference, by
            the averaged equations with a fresh profile every day (``method="averaged"``).
        epoch: Date of the orbit (``YYYY-MM-DD`` or with a time, a ``datetime.date``/``datetime`` or
            ``numpy.datetime64``, or unix days). With NRLMSIS it
            makes the season count, and places the orbit in time-varying activity.
            None: a table's first date; for other activity day 0 (1970-01-01)
            with the season averaged (use ``CycleActivity.with_phase(phase, 0.0)``).
        ascending_node_local_time_h: NRLMSIS, Sun-synchronous orbits: the node's
            local solar time (else local time is averaged over).
        chunk_days: Time step [days] of the time-stepped path (None: `DEFAULT_CHUNK_DAYS`); a keyword
            of the air like the others (a scenario carries its own), for a time-stepped decay only.
        progress: A time-stepped decay by the curves calls it with the days decayed so far after each
            chunk (the command line's bar of the years decayed; a cold decay over decades computes their air).

    Raises:
        TypeError: more than one orbit (arrays: see `Scenario.lifetime_days`), or a satellite or
            scenario of another type.
        ValueError: a height, method or keyword out of range, the air given twice, a keyword
            that does nothing here.

    Examples:
        >>> result = lifetime(360, 800)
        >>> round(result.nu, -1), round(result.revolutions, -2)
        (2910.0, 7600.0)
    """
    if method is not None and method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if np.ndim(perigee_km) or np.ndim(apogee_km):
        raise TypeError(
            f"lifetime() decays one orbit: perigee_km and apogee_km must be numbers, got shapes "
            f"{np.shape(perigee_km)} and {np.shape(apogee_km)}; many orbits: Scenario.lifetime_days or "
            "orbit_env.analysis.catalogue.batch_lifetimes"
        )
    hp_m, ha_m = (float(x) for x in validate_heights_km(perigee_km, apogee_km))
    satellite = Satellite() if satellite is None else satellite
    if not isinstance(satellite, Satellite):
        raise TypeError(f"satellite must be a Satellite (orbit_env.Satellite), got {type(satellite).__name__}")
    if scenario is not None:
        check_scenario(scenario)
    keywords = {
        "rho100_kg_m3": rho100_kg_m3,
        "atmosphere": atmosphere,
        "rotating_atmosphere": rotating_atmosphere,
        "activity": activity,
        "epoch": epoch,
        "ascending_node_local_time_h": ascending_node_local_time_h,
    }
    if scenario is None:
        step = DEFAULT_CHUNK_DAYS if chunk_days is None else chunk_days
        scenario = scenario_from_keywords(density_scale=density_scale, chunk_days=step, **keywords)
        if chunk_days is not None and not scenario.time_varying:
            raise ValueError(
                f"chunk_days={chunk_days!r} steps a dated decay (an epoch, or activity that changes); this air is "
                "one fixed profile"
            )
    else:
        given = ", ".join(name for name, value in {**keywords, "chunk_days": chunk_days}.items() if value is not None)
        if given or density_scale != 1.0:
            raise ValueError(
                "give the air either as a scenario or as keywords, not both (here: scenario and "
                f"{given or 'density_scale'})"
            )
    method = method or default_method(scenario, hp_m, ha_m)
    if scenario.time_varying:
        result = _lifetime_under_activity(
            hp_m, ha_m, satellite, method, scenario.density_scale, scenario.solar_model(inclination_deg), progress
        )
        solar = scenario.activity
        if isinstance(solar, TableActivity) and scenario.epoch_days is not None:
            held = solar.held_outside(scenario.epoch_days, scenario.epoch_days + result.days)
            if held is not None:
                warnings.warn(held, SolarTableWarning, stacklevel=2)
        return result
    atmosphere = scenario.air.profile(inclination_deg, scenario.density_scale)
    rho_perigee = float(np.asarray(atmosphere.density_kg_m3(hp_m)))
    if not (math.isfinite(rho_perigee) and rho_perigee > 0.0):
        raise ValueError(
            f"the density at the perigee is {rho_perigee:g} kg/m^3 in this atmosphere (it underflows): no drag, "
            "no re-entry; check the law's values"
        )
    rotating = scenario.corotating
    model = DecayModel(atmosphere, rotating_atmosphere=rotating, inclination_deg=inclination_deg)
    per_nu = satellite.revolutions_per_nu
    c = satellite.drag_parameter_m2_kg
    if method == "direct":
        from orbit_env.decay.direct import integrate_direct

        direct = integrate_direct(
            hp_m,
            ha_m,
            satellite.drag_parameter_m2_kg,
            atmosphere=atmosphere,
            rotating_atmosphere=rotating,
            inclination_deg=inclination_deg,
        )
        if not direct.reentered:
            raise ValueError(
                f"the direct integration stopped at its cap of {direct.revolutions:.0f} revolutions before "
                "re-entry; use --method averaged or curves for lifetimes this long"
            )
        revolutions = direct.revolutions
        history = DecayHistory(
            revolutions=direct.history_revolutions,
            days=direct.history_time_s / SECONDS_PER_DAY,
            perigee_km=direct.history_perigee_m / 1e3,
            apogee_km=direct.history_apogee_m / 1e3,
            nu_remaining=(revolutions - direct.history_revolutions) / per_nu,
        )
        nu, days = revolutions / per_nu, direct.time_s / SECONDS_PER_DAY
    elif method == "curves":
        UniversalCurves.check_domain_km(perigee_km, apogee_km)
        check_curves_density(atmosphere)
        curves = universal_curves(model)
        start = curves.locate(hp_m, ha_m)
        tau = np.linspace(float(start.tau), 0.0, 200)
        hp_path, ha_path, mean_period = curves.at(start.label, tau)
        nu_left = NU_REF * np.expm1(tau)
        nu, weighted = float(start.nu), float(start.weighted_s)
        weighted_left = np.concatenate([[weighted], (mean_period * nu_left)[1:]])
        history = DecayHistory(
            revolutions=(nu - nu_left) * per_nu,
            days=days_from_weighted_s(weighted - weighted_left, c),
            perigee_km=np.concatenate([[hp_m], hp_path[1:]]) / 1e3,
            apogee_km=np.concatenate([[ha_m], ha_path[1:]]) / 1e3,
            nu_remaining=nu_left,
        )
        revolutions, days = nu * per_nu, float(days_from_weighted_s(weighted, c))
    else:
        path = integrate_averaged(hp_m, ha_m, model)
        nu, weighted = float(path.nu[-1]), float(path.weighted_s[-1])
        history = DecayHistory(
            revolutions=path.nu * per_nu,
            days=days_from_weighted_s(path.weighted_s, c),
            perigee_km=path.perigee_m / 1e3,
            apogee_km=path.apogee_m / 1e3,
            nu_remaining=nu - path.nu,
        )
        revolutions, days = nu * per_nu, float(days_from_weighted_s(weighted, c))
    return LifetimeResult.from_si(hp_m, ha_m, nu, revolutions, check_lifetime_days(days), method, history)


def default_method(scenario: Scenario, perigee_m: float, apogee_m: float) -> Method:
    """The method `lifetime` takes when none is given (see its ``method``)."""
    on_curves = perigee_m <= CURVES_MAX_PERIGEE_M and apogee_m <= CURVES_MAX_APOGEE_M
    return "curves" if scenario.time_varying or (scenario.air.curves_by_default and on_curves) else "averaged"


def scenario_from_keywords(
    *,
    rho100_kg_m3: float | None = None,
    density_scale: float = 1.0,
    atmosphere: Atmosphere | None = None,
    rotating_atmosphere: bool | None = None,
    activity: SolarActivity | None = None,
    epoch: str | float | datetime.date | np.datetime64 | None = None,
    ascending_node_local_time_h: float | None = None,
    chunk_days: float = DEFAULT_CHUNK_DAYS,
) -> Scenario:
    """The `Scenario` of `lifetime`'s keywords: NRLMSIS with an activity or epoch, a user's profile, else the paper's.

    Raises:
        ValueError: keywords of two models at once, or a value out of its range.
    """
    low, high, why = DENSITY_SCALE_RANGE
    scale = check_number(density_scale, "density_scale", low=low, high=high, why=why)
    air: Air
    if activity is not None or epoch is not None:
        if atmosphere is not None or rho100_kg_m3 is not None:
            raise ValueError("solar activity selects the NRLMSIS atmosphere; do not give an atmosphere or rho100 too")
        if activity is None:
            from orbit_env.decay.solar_record import load_record

            activity = load_record()  # a date and no activity: the observed and forecast Sun
        if isinstance(activity, ConstantActivity) and epoch is None:
            air = MsisAir(activity, None, ascending_node_local_time_h)
        else:
            start = _start_days(activity, epoch)
            air = MsisAir(activity, start, ascending_node_local_time_h, follow_season=epoch is not None)
    elif atmosphere is not None:
        if rho100_kg_m3 is not None:
            raise ValueError("rho100_kg_m3 applies to the paper's atmosphere only; scale your own model instead")
        if scale != 1.0:
            raise ValueError("density_scale applies to the package's atmospheres only; scale your own model instead")
        air = ProfileAir(as_atmosphere(atmosphere))
    else:
        air = PaperAir(rho100_kg_m3)
    return Scenario(air, scale, rotating_atmosphere, chunk_days)


def check_lifetime_days(days: float) -> float:
    """A lifetime the models can answer for, in days; else an error saying how long it came out.

    Raises:
        ValueError: ``days`` is not finite or exceeds `MAX_LIFETIME_YEARS`.
    """
    if not (math.isfinite(days) and days <= MAX_LIFETIME_YEARS * DAYS_PER_YEAR):
        raise ValueError(
            f"the lifetime comes out as {days / DAYS_PER_YEAR:.3g} years, more than {MAX_LIFETIME_YEARS:,.0f}: drag "
            "hardly touches this orbit, and no atmosphere model holds that long"
        )
    return days


def _start_days(activity: SolarActivity, epoch: str | float | datetime.date | np.datetime64 | None) -> float:
    if epoch is None:
        return activity.start_days if isinstance(activity, TableActivity) else 0.0
    if isinstance(epoch, np.datetime64) and np.isnat(epoch):
        raise ValueError("epoch=NaT is not a date; allowed: a date from 1957-10-04 to 2200-12-31")
    if isinstance(epoch, (datetime.date, np.datetime64)):
        return check_date(unix_days(epoch), "epoch", text=str(epoch))
    if not isinstance(epoch, str):
        return check_date(check_number(epoch, "epoch", unit="unix days", why="or a date YYYY-MM-DD"), "epoch")
    return check_date(unix_days(epoch), "epoch", text=epoch)


def _lifetime_under_activity(
    hp_m: float,
    ha_m: float,
    satellite: Satellite,
    method: str,
    scale: float,
    model: SolarDecayModel,
    progress: Callable[[float], None] | None = None,
) -> LifetimeResult:
    """The time-stepped NRLMSIS lifetime (see `lifetime`; the caller checked the heights).

    Above the curves' domain, by either method, the averaged equations in the mean air
    of the lifetime (`orbit_env.decay.lifetime_mean`): the daily reference would take
    hours over a GTO's decades.
    """
    if method == "direct":
        raise ValueError("the direct method needs a fixed atmosphere; with changing solar activity use curves")
    c = satellite.drag_parameter_m2_kg
    per_nu = satellite.revolutions_per_nu
    if hp_m > CURVES_MAX_PERIGEE_M or ha_m > CURVES_MAX_APOGEE_M:
        from orbit_env.decay.lifetime_mean import mean_air_lifetime

        method = "averaged"
        mean = mean_air_lifetime(hp_m, ha_m, c * scale, model)
        days, reentered = mean.days, mean.reentered
        t = days_from_weighted_s(mean.trajectory.weighted_s, c, scale)
        inside = t < days
        t = np.append(t[inside], days)
        hp_path = np.append(mean.trajectory.perigee_m[inside], mean.trajectory.perigee_m[-1])
        ha_path = np.append(mean.trajectory.apogee_m[inside], mean.trajectory.apogee_m[-1])
    elif method == "averaged":
        t, hp_path, ha_path = reference_path(hp_m, ha_m, c * scale, model)
        days = float(t[-1])
        reentered = days < model.max_years * DAYS_PER_YEAR
    else:
        result = propagate(hp_m, ha_m, c, model, density_scale=scale, record=True, clock=progress)
        days, reentered = float(result.days[0]), bool(result.reentered[0])
        inside = result.history_days < days
        t = np.append(result.history_days[inside], days)
        hp_path = np.append(result.history_perigee_m[inside, 0], result.history_perigee_m[-1, 0])
        ha_path = np.append(result.history_apogee_m[inside, 0], result.history_apogee_m[-1, 0])
    # Still up at max_years is a result (reentered False), reported as the years reached.
    # Revolutions: Int dt / P, trapezoidal over the recorded orbits (the period changes slowly), to each row.
    if np.all(np.isfinite(ha_path)):
        inverse_period = 1.0 / period_s(*elements_from_heights(hp_path, ha_path))
        steps = 0.5 * (inverse_period[1:] + inverse_period[:-1]) * np.diff(t) * SECONDS_PER_DAY
        counted = np.concatenate([[0.0], np.cumsum(steps)])
    else:  # no finite path (an orbit beyond the curves' heights): at the starting period
        counted = t * (SECONDS_PER_DAY / period_s(*elements_from_heights(hp_m, ha_m)))
    revolutions = float(counted[-1])
    nu = revolutions / per_nu
    history = DecayHistory(
        revolutions=counted,
        days=t,
        perigee_km=hp_path / 1e3,
        apogee_km=ha_path / 1e3,
        nu_remaining=(revolutions - counted) / per_nu,
    )
    result = LifetimeResult.from_si(hp_m, ha_m, nu, revolutions, days, method, history)
    epoch = model.start_days if model.follow_season else None
    return replace(result, reentered=reentered, epoch_days=epoch)


def check_rule(
    perigee_km: float,
    apogee_km: float,
    rule_years: float,
    *,
    satellite: Satellite | None = None,
    scenario: Scenario | None = None,
    inclination_deg: float = 0.0,
) -> RuleCheck:
    """Does the orbit re-enter within ``rule_years`` (e.g. 25 or 5), and the smallest burn that makes it.

    The burn is a retrograde burn at apogee that lowers the perigee (the apogee stays).

    Lifetimes come from the universal curves of the scenario (time-stepped if it
    has an epoch), see `orbit_env.analysis.disposal`. Above the curves' domain
    (perigee > 1100 km or apogee > 4000 km: a GTO, a Molniya orbit) a fixed atmosphere's
    lifetimes come from the averaged equations instead (one integration per candidate
    perigee, 49 in all; the same equations as ``lifetime(method="averaged")``, so the
    printed lifetime and the verdict are one computation). A dated scenario's come from
    the averaged equations in the mean air of the orbit's own lifetime
    (`orbit_env.decay.lifetime_mean`, as `lifetime` gives it), the same air for every
    candidate perigee.

    Examples:
        >>> check = check_rule(800, 800, 25, satellite=Satellite(2.2, 100.0, 1.0))
        >>> bool(check.complies[0]), round(float(check.new_perigee_m[0]) / 1e3)
        (False, 590)
    """
    satellite = satellite or Satellite()
    scenario = scenario or Scenario()
    hp_m, ha_m = validate_heights_km(perigee_km, apogee_km)
    c = satellite.drag_parameter_m2_kg
    try:
        UniversalCurves.check_domain_km(perigee_km, apogee_km)
    except InputError:
        if scenario.time_varying:
            return check_disposal_rule(
                hp_m, ha_m, rule_years, _mean_air_lifetimes(scenario, c, inclination_deg, hp_m, ha_m)
            )
        return check_disposal_rule(hp_m, ha_m, rule_years, _averaged_lifetimes(scenario, c, inclination_deg))

    def lifetimes(hp: NDArray[np.float64], ha: NDArray[np.float64], which: NDArray[np.intp]) -> Any:
        # Called once check_disposal_rule has checked rule_years.
        cap_days = (float(rule_years) + 1.0) * DAYS_PER_YEAR
        return scenario.lifetime_days(hp, ha, np.full(hp.shape, c), inclination_deg, max_days=cap_days)

    return check_disposal_rule(hp_m, ha_m, rule_years, lifetimes)


def _mean_air_lifetimes(scenario: Scenario, c: float, inclination_deg: float, hp_m: Any, ha_m: Any) -> Any:
    """The rule's lifetime function in the mean air of the orbit's lifetime (dated; any heights)."""
    from orbit_env.decay.lifetime_mean import mean_air_lifetime, mean_air_lifetimes

    scaled = c * scenario.density_scale
    model = scenario.solar_model(inclination_deg)
    start = mean_air_lifetime(float(np.ravel(hp_m)[0]), float(np.ravel(ha_m)[0]), scaled, model)

    def lifetimes(hp: NDArray[np.float64], ha: NDArray[np.float64], which: NDArray[np.intp]) -> Any:
        return mean_air_lifetimes(hp, ha, scaled, start.model), np.ones(hp.size, dtype=bool)

    return lifetimes


def _averaged_lifetimes(scenario: Scenario, c: float, inclination_deg: float) -> Any:
    """The rule's lifetime function on the averaged equations (fixed profile; any heights)."""
    model = scenario.decay_model(inclination_deg)

    def lifetimes(hp: NDArray[np.float64], ha: NDArray[np.float64], which: NDArray[np.intp]) -> Any:
        days = np.zeros(hp.size)
        for i, (perigee, apogee) in enumerate(zip(hp.tolist(), ha.tolist(), strict=True)):
            if perigee > REENTRY_ALTITUDE_M:
                weighted = integrate_averaged(perigee, apogee, model).weighted_s[-1]
                days[i] = float(days_from_weighted_s(weighted, c, scenario.density_scale))
        return days, np.ones(hp.size, dtype=bool)

    return lifetimes
