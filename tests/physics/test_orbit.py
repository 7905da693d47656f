"""Orbit geometry: conversions, perigee burns, validation."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from orbit_env.constants import EARTH_RADIUS_M, EARTH_ROTATION_RAD_S
from orbit_env.paper.table2 import load_table2
from orbit_env.physics.orbit import (
    air_speed_at_perigee_m_s,
    apogee_after_perigee_burn_m,
    corotation_drag_factor,
    dv_for_apogee_m_s,
    elements_from_heights,
    escape_dv_m_s,
    heights_from_elements,
    perigee_velocity_m_s,
    validate_heights,
    validate_heights_km,
)

heights = st.tuples(st.floats(100e3, 2000e3), st.floats(0.0, 40000e3)).map(lambda t: (t[0], t[0] + t[1]))


@given(heights)
def test_heights_elements_round_trip(pair):
    hp, ha = pair
    p, e = elements_from_heights(hp, ha)
    assert 0.0 <= e < 1.0
    back = heights_from_elements(p, e)
    np.testing.assert_allclose(back, (hp, ha), rtol=0, atol=1e-6 * max(ha, 1.0))


def test_perigee_velocity_reproduces_table2():
    # Table II rounds v_pi to 1 m/s; a few cells are misprinted (flagged by table2),
    # so the median is the test: R = 6371 km and fM = 3.986e14 give 0.4 m/s.
    table = load_table2()
    v = perigee_velocity_m_s(table.perigee_km * 1e3, table.apogee_km * 1e3)
    assert np.median(np.abs(v - table.v_perigee_m_s)) < 1.0


def test_paper_elongated_orbit_burn_costs_78_m_s():
    # Section 4: raising 360 x 700 km to 360 x 1000 km needs "only 78 m/sec".
    dv = float(dv_for_apogee_m_s(360e3, 700e3, 1000e3))
    assert dv == pytest.approx(78.0, abs=1.0)


@given(heights, st.floats(0.0, 500.0))
def test_burn_and_dv_are_inverse(pair, dv):
    hp, ha = pair
    new_apogee = float(apogee_after_perigee_burn_m(hp, ha, dv))
    assert new_apogee >= ha - 1e-3
    if new_apogee < 45000e3:
        assert float(dv_for_apogee_m_s(hp, ha, new_apogee)) == pytest.approx(dv, abs=1e-6)


_PERIGEE_RANGE_M = "allowed: 100000 to 50000000 m (the decay ends at the re-entry height)"


@pytest.mark.parametrize(
    ("hp", "ha", "message"),
    [
        (50e3, 800e3, f"perigee_m=50000 is out of range; {_PERIGEE_RANGE_M}"),
        (500e3, 400e3, "apogee_m=400000 is out of range; allowed: perigee_m (500000) to 50000000 m"),
        (float("nan"), 400e3, f"perigee_m=nan is not a finite number; {_PERIGEE_RANGE_M}"),
        (300e3, float("inf"), "apogee_m=inf is not a finite number; allowed: perigee_m (300000) to 50000000 m"),
        (300e3, 60000e3, "apogee_m=60000000 is out of range; allowed: perigee_m (300000) to 50000000 m"),
        (
            [300e3, 400e3],
            [500e3, 350e3],
            "apogee_m[1]=350000 is out of range; allowed: perigee_m[1] (400000) to 50000000 m",
        ),
    ],
)
def test_invalid_heights_name_the_value(hp, ha, message):
    with pytest.raises(ValueError) as info:
        validate_heights(hp, ha)
    assert str(info.value) == message


def test_heights_in_km_are_checked_in_km():
    hp, ha = validate_heights_km(360.5, 800)
    assert (float(hp), float(ha)) == (360.5e3, 800e3)
    with pytest.raises(ValueError) as info:
        validate_heights_km(np.float64(50.0), 800.0)
    assert str(info.value) == (
        "perigee_km=50 is out of range; allowed: 100 to 50000 km (the decay ends at the re-entry height)"
    )
    with pytest.raises(ValueError) as info:
        validate_heights_km(400.0, 300.0)
    assert str(info.value) == "apogee_km=300 is out of range; allowed: perigee_km (400) to 50000 km"


def test_target_below_apogee_is_rejected():
    with pytest.raises(ValueError) as info:
        dv_for_apogee_m_s(300e3, 800e3, 700e3)
    assert str(info.value) == (
        "target_apogee_m=700000 is out of range; allowed: at least apogee_m (800000) m "
        "(a perigee burn only raises the apogee)"
    )
    # A target a round-off below the apogee is the apogee: no burn, no error.
    assert float(dv_for_apogee_m_s(300e3, 800e3, 800e3 - 1e-4)) == 0.0


def test_a_burn_to_escape_has_an_unbounded_apogee():
    escape = float(escape_dv_m_s(300e3, 500e3))
    assert apogee_after_perigee_burn_m(300e3, 500e3, escape * 0.999) < 1e11  # still bound: 1.2e10 m
    assert apogee_after_perigee_burn_m(300e3, 500e3, escape * 1.001) > 1e299  # not the old apogee


@pytest.mark.parametrize("inclination_deg", [0.0, 28.5, 51.6, 97.5, 180.0])
def test_the_air_along_the_track_is_omega_r_cos_i_at_every_latitude(inclination_deg):
    """v_pi - Omega r cos i is the along-track speed through co-rotating air, wherever the perigee lies.

    Independently, with vectors: a circular orbit of inclination i, the satellite at argument of
    latitude u; the air's velocity Omega z x r; the relative velocity projected on the track.
    Exact up to rounding (1e-9 m/s).
    """
    h = 400e3
    r = EARTH_RADIUS_M + h
    v = float(perigee_velocity_m_s(h, h))
    i = np.radians(inclination_deg)
    for u in np.linspace(0.0, 2.0 * np.pi, 13):
        position = r * np.array([np.cos(u), np.sin(u) * np.cos(i), np.sin(u) * np.sin(i)])
        along = np.array([-np.sin(u), np.cos(u) * np.cos(i), np.cos(u) * np.sin(i)])
        air = np.cross([0.0, 0.0, EARTH_ROTATION_RAD_S], position)
        relative_along = float(np.dot(v * along - air, along))
        assert float(air_speed_at_perigee_m_s(h, h, inclination_deg)) == pytest.approx(relative_along, abs=1e-9)
    assert float(corotation_drag_factor(h, h, inclination_deg)) == pytest.approx((relative_along / v) ** 2, rel=1e-12)
