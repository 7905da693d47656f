"""Geometry of the osculating ellipse, SI units (m, m/s, s).

Heights are above the paper's spherical Earth (radius ``EARTH_RADIUS_M``). All
functions broadcast over numpy arrays. The ``validate_*`` functions are the
public boundary's checks: they raise ``ValueError`` naming the offending value and
the allowed range; the other functions assume valid input.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_array
from orbit_env.constants import EARTH_RADIUS_M, EARTH_ROTATION_RAD_S, MU_EARTH_M3_S2, REENTRY_ALTITUDE_M, TWO_PI

FloatArray = NDArray[np.float64]

#: Largest apogee height the public functions accept [m] (beyond it the paper's
#: density law is an extrapolation over more than an Earth radius).
MAX_APOGEE_M = 50_000e3


def _check_heights(
    perigee: ArrayLike, apogee: ArrayLike, names: tuple[str, str], unit: str, unit_m: float
) -> tuple[FloatArray, FloatArray]:
    """The checks of `validate_heights`, in the caller's unit (``unit_m`` metres)."""
    hp, ha = np.broadcast_arrays(np.asarray(perigee), np.asarray(apogee))
    hp = check_array(
        hp,
        names[0],
        unit=unit,
        low=REENTRY_ALTITUDE_M / unit_m,
        high=MAX_APOGEE_M / unit_m,
        why="the decay ends at the re-entry height",
    )
    ha = check_array(ha, names[1], unit=unit, low=hp, low_name=names[0], high=MAX_APOGEE_M / unit_m)
    return hp, ha


def validate_heights(perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Check perigee and apogee heights [m] and return them as float arrays.

    Raises:
        ValueError: a height is not a finite number, the perigee is below the
            100 km re-entry height, the apogee is below the perigee or above
            ``MAX_APOGEE_M``. The message names ``perigee_m``/``apogee_m``, the
            value (first bad element and its index for arrays) and the range.
    """
    return _check_heights(perigee_m, apogee_m, ("perigee_m", "apogee_m"), "m", 1.0)


def validate_heights_km(perigee_km: ArrayLike, apogee_km: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """`validate_heights` for heights given in km; returns them in metres.

    The check happens in km, so a message says ``perigee_km=50``, as the caller typed it.

    Raises:
        ValueError: as `validate_heights`, naming ``perigee_km``/``apogee_km``.
    """
    hp, ha = _check_heights(perigee_km, apogee_km, ("perigee_km", "apogee_km"), "km", 1e3)
    return hp * 1e3, ha * 1e3


def elements_from_heights(perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Parameter p [m] and eccentricity e from perigee and apogee heights (section 3)."""
    rp = EARTH_RADIUS_M + np.asarray(perigee_m, dtype=np.float64)
    ra = EARTH_RADIUS_M + np.asarray(apogee_m, dtype=np.float64)
    e = (ra - rp) / (ra + rp)
    return rp * (1.0 + e), e


def heights_from_elements(p_m: ArrayLike, e: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Perigee and apogee heights [m] from p [m] and e (section 3)."""
    p = np.asarray(p_m, dtype=np.float64)
    ecc = np.asarray(e, dtype=np.float64)
    return p / (1.0 + ecc) - EARTH_RADIUS_M, p / (1.0 - ecc) - EARTH_RADIUS_M


def semi_major_axis_m(p_m: ArrayLike, e: ArrayLike) -> FloatArray:
    """Semi-major axis a = p / (1 - e^2) [m]."""
    ecc = np.asarray(e, dtype=np.float64)
    return np.asarray(p_m, dtype=np.float64) / (1.0 - ecc * ecc)


def period_s(p_m: ArrayLike, e: ArrayLike) -> FloatArray:
    """Keplerian period 2 pi sqrt(a^3 / fM) [s] of the osculating ellipse."""
    a = semi_major_axis_m(p_m, e)
    return TWO_PI * np.sqrt(a**3 / MU_EARTH_M3_S2)


def perigee_velocity_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike) -> FloatArray:
    """Speed at perigee, v_pi = sqrt(fM) (1 + e) / sqrt(p) (section 3) [m/s]."""
    p, e = elements_from_heights(perigee_m, apogee_m)
    return np.sqrt(MU_EARTH_M3_S2 / p) * (1.0 + e)


def air_speed_at_perigee_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike, inclination_deg: ArrayLike) -> FloatArray:
    """Along-track speed at perigee relative to air co-rotating with the Earth [m/s]: v_pi - Omega r_p cos i.

    The air's eastward speed Omega r cos(latitude), projected on a track of inclination i
    (whose eastward share at that latitude is cos i / cos(latitude)), is Omega r cos i at any
    latitude. The wind across the track (up to Omega r sin i, some 10 m/s of the relative
    speed's magnitude at 53 deg) is left out, as in King-Hele's theory of orbits in a rotating
    atmosphere. ``inclination_deg`` broadcasts against the heights.
    """
    wind = EARTH_ROTATION_RAD_S * np.add(perigee_m, EARTH_RADIUS_M)
    return perigee_velocity_m_s(perigee_m, apogee_m) - wind * np.cos(np.radians(inclination_deg))


def corotation_drag_factor(perigee_m: ArrayLike, apogee_m: ArrayLike, inclination_deg: ArrayLike) -> FloatArray:
    """F_rot: drag in co-rotating air over drag in still air, (v_air / v_pi)^2 (`air_speed_at_perigee_m_s`).

    At the perigee, where near-circular orbits meet most of their drag: 0.875 at 0 deg for a 400 km
    circle, 1 at 90 deg, above 1 on retrograde orbits.
    """
    v_pi = perigee_velocity_m_s(perigee_m, apogee_m)
    return (air_speed_at_perigee_m_s(perigee_m, apogee_m, inclination_deg) / v_pi) ** 2


def apogee_velocity_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike) -> FloatArray:
    """Speed at apogee, v_a = sqrt(2 fM r_p / (r_a (r_p + r_a))) (vis-viva) [m/s]."""
    rp = np.add(perigee_m, EARTH_RADIUS_M)
    ra = np.add(apogee_m, EARTH_RADIUS_M)
    return np.sqrt(2.0 * MU_EARTH_M3_S2 * rp / (ra * (rp + ra)))


def dv_to_lower_perigee_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike, new_perigee_m: ArrayLike) -> FloatArray:
    """Retrograde burn at apogee [m/s] that lowers the perigee to ``new_perigee_m`` (the apogee stays; vis-viva)."""
    return apogee_velocity_m_s(perigee_m, apogee_m) - apogee_velocity_m_s(new_perigee_m, apogee_m)


def apogee_after_perigee_burn_m(perigee_m: ArrayLike, apogee_m: ArrayLike, dv_m_s: ArrayLike) -> FloatArray:
    """Apogee height [m] after a tangential burn of ``dv_m_s`` at perigee (exact vis-viva).

    A prograde burn (``dv_m_s >= 0``) at perigee keeps the perigee and raises the
    apogee; the result is clamped so that round-off never lowers it. A burn at or
    beyond escape (see `escape_dv_m_s`) returns 2e300 m: unbounded.
    """
    rp = np.add(perigee_m, EARTH_RADIUS_M)
    ra = np.add(apogee_m, EARTH_RADIUS_M)
    # Vis-viva at perigee, v^2 = 2 fM ra / (rp (rp + ra)), written in few operations:
    # a batch of a few dozen burning satellites costs numpy calls, not arithmetic.
    v = np.sqrt(2.0 * MU_EARTH_M3_S2 * ra / (rp * (rp + ra))) + dv_m_s
    inverse_a = 2.0 / rp - v * v / MU_EARTH_M3_S2
    # A burn to escape (1/a <= 0) has no apogee: the floor on 1/a puts it beyond any bound (2e300 m).
    return np.maximum(2.0 / np.maximum(inverse_a, 1e-300) - rp - EARTH_RADIUS_M, apogee_m)


def escape_dv_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike) -> FloatArray:
    """Perigee burn [m/s] that would reach escape speed sqrt(2 fM / r_p)."""
    rp = EARTH_RADIUS_M + np.asarray(perigee_m, dtype=np.float64)
    return np.sqrt(2.0 * MU_EARTH_M3_S2 / rp) - perigee_velocity_m_s(perigee_m, apogee_m)


def dv_for_apogee_m_s(perigee_m: ArrayLike, apogee_m: ArrayLike, target_apogee_m: ArrayLike) -> FloatArray:
    """Perigee burn [m/s] that raises the apogee to ``target_apogee_m`` (exact vis-viva).

    Raises:
        ValueError: the heights are invalid, or the target is below the current apogee.
    """
    hp, ha = validate_heights(perigee_m, apogee_m)
    ha, target = np.broadcast_arrays(ha, check_array(target_apogee_m, "target_apogee_m", unit="m", high=MAX_APOGEE_M))
    # 1 mm of round-off slack: a target computed to equal the apogee may land just below it.
    target = np.where((target < ha) & (target >= ha - 1e-3), ha, target)
    check_array(
        target, "target_apogee_m", unit="m", low=ha, low_name="apogee_m", why="a perigee burn only raises the apogee"
    )
    hp = np.broadcast_to(hp, target.shape)
    return np.maximum(perigee_velocity_m_s(hp, target) - perigee_velocity_m_s(hp, ha), 0.0)
