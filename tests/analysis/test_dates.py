"""Dates on lifetimes (re-entry date, dated history and plot) and lives longer than the propagation."""

import csv
import json

import numpy as np
import pytest

pytest.importorskip("pymsis")

from orbit_env.cli import main
from orbit_env.decay import chunked
from orbit_env.decay.chunked import SolarDecayModel
from orbit_env.decay.solar import unix_days

ORBIT = ["lifetime", "--perigee", "300", "--apogee", "300", "--inclination", "51.6"]
CUBESAT = ["--mass", "4", "--area", "0.03", "--cx", "2.2"]


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_reentry_date_is_the_epoch_plus_the_lifetime(capsys, tmp_path):
    trajectory = tmp_path / "t.csv"
    status, out, _ = run(capsys, *ORBIT, *CUBESAT, "--epoch", "2015-05-01", "--json", "--trajectory", str(trajectory))
    result = json.loads(out)
    assert status == 0 and result["reentered"] is True and result["epoch"] == "2015-05-01T00:00Z"
    reentry = unix_days("2015-05-01") + result["days"]
    assert result["reentry_date"] == str(np.datetime64(round(reentry * 1440), "m")) + "Z"
    rows = list(csv.DictReader(trajectory.open()))
    assert rows[0]["date"] == "2015-05-01T00:00Z" and rows[-1]["date"] == result["reentry_date"]
    # Days and dates agree on every row, to the minute.
    for row in rows:
        assert unix_days(row["date"].rstrip("Z")) == pytest.approx(
            unix_days("2015-05-01") + float(row["days"]), abs=1e-3
        )


def test_outliving_the_propagation_is_a_result(capsys, monkeypatch):
    # A 0.3-year cap stands in for the 200 years (same code path, a test's time).
    def short(*args, **kwargs):
        return SolarDecayModel(*args, **{**kwargs, "max_years": 0.3})

    monkeypatch.setattr(chunked, "SolarDecayModel", short)
    argv = ["lifetime", "--perigee", "500", "--apogee", "500", *CUBESAT, "--epoch", "2015-05-01"]
    status, out, _ = run(capsys, *argv, "--json")
    result = json.loads(out)
    assert status == 0
    assert result["reentered"] is False and result["days"] is None and result["years"] is None
    assert result["years_reached"] == pytest.approx(0.3, abs=20 / 365.25)  # a whole number of 20-day chunks
    assert "reentry_date" not in result
    status, out, _ = run(capsys, *argv)
    assert status == 0 and "still in orbit after 0 years" in out


def test_plot_carries_dates_and_the_sun(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "decay.png"
    status, _, _ = run(capsys, *ORBIT, *CUBESAT, "--epoch", "2015-05-01", "--plot", str(path))
    assert status == 0 and path.stat().st_size > 10_000


def test_a_dated_decays_history_counts_the_revolutions_each_row_has_flown():
    """The rows are days apart (20-day steps, then daily near re-entry): each row's revolutions are those flown.

    Independently of the trapezoid: between two rows the revolutions flown lie between the days
    over the longer and over the shorter of the two rows' periods (the period only falls).
    """
    from orbit_env import Satellite, lifetime
    from orbit_env.physics.orbit import elements_from_heights, period_s

    result = lifetime(450, 450, satellite=Satellite(2.2, 4.0, 0.03), epoch="2015-05-01", inclination_deg=51.6)
    history = result.history
    gaps = np.diff(history.days)
    assert gaps.max() > 10.0 > 2.0 > gaps.min()  # uneven rows: a row is not a fixed share of the revolutions
    period = period_s(*elements_from_heights(history.perigee_km * 1e3, history.apogee_km * 1e3)) / 86400.0
    flown = np.diff(history.revolutions)
    assert np.all(flown >= gaps / period[:-1] * (1 - 1e-12)) and np.all(flown <= gaps / period[1:] * (1 + 1e-12))
    assert history.revolutions[-1] == result.revolutions and history.revolutions[0] == 0.0
    assert history.nu_remaining[0] == pytest.approx(result.nu, rel=1e-12) and history.nu_remaining[-1] == 0.0


def test_a_dated_lifetime_reports_the_days_it_has_reached_and_a_terminal_shows_the_years(monkeypatch, capsys):
    # A cold decay over decades computes their air (38 s for a 700 km cubesat) and showed nothing. lifetime's
    # progress gets the days reached after each chunk, up to the life; the command draws them as years on a
    # terminal once a decay has run a second, and clears them; the results are those of a run without it.
    import io
    import sys

    from orbit_env import Satellite, lifetime
    from orbit_env.analysis.air import MsisAir
    from orbit_env.analysis.scenario import Scenario
    from orbit_env.cli import lifetime as command
    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    pytest.importorskip("pymsis")
    reached = []
    scenario = Scenario(MsisAir(load_record(), unix_days("2024-01-01")), rotating_atmosphere=True)
    result = lifetime(300, 320, satellite=Satellite(2.2, 4.0, 0.03), scenario=scenario, progress=reached.append)
    # One call a 20-day chunk, the last at the end of the chunk that holds the re-entry.
    assert reached == [20.0 * (k + 1) for k in range(len(reached))] and result.days <= reached[-1] < result.days + 20

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    argv = ["lifetime", "--perigee", "300", "--apogee", "320", "--mass", "4", "--area", "0.03", "--epoch"]
    argv += ["2024-01-01", "--inclination", "51.6"]
    assert main(argv) == 0
    plain = capsys.readouterr().out
    screen = Terminal()
    monkeypatch.setattr(sys, "stderr", screen)
    monkeypatch.setattr(command.YearsBar, "AFTER_S", 0.0)
    assert main(argv) == 0
    assert capsys.readouterr().out == plain
    drawn = screen.getvalue()
    assert drawn.startswith("\ryears decayed: 0.") and drawn.endswith("\r")
