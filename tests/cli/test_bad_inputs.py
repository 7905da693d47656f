"""Bad input as a new user makes it: every row kept or explained, no silent nonsense, errors in the user's words."""

import csv
import json
import math
import re

import numpy as np
import pytest

from orbit_env.analysis import catalogue, catalogue_io
from orbit_env.analysis.lifetime import Satellite, lifetime
from orbit_env.cli import main
from orbit_env.cli.common import check_finite


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


# ------------------------------------------------------------------------------------------
# Batch: every good row computed and written; each bad row says which physical line it is.

CATALOGUE = (
    "name,perigee_km,apogee_km,mass_kg,area_m2\n"  # line 1
    "good1,300,400,100,1\n"  # line 2
    "\n"  # line 3: blank, still a line in an editor
    "extra,300,400,100,1,surplus\n"  # line 4
    "massless,300,400,0,1\n"  # line 5
    "low,50,400,100,1\n"  # line 6
    "text,abc,400,100,1\n"  # line 7
    "good2,350,360,100,1\n"  # line 8
)


def test_batch_keeps_the_good_rows_and_names_the_bad_rows_lines(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text(CATALOGUE)
    out = tmp_path / "out.csv"
    status, stdout, err = run(capsys, "lifetime", "--batch", sats, "--out", out, "--no-progress", "--cx", "2.2")
    # Exit 1: the results are written, but 4 of the 6 rows have none.
    assert status == 1
    assert "wrote 6 rows" in stdout and "2 with lifetimes" in stdout
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("orbit-env: 4 of 6 rows have no lifetime (first: line 4: ")
    records = list(csv.DictReader(open(out, newline="")))
    assert [r["name"] for r in records] == ["good1", "extra", "massless", "low", "text", "good2"]
    status_of = {r["name"]: r["status"] for r in records}
    assert status_of["extra"].startswith("line 4: 6 cells, but the header has 5 columns")
    assert status_of["massless"].startswith("line 5: mass_kg=0 is out of range")
    assert status_of["low"].startswith("line 6: perigee_km=50 is out of range; allowed: 100 to 50000 km")
    assert status_of["text"] == "line 7: perigee_km='abc' is not a number"
    satellite = Satellite(2.2, 100.0, 1.0)
    for record, (hp, ha) in zip((records[0], records[5]), ((300, 400), (350, 360)), strict=True):
        assert record["status"] == "ok"
        expected = lifetime(hp, ha, satellite=satellite, method="curves").days
        assert float(record["days"]) == pytest.approx(expected, rel=1e-5)  # the CSV's 6 digits


def test_batch_all_good_exits_0_reads_an_excel_bom_and_writes_lf(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_bytes("\ufeffperigee_km,apogee_km\r\n300,400\r\n400,400\r\n".encode())
    out = tmp_path / "out.csv"
    status, stdout, err = run(capsys, "lifetime", "--batch", sats, "--out", out, "--no-progress")
    assert status == 0 and err == ""
    assert "2 with lifetimes, 0 with a status message" in stdout
    data = out.read_bytes()
    assert b"\r" not in data and data.count(b"\n") == 3


def test_batch_never_replaces_its_input_or_an_existing_file_unasked(capsys, tmp_path, monkeypatch):
    sats = tmp_path / "sats.csv"
    sats.write_text("perigee_km,apogee_km\n300,400\n")
    before = sats.read_bytes()
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", tmp_path / "." / "sats.csv", "--no-progress")
    assert status == 2 and "is the input file" in err and err.count("\n") == 1
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", sats, "--force", "--no-progress")
    assert status == 2 and "is the input file" in err
    assert sats.read_bytes() == before

    out = tmp_path / "out.csv"
    out.write_text("precious\n")
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", out, "--no-progress")
    assert (
        status == 2
        and err == f"orbit-env: error: --out {out} exists; give --force to replace it, or another file name\n"
    )
    assert out.read_text() == "precious\n"
    status, _, _ = run(capsys, "lifetime", "--batch", sats, "--out", out, "--no-progress", "--force")
    assert status == 0 and out.read_text().startswith("perigee_km,")

    # A folder that does not exist is found before any computing.
    def never(*args, **kwargs):
        raise AssertionError("the batch was computed before its output was checked")

    monkeypatch.setattr(catalogue_io, "read_batch", never)
    monkeypatch.setattr(catalogue, "batch_lifetimes", never)
    missing = tmp_path / "no-such-folder" / "out.csv"
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", missing, "--no-progress")
    assert status == 2 and err == (f"orbit-env: error: --out {missing}: the folder {missing.parent} does not exist\n")


def test_batch_output_is_written_whole_or_not_at_all(tmp_path, monkeypatch):
    out = tmp_path / "out.csv"
    out.write_text("earlier results\n")

    def disk_full(self, rows):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(csv.DictWriter, "writerows", disk_full)
    with pytest.raises(OSError, match="No space left"):
        catalogue_io.write_records(out, [{"perigee_km": "300", "status": "ok"}])
    assert out.read_text() == "earlier results\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]  # no temporary file left behind


def test_batch_refuses_a_binary_file_by_name(capsys, tmp_path):
    sats = tmp_path / "sats.xlsx"
    sats.write_bytes(b"PK\x03\x04\x14\x00\x06\x00\x08\x00\x00\x00!\x00\xb5U0#\xf4")
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", tmp_path / "out.csv", "--no-progress")
    assert status == 2 and err.count("\n") == 1
    assert err.startswith(f"orbit-env: error: {sats}: not a text CSV file")
    assert not (tmp_path / "out.csv").exists()


# ------------------------------------------------------------------------------------------
# fit-density: one time axis.


def test_fit_density_reentry_on_the_observations_axis(capsys, tmp_path):
    in_days = tmp_path / "days.csv"
    in_days.write_text("days,perigee_km,apogee_km\n10,300,320\n")
    dated = tmp_path / "dated.csv"
    dated.write_text("date,perigee_km,apogee_km\n2020-09-01,300,320\n")
    # The same decay, 31 days from the first orbit to re-entry, on either axis and in the same
    # (undated) air: the same scale, to the last bits (one fit, only the axis differs).
    status, out_days, _ = run(capsys, "fit-density", in_days, "--reentry", "41", "--json", "--atmosphere", "paper")
    assert status == 0
    status, out_dated, _ = run(
        capsys, "fit-density", dated, "--reentry", "2020-10-02", "--json", "--atmosphere", "paper"
    )
    assert status == 0
    assert json.loads(out_days)["scale"] == pytest.approx(json.loads(out_dated)["scale"], rel=1e-12)
    # Left to the defaults, dates select NRLMSIS under the shipped record (days: the paper's air).
    status, out_dated, _ = run(capsys, "fit-density", dated, "--reentry", "2020-10-02", "--json")
    assert status == 0
    assert json.loads(out_dated)["atmosphere"].startswith("NRLMSIS 2.1, CelesTrak space weather")
    assert json.loads(out_days)["atmosphere"].startswith("paper")
    # Mixed axes: refused, naming both.
    status, _, err = run(capsys, "fit-density", in_days, "--reentry", "2020-10-02")
    assert status == 2 and err == (
        f"orbit-env: error: --reentry 2020-10-02 is a date, but {in_days} gives its times in days "
        "(a 'days' column); give the re-entry in days on that axis\n"
    )
    status, _, err = run(capsys, "fit-density", dated, "--reentry", "31")
    assert status == 2 and "--reentry 31 is a number" in err and "'date' column" in err
    both = tmp_path / "both.csv"
    both.write_text("date,days,perigee_km,apogee_km\n2020-09-01,0,300,320\n")
    status, _, err = run(capsys, "fit-density", both, "--reentry", "31")
    assert status == 2 and "'date' and 'days'" in err and err.count("\n") == 1


def test_fit_density_refuses_a_scale_no_atmosphere_has(capsys, tmp_path):
    observations = tmp_path / "obs.csv"
    observations.write_text("days,perigee_km,apogee_km\n0,400,420\n")
    # Down from 400 km in an hour: a thousand times any density there, not a measurement.
    status, out, err = run(capsys, "fit-density", observations, "--reentry", "0.04")
    assert status == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("orbit-env: error: the fitted density scale, ")
    assert "is outside 0.001 to 1000: the data do not fit this satellite in this atmosphere" in err


def test_argparse_never_stores_an_empty_list(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["lifetime", "--perigee", "300", "--apogee=--"])
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err == (
        "orbit-env lifetime: error: argument --apogee: expected one argument, got '--' (see --help)\n"
    )


def test_fit_density_errors_name_the_file_and_line(capsys, tmp_path):
    observations = tmp_path / "obs.csv"
    observations.write_text("days,perigee_km,apogee_km\n0,300,320\n\n1,abc,310\n")
    status, _, err = run(capsys, "fit-density", observations, "--reentry", "5")
    assert status == 2 and err == f"orbit-env: error: {observations}, line 4: perigee_km='abc' is not a number\n"
    observations.write_text("days,perigee_km,apogee_km\n0,300,320\n2,300,310\n1,299,305\n")
    status, _, err = run(capsys, "fit-density", observations)
    assert status == 2 and err.startswith(f"orbit-env: error: {observations}, line 4: the time is not after line 3's")


# ------------------------------------------------------------------------------------------
# No nonsense with exit 0.

ORBIT = ["lifetime", "--perigee", "400", "--apogee", "500"]


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        (["--mass-per-area", "1e300"], "--mass-per-area 1e300 is out of range; allowed: 0.01 to 100000 kg/m^2 ("),
        (["--density-scale", "1e300"], "--density-scale 1e300 is out of range; allowed: 0.001 to 1000 ("),
        (["--cx", "1e6"], "--cx 1e6 is out of range; allowed: above 0 and at most 10 ("),
        (["--mass", "1e9", "--area", "1"], "--mass 1e9 is out of range; allowed: above 0 and at most 1000000 kg ("),
        (
            ["--atmosphere", "exponential", "--rho0", "1.3", "--h0-km", "0", "--scale-height-km", "-8.5"],
            "--scale-height-km -8.5 is out of range; allowed: 1 to 500 km (",
        ),
        (
            ["--atmosphere", "exponential", "--scale-height-km", "8.5"],
            "give --rho0, --h0-km and --scale-height-km together",
        ),
        (
            ["--atmosphere", "msis", "--epoch", "99999-01-01"],
            "--epoch 99999-01-01 is out of range; allowed: 1957-10-04 to 2200-12-31 (",
        ),
        (["--atmosphere", "msis", "--epoch", "1950-06-01"], "--epoch 1950-06-01 is out of range"),
    ],
)
def test_implausible_inputs_are_refused_with_their_bounds_and_why(capsys, argv, start):
    status, out, err = run(capsys, *ORBIT, *argv)
    assert status == 2 and out == ""
    assert err.startswith(f"orbit-env: error: {start}") and err.count("\n") == 1


#: An exponential law whose 1 km scale height leaves no air at 1100 km.
_SEA_LEVEL_KM_LAW = ("--rho0", "1e-13", "--h0-km", "0", "--scale-height-km", "1")


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        # 1100 x 4000 km, the heaviest load, a thousandth of the density: 6e8 years (lifetime ~ G/F / rho).
        (
            ["--perigee", "1100", "--apogee", "4000", "--mass-per-area", "1e5", "--density-scale", "0.001"],
            "the lifetime comes out as 6.08e+08 years, more than 1,000,000: ",
        ),
        # exp(-1100 km / 1 km) underflows: no drag at all.
        (
            [*("--perigee", "1100", "--apogee", "4000", "--atmosphere", "exponential"), *_SEA_LEVEL_KM_LAW],
            "the density at the perigee is 0 kg/m^3 in this atmosphere (it underflows)",
        ),
        (
            ["--perigee", "50000", "--apogee", "50000", "--rho100", "1e-7", "--rotating-atmosphere"],
            "the averaged equations could not follow this decay to re-entry",
        ),
    ],
)
def test_lifetimes_beyond_any_model_are_refused(capsys, argv, start):
    status, out, err = run(capsys, "lifetime", *argv)
    assert status == 2 and out == "" and err.startswith(f"orbit-env: error: {start}") and err.count("\n") == 1


@pytest.mark.parametrize(
    "argv",
    [
        ["--density-scale", "200", "--rotating-atmosphere", "--method", "curves"],
        ["--rho100", "1e-4", "--method", "curves"],
    ],
)
def test_air_too_dense_for_the_curves_is_refused(capsys, argv):
    # 200 and 61 times the paper's density at 100 km; the curves are built up to 20 times.
    status, out, err = run(capsys, *ORBIT, *argv)
    assert status == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("orbit-env: error: the air at 100 km is ") and "built up to 20 times" in err


def test_a_batch_row_beyond_any_model_gets_its_line(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text("perigee_km,apogee_km,mass_per_area_kg_m2\n\n1100,4000,90000\n300,400,50\n")
    out = tmp_path / "out.csv"
    status, _, _ = run(capsys, "lifetime", "--batch", sats, "--out", out, "--density-scale", "0.001", "--no-progress")
    assert status == 1
    far, near = csv.DictReader(open(out))
    assert far["days"] == "" and far["status"].startswith("line 3: the lifetime comes out as ")
    assert near["status"] == "ok" and 0 < float(near["years"]) < 1e6


def test_the_exponential_law_defaults_to_orbital_heights_and_says_so(capsys):
    status, out, _ = run(capsys, *ORBIT, "--atmosphere", "exponential", "--json")
    assert status == 0
    summary = json.loads(out)
    assert "3.725e-12 kg/m^3 at 400 km, scale height 58.515 km" in summary["atmosphere"]
    assert "default law for orbital heights" in summary["atmosphere"]
    # Months, as for the paper's atmosphere (217 days here), not the sea-level law's millions of years.
    assert 60 < summary["days"] < 2000


def test_nrlmsis_says_when_the_inclination_is_not_the_users(capsys):
    status, out, _ = run(capsys, *ORBIT, "--atmosphere", "msis")
    assert status == 0
    assert "inclination 0 deg" in out and "(the default: no --inclination given)" in out
    status, out, _ = run(capsys, *ORBIT, "--atmosphere", "msis", "--inclination", "97.8")
    assert status == 0
    assert "inclination 97.8 deg" in out and "no --inclination given" not in out


def test_a_batch_under_nrlmsis_says_each_row_has_its_own_inclination(capsys, tmp_path):
    # The rows' inclination_deg, not --inclination's one value, set each row's air: the line says so.
    sats = tmp_path / "sats.csv"
    sats.write_text("perigee_km,apogee_km,inclination_deg\n300,400,97.5\n300,400,\n")
    for extra, default in (
        ((), "0 deg where a row has none: the default, no --inclination given"),
        (("--inclination", "51.6"), "51.6 deg where a row has none: --inclination"),
    ):
        out = tmp_path / f"out{len(extra)}.csv"
        status, stdout, _ = run(capsys, "lifetime", "--batch", sats, "--out", out, "--atmosphere", "msis", *extra)
        assert status == 0
        assert f"each row's inclination_deg ({default})" in stdout
        assert "inclination 0 deg" not in stdout and "(the default: no --inclination given)" not in stdout


def test_a_solar_table_that_ends_early_is_named_with_its_dates(capsys, tmp_path):
    table = tmp_path / "two_weeks.csv"
    table.write_text("date,f107\n" + "".join(f"2013-10-{d:02d},120\n" for d in range(1, 15)))
    status, out, err = run(capsys, *ORBIT, "--atmosphere", "msis", "--solar-csv", table, "--json")
    assert status == 0
    days = json.loads(out)["days"]
    assert days > 60  # well past the table's 13 days
    assert err.count("\n") == 1
    assert err.startswith(f"orbit-env: warning: the solar table {table} ends on 2013-10-14, ")
    reentry = np.datetime64("2013-10-01") + np.timedelta64(math.floor(days), "D")
    assert f"before the re-entry on {reentry}" in err
    assert "held constant" in err


def test_no_nan_in_the_trajectory_under_changing_activity(capsys, tmp_path):
    table = tmp_path / "table.csv"
    table.write_text("date,f107\n2013-10-01,80\n2013-10-05,200\n2013-10-09,90\n")
    trajectory = tmp_path / "t.csv"
    argv = ["lifetime", "--perigee", "200", "--apogee", "230", "--atmosphere", "msis", "--solar-csv", table]
    status, _, _ = run(capsys, *argv, "--method", "averaged", "--trajectory", trajectory)
    assert status == 0
    rows = list(csv.DictReader(open(trajectory)))
    assert len(rows) > 2
    numbers = ("revolutions", "days", "perigee_km", "apogee_km", "nu_remaining")
    values = np.array([[float(row[key]) for key in numbers] for row in rows])
    assert np.isfinite(values).all()
    perigee, apogee = values[:, 2], values[:, 3]
    assert np.all(perigee <= apogee + 1e-9)
    assert np.all(np.diff(values[:, 1]) > 0)  # days increase


def test_a_lifetime_under_a_day_is_not_printed_as_zero(capsys):
    # A drag sail (1 kg/m^2) at 200 km comes down in minutes; "0.00 days" would read as no lifetime.
    status, out, _ = run(capsys, "lifetime", "--perigee", "200", "--apogee", "200", "--mass-per-area", "1")
    assert status == 0
    line = next(line for line in out.splitlines() if line.startswith("lifetime"))
    days, hours = re.match(r"lifetime\s+(\S+) days \((\S+) hours\)", line).groups()
    assert 0.0 < float(days) < 1.0 and float(hours) == pytest.approx(24.0 * float(days), rel=0.01)


def test_check_finite_refuses_nan_and_infinity():
    check_finite({"days": 1.0, "interval": [0.5, 2.0], "name": "x"}, "the result")
    with pytest.raises(ValueError, match="days came out as nan"):
        check_finite({"days": float("nan")}, "the result")
    with pytest.raises(ValueError, match="interval came out as inf"):
        check_finite({"interval": [1.0, float("inf")]}, "the fit")


# ------------------------------------------------------------------------------------------
# Files named in every file error.


def test_a_binary_solar_file_is_named(capsys, tmp_path):
    binary = tmp_path / "solar.bin"
    binary.write_bytes(bytes(range(256)))
    status, _, err = run(capsys, *ORBIT, "--atmosphere", "msis", "--solar-csv", binary)
    assert status == 2 and err.count("\n") == 1
    assert err.startswith(f"orbit-env: error: {binary}: not a text CSV file (byte 0x80 at offset 128 is not UTF-8")


def test_a_solar_file_error_names_its_physical_line(capsys, tmp_path):
    table = tmp_path / "solar.csv"
    table.write_text("date,f107\n2013-10-01,100\n\n2013-10-02,lots\n")
    status, _, err = run(capsys, *ORBIT, "--atmosphere", "msis", "--solar-csv", table)
    assert status == 2 and err == f"orbit-env: error: {table}, line 4: f107='lots' is not a number\n"


# ------------------------------------------------------------------------------------------
# Element sets and mean elements that no decay starts from: said in their own terms (a review's
# findings: the messages named --perigee, --area or a mass per area the user never gave).

GEO_TLE = """GEO-TEST
1 99998U 24001B   24100.50000000  .00000000  00000-0  10000-3 0  9997
2 99998   0.0500 120.0000 0001000  90.0000 270.0000  1.00270000    14
"""
BELOW_GROUND_TLE = """ECC5
1 99996U 24001C   24100.50000000  .00002000  00000-0  25000-3 0  9993
2 99996  51.6000 120.0000 5000000  90.0000 270.0000 15.05164753    10
"""
CUBESAT_TLE = """CUBESAT-550 (synthetic)
1 99999U 24001A   24100.50000000  .00002000  00000-0  25000-3 0  9996
2 99999  97.5000 120.0000 0010000  90.0000 270.0000 15.05164753    18
"""


def tle_error(capsys, tmp_path, text):
    """What ``lifetime --tle`` says of an element set it refuses (usage error: status 2)."""
    path = tmp_path / "set.tle"
    path.write_text(text)
    status, _, err = run(capsys, "lifetime", "--tle", path)
    assert status == 2
    return err


def test_an_element_set_below_the_ground_or_the_reentry_height_says_so(capsys, tmp_path):
    err = tle_error(capsys, tmp_path, BELOW_GROUND_TLE)
    assert "the element set (a = 6929.910 km, e = 0.5000000) is flown at -2913.9 x 4016.0 km" in err
    assert "below the Earth's surface" in err and "--area" not in err
    status, _, err = run(capsys, "lifetime", "--semi-major-axis-km", "12800", "--eccentricity", "0.5")
    assert status == 2
    assert "--semi-major-axis-km/--eccentricity (a = 12800.000 km, e = 0.5000000) is flown at 16.7 x" in err
    assert "below the re-entry height (100 km above the 6371 km sphere, 92.9 km here)" in err
    assert "--perigee" not in err


def test_a_drag_no_satellite_has_names_where_it_came_from(capsys, tmp_path):
    # B* 1e-4 at 35 786 km, calibrated to NRLMSIS there: about 3600 m^2/kg, a mass per area of 0.0003 kg/m^2.
    err = tle_error(capsys, tmp_path, GEO_TLE)
    calibrated = r"the element set \(its B\* calibrated to this air at its epoch\) gives a drag parameter"
    assert re.search(calibrated + r" c_x A/m = 36\d\d ", err)
    assert "give the satellite: --mass and --area" in err and "mass_kg / area_m2" not in err


def test_a_batch_of_element_sets_reads_them_as_pasted_and_says_why_a_row_is_beyond_it(capsys, tmp_path):
    # Indented lines and a byte-order mark (a Windows editor's), as --tle reads them; a geostationary
    # object's row says in its own km why a batch, which decays on the curves, leaves it out.
    sets = tmp_path / "sets.tle"
    text = "".join("   " + line + "\n" for line in (GEO_TLE + CUBESAT_TLE).splitlines())
    sets.write_bytes("\ufeff".encode() + text.encode())
    out = tmp_path / "out.csv"
    status, _, err = run(
        capsys, "lifetime", "--batch", sets, "--out", out, "--no-progress", "--mass", "4", "--area", "0.03"
    )
    assert status == 1 and "1 of 2 rows have no lifetime" in err
    rows = list(csv.DictReader(out.open()))
    assert [r["name"] for r in rows] == ["GEO-TEST", "CUBESAT-550 (synthetic)"]  # no byte-order mark in a name
    assert rows[0]["status"].startswith("line 2: the orbit flown, 35782.4 x 35790.8 km, is outside the universal")
    assert "perigee 92.9 to 1092.9 km" in rows[0]["status"] and "perigee_m" not in rows[0]["status"]
    assert rows[1]["status"] == "ok" and float(rows[1]["days"]) > 0.0
