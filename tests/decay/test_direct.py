"""Direct (non-averaged) integration against the averaged theory: paper section 5.

The satellite is the paper's example of section 4: a sphere of diameter 0.5 m and
weight 10 kg with c_x = 2, so c = c_x F / m = 2 pi 0.25^2 / 10 = 0.0393 m^2/kg
(the paper's factor 1/(g c) = 2.6 revolutions per unit of nu). Its lifetimes from
perigees of 180-300 km are 40-300 revolutions, so the direct integration takes
well under a second per orbit (about 30 DOP853 steps per revolution). For the
higher orbits of Table II the drag parameter is raised instead (nu = N g c holds
for any c), which keeps those cases short too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from orbit_env.constants import EARTH_RADIUS_M, EARTH_ROTATION_RAD_S, G0_M_S2, MU_EARTH_M3_S2, REENTRY_ALTITUDE_M
from orbit_env.decay.averaged import DecayModel, integrate_averaged
from orbit_env.decay.direct import initial_state, integrate_direct, osculating_heights_m, state_derivative
from orbit_env.physics.atmosphere import ExponentialAtmosphere, PaperAtmosphere
from orbit_env.physics.orbit import elements_from_heights, period_s

SPHERE_C_M2_KG = 2.0 * math.pi * 0.25**2 / 10.0
KM = 1e3

#: The issue's requirement, and the paper's section 5 claim that averaging is
#: accurate. Measured disagreements are 0.01-0.4% (docs/validation.md); the
#: direct integration always runs 0.1-0.3 revolution longer, from the last,
#: strongly braked revolution, which the averaged equations cannot resolve.
AVERAGING_TOLERANCE = 0.03


def averaged_lifetime(perigee_m, apogee_m, c_m2_kg, model=None):
    """Revolutions N = nu / (g c) and time t = W / (g c) of the averaged model."""
    trajectory = integrate_averaged(perigee_m, apogee_m, model or DecayModel())
    return trajectory.nu[-1] / (G0_M_S2 * c_m2_kg), trajectory.weighted_s[-1] / (G0_M_S2 * c_m2_kg)


# (perigee km, apogee km, drag parameter, atmosphere): lifetimes of 39 to 291 revolutions.
ORBITS = {
    "near-circular 250x260": (250, 260, SPHERE_C_M2_KG, None),
    "near-circular 300x310": (300, 310, SPHERE_C_M2_KG, None),
    "paper example 200x400": (200, 400, SPHERE_C_M2_KG, None),
    "elongated 180x600": (180, 600, SPHERE_C_M2_KG, None),
    "elongated 200x1000": (200, 1000, SPHERE_C_M2_KG, None),
    # Table II's worked example 360x800 (nu = 2760) with a 50x lighter satellite.
    "table II 360x800, c x50": (360, 800, 50 * SPHERE_C_M2_KG, None),
    # Any atmosphere object works on both sides: a single exponential layer.
    "exponential 200x400": (200, 400, SPHERE_C_M2_KG, ExponentialAtmosphere(2.5e-10, 200e3, 40e3)),
}

SLOW_ORBITS = {
    "elongated 200x1500": (200, 1500, SPHERE_C_M2_KG, None),
    "elongated 220x2000": (220, 2000, SPHERE_C_M2_KG, None),
    "table II 500x1500, c x1000": (500, 1500, 1000 * SPHERE_C_M2_KG, None),
    "elongated 300x3000, c x5": (300, 3000, 5 * SPHERE_C_M2_KG, None),
}


def _check_against_averaged(perigee_km, apogee_km, c_m2_kg, atmosphere):
    model = DecayModel(atmosphere=atmosphere or PaperAtmosphere())
    n_avg, t_avg = averaged_lifetime(perigee_km * KM, apogee_km * KM, c_m2_kg, model)
    direct = integrate_direct(perigee_km * KM, apogee_km * KM, c_m2_kg, atmosphere=atmosphere)
    assert direct.reentered
    assert direct.revolutions == pytest.approx(n_avg, rel=AVERAGING_TOLERANCE)
    assert direct.time_s == pytest.approx(t_avg, rel=AVERAGING_TOLERANCE)
    # Sharper, and independent of the lifetime: averaging errs only in the final
    # revolution (measured 0.06-0.29 revolution from 4 to 5000 revolutions).
    assert abs(direct.revolutions - n_avg) < 0.5


@pytest.mark.parametrize("orbit", ORBITS.values(), ids=ORBITS.keys())
def test_averaged_lifetime_matches_direct_integration(orbit):
    _check_against_averaged(*orbit)


@pytest.mark.slow
@pytest.mark.parametrize("orbit", SLOW_ORBITS.values(), ids=SLOW_ORBITS.keys())
def test_averaged_lifetime_matches_direct_integration_long(orbit):
    _check_against_averaged(*orbit)


def test_paper_example_200x400_revolutions():
    # Section 4: h_pi = 200 km, h_a = 400 km gives nu = 16.8 and N ~ 44 for the
    # sphere (factor 2.6). The tolerance is the paper's own: its Euler steps cost
    # "2-5%" in the lifetime (section 3); the density rho1 is our calibration.
    direct = integrate_direct(200 * KM, 400 * KM, SPHERE_C_M2_KG)
    assert direct.revolutions * G0_M_S2 * SPHERE_C_M2_KG == pytest.approx(16.8, rel=0.05)


# --- rotating atmosphere (section 5) ---------------------------------------------------

ROTATION_ORBITS = [(250, 260), (200, 400), (200, 1000)]


def _averaged_nu(perigee_km, apogee_km, **model):
    return integrate_averaged(perigee_km * KM, apogee_km * KM, DecayModel(**model)).nu[-1]


@pytest.mark.parametrize(("perigee_km", "apogee_km"), ROTATION_ORBITS)
def test_rotating_air_lengthens_eastward_and_shortens_westward_life(perigee_km, apogee_km):
    still = _averaged_nu(perigee_km, apogee_km)
    east = _averaged_nu(perigee_km, apogee_km, rotating_atmosphere=True, inclination_deg=0.0) / still
    west = _averaged_nu(perigee_km, apogee_km, rotating_atmosphere=True, inclination_deg=180.0) / still
    # Section 5: east-going satellites live longer, west-going shorter, by "not
    # more than 10-12%". That figure is first order in x = Omega r / v (2x = 0.123
    # at 200 km), and the lower end (10%) keeps the test from passing with the
    # rotation ignored. The westward shortening, 1 - 1/(1+x)^2 = 11.2%, meets the
    # 12%; the eastward lengthening is 1/(1-x)^2 - 1 = 13.4-13.7% (measured, and
    # confirmed by the direct integration below), above the paper's rounded
    # first-order figure, so its bound is 14%.
    assert 1.10 <= east <= 1.14
    assert 0.88 <= west <= 0.90


def test_rotating_air_effect_is_the_dynamic_pressure_change():
    # For a near-circular orbit the drag scales with the relative dynamic pressure
    # (v -+ Omega r cos i)^2, so the lifetime scales by (1 -+ x)^-2 with x the
    # value at the orbit (it varies by 2% over the decay, hence 0.5%).
    perigee_km, apogee_km = 250, 260
    r_m = EARTH_RADIUS_M + 0.5 * (perigee_km + apogee_km) * KM
    x = EARTH_ROTATION_RAD_S * r_m / math.sqrt(MU_EARTH_M3_S2 / r_m)
    still = _averaged_nu(perigee_km, apogee_km)
    for inclination_deg in (0.0, 45.0, 135.0, 180.0):
        x_i = x * math.cos(math.radians(inclination_deg))
        ratio = _averaged_nu(perigee_km, apogee_km, rotating_atmosphere=True, inclination_deg=inclination_deg) / still
        assert ratio == pytest.approx((1.0 - x_i) ** -2, rel=0.005)


def test_polar_orbit_is_unaffected_by_rotating_air():
    # Section 5: "For a polar orbit the difference will be zero." The averaged
    # model keeps only the in-plane wind Omega r cos i, zero at i = 90; the direct
    # integration keeps the out-of-plane wind Omega r cos u too, which raises
    # |v_rel| by at most x^2/2 = 0.2% (second order): measured -0.14% in lifetime.
    still_nu = _averaged_nu(200, 400)
    polar_nu = _averaged_nu(200, 400, rotating_atmosphere=True, inclination_deg=90.0)
    assert polar_nu == pytest.approx(still_nu, rel=0.005)
    still = integrate_direct(200 * KM, 400 * KM, SPHERE_C_M2_KG)
    polar = integrate_direct(200 * KM, 400 * KM, SPHERE_C_M2_KG, rotating_atmosphere=True, inclination_deg=90.0)
    assert polar.revolutions == pytest.approx(still.revolutions, rel=0.005)
    assert polar.revolutions < still.revolutions  # the extra wind only adds drag


@pytest.mark.parametrize("inclination_deg", [0.0, 180.0])
def test_rotating_air_averaged_matches_direct(inclination_deg):
    # The equatorial case is exact for the averaged model's wind (all in-plane).
    model = DecayModel(rotating_atmosphere=True, inclination_deg=inclination_deg)
    n_avg, t_avg = averaged_lifetime(200 * KM, 400 * KM, SPHERE_C_M2_KG, model)
    direct = integrate_direct(
        200 * KM, 400 * KM, SPHERE_C_M2_KG, rotating_atmosphere=True, inclination_deg=inclination_deg
    )
    assert direct.revolutions == pytest.approx(n_avg, rel=AVERAGING_TOLERANCE)
    assert direct.time_s == pytest.approx(t_avg, rel=AVERAGING_TOLERANCE)


# --- the building blocks -------------------------------------------------------------


@pytest.mark.parametrize("inclination_deg", [0.0, 51.6, 90.0, 180.0])
def test_initial_state_has_the_requested_heights(inclination_deg):
    perigee, apogee = osculating_heights_m(initial_state(210 * KM, 1700 * KM, inclination_deg))
    # Relative 1e-9 of the radius: a few mm, far below anything physical.
    assert float(perigee) == pytest.approx(210 * KM, abs=1e-9 * EARTH_RADIUS_M)
    assert float(apogee) == pytest.approx(1700 * KM, abs=1e-9 * EARTH_RADIUS_M)
    state = initial_state(210 * KM, 1700 * KM, inclination_deg)
    angular_momentum = np.cross(state[:3], state[3:6])
    cos_i = angular_momentum[2] / np.linalg.norm(angular_momentum)
    assert cos_i == pytest.approx(math.cos(math.radians(inclination_deg)), abs=1e-12)


def test_osculating_heights_broadcast_over_a_batch():
    batch = np.column_stack([initial_state(h * KM, 800 * KM) for h in (150, 300, 450)])
    perigee, apogee = osculating_heights_m(batch)
    assert perigee.shape == apogee.shape == (3,)
    np.testing.assert_allclose(perigee, [150 * KM, 300 * KM, 450 * KM], atol=0.01)
    np.testing.assert_allclose(apogee, 800 * KM, atol=0.01)
    unbound = initial_state(300 * KM, 800 * KM)
    unbound[3:6] *= 1.5  # above escape speed
    assert np.isinf(osculating_heights_m(unbound)[1])


def test_state_derivative_dissipates_energy_at_the_drag_power():
    # d/dt (v^2/2 - fM/r) = -(c/2) rho |v_rel| (v . v_rel): the drag power, exactly.
    # Any state will do: random directions at 150-900 km, random velocities.
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(3, 4))
    positions = directions / np.linalg.norm(directions, axis=0) * (EARTH_RADIUS_M + np.array([150, 220, 400, 900]) * KM)
    states = np.vstack([positions, rng.normal(0.0, 5e3, size=(3, 4)), np.zeros((1, 4))])
    rho = PaperAtmosphere().density_kg_m3(np.linalg.norm(positions, axis=0) - EARTH_RADIUS_M)
    for rotation in (0.0, EARTH_ROTATION_RAD_S):
        deriv = state_derivative(states, 0.05, rotation_rad_s=rotation)
        r, v, a = states[:3], states[3:6], deriv[3:6]
        r_norm = np.linalg.norm(r, axis=0)
        energy_rate = np.sum(v * a, axis=0) + MU_EARTH_M3_S2 * np.sum(r * v, axis=0) / r_norm**3
        v_rel = v - np.cross([0.0, 0.0, rotation], r, axis=0)
        drag_power = -0.025 * rho * np.linalg.norm(v_rel, axis=0) * np.sum(v * v_rel, axis=0)
        np.testing.assert_allclose(energy_rate, drag_power, rtol=1e-6)
        np.testing.assert_allclose(deriv[6], np.linalg.norm(np.cross(r, v, axis=0), axis=0) / r_norm**2)
        # The batch gives the same numbers as one column at a time.
        np.testing.assert_allclose(deriv[:, 1], state_derivative(states[:, 1], 0.05, rotation_rad_s=rotation))


def test_revolution_count_and_time_without_appreciable_drag():
    # c = 1e-12 m^2/kg: the orbit is Keplerian for 3 revolutions, so the cap stops
    # the run at exactly 3 revolutions after 3 Keplerian periods (the event time
    # is found to the integrator's tolerance, 1e-10 relative; 1e-8 leaves margin).
    perigee_m, apogee_m = 400 * KM, 3000 * KM
    result = integrate_direct(perigee_m, apogee_m, 1e-12, max_revolutions=3)
    assert not result.reentered
    assert result.revolutions == pytest.approx(3.0, rel=1e-8)
    assert result.time_s == pytest.approx(3.0 * float(period_s(*elements_from_heights(perigee_m, apogee_m))), rel=1e-8)
    np.testing.assert_allclose(result.history_perigee_m, perigee_m, atol=0.01)
    np.testing.assert_allclose(result.history_apogee_m, apogee_m, atol=0.01)


def test_history_runs_from_start_to_reentry():
    result = integrate_direct(200 * KM, 600 * KM, SPHERE_C_M2_KG, history_points=50)
    assert 2 <= result.history_time_s.size <= 50
    assert result.history_time_s[0] == 0.0
    assert result.history_time_s[-1] == result.time_s
    assert result.history_revolutions[-1] == pytest.approx(result.revolutions)
    assert np.all(np.diff(result.history_time_s) > 0.0)
    assert result.history_perigee_m[0] == pytest.approx(200 * KM, abs=0.01)
    assert result.history_apogee_m[0] == pytest.approx(600 * KM, abs=0.01)
    assert result.history_perigee_m[-1] == pytest.approx(REENTRY_ALTITUDE_M, abs=1.0)
    assert np.all(result.history_apogee_m >= result.history_perigee_m)
    assert result.steps > 0 and result.rhs_evaluations > result.steps


def test_perigee_at_reentry_height_gives_zero_life():
    result = integrate_direct(REENTRY_ALTITUDE_M, 300 * KM, SPHERE_C_M2_KG)
    assert result.reentered
    assert result.revolutions == 0.0
    assert result.time_s == 0.0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"perigee_m": 90 * KM}, "perigee"),
        ({"perigee_m": float("nan")}, "perigee"),
        ({"apogee_m": 150 * KM}, "apogee"),
        ({"perigee_m": np.array([200 * KM, 300 * KM])}, "perigee_m"),
        ({"drag_parameter_m2_kg": 0.0}, "drag_parameter_m2_kg"),
        ({"drag_parameter_m2_kg": -1.0}, "drag_parameter_m2_kg"),
        ({"inclination_deg": 181.0}, "inclination_deg"),
        ({"inclination_deg": -1.0}, "inclination_deg"),
        ({"max_revolutions": 0.0}, "max_revolutions"),
        ({"max_revolutions": float("inf")}, "max_revolutions"),
        ({"rtol": 1e-2}, "rtol"),
        ({"history_points": 1}, "history_points"),
    ],
)
def test_invalid_input_is_rejected_with_its_name(kwargs, name):
    arguments = {"perigee_m": 200 * KM, "apogee_m": 400 * KM, "drag_parameter_m2_kg": SPHERE_C_M2_KG} | kwargs
    positional = [arguments.pop(key) for key in ("perigee_m", "apogee_m", "drag_parameter_m2_kg")]
    with pytest.raises(ValueError, match=name):
        integrate_direct(*positional, **arguments)
