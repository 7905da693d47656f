"""Orbit-averaged decay under drag: the secular equations of the paper's section 3.

SI units inside (m, kg, s). The independent variable is the paper's nu = N g c
(Eq. 4.1), with N the revolution count, c = c_x F / m the drag parameter
[m^2/kg] and g = 9.81 m/s^2: nu is in m^3/(kg s^2) and is the same for every
satellite. A density multiplier s enters the same way: nu = N g c s.

Derivation (the transcription prints Eqs. 3.5 and 3.13 with errors, so they are
derived here from the Gauss equations (2.1)). With the true anomaly theta as the
variable of the unperturbed motion, r^2 dtheta = sqrt(fM p) dt (Eq. 2.12, exact to
first order), and the drag components of Eq. (3.2)-(3.3) relative to an air
mass that may co-rotate with the Earth (transverse air speed w = Omega r cos i,
section 5),

    S = -(c/2) rho |v_rel| v_r,      T = -(c/2) rho |v_rel| (v_n - w),
    v_r = sqrt(fM/p) e sin(theta),   v_n = sqrt(fM/p) (1 + e cos(theta)),

the Gauss equations give per revolution

    dp/dN = -c/fM   * Int_0^2pi r^3 rho |v_rel| (v_n - w) dtheta
    de/dN = -c/2fM  * Int_0^2pi r^2 rho |v_rel| [sin(theta) v_r
                     + ((1 + r/p) cos(theta) + e r/p) (v_n - w)] dtheta.

For a still atmosphere (w = 0) these reduce to

    dp/dN = -c Int p^2 rho xi / (1 + e cos)^2 dtheta,
    de/dN = -c Int p rho xi (e + cos) / (1 + e cos)^2 dtheta,   xi = sqrt(1 + 2e cos + e^2),

i.e. Eq. (3.10) with phi = p^2 Delta xi / (1 + e cos)^2 (the transcription has p^3)
and psi = p Delta xi (e + cos) / (1 + e cos)^2 (the transcription drops e + cos;
the zeta integrand of Eq. 3.13 has it). Dividing by dnu/dN = g c gives rates per
unit nu that contain no satellite parameter: the paper's universal curves.

The orbit average is the trapezoidal rule over ``QUADRATURE_POINTS`` equally
spaced anomalies. The integrands are smooth and periodic, so the rule converges
geometrically; with 64 points its relative error is below 3e-4 everywhere in the
domain of the universal curves (the density law has kinks at 150 and 250 km,
which make the rule second order there), measured in
``tests/decay/test_decay.py`` against 1024 points.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_int, check_number
from orbit_env.constants import (
    EARTH_RADIUS_M,
    EARTH_ROTATION_RAD_S,
    G0_M_S2,
    MU_EARTH_M3_S2,
    REENTRY_ALTITUDE_M,
)
from orbit_env.physics.atmosphere import Atmosphere, PaperAtmosphere
from orbit_env.physics.orbit import elements_from_heights, heights_from_elements, period_s

FloatArray = NDArray[np.float64]

#: Anomalies in the trapezoidal orbit average (see the module docstring).
QUADRATURE_POINTS = 64


@dataclass(frozen=True)
class DecayModel:
    """What the averaged decay depends on, apart from the satellite.

    Args:
        atmosphere: Density model (any object with ``density_kg_m3(altitude_m)``).
        rotating_atmosphere: Let the air co-rotate with the Earth (section 5).
            Then the inclination matters: a prograde (east-going) orbit meets a
            slower wind and lives longer than a retrograde one.
        inclination_deg: Orbit inclination, used only with a rotating atmosphere; in still air it is
            held at 0, so that the models of one profile are one model (one curve family in the
            caches, whatever inclination a catalogue's rows give).
        quadrature_points: Anomalies in the orbit average.
    """

    atmosphere: Atmosphere = field(default_factory=PaperAtmosphere)
    rotating_atmosphere: bool = False
    inclination_deg: float = 0.0
    quadrature_points: int = QUADRATURE_POINTS

    def __post_init__(self) -> None:
        check_number(self.inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
        check_int(self.quadrature_points, "quadrature_points", low=8)
        if not self.rotating_atmosphere:
            object.__setattr__(self, "inclination_deg", 0.0)

    @property
    def corotation_rad_s(self) -> float:
        """Omega cos(i): the air's transverse speed divided by the radius [rad/s]."""
        if not self.rotating_atmosphere:
            return 0.0
        return EARTH_ROTATION_RAD_S * float(np.cos(np.radians(self.inclination_deg)))

    @cached_property
    def _cos_sin(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The anomalies of the rule from 0 to pi, and their weights.

        Both integrands are even in theta (r and the speed depend on cos(theta); sin(theta)
        enters squared), so the 2n-point rule over the circle is the rule over the half circle
        with the inner points counted twice: the same sum in half the evaluations (an odd
        n keeps its full circle).
        """
        n = self.quadrature_points
        theta = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        if n % 2:
            return np.cos(theta), np.sin(theta), np.full(n, 1.0 / n)
        half = theta[: n // 2 + 1]
        weights = np.full(half.size, 2.0 / n)
        weights[[0, -1]] = 1.0 / n
        return np.cos(half), np.sin(half), weights

    def drag_kernels(self, p_m: ArrayLike, e: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The heights [m] at the rule's anomalies and the kernels K_p, K_e of the orbit-averaged rates.

        dp/dnu = sum(K_p rho(h)) and de/dnu = sum(K_e rho(h)) over the last axis, for any
        density rho at those heights (`rates_per_nu` with this model's air). The kernels hold
        the geometry, the air's speed, the rule's weights and the constants, so callers
        that weigh one orbit under several densities compute them once. Shapes: those of
        ``p_m`` and ``e`` broadcast, with the anomalies last.
        """
        geometry = self._kernel_geometry(p_m, e)
        k_p, k_e = _kernels_in_air(geometry, self.corotation_rad_s)
        return geometry[0] - EARTH_RADIUS_M, k_p, k_e

    def drag_kernels_in_air(
        self, p_m: ArrayLike, e: ArrayLike, air_rad_s: Sequence[float]
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """`drag_kernels` in air turning at each of ``air_rad_s`` (Omega cos i) instead of the model's.

        The kernels gain a leading axis, one entry per air speed; the geometry is shared.
        """
        geometry = self._kernel_geometry(p_m, e)
        kernels = [_kernels_in_air(geometry, air) for air in air_rad_s]
        k_p, k_e = (np.stack(k) for k in zip(*kernels, strict=True))
        return geometry[0] - EARTH_RADIUS_M, k_p, k_e

    def _kernel_geometry(self, p_m: ArrayLike, e: ArrayLike) -> tuple[FloatArray, ...]:
        """What the kernels share across air speeds: r, v_r^2, v_r sin, the still-air v_n, the arm of de, drag r^2."""
        p = np.asarray(p_m, dtype=np.float64)[..., None]
        ecc = np.asarray(e, dtype=np.float64)[..., None]
        cos, sin, weights = self._cos_sin
        k = 1.0 + ecc * cos
        r = p / k
        v_scale = np.sqrt(MU_EARTH_M3_S2 / p)
        v_r = (v_scale * ecc) * sin
        e_arm = cos + (cos + ecc) / k  # (1 + 1/k) cos + e/k
        # Int_0^2pi = 2 pi * mean; the minus sign is drag; 1/g turns dN into dnu/(c).
        drag_r2 = ((-2.0 * np.pi / (G0_M_S2 * MU_EARTH_M3_S2)) * weights) * (r * r)
        return r, v_r * v_r, v_r * sin, v_scale * k, e_arm, drag_r2

    def rates_per_nu(self, p_m: ArrayLike, e: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Orbit-averaged dp/dnu [m / (m^3 kg^-1 s^-2)] and de/dnu, both negative.

        Broadcasts over the shapes of ``p_m`` and ``e``.
        """
        height_m, k_p, k_e = self.drag_kernels(p_m, e)
        return kernel_rates(k_p, k_e, self.atmosphere.density_kg_m3(height_m))


def kernel_rates(k_p: FloatArray, k_e: FloatArray, rho_kg_m3: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """dp/dnu and de/dnu from `DecayModel.drag_kernels` and the density at its heights (broadcasting)."""
    return np.einsum("...j,...j->...", k_p, rho_kg_m3), np.einsum("...j,...j->...", k_e, rho_kg_m3)


def _kernels_in_air(geometry: tuple[FloatArray, ...], air_rad_s: float) -> tuple[FloatArray, FloatArray]:
    """K_p and K_e of `DecayModel.drag_kernels` from its shared geometry, in air turning at ``air_rad_s``."""
    r, v_r_squared, v_r_sin, v_n, e_arm, drag_r2 = geometry
    v_n_rel = v_n - air_rad_s * r if air_rad_s else v_n  # the transverse speed through the air
    drag = drag_r2 * np.sqrt(v_r_squared + v_n_rel * v_n_rel)
    return drag * r * v_n_rel, 0.5 * drag * (v_r_sin + e_arm * v_n_rel)


@dataclass(frozen=True)
class Trajectory:
    """A decay history, from the start (index 0) to re-entry (last index).

    All arrays have the same length. ``nu`` is the universal variable elapsed since
    the start [m^3/(kg s^2)]; ``weighted_s`` is W = Int P dnu, so the elapsed time is
    W / (g c s) [s] for a satellite with drag parameter c and density multiplier s.
    """

    nu: FloatArray
    weighted_s: FloatArray
    perigee_m: FloatArray
    apogee_m: FloatArray
    eccentricity: FloatArray


def integrate_averaged(
    perigee_m: float,
    apogee_m: float,
    model: DecayModel | None = None,
    *,
    samples: int = 200,
    rtol: float = 1e-9,
) -> Trajectory:
    """Integrate the averaged equations from an orbit to re-entry (perigee 100 km).

    The parameter p falls monotonically under drag, so it is the independent
    variable (as in the paper's Eq. 3.12); the state is (e, nu, W). The reference
    solution for the universal curves and the direct integration's partner.

    Args:
        perigee_m: Initial perigee height [m] (valid: see ``validate_heights``).
        apogee_m: Initial apogee height [m].
        model: Decay model (default: the paper's atmosphere, still air).
        samples: Points of the returned trajectory, evenly spaced in p.
        rtol: Relative tolerance of the ODE solver.
    """
    model = model or DecayModel()
    p0, e0 = (float(x) for x in elements_from_heights(perigee_m, apogee_m))

    def rhs(p: float, state: FloatArray) -> list[float]:
        e = max(state[0], 0.0)
        dp_dnu, de_dnu = model.rates_per_nu(p, e)
        dnu_dp = 1.0 / float(dp_dnu)
        # dW/dnu is the Keplerian period: time = W / (g c s) for any satellite.
        return [float(de_dnu) * dnu_dp, dnu_dp, float(period_s(p, e)) * dnu_dp]

    def reentry(p: float, state: FloatArray) -> float:
        return p / (1.0 + max(state[0], 0.0)) - EARTH_RADIUS_M - REENTRY_ALTITUDE_M

    reentry.terminal = True  # type: ignore[attr-defined]
    p_end_bound = EARTH_RADIUS_M + REENTRY_ALTITUDE_M - 1.0
    if perigee_m <= REENTRY_ALTITUDE_M:
        p_grid = np.array([p0])
        states = np.array([[e0], [0.0], [0.0]])
    else:
        from scipy.integrate import solve_ivp  # on use: half a second of start-up

        solution = solve_ivp(
            rhs,
            (p0, p_end_bound),
            [e0, 0.0, 0.0],
            method="DOP853",
            events=reentry,
            dense_output=True,
            rtol=rtol,
            atol=[1e-13, 1e-12, 1e-8],
        )
        if solution.status != 1:  # reachable from valid inputs (an orbit drag hardly touches): a user's error
            raise ValueError(
                f"the averaged equations could not follow this decay to re-entry ({solution.message.rstrip('.')}): "
                "drag hardly touches this orbit"
            )
        p_end = float(solution.t_events[0][0])
        p_grid = np.linspace(p0, p_end, samples)
        states = solution.sol(p_grid)
        states[:, -1] = solution.y_events[0][0]
    e = np.maximum(states[0], 0.0)
    hp, ha = heights_from_elements(p_grid, e)
    return Trajectory(
        nu=np.maximum(states[1], 0.0),
        weighted_s=np.maximum(states[2], 0.0),
        perigee_m=hp,
        apogee_m=ha,
        eccentricity=e,
    )
