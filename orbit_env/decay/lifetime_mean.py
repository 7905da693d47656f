"""Dated decay above the universal curves' domain: the averaged equations in the lifetime's mean air. SI units.

The time-stepped decay under the real Sun (`orbit_env.decay.chunked`) moves
satellites along the universal curves, which end at a 1100 km perigee and a
4000 km apogee. A GTO or a Molniya disposal orbit starts above them and lives
for years to decades, and integrating the averaged equations with a fresh
NRLMSIS profile every day over decades is far too slow (over 15 minutes for a
250 x 20 000 km stage). Over such lives the orbit changes slowly against the
Sun's changes, so the decay depends on the air's time integral: if the density
were rho(h, t) = a(t) b(h), the lifetime in the time-varying air would be
exactly the lifetime in the time-mean profile over that lifetime. So here:

1. the mean profile of NRLMSIS (the chunked model's binned profiles, sampled
   every `SAMPLE_DAYS` from the epoch) is taken over one solar cycle
   (`FIRST_WINDOW_DAYS`), and the averaged equations give a first lifetime L1;
2. the mean is taken again over [epoch, epoch + L1] and gives the lifetime L2,
   which is reported (`PASSES` passes in all).

The approximation is not exact (the scale height changes with activity, so
rho(h, t) does not factor), and it is measured where both paths exist, inside
the curves' domain, against the time-stepped curves (docs/validation-modern.md,
"Dated lifetimes above the curves"; ``tests/decay/test_lifetime_mean.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.constants import DAYS_PER_YEAR, REENTRY_ALTITUDE_M
from orbit_env.decay.averaged import DecayModel, Trajectory, integrate_averaged
from orbit_env.decay.chunked import SolarDecayModel
from orbit_env.decay.curves import days_from_weighted_s
from orbit_env.physics.atmosphere.msis import interpolate_log_density
from orbit_env.physics.orbit import elements_from_heights, period_s

FloatArray = NDArray[np.float64]

#: Spacing of the profiles averaged [days]: one solar rotation.
SAMPLE_DAYS = 27.0
#: The first pass's window [days]: one solar cycle.
FIRST_WINDOW_DAYS = 11.0 * DAYS_PER_YEAR
#: Passes: the window of each is the lifetime the one before gave.
PASSES = 2
#: A first pass's life this many times the cap ends the search: still up. The second pass's air moved lives
#: of 900-2000 km orbits by factors of 0.79-1.18 (measured 2026-12-06: 1071 -> 1354, 6520 -> 5534 and
#: 752 552 -> 848 354 years, from 2014, 2009 and 2024): the second pass, its air over the cap's 200 years and its
#: integration, would not change the verdict.
FAR_BEYOND = 10.0


@dataclass(frozen=True, eq=False)
class MeanProfileAtmosphere:
    """NRLMSIS's orbit-averaged profile averaged in time (mean density) over a window of days.

    Attributes:
        log_density: ln(mean density [kg/m^3]) on ``ALTITUDE_GRID_M``.
        start_days: The window's first day [unix days].
        window_days: Its length [days].
    """

    log_density: FloatArray = field(repr=False)
    start_days: float
    window_days: float

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Mean density [kg/m^3] at altitude [m]."""
        return interpolate_log_density(altitude_m, self.log_density)


def mean_profile(model: SolarDecayModel, window_days: float) -> MeanProfileAtmosphere:
    """The mean over ``window_days`` from the model's start of the profiles its chunks use."""
    count = max(1, math.ceil(window_days / SAMPLE_DAYS))
    total = None
    for t in (np.arange(count) + 0.5) * (window_days / count):
        atmosphere = model.bin_model(model.chunk_bin(float(t))).atmosphere
        density = np.exp(atmosphere.log_density_table())  # type: ignore[attr-defined]
        total = density if total is None else total + density
    assert total is not None
    return MeanProfileAtmosphere(np.log(total / count), model.start_days, float(window_days))


@dataclass(frozen=True)
class MeanAirLifetime:
    """A lifetime in the lifetime's mean air (see the module)."""

    days: float
    reentered: bool
    trajectory: Trajectory
    atmosphere: MeanProfileAtmosphere
    model: DecayModel


def _days(trajectory: Trajectory, drag_parameter_m2_kg: float) -> float:
    return float(days_from_weighted_s(trajectory.weighted_s[-1], drag_parameter_m2_kg))


def _first_metre_days(perigee_m: float, apogee_m: float, drag_parameter_m2_kg: float, decay: DecayModel) -> float:
    """Days the parameter p takes to fall its first metre at the start's rate (inf: no decay at all).

    The metre's weighted time is W = P dnu = P / |dp/dnu| (one metre of p), in days by `days_from_weighted_s`.
    Drag grows as the orbit comes down, so the whole life is longer than this: a lower bound.
    """
    p, e = elements_from_heights(perigee_m, apogee_m)
    dp_dnu = float(decay.rates_per_nu(p, e)[0])
    if not dp_dnu < 0.0:
        return math.inf
    return float(days_from_weighted_s(float(period_s(p, e)) / -dp_dnu, drag_parameter_m2_kg))


def _staying(perigee_m: float, apogee_m: float) -> Trajectory:
    """The trajectory of an orbit that stays: its start, twice."""
    _, e = elements_from_heights(perigee_m, apogee_m)
    return Trajectory(np.zeros(2), np.zeros(2), np.full(2, perigee_m), np.full(2, apogee_m), np.full(2, float(e)))


def mean_air_model(model: SolarDecayModel, atmosphere: MeanProfileAtmosphere) -> DecayModel:
    """The averaged equations' model in a mean profile (the chunked model's air options)."""
    return DecayModel(atmosphere, model.rotating_atmosphere, model.inclination_deg)


def mean_air_lifetime(
    perigee_m: float, apogee_m: float, drag_parameter_m2_kg: float, model: SolarDecayModel
) -> MeanAirLifetime:
    """Lifetime [days] from ``model``'s start, in the mean air over the lifetime (see the module).

    ``drag_parameter_m2_kg``: c_x A / m times any density scale. A life longer
    than the model's ``max_years`` is reported as not re-entered, at ``max_years``.
    """
    cap_days = model.max_years * DAYS_PER_YEAR
    window = min(FIRST_WINDOW_DAYS, cap_days)
    for _ in range(PASSES):
        atmosphere = mean_profile(model, window)
        decay = mean_air_model(model, atmosphere)
        if _first_metre_days(perigee_m, apogee_m, drag_parameter_m2_kg, decay) > cap_days:
            # Still up at the cap for certain (drag only grows as the orbit comes down): no integration, which
            # fails where drag hardly touches the orbit (a geostationary satellite in co-rotating air).
            return MeanAirLifetime(cap_days, False, _staying(perigee_m, apogee_m), atmosphere, decay)
        trajectory = integrate_averaged(perigee_m, apogee_m, decay)
        days = _days(trajectory, drag_parameter_m2_kg) if perigee_m > REENTRY_ALTITUDE_M else 0.0
        if days > FAR_BEYOND * cap_days:  # still up at the cap whatever the second pass's air (`FAR_BEYOND`)
            break
        window = min(max(days, SAMPLE_DAYS), cap_days)
    reentered = days <= cap_days
    return MeanAirLifetime(min(days, cap_days), reentered, trajectory, atmosphere, decay)


def mean_air_lifetimes(
    perigee_m: FloatArray, apogee_m: FloatArray, drag_parameter_m2_kg: float, decay: DecayModel
) -> FloatArray:
    """Lifetimes [days] of several orbits in one mean air (the disposal rule's candidates)."""
    days = np.zeros(np.size(perigee_m))
    for i, (hp, ha) in enumerate(zip(np.ravel(perigee_m).tolist(), np.ravel(apogee_m).tolist(), strict=True)):
        if hp > REENTRY_ALTITUDE_M:
            days[i] = _days(integrate_averaged(hp, ha, decay), drag_parameter_m2_kg)
    return days
