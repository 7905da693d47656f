"""The command line and the Python API at the public boundary."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from orbit_env.analysis import plots
from orbit_env.analysis.elements import read_tle
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
    # The command line's default is the universal curves (the API's, the averaged reference): the same nu
    # as the API's curves, within the curves' 0.5% of the reference.
    assert result["method"] == "curves"
    assert result["nu"] == pytest.approx(lifetime(360, 800, method="curves").nu, rel=1e-12)
    assert result["nu"] == pytest.approx(lifetime(360, 800).nu, rel=5e-3)


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


def test_a_history_plot_draws_its_element_sets_where_the_decay_starts_from_the_latest(capsys, tmp_path, monkeypatch):
    # BEESAT-4's last four sets (benchmarks/data/reentry_tles): the plot's points are the sets' orbits flown,
    # on the decay's heights and days, so the latest sits on the decay's first point.
    source = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "reentry_tles" / "41619_beesat4.tle"
    tle = tmp_path / "beesat4.tle"
    tle.write_text("\n".join(source.read_text().split("\n")[-9:]))  # the last four sets (and the file's end)
    sets = read_tle(tle)
    assert len(sets) == 4
    drawn = {}
    real = plots.plot_history

    def spy(result, path, **keywords):
        drawn.update(keywords, result=result)
        return real(result, path, **keywords)

    monkeypatch.setattr(plots, "plot_history", spy)
    for air in ("msis", "paper"):  # dated: days from the epoch; the paper's undated air: from the latest set
        png = tmp_path / f"{air}.png"
        status, out, _ = run(capsys, "lifetime", "--tle", str(tle), "--atmosphere", air, "--plot", str(png), "--json")
        assert status == 0 and png.stat().st_size > 10_000
        summary, result = json.loads(out), drawn["result"]
        days, perigee, apogee = (np.array(column) for column in zip(*drawn["observed"], strict=True))
        # Days from the decay's start: the latest set's epoch, which dates the air to the second (1.2e-5 day).
        np.testing.assert_allclose(days, [s.epoch_days - sets[-1].epoch_days for s in sets], rtol=0, atol=1.2e-5)
        # The latest set's point is the decay's start, in the heights the plot draws (above the equator).
        offset = drawn["height_offset_km"]
        assert perigee[-1] == pytest.approx(result.history.perigee_km[0] - offset, abs=1e-6)
        assert apogee[-1] == pytest.approx(result.history.apogee_km[0] - offset, abs=1e-6)
        assert (perigee[-1], apogee[-1]) == pytest.approx((summary["perigee_km"], summary["apogee_km"]), abs=1e-6)
        assert np.all(np.diff(perigee) < 0.0)  # the sets decay


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


_ORBIT = ["lifetime", "--perigee", "400", "--apogee", "400"]
#: A complete exponential law (the three values go together): poliastro's sea-level law.
_LAW = ["--rho0", "1.3", "--h0-km", "0"]


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["lifetime", "--perigee", "50", "--apogee", "800"],
            "--perigee 50 is out of range; allowed: 100 to 50000 km (the decay ends at the re-entry height)",
        ),
        (
            ["lifetime", "--perigee", "500", "--apogee", "400.5"],
            "--apogee 400.5 is out of range; allowed: --perigee (500) to 50000 km",
        ),
        (
            ["lifetime", "--perigee", "1200", "--apogee", "1300", "--method", "curves"],
            "--perigee 1200 is out of range; allowed: at most 1100 km "
            "(the universal curves end there; the averaged ODE goes higher)",
        ),
        (
            [*_ORBIT, "--atmosphere", "exponential", *_LAW, "--scale-height-km", "-8.5"],
            "--scale-height-km -8.5 is out of range; allowed: 1 to 500 km "
            "(the air's scale height runs from 6 km near the ground to 100 km at 1000 km)",
        ),
        (
            [*_ORBIT, "--atmosphere", "exponential", "--rho0", "-1", "--h0-km", "0", "--scale-height-km", "8.5"],
            "--rho0 -1 is out of range; allowed: above 0 and at most 10 kg/m^3 (air at sea level is 1.2 kg/m^3)",
        ),
        (
            [*_ORBIT, "--atmosphere", "exponential", "--rho0", "1.3", "--h0-km", "inf", "--scale-height-km", "8.5"],
            "--h0-km inf is not a finite number; allowed: 0 to 2000 km "
            "(from sea level to the top of the orbits computed here)",
        ),
        (
            [*_ORBIT, "--atmosphere", "msis", "--inclination", "200"],
            "--inclination 200 is out of range; allowed: 0 to 180 deg",
        ),
        ([*_ORBIT, "--inclination", "200"], "--inclination 200 is out of range; allowed: 0 to 180 deg"),
        ([*_ORBIT, "--atmosphere", "msis", "--f107", "1e3"], "--f107 1e3 is out of range; allowed: 40 to 400 sfu"),
        (
            [*_ORBIT, "--atmosphere", "msis", "--node-local-time", "25"],
            "--node-local-time 25 is out of range; allowed: 0 to 24 h",
        ),
        (
            [*_ORBIT, "--atmosphere", "msis", "--solar-cycle", "--epoch", "2020-01-01", "--cycle-phase", "1.5"],
            "--cycle-phase 1.5 is out of range; allowed: 0 to 1",
        ),
        (
            [*_ORBIT, "--mass", "0", "--area", "1"],
            "--mass 0 is out of range; allowed: above 0 and at most 1000000 kg "
            "(the largest satellite, the ISS, is 4.2e5 kg)",
        ),
        (
            [*_ORBIT, "--mass", "10", "--area", "0.0"],
            "--area 0.0 is out of range; allowed: above 0 and at most 100000 m^2 "
            "(a 300 m drag sail; the ISS spans about 2500 m^2)",
        ),
        (
            [*_ORBIT, "--mass-per-area", "0"],
            "--mass-per-area 0 is out of range; allowed: 0.01 to 100000 kg/m^2 "
            "(ten times beyond a solar sail's 0.1 kg/m^2 and a solid metal body's 1e4 kg/m^2, metres across)",
        ),
        (
            [*_ORBIT, "--cx", "-1"],
            "--cx -1 is out of range; allowed: above 0 and at most 10 "
            "(free-molecular drag coefficients are 2 to 4 for any shape)",
        ),
        (
            [*_ORBIT, "--rho100", "-3"],
            "--rho100 -3 is out of range; allowed: 1e-08 to 0.0001 kg/m^3 "
            "(every model and season puts 100 km between 2e-7 and 2e-6 kg/m^3)",
        ),
        (
            [*_ORBIT, "--density-scale", "0"],
            "--density-scale 0 is out of range; allowed: 0.001 to 1000 "
            "(the models are off by a factor of a few at most; 1000 is another atmosphere)",
        ),
        ([*_ORBIT, "--rule", "0"], "--rule 0 is out of range; allowed: above 0 years"),
        ([*_ORBIT, "--msis-version", "00", "--atmosphere", "paper"], "--msis-version applies to --atmosphere msis"),
    ],
)
def test_bad_values_name_the_flag_and_the_value_as_typed(capsys, argv, message):
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == ""
    assert err == f"orbit-env: error: {message}\n"
    for internal in ("np.float64", "_m ", "_m=", "_kg_m3", "_deg", "Traceback"):
        assert internal not in err


def test_fit_density_flags_are_named(capsys, tmp_path):
    observations = tmp_path / "obs.csv"
    observations.write_text("date,perigee_km,apogee_km\n2020-01-01,300,320\n")
    argv = ["fit-density", str(observations), "--reentry", "2020-02-01", "--height-sigma-km", "-1"]
    status, _, err = run(capsys, *argv)
    assert status == 2
    assert err == "orbit-env: error: --height-sigma-km -1 is out of range; allowed: at least 0 km\n"


def test_fit_density_names_the_bad_observation(capsys, tmp_path):
    observations = tmp_path / "obs.csv"
    observations.write_text("days,perigee_km,apogee_km\n0,300,320\n1,300,290\n2,299,300\n")
    status, _, err = run(capsys, "fit-density", str(observations))
    assert status == 2
    assert err == (
        f"orbit-env: error: {observations}, line 3: apogee_km=290 is out of range; "
        "allowed: perigee_km (300) to 50000 km\n"
    )


def test_the_api_names_its_parameters_in_its_units():
    with pytest.raises(ValueError) as info:
        lifetime(np.float64(50.0), 800)
    assert str(info.value) == (
        "perigee_km=50 is out of range; allowed: 100 to 50000 km (the decay ends at the re-entry height)"
    )
    with pytest.raises(ValueError) as info:
        lifetime(300, 400, density_scale=-1)
    assert str(info.value) == (
        "density_scale=-1 is out of range; allowed: 0.001 to 1000 "
        "(the models are off by a factor of a few at most; 1000 is another atmosphere)"
    )
    with pytest.raises(ValueError) as info:
        lifetime(300, 400, inclination_deg=np.float64(-150.0))
    assert str(info.value) == "inclination_deg=-150 is out of range; allowed: 0 to 180 deg"


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
    with pytest.raises(ValueError, match=r"^mass_kg=0 is out of range; allowed: above 0 and at most 1000000 kg \("):
        Satellite(mass_kg=0)
    with pytest.raises(
        ValueError, match=r"^area_m2=nan is not a finite number; allowed: above 0 and at most 100000 m\^2"
    ):
        Satellite(area_m2=float("nan"))
    # Each value within its bounds, but together a body denser than any: mass / area is bounded too.
    with pytest.raises(
        ValueError, match=r"^mass_kg / area_m2=100000000 is out of range; allowed: 0.01 to 100000 kg/m\^2"
    ):
        Satellite(mass_kg=1e5, area_m2=1e-3)
    with pytest.raises(ValueError, match=r"^drag_coefficient=True is not a number \(got a bool\)"):
        make_satellite(True)
    with pytest.raises(ValueError, match="not both"):
        make_satellite(2.0, 10.0, 1.0, 50.0)
    # Section 4: for the paper's sphere, 4G / (pi d^2) / (g c_x) is about 2.6.
    assert Satellite().revolutions_per_nu == pytest.approx(2.6, abs=0.01)


def _lifetime_line_days(text):
    """The days of the text summary's lifetime line."""
    line = next(line for line in text.splitlines() if line.startswith("lifetime "))
    return float(line.split()[1])


def test_msis_version_00_is_nrlmsise00_and_shortens_the_life(capsys):
    pytest.importorskip("pymsis")
    orbit = ["lifetime", "--perigee", "400", "--apogee", "420", "--atmosphere", "msis", "--inclination", "51.6"]
    _, out, _ = run(capsys, *orbit, "--json")
    default = json.loads(out)
    status, out, _ = run(capsys, *orbit, "--msis-version", "00", "--json")
    v00 = json.loads(out)
    assert status == 0
    assert default["atmosphere"].startswith("NRLMSIS 2.1, ") and v00["atmosphere"].startswith("NRLMSISE-00, ")
    # The life goes about as 1/density, and NRLMSISE-00 is 8-19% denser (tests/physics/test_msis.py): 0.84-0.93,
    # with margin for the profile's shape.
    assert 0.80 < v00["days"] / default["days"] < 0.95
    _, out, _ = run(capsys, *orbit, "--msis-version", "2.1", "--json")
    assert json.loads(out) == default  # 2.1 given is the default


def test_msis_version_on_a_dated_life_and_in_the_text(capsys):
    pytest.importorskip("pymsis")
    orbit = ["lifetime", "--perigee", "300", "--apogee", "320", "--epoch", "2003-10-01", "--inclination", "28.5"]
    orbit += ["--mass", "4", "--area", "0.03", "--cx", "2.2"]
    _, default, _ = run(capsys, *orbit)
    status, v00, _ = run(capsys, *orbit, "--msis-version", "00")
    assert status == 0
    assert "atmosphere         NRLMSIS 2.1, " in default and "atmosphere         NRLMSISE-00, " in v00
    # The time-stepped path (bins and day ratios) in NRLMSISE-00: shorter, by about the density ratio.
    assert 0.80 < _lifetime_line_days(v00) / _lifetime_line_days(default) < 0.95


def test_fit_density_takes_the_msis_version(capsys, tmp_path):
    pytest.importorskip("pymsis")
    observations = tmp_path / "obs.csv"
    observations.write_text("days,perigee_km,apogee_km\n0,400,420\n")
    argv = ["fit-density", str(observations), "--reentry", "200", "--atmosphere", "msis", "--inclination", "51.6"]
    argv += ["--mass", "4", "--area", "0.03", "--cx", "2.2", "--json"]
    _, out, _ = run(capsys, *argv)
    default = json.loads(out)
    status, out, _ = run(capsys, *argv, "--msis-version", "00")
    v00 = json.loads(out)
    assert status == 0 and v00["atmosphere"].startswith("NRLMSISE-00, ")
    # The same decay in denser air takes a smaller scale: by the density ratio, 1/1.19 to 1/1.08.
    assert 0.80 < v00["scale"] / default["scale"] < 0.95


@pytest.mark.parametrize(
    ("percentiles", "expected"),
    [
        ({"5": 27.61, "50": 34.34, "95": 43.44}, "27.6 / 34.3 / 43.4 days"),  # a short band in days
        ({"5": 3393.0, "50": 6669.5, "95": 12108.0}, "9.29 / 18.26 / 33.15 years"),
        ({"5": 3393.0, "50": 6669.5, "95": None}, "9.29 / 18.26 years / beyond the propagation"),
        ({"5": None, "50": None, "95": None}, " / ".join(["beyond the propagation"] * 3)),
    ],
)
def test_the_band_is_in_days_when_it_is_short_and_in_years_otherwise(percentiles, expected):
    from orbit_env.cli.orbit_inputs import uncertainty_lines

    summary = {"days_percentiles": percentiles, "uncertainty_samples": 1000, "uncertainty_seed": 0}
    assert uncertainty_lines(summary)[0] == f"lifetime 5/50/95%  {expected} (1000 samples, seed 0)"
