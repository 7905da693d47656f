"""Damaged element sets, contradictory options and data that say nothing: refused in the user's words.

Each case was reproduced by a review that fed the command line what users produce (2026-12-06); before
the fixes each one gave a plausible answer with exit status 0, or a message blaming the wrong input.
The element set is NSIGHT-1's first of ``benchmarks/data/reentry_tles/42726_nsight.tle`` (sources in
that folder's README), damaged column by column with the checksum made right again, so that only the
field under test is wrong.
"""

import json
from pathlib import Path

import pytest

from orbit_env.analysis.elements import parse_tle, tle_checksum
from orbit_env.cli import main

NSIGHT = (Path(__file__).resolve().parents[2] / "benchmarks/data/reentry_tles/42726_nsight.tle").read_text().split("\n")
LINE1, LINE2 = NSIGHT[0], NSIGHT[1]


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def damaged(line: str, column: int, text: str) -> str:
    """``line`` with ``text`` from 1-based ``column`` on, its checksum made right."""
    body = line[: column - 1] + text + line[column - 1 + len(text) : 68]
    return body + str(tle_checksum(body))


@pytest.mark.parametrize(
    ("line", "column", "text", "message"),
    [
        (1, 21, "400.00000000", "line 1, columns 21-32: the epoch day of the year is 400.00000000; allowed: 1 to"),
        (1, 21, "000.00000000", "line 1, columns 21-32: the epoch day of the year is 000.00000000; allowed: 1 to"),
        # 2017 is a common year: day 366 had been read as 2018-01-01
        (1, 21, "366.50000000", "line 1, columns 21-32: the epoch day of the year is 366.50000000; allowed: 1 to 365"),
        (1, 19, "  ", "line 1, columns 19-20: the epoch year reads '  ', not a number of its form"),
        (1, 19, "57", "line 1, columns 19-32: the epoch is 1957-09-28T09:17:16Z"),
        (1, 54, " ABCDE-3", "line 1, columns 54-61: the B* reads ' ABCDE-3'"),
        (2, 9, "200.0000", "line 2, columns 9-16: the inclination [deg] is 200.0000; allowed: 0 to 180"),
        (2, 9, "        ", "line 2, columns 9-16: the inclination [deg] reads '        '"),
        (2, 27, "00A6238", "line 2, columns 27-33: the eccentricity (seven digits, decimal point assumed) reads"),
    ],
)
def test_a_damaged_field_is_named_by_its_line_and_columns(tmp_path, capsys, line, column, text, message):
    # SGP4 had read day 400 as 2018-02-04, a blank year as 2027, letters in B* as c_x A/m = nan, an
    # inclination of 200 as "--inclination 200 is out of range" (a flag never given).
    lines = [damaged(LINE1, column, text), LINE2] if line == 1 else [LINE1, damaged(LINE2, column, text)]
    path = tmp_path / "set.tle"
    path.write_text("\n".join(lines) + "\n")
    status, out, err = run(capsys, "lifetime", "--tle", path)
    assert status == 2 and out == ""
    assert err.startswith(f"orbit-env: error: {path}, {message}"), err


def test_every_shipped_element_set_passes_the_field_checks():
    # The checks must not refuse what the catalogues really publish: the 4228 sets of 34 objects.
    folder = Path(__file__).resolve().parents[2] / "benchmarks/data/reentry_tles"
    count = 0
    for path in sorted(folder.glob("*.tle")):
        lines = [line for line in path.read_text().splitlines() if line.strip()]
        ones = [k for k, line in enumerate(lines) if line.startswith("1 ")]
        for k in ones:
            parse_tle(lines[k], lines[k + 1])
            count += 1
    assert count == 4228


def test_a_name_line_in_latin_1_is_read_and_bytes_that_are_no_text_name_a_line(tmp_path, capsys):
    named = tmp_path / "named.tle"
    named.write_bytes("NSIGHT-1 \xe9tude\n".encode("latin-1") + f"{LINE1}\n{LINE2}\n".encode())
    status, out, _ = run(capsys, "lifetime", "--tle", named)
    assert status == 0 and "element set        NSIGHT-1 \xe9tude" in out
    named.write_bytes(b"NSIGHT\x85 1\n" + f"{LINE1}\n{LINE2}\n".encode())  # cp1252's ellipsis: U+0085 in Latin-1
    status, out, err = run(capsys, "lifetime", "--tle", named)
    assert status == 0, err  # it had split the name in two: "line 2: a TLE line has 69 columns, this one 1"
    noise = tmp_path / "noise.tle"
    noise.write_bytes(bytes(range(256)) * 4)
    status, _, err = run(capsys, "lifetime", "--tle", noise)
    assert status == 2 and err.startswith(f"orbit-env: error: {noise}") and "codec" not in err


def test_the_inclination_of_an_element_set_is_not_overridden(tmp_path, capsys):
    # --inclination 98 had flown the 51.6-degree set at 98 degrees and printed "inclination 98 deg" as the set's.
    path = tmp_path / "set.tle"
    path.write_text(f"{LINE1}\n{LINE2}\n")
    status, _, err = run(capsys, "lifetime", "--tle", path, "--inclination", "98")
    assert status == 2
    assert "--inclination: the element set gives the inclination (51.6391 deg); drop --inclination" in err
    status, _, err = run(capsys, "lifetime", "--batch", path, "--out", tmp_path / "o.csv", "--inclination", "98")
    assert status == 2 and "each object's element set gives its inclination" in err
    assert not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize(
    ("argv", "allowed"),
    [
        (["--perigee", "92", "--apogee", "93"], "--perigee 92 is out of range; allowed: 92.863 to 49992.863 km"),
        (["--perigee", "300", "--apogee", "49999"], "--apogee 49999 is out of range; allowed: --perigee (300) to"),
        (["--perigee", "1095", "--apogee", "1100", "--method", "curves"], "allowed: at most 1092.863 km"),
    ],
)
def test_height_bounds_are_given_above_the_users_surface(capsys, argv, allowed):
    # Under NRLMSIS heights are above the equatorial radius (7.137 km above the 6371 km sphere the decay
    # checks): "allowed: 100 to 50000 km" had refused 92 km while 93 km ran (100.137 km on the sphere).
    status, _, err = run(capsys, "lifetime", "--atmosphere", "msis", *argv)
    assert status == 2 and allowed in err, err
    status, _, err = run(capsys, "lifetime", "--perigee", "92", "--apogee", "93")  # the paper's sphere: as typed
    assert status == 2 and "allowed: 100 to 50000 km" in err


OBSERVATIONS = "days,perigee_km,apogee_km\n0,350,700\n18.52,347.5,680.5\n39.04,344.4,657.4\n140.57,314.5,492.3\n"


def test_fit_density_refuses_a_reentry_before_the_last_observation(tmp_path, capsys):
    path = tmp_path / "obs.csv"
    path.write_text(OBSERVATIONS)
    status, _, err = run(capsys, "fit-density", path, "--reentry", "100")
    assert status == 2
    assert "the re-entry (100) is not after the last observation (" in err and "line 5" in err
    status, out, _ = run(capsys, "fit-density", path, "--reentry", "200")
    assert status == 0 and "density scale" in out


def test_fit_density_refuses_data_that_leave_the_scale_undetermined(tmp_path, capsys):
    # 350 -> 300 -> 349 km: a decay, then a raise. The fit had printed "0.06777 (68%: 1.755e-17 to 2.617e+14)".
    path = tmp_path / "obs.csv"
    path.write_text("days,perigee_km,apogee_km\n0,350,700\n10,300,700\n20,349,699\n")
    status, out, err = run(capsys, "fit-density", path)
    assert status == 2 and out == ""
    assert "the data do not determine the density scale" in err and "beyond 0.001 to 1000" in err


def test_a_solar_table_that_ends_before_the_decay_starts_is_refused(tmp_path, capsys):
    # Every day of the decay had been the table's last row held, with exit status 0 and a warning.
    table = tmp_path / "solar.csv"
    table.write_text("date,f107,f107a,ap\n2013-10-01,132,125,9\n2013-10-02,130,125,8\n")
    argv = ["lifetime", "--perigee", "300", "--apogee", "400", "--atmosphere", "msis", "--solar-csv", table]
    status, out, err = run(capsys, *argv, "--epoch", "2020-01-01")
    assert status == 2 and out == ""
    assert "ends on 2013-10-02, before the decay starts on 2020-01-01" in err


ORBIT = ["lifetime", "--perigee", "300", "--apogee", "400"]


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        # An OverflowError traceback, and 1e150 blamed on "--area 7.85e+299".
        (["--shape", "sphere", "--mass", "10", "--diameter-m", "1e160"], "--diameter-m 1e160 is out of range"),
        (["--shape", "sphere", "--mass", "10", "--diameter-m", "1e150"], "--diameter-m 1e150 is out of range"),
        # Read as the year 20200101 ("out of range"); a bad month echoed as '2020-13-15'.
        (["--epoch", "20200101"], "cannot read the date '20200101'"),
        (["--epoch", "2020-13"], "cannot read the date '2020-13';"),
        # "mass_kg / area_m2=1e-300", a parameter's name on the command line.
        (["--mass", "1e-300", "--area", "1"], "--mass / --area 1e-300 is out of range; allowed: 0.01 to 100000"),
        # "must be a positive integer" for 0, "an integer 10 to 1000000" for 1.
        (["--uncertainty", "--samples", "0"], "--samples 0 is out of range; allowed: an integer 10 to 1000000"),
        (["--atmosphere", "msis", "--daily-ap"], "--daily-ap chooses a dated decay's Ap: it goes with --epoch"),
    ],
)
def test_a_value_is_refused_in_the_command_lines_words(capsys, argv, start):
    status, out, err = run(capsys, *ORBIT, *argv)
    assert status == 2 and out == ""
    assert err.startswith(f"orbit-env: error: {start}") and err.count("\n") == 1, err


def test_a_number_beyond_any_orbit_is_printed_in_four_digits(capsys):
    status, _, err = run(capsys, "lifetime", "--semi-major-axis-km", "1e300", "--eccentricity", "0")
    assert status == 2 and "(a = 1e+300 km, e = 0.0000000) is flown at 1e+300 x 1e+300 km" in err
    assert len(err) < 300  # it had printed 301 digits three times


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        ([*ORBIT, "--trajectory", ""], "--trajectory"),
        ([*ORBIT, "--plot", ""], "--plot"),
        (["fig2", "--out", ""], "--out"),
    ],
)
def test_an_empty_output_name_is_refused(capsys, tmp_path, monkeypatch, argv, flag):
    # --trajectory "" and --plot "" had written nothing and exited 0; fig2 --out "" said "--out  is a directory".
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    assert f"argument {flag}: an empty file name" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_standard_output_is_no_output_file(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # --trajectory - had written a file named "-"
    with pytest.raises(SystemExit):
        main([*ORBIT, "--trajectory", "-"])
    assert "'-' (standard output) is not written to" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_figure_format_that_needs_latex_is_offered_only_with_latex(capsys, tmp_path):
    import shutil

    pytest.importorskip("matplotlib")
    from matplotlib import rcParams

    if shutil.which(rcParams["pgf.texsystem"]) is not None:
        pytest.skip("this machine has LaTeX: PGF is written")
    # The figure had been refused only after the computing: "RuntimeError: 'xelatex' not found".
    status, out, err = run(capsys, *ORBIT, "--plot", tmp_path / "decay.pgf")
    assert status == 2 and out == "" and "the file name's extension gives the figure's format" in err
    assert ".pgf" not in err.split("allowed:")[1]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--reentry-sigma-days", "2"], "--reentry-sigma-days is an uncertainty of a fit to a re-entry"),
        (["--height-sigma-km", "2"], "--height-sigma-km is an uncertainty of a fit to a re-entry"),
    ],
)
def test_fit_density_refuses_a_re_entrys_uncertainty_without_the_re_entry(capsys, tmp_path, argv, message):
    path = tmp_path / "obs.csv"
    path.write_text(OBSERVATIONS)
    status, _, err = run(capsys, "fit-density", path, *argv)
    assert status == 2 and message in err
    assert run(capsys, "fit-density", path, "--reentry", "200", *argv)[0] == 0


def test_options_that_change_nothing_with_element_sets_are_refused(capsys, tmp_path):
    path = tmp_path / "set.tle"
    path.write_text(f"{LINE1}\n{LINE2}\n")
    status, _, err = run(capsys, "lifetime", "--tle", path, "--drag-from", "ndot", "--mass", "10", "--area", "1")
    assert status == 2 and "--drag-from chooses what an element set's drag is read from" in err
    assert "the satellite given (--mass, --area)" in err
    status, _, err = run(capsys, "lifetime", "--tle", path, "--drag-from", "ndot", "--cx", "2.2")
    assert status == 2 and "the satellite given (--cx) flies its own drag" in err
    batch = tmp_path / "batch.csv"
    batch.write_text("perigee_km,apogee_km\n300,400\n")
    argv = ["lifetime", "--batch", batch, "--out", tmp_path / "o.csv", "--semi-major-axis-km", "6800"]
    status, _, err = run(capsys, *argv, "--eccentricity", "0")
    assert status == 2 and "do not give --semi-major-axis-km/--eccentricity" in err
    assert not (tmp_path / "o.csv").exists()


def test_a_batch_of_histories_shows_its_drag_fits_progress(tmp_path, capsys):
    # The fits (NRLMSIS over each day of a history's span, cold) had run with nothing shown: 13 s for 34 objects.
    path = tmp_path / "sets.tle"
    path.write_text("\n".join(NSIGHT[:4]) + "\n")  # two sets of one object: a history
    status, _, err = run(capsys, "lifetime", "--batch", path, "--out", tmp_path / "o.csv")
    assert status == 0 and "drag: 100%" in err and "1/1" in err
    status, _, err = run(capsys, "lifetime", "--batch", path, "--out", tmp_path / "p.csv", "--no-progress")
    assert status == 0 and err == ""


@pytest.mark.parametrize(
    "argv",
    [
        ["--semi-major-axis-km", "6778", "--eccentricity", "0.001"],  # J2's shift to the orbit flown
        ["--perigee", "400", "--apogee", "420", "--atmosphere", "exponential"],  # equatorial heights to geodetic
    ],
)
def test_the_inclination_is_taken_in_still_air_where_it_changes_the_life(capsys, argv):
    # A refusal of --inclination in still uniform air (a review's wish) had left these at 0 degrees.
    satellite = ["--mass", "100", "--area", "1", "--json"]
    lives = []
    for inclination in ("0", "97"):
        status, out, _ = run(capsys, "lifetime", *argv, *satellite, "--inclination", inclination)
        assert status == 0
        lives.append(json.loads(out)["days"])
    assert lives[1] > 1.05 * lives[0]  # measured: 181.70 -> 238.82 days, 206.51 -> 245.86 at 90 deg


def test_a_re_entry_day_may_be_the_day_of_the_last_observation(tmp_path, capsys):
    # A day-only date is the whole day: a last tracking that afternoon had been called "after" the re-entry.
    path = tmp_path / "obs.csv"
    path.write_text("date,perigee_km,apogee_km\n2020-01-01,350,700\n2020-03-01,340,620\n2020-05-20T14:00,300,400\n")
    argv = ["fit-density", path, "--atmosphere", "paper", "--mass", "100", "--area", "1", "--reentry"]
    status, out, err = run(capsys, *argv, "2020-05-20")
    assert status == 0 and "density scale" in out, err
    status, _, err = run(capsys, *argv, "2020-05-20T12:00")
    assert status == 2 and "is not after the last observation" in err
