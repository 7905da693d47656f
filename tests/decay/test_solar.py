"""Solar activity sources: dates, the CSV reader, the smooth cycle."""

import numpy as np
import pytest

from orbit_env.decay.solar import (
    ConstantActivity,
    CycleActivity,
    centred_mean,
    day_of_year,
    iso_date,
    read_solar_csv,
    unix_days,
)


def test_dates():
    assert unix_days("1970-01-02") == 1.0
    assert unix_days("2013-11") == unix_days("2013-11-15")
    assert iso_date(unix_days("2013-11-11T00:16")) == "2013-11-11"
    assert day_of_year(unix_days("2013-01-01")) == 1.0
    assert day_of_year(unix_days("2012-12-31")) == 366.0  # leap year
    with pytest.raises(ValueError, match="2013-13-45"):
        unix_days("2013-13-45")


def test_csv_with_all_columns(tmp_path):
    path = tmp_path / "flux.csv"
    path.write_text("date,f107,f107a,ap\n2013-10-01,130,120,5\n2013-10-03,150,122,25\n")
    table = read_solar_csv(path)
    f107, f107a, ap = table.indices(np.array([unix_days("2013-10-02"), unix_days("2014-01-01")]))
    assert f107.tolist() == [140.0, 150.0]  # linear inside, last row held after the end
    assert f107a.tolist() == [121.0, 122.0]
    assert ap.tolist() == [15.0, 25.0]
    assert table.end_days - table.start_days == 2.0


def test_csv_computes_the_81_day_mean_and_default_ap(tmp_path):
    days = np.arange(200)
    rows = "\n".join(f"{iso_date(unix_days('2000-01-01') + d)},{100 + d}" for d in days)
    path = tmp_path / "flux.csv"
    path.write_text("date,f107\n" + rows + "\n")
    table = read_solar_csv(path, default_ap=7.0)
    # The centred mean of a ramp is the ramp itself, away from the ends.
    assert table.f107a_sfu[100] == pytest.approx(200.0)
    assert table.f107a_sfu[0] > table.f107_sfu[0]  # near the start the window holds the first row
    assert np.all(table.ap == 7.0)


def test_centred_mean_of_a_27_day_wave_is_flat():
    days = np.arange(0.0, 400.0)
    values = 150 + 30 * np.sin(2 * np.pi * days / 27.0)
    mean = centred_mean(days, values)
    # 81 days = 3 solar rotations: the rotation averages out.
    assert np.allclose(mean[50:-50], 150.0, atol=0.5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("day,f107\n2013-10-01,130\n", "'date' column"),
        ("date,f107\n2013-10-02,130\n2013-10-01,131\n", "increasing"),
        ("date,f107\n2013-10-01,abc\n", "line 2"),
        (
            "date,f107\n2013-10-01,130\n2013-10-02,1000\n",
            r"flux\.csv: f107=1000 on 2013-10-02 is out of range; allowed: 40 to 400 sfu$",
        ),
        ("date,f107\n", "no rows"),
    ],
)
def test_csv_errors_name_the_problem(tmp_path, text, message):
    path = tmp_path / "flux.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        read_solar_csv(path)


def test_cycle_minimum_maximum_and_period():
    cycle = CycleActivity()
    t_min = cycle.minimum_days
    f107, f107a, ap = cycle.indices(np.array([t_min, t_min + cycle.peak_phase * cycle.period_days]))
    assert f107.tolist() == pytest.approx([68.0, 150.0])
    assert f107a.tolist() == pytest.approx([68.0, 150.0])
    assert ap.tolist() == pytest.approx([6.0, 15.0])
    t = np.linspace(t_min, t_min + cycle.period_days, 1000)
    assert np.allclose(cycle.indices(t)[0], cycle.indices(t + 3 * cycle.period_days)[0])
    # Smooth across the minimum: no jump between the end of one cycle and the start of the next.
    left, right = cycle.indices(np.array([t_min - 1.0, t_min + 1.0]))[0]
    assert abs(left - right) < 0.05
    # Rises faster than it falls.
    assert cycle.peak_phase < 0.5


def test_cycle_with_phase():
    at = unix_days("2030-01-01")
    cycle = CycleActivity.with_phase(0.4, at)
    assert cycle.phase(at) == pytest.approx(0.4)
    assert cycle.indices(at)[1] == pytest.approx(150.0)
    with pytest.raises(ValueError, match=r"^phase=1\.5 is out of range; allowed: 0 to 1$"):
        CycleActivity.with_phase(1.5, at)


def test_cycle_bounds_from_other_fields_are_named():
    with pytest.raises(ValueError) as info:
        CycleActivity(f107_min_sfu=100.0, f107_max_sfu=90.0)
    assert str(info.value) == "f107_max_sfu=90 is out of range; allowed: f107_min_sfu (100) to 400 sfu"


def test_constant_activity_checks_its_range():
    with pytest.raises(ValueError) as info:
        ConstantActivity(150.0, 150.0, np.float64(500.0))
    assert str(info.value) == "ap=500 is out of range; allowed: 0 to 400"
    with pytest.raises(ValueError) as info:
        ConstantActivity(30.0, 150.0, 15.0)
    assert str(info.value) == "f107_sfu=30 is out of range; allowed: 40 to 400 sfu"
