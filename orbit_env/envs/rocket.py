"""The rocket physics of the task's perigee burn: the rocket equation, the burn and its cap, its period gain.

Pure functions on floats (one satellite, no numpy calls) or arrays that broadcast. SI units
(m, kg, s, m/s); days only in `period_gain_days_per_m_s_per_step`. The burn keeps the
perigee and raises the apogee (exact vis-viva, `orbit_env.physics.orbit`), up to the top of
the universal curves (`orbit_env.decay.curves.CURVES_MAX_APOGEE_M`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.constants import REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M
from orbit_env.physics.orbit import (
    apogee_after_perigee_burn_m,
    elements_from_heights,
    perigee_velocity_m_s,
    period_s,
)

FloatArray = NDArray[np.float64]


def delta_v_left_m_s(mass_kg: ArrayLike, dry_mass_kg: ArrayLike, exhaust_velocity_m_s: ArrayLike) -> FloatArray:
    """Delta-v the propellant on board still gives, Tsiolkovsky: v_e ln(m / m_dry) [m/s]."""
    if isinstance(mass_kg, float) and isinstance(dry_mass_kg, float) and isinstance(exhaust_velocity_m_s, float):
        return exhaust_velocity_m_s * math.log(mass_kg / dry_mass_kg)  # one satellite: no numpy on floats
    return exhaust_velocity_m_s * np.log(np.divide(mass_kg, dry_mass_kg))


def mass_from_delta_v_left_kg(dv_left_m_s: ArrayLike, dry_mass_kg: ArrayLike, exhaust_velocity_m_s: ArrayLike) -> Any:
    """The mass that still gives ``dv_left_m_s`` of delta-v, by the rocket equation [kg]."""
    return dry_mass_kg * np.exp(np.divide(dv_left_m_s, exhaust_velocity_m_s))


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
    if over.any():
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
