"""Secular perturbations by the Earth's oblateness: Eqs. (5.5) and (5.6), SI units.

Angles in radians, lengths in metres, times in seconds. Section 5 of the paper
averages the Gauss equations (2.8) with the perturbing accelerations (5.3) of the
potential (5.1) over one revolution, elements frozen and gamma = 1. Only the node
Omega and the argument of perigee omega drift; p, e and i have no secular change,
which is why the lifetime computation may ignore the oblateness:

    dOmega/dN = -2 pi eps cos(i) / (p^2 fM),               Eq. (5.5)
    domega/dN =    pi eps (5 cos^2(i) - 1) / (p^2 fM),      Eq. (5.6)

with eps = fM a^2 (alpha - m/2) of Eq. (5.2), equal to fM a^2 (3/2) J2 to first
order in the flattening (a the equatorial radius). N counts revolutions in the
argument of latitude u. Note that the rates depend on p alone, not on e.

The per-day rates multiply by the number of Keplerian periods in a day. The paper
instead divides by a 90-minute orbit (16 revolutions a day, section 4), so its
per-day figures are some 5% above these at 500 km (see ``docs/validation.md``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_array
from orbit_env.constants import EARTH_EQUATORIAL_RADIUS_M, J2_EARTH, MU_EARTH_M3_S2, SECONDS_PER_DAY
from orbit_env.physics.orbit import period_s

FloatArray = NDArray[np.float64]

#: eps of Eq. (5.2) as fM a^2 (3/2) J2 [m^5/s^2].
EPSILON_M5_S2 = MU_EARTH_M3_S2 * EARTH_EQUATORIAL_RADIUS_M**2 * 1.5 * J2_EARTH


def _check_p(p_m: ArrayLike) -> FloatArray:
    # Any orbit that does not cut through the Earth; the formulas themselves only
    # need p > 0, but a smaller p is certainly a unit mistake (km for m).
    return check_array(p_m, "p_m", unit="m", low=EARTH_EQUATORIAL_RADIUS_M / 2.0, why="p in metres, not km")


def _check_inclination(inclination_rad: ArrayLike) -> FloatArray:
    return check_array(inclination_rad, "inclination_rad", unit="rad", low=0.0, high=np.pi)


def node_rate_rad_per_rev(p_m: ArrayLike, inclination_rad: ArrayLike) -> FloatArray:
    """Secular drift of the ascending node per revolution [rad], Eq. (5.5).

    Negative (regression) for prograde orbits, zero for polar ones.

    Args:
        p_m: Parameter (semi-latus rectum) of the orbit [m].
        inclination_rad: Inclination [rad], from 0 to pi.

    Raises:
        ValueError: ``p_m`` below half the Earth's radius or not finite, or an
            inclination outside [0, pi].
    """
    p = _check_p(p_m)
    inclination = _check_inclination(inclination_rad)
    return -2.0 * np.pi * EPSILON_M5_S2 * np.cos(inclination) / (p * p * MU_EARTH_M3_S2)


def perigee_rate_rad_per_rev(p_m: ArrayLike, inclination_rad: ArrayLike) -> FloatArray:
    """Secular drift of the argument of perigee per revolution [rad], Eq. (5.6).

    Positive below the critical inclination arccos(1/sqrt(5)) = 63.4 deg, zero at it.

    Args:
        p_m: Parameter (semi-latus rectum) of the orbit [m].
        inclination_rad: Inclination [rad], from 0 to pi.

    Raises:
        ValueError: as `node_rate_rad_per_rev`.
    """
    p = _check_p(p_m)
    cos_i = np.cos(_check_inclination(inclination_rad))
    return np.pi * EPSILON_M5_S2 * (5.0 * cos_i * cos_i - 1.0) / (p * p * MU_EARTH_M3_S2)


def revolutions_per_day(p_m: ArrayLike, e: ArrayLike) -> FloatArray:
    """Keplerian periods in a day for the orbit (p, e).

    Raises:
        ValueError: ``p_m`` as in `node_rate_rad_per_rev`, or e outside [0, 1).
    """
    p = _check_p(p_m)
    ecc = check_array(e, "e", low=0.0, high=1.0, high_inclusive=False, why="an ellipse")
    return SECONDS_PER_DAY / period_s(p, ecc)


def node_rate_rad_per_day(p_m: ArrayLike, e: ArrayLike, inclination_rad: ArrayLike) -> FloatArray:
    """Secular drift of the ascending node per day [rad/day]: Eq. (5.5) times revolutions a day.

    Raises:
        ValueError: as `node_rate_rad_per_rev` and `revolutions_per_day`.
    """
    return node_rate_rad_per_rev(p_m, inclination_rad) * revolutions_per_day(p_m, e)


def perigee_rate_rad_per_day(p_m: ArrayLike, e: ArrayLike, inclination_rad: ArrayLike) -> FloatArray:
    """Secular drift of the argument of perigee per day [rad/day]: Eq. (5.6) times revolutions a day.

    Raises:
        ValueError: as `perigee_rate_rad_per_rev` and `revolutions_per_day`.
    """
    return perigee_rate_rad_per_rev(p_m, inclination_rad) * revolutions_per_day(p_m, e)


def mean_to_flown_radius_offset_m(semi_major_axis_m: ArrayLike, inclination_deg: ArrayLike) -> FloatArray:
    """How far the orbit flown lies above the radius of its mean elements, averaged over a revolution [m].

    Mean elements (SGP4's and Brouwer's, an element set's) leave out J2's short-period
    terms. Averaged over the argument of latitude, the radius of the orbit flown is

        <r> - a_mean = -(3/2) J2 Re^2 / a (1 - (3/2) sin^2 i)

    to first order in J2 and e (Brouwer 1959, the short-period part of r; D. A. Vallado,
    *Fundamentals of Astrodynamics and Applications*, 4th ed., 2013, section 9.6): about
    -9.7 km at 0 deg, -0.8 km at 51.6 deg and +4.6 km at 97.5 deg for a 400 km orbit. The
    decay integrates the orbit flown, so the heights of an element set move by this much.
    Tested against SGP4's own propagation (``tests/analysis/test_elements.py``).
    """
    a_m = check_array(semi_major_axis_m, "semi_major_axis_m", unit="m", low=EARTH_EQUATORIAL_RADIUS_M)
    sin_i = np.sin(np.radians(check_array(inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)))
    return -1.5 * J2_EARTH * EARTH_EQUATORIAL_RADIUS_M**2 / a_m * (1.0 - 1.5 * sin_i**2)
