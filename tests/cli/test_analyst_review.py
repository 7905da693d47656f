"""What an analyst's review of the command line found (2026-12-06): each case failed before its fix.

Files are never written over an input or silently renamed; options that would do nothing, or
something other than they say, are refused; a bad element set in a batch is its object's row, not
the batch's end; errors name the option and the file.
"""

import csv
import json
from pathlib import Path

import pytest

from orbit_env.analysis import drag_calibration
from orbit_env.analysis.uncertainty import ONE_SET_DRAG_SIGMA
from orbit_env.cli import lifetime as lifetime_cli
from orbit_env.cli import main
from orbit_env.decay.solar import unix_days

SETS = Path(__file__).parents[2] / "benchmarks" / "data" / "reentry_tles"


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def last_lines(path: Path, n: int) -> str:
    return "\n".join(path.read_text().splitlines()[-n:]) + "\n"


@pytest.fixture
def beesat(tmp_path):
    """BEESAT-4's last two sets (a history of one object)."""
    path = tmp_path / "beesat4.tle"
    path.write_text(last_lines(SETS / "41619_beesat4.tle", 4))
    return path


def never_computed(monkeypatch):
    def never(*args, **kwargs):
        raise AssertionError("the decay ran before the options were checked")

    monkeypatch.setattr(lifetime_cli, "lifetime", never)


def test_outputs_never_replace_an_input_and_are_checked_before_any_decay(capsys, tmp_path, beesat, monkeypatch):
    before = beesat.read_bytes()
    never_computed(monkeypatch)
    cases = [
        (["--trajectory", beesat], f"--trajectory {beesat} is the input file of --tle; write to another file"),
        (["--plot", beesat], f"--plot {beesat} is the input file of --tle; write to another file"),
        (["--plot", tmp_path], f"--plot {tmp_path} is a directory; give a file name"),
        (["--plot", tmp_path / "x" / "p.png"], f"--plot {tmp_path / 'x' / 'p.png'}: the folder {tmp_path / 'x'} does"),
        (["--trajectory", tmp_path / "t.csv", "--plot", tmp_path / "t.csv"], f"--plot {tmp_path / 't.csv'} is the --"),
    ]
    for extra, message in cases:
        status, out, err = run(capsys, "lifetime", "--tle", beesat, *extra)
        assert status == 2 and out == "" and err.startswith(f"orbit-env: error: {message}"), (extra, err)
    # A name without a format's extension: matplotlib would have written p.png, not the file asked for.
    status, _, err = run(capsys, "lifetime", "--tle", beesat, "--plot", tmp_path / "p")
    assert status == 2 and "the file name's extension gives the figure's format; allowed: " in err and ".png" in err
    assert beesat.read_bytes() == before and sorted(p.name for p in tmp_path.iterdir()) == ["beesat4.tle"]


def test_options_that_would_do_nothing_are_refused(capsys, beesat):
    cases = [
        # The set's epoch is where its orbit was measured: a later --epoch flew a years-old orbit from then.
        (["--tle", beesat, "--epoch", "2020-01-01"], "--epoch 2020-01-01: the decay starts at the element set's epoch"),
        # A drag calibrated (or fitted) to the air absorbs the scale: the same life whatever it is.
        (["--tle", beesat, "--density-scale", "3"], "--density-scale changes nothing when the drag is calibrated"),
        (["--perigee", 400, "--apogee", 400, "--drag-from", "ndot"], "--drag-from says what an element set's drag"),
        (["--perigee", 400, "--apogee", 400, "--samples", 5], "--samples goes with --uncertainty"),
        (["--perigee", 400, "--apogee", 400, "--seed", 5], "--seed goes with --uncertainty"),
        (["--perigee", 400, "--apogee", 400, "--chunk-days", 5], "--chunk-days is the time step of a dated decay"),
    ]
    for argv, message in cases:
        status, out, err = run(capsys, "lifetime", *argv)
        assert status == 2 and out == "" and err.startswith(f"orbit-env: error: {message}"), (argv, err)
    # With the satellite given, the scale is flown (the drag is no longer read from the sets).
    status, out, _ = run(capsys, "lifetime", "--tle", beesat, "--mass", 1, "--area", 0.012, "--density-scale", 3)
    assert status == 0 and "x 3" in out


def test_uncertainty_above_the_curves_is_refused_at_once_in_the_heights_typed(capsys, monkeypatch):
    never_computed(monkeypatch)
    status, _, err = run(
        capsys, "lifetime", "--perigee", 250, "--apogee", 35786, "--mass", 1000, "--area", 10, "--uncertainty"
    )
    assert status == 2 and err == (
        "orbit-env: error: --uncertainty samples decays on the universal curves (perigee up to 1100.0 km, apogee up "
        "to 4000.0 km here); this orbit (250.0 x 35786.0 km) is above them: drop --uncertainty for its lifetime "
        "(and --rule's verdict) by the averaged equations\n"
    )


def test_a_file_that_cannot_be_read_is_named_with_its_option(capsys, tmp_path):
    missing = tmp_path / "none.tle"
    err = run(capsys, "lifetime", "--tle", missing)[2]
    assert err == f"orbit-env: error: --tle {missing}: no such file or directory\n"
    assert run(capsys, "lifetime", "--tle", tmp_path)[2] == f"orbit-env: error: --tle {tmp_path}: is a directory\n"
    status, _, err = run(capsys, "fit-density", missing)
    assert status == 2 and err == f"orbit-env: error: {missing}: no such file or directory\n"


def test_ctrl_c_is_one_line_and_the_shells_status(capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(lifetime_cli, "lifetime", interrupted)
    status, out, err = run(capsys, "lifetime", "--perigee", 300, "--apogee", 300)
    assert (status, out, err) == (130, "", "orbit-env: interrupted\n")


def test_a_bad_set_in_a_batch_is_its_objects_row_and_each_row_says_its_drag(capsys, tmp_path, beesat):
    raiko = last_lines(SETS / "38852_raiko.tle", 2)
    minxss = last_lines(SETS / "41474_minxss.tle", 2).splitlines()
    broken = minxss[1][:-1] + str((int(minxss[1][-1]) + 1) % 10)  # its checksum digit off by one
    batch = tmp_path / "mix.tle"
    batch.write_text(beesat.read_text() + f"{minxss[0]}\n{broken}\n" + raiko)
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "lifetime", "--batch", batch, "--out", out, "--no-progress")
    assert status == 1 and "1 of 3 rows have no lifetime (first: line 6: bad checksum" in err
    rows = {r["name"]: r for r in csv.DictReader(open(out, newline=""))}
    assert rows["41619"]["drag_parameter_source"] == "history_fit" and rows["41619"]["status"] == "ok"
    assert rows["38852"]["drag_parameter_source"] == "bstar_calibrated" and rows["38852"]["status"] == "ok"
    assert rows["41474"]["status"].startswith("line 6: bad checksum")
    assert rows["41474"]["days"] == rows["41474"]["drag_parameter_m2_kg"] == ""
    # The same file with --tle still refuses the bad set (one object's file is all or nothing).
    status, _, err = run(capsys, "lifetime", "--tle", batch)
    assert status == 2 and "line 6: bad checksum" in err


def test_a_set_whose_drag_cannot_be_read_shows_no_drag_in_its_row(capsys, tmp_path):
    iss = "1 25544U 98067A   08264.51782528 -.00002182  00000-0 -11606-4 0  2927\n"
    iss += "2 25544  51.6416 247.4627 0006703 130.5360 325.0288 15.72125391563537\n"
    batch = tmp_path / "iss.tle"
    batch.write_text(iss)
    out = tmp_path / "out.csv"
    status, _, _ = run(capsys, "lifetime", "--batch", batch, "--out", out, "--no-progress")
    (row,) = csv.DictReader(open(out, newline=""))
    assert status == 1 and row["status"] == "line 1: B* = -1.1606e-05 /ER gives no drag parameter"
    assert row["drag_parameter_m2_kg"] == row["drag_parameter_source"] == ""


def test_a_dated_csv_batch_gives_the_reentry_date(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text("name,perigee_km,apogee_km,mass_kg,area_m2,cx\na,300,350,4,0.03,2.2\n")
    out = tmp_path / "out.csv"
    argv = ["--batch", sats, "--out", out, "--epoch", "2024-01-01", "--inclination", 51.6, "--no-progress"]
    assert run(capsys, "lifetime", *argv)[0] == 0
    (row,) = csv.DictReader(open(out, newline=""))
    # A single dated lifetime of the same orbit, for the date the batch must agree with.
    _, out_json, _ = run(
        capsys, "lifetime", "--perigee", 300, "--apogee", 350, "--mass", 4, "--area", 0.03, "--cx", 2.2,
        "--epoch", "2024-01-01", "--inclination", 51.6, "--json",
    )  # fmt: skip
    single = json.loads(out_json)
    assert row["epoch"] == "2024-01-01T00:00Z"
    # A batch decays its inclination group on one family of curves: within 0.5% of the single orbit's
    # (docs/how-to/catalogue.md); its date is its own epoch plus its own days, to the minute printed.
    assert float(row["days"]) == pytest.approx(single["days"], rel=5e-3)
    reentry = unix_days(row["reentry_date"])
    assert abs(reentry - (unix_days("2024-01-01") + float(row["days"]))) <= 0.5 / 1440 + 1e-4


def test_a_set_given_twice_counts_once_and_two_sets_are_as_uncertain_as_one(capsys, tmp_path, beesat):
    twice = tmp_path / "twice.tle"
    twice.write_text(beesat.read_text() + last_lines(beesat, 2))
    once = json.loads(run(capsys, "lifetime", "--tle", beesat, "--json")[1])
    doubled = json.loads(run(capsys, "lifetime", "--tle", twice, "--json")[1])
    assert doubled["drag_fit"] == once["drag_fit"] and doubled["days"] == once["days"]
    # Two sets: the fit goes through both, so its residual says nothing; one set's measured scatter instead.
    assert once["drag_fit"]["sets"] == 2 and once["drag_fit"]["residual_km"] is None
    assert once["drag_fit"]["sigma_ln"] == ONE_SET_DRAG_SIGMA == drag_calibration.ONE_SET_DRAG_SIGMA


def test_fit_density_says_its_satellite_and_refuses_what_is_not_one_decay(capsys, tmp_path):
    rising = tmp_path / "rising.csv"
    rising.write_text("date,perigee_km,apogee_km\n2023-07-04,372,382\n2023-07-07,373,383\n2023-08-07,375,385\n")
    status, _, err = run(capsys, "fit-density", rising)
    assert status == 2 and err.startswith(
        "orbit-env: error: the orbit does not come down between the first and the last observation (its mean height "
        "+3.000 km over 34.0 days)"
    )
    tle = tmp_path / "sets.tle"
    tle.write_text(last_lines(SETS / "41619_beesat4.tle", 4))
    status, _, err = run(capsys, "fit-density", tle)
    assert status == 2 and f"{tle} holds element sets, not observed orbits" in err and "lifetime --tle" in err
    days = tmp_path / "days.csv"
    days.write_text("days,perigee_km,apogee_km\n0,350,700\n18.52,347.5,680.5\n39.04,344.4,657.4\n")
    status, out, _ = run(capsys, "fit-density", days, "--mass", 4, "--area", 0.03, "--cx", 2.2)
    assert status == 0 and out.startswith("satellite          c_x 2.2, 4 kg, 0.03 m^2")
    summary = json.loads(run(capsys, "fit-density", days, "--mass", 4, "--area", 0.03, "--cx", 2.2, "--json")[1])
    assert summary["drag_parameter_m2_kg"] == pytest.approx(2.2 * 0.03 / 4) and summary["drag_parameter_source"] == (
        "satellite"
    )


def test_fit_density_takes_the_first_observations_date_as_its_epoch(capsys, tmp_path):
    observed = tmp_path / "obs.csv"
    observed.write_text(
        "date,perigee_km,apogee_km\n2023-07-04T02:19,372.440,382.096\n2023-07-20T10:10,369.1,378.6\n"
        "2023-08-20T10:10,360.2,369.8\n"
    )
    options = ["--mass", 1, "--area", 0.012, "--cx", 2.2, "--inclination", 97.15, "--json"]
    status, plain, _ = run(capsys, "fit-density", observed, *options)
    status_dated, dated, err = run(capsys, "fit-density", observed, "--epoch", "2023-07-04", *options)
    assert status == status_dated == 0 and json.loads(dated)["scale"] == json.loads(plain)["scale"]
    status, _, err = run(capsys, "fit-density", observed, "--epoch", "2023-07-09", *options)
    assert status == 2 and err == (
        "orbit-env: error: the fit starts at the first observation (2023-07-04T02:19Z), in the air of its days, not "
        "in air from 2023-07-09T00:00Z: give no --epoch (or the first observation's date)\n"
    )


def test_dates_with_a_zone_are_read_in_utc_without_warnings():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert unix_days("2024-04-09T12:00:00Z") == unix_days("2024-04-09T12:00") == 19822.5
        assert unix_days("2024-04-09T14:00:00+02:00") == unix_days("2024-04-09T07:00-05:00") == 19822.5
    with pytest.raises(ValueError, match="expected YYYY-MM-DD, YYYY-MM or YYYY-MM-DDTHH:MM"):
        unix_days("2024-13-01")


def test_solar_command_without_a_subcommand_names_them(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["solar"])
    assert stop.value.code == 2 and "the following arguments are required: {show,update}" in capsys.readouterr().err


def test_an_epoch_given_as_the_sets_own_is_accepted_in_any_form(capsys, beesat):
    plain = json.loads(run(capsys, "lifetime", "--tle", beesat, "--json")[1])
    for form in ("2023-08-20T15:28:19Z", "2023-08-20T17:28:19+02:00", "2023-08-20T15:28:19"):
        status, out, err = run(capsys, "lifetime", "--tle", beesat, "--epoch", form, "--json")
        assert status == 0 and json.loads(out)["days"] == plain["days"], (form, err)


def test_fit_density_names_a_three_line_element_set_file(capsys, tmp_path):
    tle = tmp_path / "named.tle"
    tle.write_text("BEESAT 4\n" + last_lines(SETS / "41619_beesat4.tle", 2))
    status, _, err = run(capsys, "fit-density", tle)
    assert status == 2 and "holds element sets, not observed orbits" in err


def test_a_plot_without_matplotlib_names_the_extra_before_any_decay(capsys, monkeypatch, tmp_path):
    import builtins

    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError("No module named 'matplotlib'")
        return real_import(name, *args, **kwargs)

    never_computed(monkeypatch)
    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    status, _, err = run(capsys, "lifetime", "--perigee", 300, "--apogee", 300, "--plot", tmp_path / "p.png")
    assert status == 2 and err == "orbit-env: error: --plot needs matplotlib: pip install 'orbit-env[plot]'\n"


def test_a_dated_batch_with_bands_keeps_the_nominal_dates(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text("name,perigee_km,apogee_km,mass_kg,area_m2,cx\na,300,350,4,0.03,2.2\n")
    plain, banded = tmp_path / "plain.csv", tmp_path / "banded.csv"
    common = ["--batch", sats, "--epoch", "2024-01-01", "--inclination", 51.6, "--no-progress"]
    assert run(capsys, "lifetime", *common, "--out", plain)[0] == 0
    argv = [*common, "--out", banded, "--uncertainty", "--samples", 20, "--workers", 1]
    assert run(capsys, "lifetime", *argv)[0] == 0
    (nominal,) = csv.DictReader(open(plain, newline=""))
    (row,) = csv.DictReader(open(banded, newline=""))
    assert row["epoch"] == nominal["epoch"] == "2024-01-01T00:00Z" and row["reentry_date"] == nominal["reentry_date"]
    assert row["reentry_date_p50"] != ""


def test_a_batch_of_named_sets_keeps_their_catalogue_numbers(capsys, tmp_path):
    named = tmp_path / "named.tle"
    named.write_text("BEESAT 4\n" + last_lines(SETS / "41619_beesat4.tle", 2))
    out = tmp_path / "out.csv"
    assert run(capsys, "lifetime", "--batch", named, "--out", out, "--no-progress")[0] == 0
    (row,) = csv.DictReader(open(out, newline=""))
    assert (row["name"], row["id"]) == ("BEESAT 4", "41619")


def test_a_row_that_gives_its_satellite_twice_is_not_guessed(capsys, tmp_path):
    sats = tmp_path / "two.csv"
    sats.write_text(
        "name,perigee_km,apogee_km,mass_per_area_kg_m2,drag_parameter_m2_kg,mass_kg,area_m2\n"
        "d,400,400,100,0.02,,\ne,400,400,,0.02,5,0.05\nok,400,400,,0.02,,\n"
    )
    out = tmp_path / "out.csv"
    assert run(capsys, "lifetime", "--batch", sats, "--out", out, "--no-progress")[0] == 1
    rows = {r["name"]: r["status"] for r in csv.DictReader(open(out, newline=""))}
    twice = "the satellite is given twice"
    assert rows["d"] == f"line 2: {twice} (drag_parameter_m2_kg; mass_per_area_kg_m2): give one of them"
    assert rows["e"] == f"line 3: {twice} (drag_parameter_m2_kg; mass_kg and area_m2): give one of them"
    assert rows["ok"] == "ok"
