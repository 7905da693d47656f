"""Direct (non-averaged) integration of the drag decay: the check of section 5.

SI units throughout (m, m/s, s, kg, rad). The paper replaces the motion by the
orbit-averaged equations (3.10)-(3.11) and claims in section 5 that averaging
costs no appreciable accuracy. This module tests that claim: it integrates the
Cartesian equations of motion of a point mass in the central field fM / r^2 with
the drag acceleration of Eq. (3.2),

    d^2 r / dt^2 = -fM r / |r|^3 - (c / 2) rho(|r| - R) |v_rel| v_rel,
    v_rel = v - Omega x r   (co-rotating air, section 5; v_rel = v in still air),

with c = c_x F / m the drag parameter [m^2/kg] and rho any atmosphere of
`orbit_env.physics.atmosphere`. It starts at the perigee of the orbit given by its
perigee and apogee heights, in a plane inclined by i to the equator (the
ascending node is on the x axis, the perigee at the node), and stops when the
osculating perigee height, from the energy and the angular momentum, falls to
100 km: the re-entry condition of section 3.

Revolutions are counted as the accumulated angle sigma swept by the radius
vector divided by 2 pi, with d(sigma)/dt = |r x v| / r^2: Eq. (2.3), the
paper's own measure of angular progress in perturbed motion, so that N is the
same quantity as the N = u / 2 pi of Eq. (3.10). The state is the flat vector
(x, y, z, vx, vy, vz, sigma).

The averaged model predicts N = nu / (g c) revolutions and t = W / (g c) seconds
(`orbit_env.decay.averaged.integrate_averaged`); ``tests/decay/test_direct.py`` compares
the two and ``docs/validation.md`` lists the numbers.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_int, check_number
from orbit_env.constants import (
    EARTH_RADIUS_M,
    EARTH_ROTATION_RAD_S,
    MU_EARTH_M3_S2,
    REENTRY_ALTITUDE_M,
    TWO_PI,
)
from orbit_env.physics.atmosphere import Atmosphere, as_atmosphere
from orbit_env.physics.orbit import elements_from_heights, perigee_velocity_m_s, period_s, validate_heights

FloatArray = NDArray[np.float64]

#: Default relative tolerance of DOP853. The revolution count changes by about
#: 2e-5 relative between 1e-8 and 1e-12 (measured on a 43-revolution decay), so
#: 1e-10 leaves the integration error far below the 3% being tested.
DEFAULT_RTOL = 1e-10
#: Default cap on the revolutions integrated (a safety net, not a physical limit).
DEFAULT_MAX_REVOLUTIONS = 20_000.0

# Absolute tolerances per unit of rtol: position [m], velocity [m/s], sigma [rad].
# They sit about 1e-7 below the scale of each component (7e6 m, 8e3 m/s, one
# revolution 6 rad), so that the relative tolerance governs.
_ATOL_PER_RTOL = np.array([1.0, 1.0, 1.0, 1e-3, 1e-3, 1e-3, 1e-6])


@dataclass(frozen=True)
class DirectResult:
    """The outcome of `integrate_direct`.

    Attributes:
        revolutions: Revolutions completed up to re-entry (or up to the cap),
            sigma / 2 pi, fractional.
        time_s: Time up to re-entry (or up to the cap) [s].
        reentered: True if the osculating perigee reached 100 km, False if the
            integration stopped at ``max_revolutions`` first.
        history_time_s: Times of the decimated history [s], from 0 to ``time_s``.
        history_revolutions: Revolutions at those times.
        history_perigee_m: Osculating perigee heights at those times [m].
        history_apogee_m: Osculating apogee heights at those times [m].
        steps: Accepted steps of the integrator (for benchmarks).
        rhs_evaluations: Right-hand side evaluations (for benchmarks).
    """

    revolutions: float
    time_s: float
    reentered: bool
    history_time_s: FloatArray
    history_revolutions: FloatArray
    history_perigee_m: FloatArray
    history_apogee_m: FloatArray
    steps: int
    rhs_evaluations: int


def osculating_heights_m(state: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Osculating perigee and apogee heights [m] of a flat state or a batch of them.

    From the energy E = v^2 / 2 - fM / r and the angular momentum h = |r x v|:
    p = h^2 / fM, e^2 = 1 + 2 E h^2 / fM^2, heights p / (1 +- e) - R. The apogee
    is infinite for an unbound state (e >= 1).

    Args:
        state: Array of shape (6, ...) or (7, ...): x, y, z [m], vx, vy, vz [m/s]
            along the first axis (a sigma row, if present, is ignored).
    """
    p, e = _osculating_p_e(*np.asarray(state, dtype=np.float64)[:6])
    bound = e < 1.0
    apogee_m = np.where(bound, p / np.where(bound, 1.0 - e, 1.0) - EARTH_RADIUS_M, np.inf)
    return np.asarray(p / (1.0 + e) - EARTH_RADIUS_M), apogee_m


def _osculating_p_e(x, y, z, vx, vy, vz):
    # Plain arithmetic only, so that the same code serves the event function on
    # Python floats (called once per step, where numpy calls would dominate) and
    # the history on arrays.
    hx = y * vz - z * vy
    hy = z * vx - x * vz
    hz = x * vy - y * vx
    h2 = hx * hx + hy * hy + hz * hz
    r = (x * x + y * y + z * z) ** 0.5
    energy = 0.5 * (vx * vx + vy * vy + vz * vz) - MU_EARTH_M3_S2 / r
    # e^2 = 1 + 2 E h^2 / fM^2 can round to a tiny negative for a circular orbit;
    # abs() keeps e real there (the error is ~1e-8 in e, ~0.1 m in height).
    e = abs(1.0 + 2.0 * energy * h2 / (MU_EARTH_M3_S2 * MU_EARTH_M3_S2)) ** 0.5
    return h2 / MU_EARTH_M3_S2, e


def _derivative(x, y, z, vx, vy, vz, half_c_m2_kg, rotation_rad_s, density):
    # The dynamics, written once in plain arithmetic so that it runs on Python
    # floats inside the integrator and on arrays in state_derivative().
    r2 = x * x + y * y + z * z
    r = r2**0.5
    gravity = -MU_EARTH_M3_S2 / (r2 * r)
    # Air velocity Omega x r with Omega along +z: (-Omega y, Omega x, 0).
    ux = vx + rotation_rad_s * y
    uy = vy - rotation_rad_s * x
    speed = (ux * ux + uy * uy + vz * vz) ** 0.5
    k = half_c_m2_kg * density(r - EARTH_RADIUS_M) * speed
    hx = y * vz - z * vy
    hy = z * vx - x * vz
    hz = x * vy - y * vx
    sigma_rate = (hx * hx + hy * hy + hz * hz) ** 0.5 / r2  # Eq. (2.3)
    return vx, vy, vz, gravity * x - k * ux, gravity * y - k * uy, gravity * z - k * vz, sigma_rate


def state_derivative(
    state: ArrayLike,
    drag_parameter_m2_kg: float,
    atmosphere: Atmosphere | None = None,
    rotation_rad_s: float = 0.0,
) -> FloatArray:
    """Time derivative of the flat state (x, y, z, vx, vy, vz, sigma), vectorized.

    Args:
        state: Array of shape (7, ...) in SI units.
        drag_parameter_m2_kg: c = c_x F / m of Eq. (3.2).
        atmosphere: Density model (default: the paper's).
        rotation_rad_s: Angular velocity of the air about +z (0 for still air).

    Returns:
        Array of the shape of ``state``: velocities, accelerations [m/s^2] and
        d(sigma)/dt [rad/s].
    """
    components = np.asarray(state, dtype=np.float64)[:6]
    density = as_atmosphere(atmosphere).density_kg_m3
    return np.stack(np.broadcast_arrays(*_derivative(*components, 0.5 * drag_parameter_m2_kg, rotation_rad_s, density)))


def initial_state(perigee_m: float, apogee_m: float, inclination_deg: float = 0.0) -> FloatArray:
    """Flat state at the perigee of the orbit, the perigee placed at the ascending node.

    The position is on +x and the velocity in the plane through x inclined by i
    to the equator (x-y plane), so i < 90 deg is prograde (east-going).
    """
    r_m = EARTH_RADIUS_M + perigee_m
    v_m_s = float(perigee_velocity_m_s(perigee_m, apogee_m))
    inclination_rad = math.radians(inclination_deg)
    return np.array([r_m, 0.0, 0.0, 0.0, v_m_s * math.cos(inclination_rad), v_m_s * math.sin(inclination_rad), 0.0])


def integrate_direct(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    *,
    atmosphere: Atmosphere | Callable[[FloatArray], ArrayLike] | None = None,
    rotating_atmosphere: bool = False,
    inclination_deg: float = 0.0,
    max_revolutions: float = DEFAULT_MAX_REVOLUTIONS,
    rtol: float = DEFAULT_RTOL,
    history_points: int = 500,
) -> DirectResult:
    """Integrate the non-averaged motion under drag from perigee to re-entry.

    Cost: about 30 accepted DOP853 steps per revolution at the default ``rtol``
    (some 0.1 ms each), and the step history is kept until the end (about 2 kB
    per revolution) to build the decimated history.

    Args:
        perigee_m: Initial perigee height [m] (see ``validate_heights``).
        apogee_m: Initial apogee height [m].
        drag_parameter_m2_kg: c = c_x F / m [m^2/kg], in (0, 100].
        atmosphere: Density model or a vectorized function of altitude [m]
            (default: the paper's atmosphere, Eq. 1.1).
        rotating_atmosphere: Let the air co-rotate with the Earth (section 5).
        inclination_deg: Inclination of the orbit plane to the equator, in
            [0, 180]; below 90 the motion is east-going.
        max_revolutions: Stop after this many revolutions if re-entry has not
            come first, in (0, 1e6].
        rtol: Relative tolerance of DOP853, in [1e-13, 1e-5].
        history_points: Points of the decimated history, at least 2.

    Returns:
        A `DirectResult`.

    Raises:
        ValueError: An argument is out of range (the message names it and the range).
        RuntimeError: The integrator failed.
    """
    if np.ndim(perigee_m) != 0 or np.ndim(apogee_m) != 0:
        raise ValueError(
            f"integrate_direct takes one orbit: perigee_m and apogee_m must be scalars, "
            f"got shapes {np.shape(perigee_m)} and {np.shape(apogee_m)}"
        )
    hp, ha = (float(v) for v in validate_heights(perigee_m, apogee_m))
    c_m2_kg = check_number(
        drag_parameter_m2_kg, "drag_parameter_m2_kg", unit="m^2/kg", low=0.0, high=100.0, low_inclusive=False
    )
    inclination = check_number(inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
    max_revs = check_number(max_revolutions, "max_revolutions", low=0.0, high=1e6, low_inclusive=False)
    tolerance = check_number(rtol, "rtol", low=1e-13, high=1e-5)
    history_points = check_int(history_points, "history_points", low=2)
    model = as_atmosphere(atmosphere)

    y0 = initial_state(hp, ha, inclination)
    if hp <= REENTRY_ALTITUDE_M:
        heights = osculating_heights_m(y0)
        return DirectResult(
            revolutions=0.0,
            time_s=0.0,
            reentered=True,
            history_time_s=np.zeros(1),
            history_revolutions=np.zeros(1),
            history_perigee_m=np.atleast_1d(heights[0]),
            history_apogee_m=np.atleast_1d(heights[1]),
            steps=0,
            rhs_evaluations=0,
        )

    half_c = 0.5 * c_m2_kg
    rotation = EARTH_ROTATION_RAD_S if rotating_atmosphere else 0.0
    density_kg_m3 = model.density_kg_m3

    def density(altitude_m: float) -> float:
        return float(density_kg_m3(altitude_m))

    # solve_ivp calls these with a 7-vector thousands of times per revolution:
    # tolist() once and Python float arithmetic is ~3x faster than numpy on
    # 7-element arrays (measured: 4 us against 13 us per call, of which 3 us is
    # the density model).
    def rhs(_t: float, state: FloatArray) -> FloatArray:
        x, y, z, vx, vy, vz, _ = state.tolist()
        return np.array(_derivative(x, y, z, vx, vy, vz, half_c, rotation, density))

    def reentry(_t: float, state: FloatArray) -> float:
        x, y, z, vx, vy, vz, _ = state.tolist()
        p_m, e = _osculating_p_e(x, y, z, vx, vy, vz)
        return p_m / (1.0 + e) - EARTH_RADIUS_M - REENTRY_ALTITUDE_M

    def revolution_cap(_t: float, state: FloatArray) -> float:
        return max_revs * TWO_PI - state[6]

    reentry.terminal = True  # type: ignore[attr-defined]
    reentry.direction = -1  # type: ignore[attr-defined]
    revolution_cap.terminal = True  # type: ignore[attr-defined]

    # A revolution takes about the Keplerian period, which only shrinks under
    # drag: twice the cap's worth of initial periods cannot end before the cap.
    p0_m, e0 = elements_from_heights(hp, ha)
    t_bound_s = 2.0 * (max_revs + 1.0) * float(period_s(p0_m, e0))
    from scipy.integrate import solve_ivp  # on use: half a second of start-up

    solution = solve_ivp(
        rhs,
        (0.0, t_bound_s),
        y0,
        method="DOP853",
        rtol=tolerance,
        atol=tolerance * _ATOL_PER_RTOL,
        events=(reentry, revolution_cap),
    )
    if solution.status < 0:
        raise RuntimeError(f"direct integration failed: {solution.message}")
    reentered = solution.t_events[0].size > 0

    times = solution.t
    states = solution.y
    if solution.status == 1:
        # solve_ivp ends the arrays at the event, but make the last point the
        # event state exactly whichever event fired.
        fired = 0 if reentered else 1
        times = np.append(times[:-1], solution.t_events[fired][0])
        states = np.column_stack([states[:, :-1], solution.y_events[fired][0]])
    keep = np.unique(np.linspace(0, times.size - 1, min(history_points, times.size)).round().astype(int))
    perigee_hist, apogee_hist = osculating_heights_m(states[:, keep])
    return DirectResult(
        revolutions=float(states[6, -1] / TWO_PI),
        time_s=float(times[-1]),
        reentered=bool(reentered),
        history_time_s=times[keep],
        history_revolutions=states[6, keep] / TWO_PI,
        history_perigee_m=perigee_hist,
        history_apogee_m=apogee_hist,
        steps=int(solution.t.size - 1),
        rhs_evaluations=int(solution.nfev),
    )
