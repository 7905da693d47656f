"""The public boundary's validation helper: messages name the value as given and the allowed range."""

from __future__ import annotations

import math

import numpy as np
import pytest

from orbit_env.checks import InputError, check_array, check_int, check_number, format_number


def _message(call, *args, **kwargs) -> str:
    with pytest.raises(InputError) as info:
        call(*args, **kwargs)
    assert isinstance(info.value, ValueError)
    return str(info.value)


def test_valid_numbers_come_back_as_plain_floats():
    value = check_number(np.float64(400.5), "perigee_km", unit="km", low=100, high=50_000)
    assert type(value) is float and value == 400.5
    assert check_number(100, "perigee_km", low=100, high=50_000) == 100.0  # inclusive bounds
    assert check_number(50_000, "perigee_km", low=100, high=50_000) == 50_000.0
    assert check_number(np.array(3.0), "x") == 3.0  # a 0-d array is a number


def test_out_of_range_names_the_parameter_value_and_range():
    text = _message(check_number, 50, "perigee_km", unit="km", low=100, high=50_000)
    assert text == "perigee_km=50 is out of range; allowed: 100 to 50000 km"


def test_numpy_values_are_shown_as_plain_numbers():
    text = _message(check_number, np.float64(-150.0), "inclination_deg", unit="deg", low=0, high=180)
    assert text == "inclination_deg=-150 is out of range; allowed: 0 to 180 deg"
    assert "np." not in text and "float64" not in text


def test_exclusive_bounds_are_said_in_words():
    assert _message(check_number, 0, "mass_kg", unit="kg", low=0, low_inclusive=False) == (
        "mass_kg=0 is out of range; allowed: above 0 kg"
    )
    assert _message(check_number, 1.0, "e", low=0, high=1, high_inclusive=False) == (
        "e=1 is out of range; allowed: at least 0 and below 1"
    )
    assert _message(check_number, 200, "f107_sfu", unit="sfu", high=180, high_inclusive=True) == (
        "f107_sfu=200 is out of range; allowed: at most 180 sfu"
    )


def test_the_reason_follows_the_range():
    text = _message(check_number, 95.5, "perigee_km", unit="km", low=100, why="re-entry at 100 km")
    assert text == "perigee_km=95.5 is out of range; allowed: at least 100 km (re-entry at 100 km)"


@pytest.mark.parametrize(
    ("value", "shown"), [(math.nan, "nan"), (math.inf, "inf"), (-math.inf, "-inf"), (np.float64("nan"), "nan")]
)
def test_nan_and_infinities_are_refused_even_without_bounds(value, shown):
    assert _message(check_number, value, "h0_km") == f"h0_km={shown} is not a finite number; allowed: a finite number"
    assert _message(check_number, value, "rho0_kg_m3", unit="kg/m^3", low=0, low_inclusive=False) == (
        f"rho0_kg_m3={shown} is not a finite number; allowed: above 0 kg/m^3"
    )


@pytest.mark.parametrize(
    ("value", "kind"),
    [(True, "a bool"), (np.bool_(False), "a bool"), (None, "None"), (1j, "complex"), ([400], "list")],
)
def test_non_numbers_are_refused_by_type(value, kind):
    assert f"is not a number (got {kind})" in _message(check_number, value, "perigee_km", unit="km", low=100)


def test_text_is_not_a_number_and_is_shown_quoted():
    assert _message(check_number, "400", "perigee_km", unit="km", low=100) == (
        "perigee_km='400' is not a number; allowed: at least 100 km"
    )


def test_counts_must_be_whole():
    assert check_int(4.0, "history_points", low=2) == 4
    assert type(check_int(np.int64(4), "history_points", low=2)) is int
    assert _message(check_int, 2.5, "history_points", low=2) == (
        "history_points=2.5 is not an integer; allowed: an integer at least 2"
    )
    assert _message(check_int, 1, "history_points", low=2) == (
        "history_points=1 is out of range; allowed: an integer at least 2"
    )


def test_arrays_report_the_first_bad_element_and_its_index():
    values = check_array([200.0, 300.0], "perigee_km", unit="km", low=100)
    assert values.dtype == np.float64 and values.tolist() == [200.0, 300.0]
    assert _message(check_array, [200.0, 50.0, 20.0], "perigee_km", unit="km", low=100) == (
        "perigee_km[1]=50 is out of range; allowed: at least 100 km"
    )
    assert _message(check_array, [[1.0, 2.0], [3.0, np.inf]], "h_km") == (
        "h_km[1, 1]=inf is not a finite number; allowed: a finite number"
    )
    # A scalar has no index to report.
    assert _message(check_array, 50.0, "perigee_km", low=100) == "perigee_km=50 is out of range; allowed: at least 100"
    assert "is not a number" in _message(check_array, ["a"], "perigee_km")


def test_a_bound_from_another_parameter_is_named_with_its_value():
    text = _message(
        check_array, [500.0, 300.0], "apogee_km", unit="km", low=[400.0, 400.0], low_name="perigee_km", high=50_000
    )
    assert text == "apogee_km[1]=300 is out of range; allowed: perigee_km[1] (400) to 50000 km"


def test_a_front_end_re_renders_in_its_own_words_and_units():
    with pytest.raises(InputError) as info:
        check_number(-8500.0, "scale_height_m", unit="m", low=0, low_inclusive=False)
    error = info.value
    assert (error.name, error.value, error.unit, error.low) == ("scale_height_m", -8500.0, "m", 0)
    assert error.message("--scale-height-km", value_text="-8.5", scale=1e-3, unit="km") == (
        "--scale-height-km -8.5 is out of range; allowed: above 0 km"
    )
    with pytest.raises(InputError) as info:
        check_number(300e3, "apogee_m", unit="m", low=400e3, low_name="perigee_m", high=50_000e3)
    assert info.value.message("--apogee", scale=1e-3, unit="km", rename={"perigee_m": "--perigee"}.get) == (
        "--apogee 300 is out of range; allowed: --perigee (400) to 50000 km"
    )


@pytest.mark.parametrize(
    ("value", "text"), [(50, "50"), (50.0, "50"), (-8.5, "-8.5"), (1e300, "1e+300"), (np.float64(0.1), "0.1")]
)
def test_format_number_is_plain(value, text):
    assert format_number(value) == text
