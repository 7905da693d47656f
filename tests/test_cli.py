"""The command line and the Python API at the public boundary."""

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from orbit_env.analysis.lifetime import Satellite, lifetime, make_satellite
from orbit_env.cli import main


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_lifetime_json_has_the_public_keys(capsys):
    status, out, _ = run(capsys, "lifetime", "--perigee", "360", "--apogee", "800", "--json")
    assert status == 0
    result = json.loads(out)
    for key in ("nu", "revolutions", "days", "perigee_velocity_m_s"):
        assert math.isfinite(result[key]) and result[key] > 0
    assert result["nu"] == pytest.approx(lifetime(360, 800).nu, rel=1e-12)


def test_satellite_options(capsys):
    _, out, _ = run(capsys, "lifetime", "--perigee", "300", "--apogee", "600", "--mass-per-area", "100", "--json")
    by_load = json.loads(out)
    _, out, _ = run(capsys, "lifetime", "--perigee", "300", "--apogee", "600", "--mass", "100", "--area", "1", "--json")
    by_mass = json.loads(out)
    assert by_load["revolutions"] == pytest.approx(by_mass["revolutions"], rel=1e-12)
    # Eq. (4.1): N = nu (G/F) / (g c_x).
    assert by_load["revolutions"] == pytest.approx(by_load["nu"] * 100 / (9.81 * 2.0), rel=1e-12)


def test_methods_agree(capsys):
    results = {}
    for method in ("averaged", "curves"):
        _, out, _ = run(capsys, "lifetime", "--perigee", "250", "--apogee", "900", "--method", method, "--json")
        results[method] = json.loads(out)
    assert results["curves"]["days"] == pytest.approx(results["averaged"]["days"], rel=5e-3)


def test_trajectory_and_plot_files(capsys, tmp_path):
    csv_path, png_path = tmp_path / "t.csv", tmp_path / "t.png"
    files = ("--trajectory", str(csv_path), "--plot", str(png_path))
    status, out, _ = run(capsys, "lifetime", "--perigee", "200", "--apogee", "400", *files)
    assert status == 0 and "revolutions" in out
    lines = csv_path.read_text().splitlines()
    assert lines[0] == "revolutions,days,perigee_km,apogee_km,nu_remaining"
    last = [float(x) for x in lines[-1].split(",")]
    assert last[2] == pytest.approx(100.0, abs=1e-6) and last[4] == 0.0
    assert png_path.stat().st_size > 10_000


def test_table2_json(capsys):
    status, out, _ = run(capsys, "table2", "--json")
    assert status == 0
    cells = json.loads(out)
    assert len(cells) == 351
    keys = {"perigee_km", "apogee_km", "nu_paper", "nu", "rel_error", "v_perigee_paper", "v_perigee"}
    assert keys <= set(cells[0])
    assert np.median([abs(c["rel_error"]) for c in cells]) <= 0.05


def test_table2_text_summary(capsys):
    status, out, _ = run(capsys, "table2")
    assert status == 0
    assert out.splitlines()[-2].startswith("351 cells: median |error|")
    assert out.splitlines()[-1].startswith("with the paper's own Euler scheme")


def test_fig2(capsys, tmp_path):
    status, _, _ = run(capsys, "fig2", "--out", str(tmp_path / "fig2.png"))
    assert status == 0 and (tmp_path / "fig2.png").stat().st_size > 20_000


@pytest.mark.parametrize(
    "argv",
    [
        ["lifetime", "--perigee", "50", "--apogee", "800"],
        ["lifetime", "--perigee", "500", "--apogee", "400"],
        ["lifetime", "--perigee", "nan", "--apogee", "400"],
        ["lifetime", "--perigee", "300", "--apogee", "400", "--cx", "-1"],
        ["lifetime", "--perigee", "300", "--apogee", "400", "--mass", "10"],
        ["lifetime", "--perigee", "300", "--apogee", "400", "--mass-per-area", "0"],
        ["lifetime", "--perigee", "300", "--apogee", "400", "--rho100", "-3"],
        ["lifetime", "--perigee", "300", "--apogee", "400", "--method", "magic"],
        ["lifetime", "--perigee", "abc", "--apogee", "400"],
        ["lifetime", "--perigee", "1200", "--apogee", "1300", "--method", "curves"],
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, argv):
    try:
        status = main(argv)
    except SystemExit as raised:  # argparse's own errors (through our one-line parser)
        status = raised.code
    _, err = capsys.readouterr()
    assert status == 2
    assert err.count("\n") == 1 and "error" in err and "Traceback" not in err


finite = st.floats(allow_nan=True, allow_infinity=True, width=64)


@given(finite, finite)
def test_api_never_returns_nan(perigee_km, apogee_km):
    try:
        result = lifetime(perigee_km, apogee_km, method="curves") if apogee_km <= 4000 else None
    except ValueError as error:
        assert str(error)  # a clear message, never a NaN
        return
    if result is not None:
        assert all(math.isfinite(v) and v >= 0 for v in (result.nu, result.revolutions, result.days))


@given(st.floats(140, 1000), st.floats(0, 2000), st.floats(1, 300))
def test_lifetime_rises_with_perigee(perigee_km, extra_km, step_km):
    low = lifetime(perigee_km, perigee_km + extra_km, method="curves")
    if perigee_km + step_km <= 1100 and perigee_km + extra_km + step_km <= 4000:
        high = lifetime(perigee_km + step_km, perigee_km + extra_km + step_km, method="curves")
        assert high.days > low.days


def test_satellite_validation():
    with pytest.raises(ValueError, match="mass"):
        Satellite(mass_kg=0)
    with pytest.raises(ValueError, match="not both"):
        make_satellite(2.0, 10.0, 1.0, 50.0)
    # Section 4: for the paper's sphere, 4G / (pi d^2) / (g c_x) is about 2.6.
    assert Satellite().revolutions_per_nu == pytest.approx(2.6, abs=0.01)
