"""The Python API as an analyst meets it: bad inputs refused with their names, a table's edge said, results compared."""

from __future__ import annotations

import pickle
import warnings
from pathlib import Path

import numpy as np
import pytest

import orbit_env
from orbit_env import Satellite
from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.scenario import Scenario
from orbit_env.analysis.uncertainty import lifetime_spread
from orbit_env.decay.solar import ConstantActivity, SolarTableWarning, read_solar_csv, unix_days
from orbit_env.decay.solar_record import load_record

CUBESAT = Satellite(2.2, 4.0, 0.03)
TABLE = Path(__file__).parents[2] / "docs" / "data" / "solar_daily_1995_2018.csv"


def test_one_orbit_takes_numbers_and_a_satellite_and_says_so():
    with pytest.raises(TypeError, match=r"decays one orbit: .* shapes \(2,\) and \(2,\); many orbits: Scenario"):
        orbit_env.lifetime(np.array([360.0, 400.0]), np.array([800.0, 800.0]))
    with pytest.raises(TypeError, match=r"satellite must be a Satellite .*, got float"):
        orbit_env.lifetime(360, 800, satellite=2.2)
    with pytest.raises(TypeError, match=r"scenario must be a Scenario .*, got str"):
        orbit_env.lifetime(360, 800, scenario="msis")
    assert orbit_env.lifetime(np.float64(360.0), 800).days == orbit_env.lifetime(360, 800).days  # numpy scalars


def test_chunk_days_is_refused_where_it_would_do_nothing():
    with pytest.raises(ValueError, match=r"chunk_days=5 steps a dated decay .*one fixed profile"):
        orbit_env.lifetime(360, 800, chunk_days=5)
    dated = Scenario(MsisAir(load_record(), unix_days("2024-01-01")))
    with pytest.raises(ValueError, match="not both \\(here: scenario and chunk_days\\)"):
        orbit_env.lifetime(350, 350, satellite=CUBESAT, scenario=dated, chunk_days=5)


def test_an_msis_air_checks_its_epoch():
    record = load_record()
    with pytest.raises(ValueError, match=r"epoch_days=10000000 is out of range; allowed: 1957-10-04 to 2200-12-31"):
        MsisAir(record, 1e7)
    with pytest.raises(TypeError, match=r"epoch_days='2024-01-01' must be unix days .*unix_days\('2024-01-01'\)"):
        MsisAir(record, "2024-01-01")
    assert MsisAir(record, record.start_days).epoch_days == record.start_days  # a table's own first day


def test_many_orbits_refuse_a_drag_parameter_that_is_not_one():
    for bad in (-0.0165, 0.0, float("nan")):
        with pytest.raises(ValueError, match=r"drag_parameter_m2_kg=(-0.0165|0|nan) is (out of range|not a finite)"):
            Scenario().lifetime_days(np.array([400e3]), np.array([400e3]), bad, 0.0)


def test_the_spread_checks_its_orbit_in_metres_and_its_drag():
    dated = Scenario(MsisAir(load_record(), unix_days("2024-01-01")))
    with pytest.raises(ValueError, match=r"perigee_m=300 is out of range"):  # km typed where metres are asked
        lifetime_spread(300, 300, 0.0165, dated, 51.6, samples=20)
    with pytest.raises(ValueError, match="perigee"):
        lifetime_spread(400e3, 300e3, 0.0165, dated, 51.6, samples=20)
    with pytest.raises(ValueError, match=r"drag_parameter_m2_kg=-0\.0165 is out of range"):
        lifetime_spread(400e3, 400e3, -0.0165, Scenario(), 0.0, samples=20)
    with pytest.raises(TypeError, match="scenario must be a Scenario"):
        lifetime_spread(400e3, 400e3, 0.0165, None, 0.0, samples=20)


def test_a_solar_table_that_ends_before_the_reentry_is_a_warning_in_python_too():
    table = read_solar_csv(TABLE)
    with pytest.warns(SolarTableWarning, match=r"ends on 2018-12-31, \d+ days before the re-entry on 203\d-"):
        orbit_env.lifetime(400, 400, satellite=CUBESAT, activity=table, epoch="2030-01-01", inclination_deg=51.6)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SolarTableWarning)  # inside the table: nothing to say
        orbit_env.lifetime(400, 400, satellite=CUBESAT, activity=table, epoch="2010-01-01", inclination_deg=51.6)


def test_results_compare_and_hash_by_their_numbers():
    result = orbit_env.lifetime(360, 800)
    again = pickle.loads(pickle.dumps(result))
    assert again == result and hash(again) == hash(result)
    assert result != orbit_env.lifetime(360, 900)
    constant = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    assert len({result, orbit_env.lifetime(360, 800, scenario=constant)}) == 2


def test_an_epoch_may_be_a_date_a_datetime_or_a_numpy_datetime():
    import datetime

    sat = dict(satellite=CUBESAT, inclination_deg=51.6)
    text = orbit_env.lifetime(350, 350, epoch="2024-01-01T06:00Z", **sat)
    utc = datetime.UTC
    assert orbit_env.lifetime(350, 350, epoch=datetime.datetime(2024, 1, 1, 6, tzinfo=utc), **sat) == text
    zoned = datetime.datetime(2024, 1, 1, 8, tzinfo=datetime.timezone(datetime.timedelta(hours=2)))
    assert orbit_env.lifetime(350, 350, epoch=zoned, **sat) == text  # 08:00 at +02:00 is 06:00 UTC
    assert orbit_env.lifetime(350, 350, epoch=np.datetime64("2024-01-01T06:00"), **sat) == text
    day = orbit_env.lifetime(350, 350, epoch=datetime.date(2024, 1, 1), **sat)
    assert day == orbit_env.lifetime(350, 350, epoch="2024-01-01", **sat) != text


def test_a_numpy_month_is_its_first_day_and_nat_is_no_date():
    """numpy reads ``datetime64('2024-01')`` as 2024-01-01 (the text '2024-01' is the 15th here); seconds kept."""
    import datetime

    sat = dict(satellite=CUBESAT, inclination_deg=51.6)
    month = orbit_env.lifetime(350, 350, epoch=np.datetime64("2024-01"), **sat)
    assert month.epoch_days == unix_days("2024-01-01")
    assert month == orbit_env.lifetime(350, 350, epoch="2024-01-01", **sat)
    half = datetime.datetime(2024, 1, 1, 6, 0, 0, 500000)
    naive = orbit_env.lifetime(350, 350, epoch=half, **sat)
    assert naive == orbit_env.lifetime(350, 350, epoch=half.replace(tzinfo=datetime.UTC), **sat)  # naive is UTC
    assert naive.epoch_days == unix_days("2024-01-01T06:00:00") + 0.5 / 86400.0
    with pytest.raises(ValueError, match="epoch=NaT is not a date"):
        orbit_env.lifetime(350, 350, epoch=np.datetime64("NaT"), **sat)
