"""The paper's density law (Table 1, Eq. 1.1) and the pluggable models."""

import numpy as np
import pytest

from orbit_env.physics.atmosphere import (
    RHO100_CALIBRATED_KG_M3,
    ExponentialAtmosphere,
    FunctionAtmosphere,
    PaperAtmosphere,
    as_atmosphere,
    paper_delta,
)


def test_delta_is_one_at_100_km_and_matches_table1_chi_at_band_edges():
    assert paper_delta(100e3) == pytest.approx(1.0, rel=1e-15)
    # Table 1 prints chi of the upper bands to 4 digits: the lower band's formula at
    # the edge must reproduce them to that precision (the law is continuous).
    below_150 = 1.0 / (1.0 + 50.0 / 55.0) ** 8
    below_250 = 5.667e-3 / (1.0 + 100.0 / 100.0) ** 7
    assert paper_delta(150e3) == pytest.approx(below_150, rel=5e-4)
    assert paper_delta(250e3) == pytest.approx(below_250, rel=5e-4)
    assert paper_delta(149_999.0) == pytest.approx(paper_delta(150e3), rel=5e-4)


def test_delta_decreases_with_altitude_and_extends_above_900_km():
    heights = np.linspace(100e3, 3000e3, 2000)
    delta = paper_delta(heights)
    assert np.all(np.diff(delta) < 0)
    # Above 900 km the 250-900 km band's formula continues (section 3).
    assert paper_delta(1500e3) == pytest.approx(4.428e-5 / (1 + 1250 / 215) ** 6, rel=1e-12)


def test_density_scales_with_rho100_and_scale():
    base = PaperAtmosphere().density_kg_m3(np.array([120e3, 400e3]))
    assert base[0] == pytest.approx(RHO100_CALIBRATED_KG_M3 * paper_delta(120e3), rel=1e-12)
    scaled = PaperAtmosphere(rho100_kg_m3=2e-6, scale=3.0).density_kg_m3(np.array([120e3, 400e3]))
    np.testing.assert_allclose(scaled / base, 3.0 * 2e-6 / RHO100_CALIBRATED_KG_M3, rtol=1e-12)


def test_exponential_model_and_plain_functions_plug_in():
    model = ExponentialAtmosphere(rho0_kg_m3=1.3, h0_m=0.0, scale_height_m=8.5e3)
    assert model.density_kg_m3(8.5e3) == pytest.approx(1.3 / np.e, rel=1e-12)
    wrapped = as_atmosphere(lambda h: 2.0 * np.exp(-h / 1e4))
    assert isinstance(wrapped, FunctionAtmosphere)
    assert wrapped.density_kg_m3(1e4) == pytest.approx(2.0 / np.e, rel=1e-12)
    assert isinstance(as_atmosphere(None), PaperAtmosphere)
    with pytest.raises(TypeError, match="density_kg_m3"):
        as_atmosphere(42)


#: The paper law's bounds on rho(100 km), as the error gives them.
_RHO100 = "1e-08 to 0.0001 kg/m^3 (every model and season puts 100 km between 2e-7 and 2e-6 kg/m^3)"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"rho100_kg_m3": -1.0}, f"rho100_kg_m3=-1 is out of range; allowed: {_RHO100}"),
        ({"rho100_kg_m3": float("nan")}, f"rho100_kg_m3=nan is not a finite number; allowed: {_RHO100}"),
        ({"scale": 0.0}, "scale=0 is out of range; allowed: above 0"),
    ],
)
def test_paper_atmosphere_rejects_bad_parameters(kwargs, message):
    with pytest.raises(ValueError) as info:
        PaperAtmosphere(**kwargs)
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (
            {"rho0_kg_m3": 0.0},
            "rho0_kg_m3=0 is out of range; allowed: above 0 and at most 10 kg/m^3 (air at sea level is 1.2 kg/m^3)",
        ),
        (
            {"h0_m": float("inf")},
            "h0_m=inf is not a finite number; allowed: 0 to 2000000 m "
            "(from sea level to the top of the orbits computed here)",
        ),
        (
            {"scale_height_m": -8500.0},
            "scale_height_m=-8500 is out of range; allowed: 1000 to 500000 m "
            "(the air's scale height runs from 6 km near the ground to 100 km at 1000 km)",
        ),
        ({"scale": -2.0}, "scale=-2 is out of range; allowed: above 0"),
    ],
)
def test_exponential_atmosphere_rejects_bad_parameters(kwargs, message):
    with pytest.raises(ValueError) as info:
        ExponentialAtmosphere(**kwargs)
    assert str(info.value) == message
