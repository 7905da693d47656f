"""The modern CLI: atmospheres, batch CSV files, the disposal rule; and poliastro's drag test."""

import csv
import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from orbit_env.analysis.lifetime import Satellite, lifetime
from orbit_env.cli import main
from orbit_env.physics.atmosphere import ExponentialAtmosphere


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_poliastro_drag_test_48_2_days():
    # poliastro's test_atmospheric_demise: 230 km circular, C_D 2.2, A = pi/4 m^2, m = 100 kg,
    # rho = 1.3 exp(-h / 8.5 km) kg/m^3, re-enters at 48.2 days. The issue asks for 2%; we are
    # within 0.3% (the difference: the re-entry criterion, the gravitational parameter and the
    # curves' interpolation; the radius heights are measured from moves the lives by 0.04% at most).
    satellite = Satellite(2.2, 100.0, math.pi / 4)
    atmosphere = ExponentialAtmosphere(1.3, 0.0, 8.5e3)
    for method in ("averaged", "curves"):
        result = lifetime(230, 230, satellite=satellite, atmosphere=atmosphere, method=method)
        assert result.days == pytest.approx(48.2, rel=0.02)


def test_cli_exponential_matches_the_api(capsys):
    argv = ["lifetime", "--perigee", "230", "--apogee", "230", "--atmosphere", "exponential", "--cx", "2.2"]
    law = ["--rho0", "1.3", "--h0-km", "0", "--scale-height-km", "8.5"]  # poliastro's sea-level law
    status, out, _ = run(capsys, *argv, *law, "--mass", "100", "--area", str(math.pi / 4), "--json")
    assert status == 0
    assert json.loads(out)["days"] == pytest.approx(48.2, rel=0.02)
    status, out, _ = run(
        capsys, *argv, "--mass", "100", "--area", "0.785", "--rho0", "1.3", "--h0-km", "0", "--scale-height-km", "17"
    )
    assert status == 0 and "scale height 17 km" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--f107", "100"], "--f107 applies to --atmosphere msis"),
        (["--atmosphere", "msis", "--rho0", "1"], "--rho0 applies to --atmosphere exponential"),
        (["--atmosphere", "msis", "--solar-cycle"], "--solar-cycle needs --epoch"),
        (["--atmosphere", "msis", "--cycle-phase", "0.3"], "--cycle-phase applies to --solar-cycle"),
        (["--atmosphere", "msis", "--f107", "10"], "--f107 10 is out of range; allowed: 40 to 400 sfu"),
        (["--atmosphere", "msis", "--epoch", "2024-13-01"], "cannot read the date"),
        (["--out", "x.csv"], "--out goes with --batch"),
    ],
)
def test_cli_errors_are_one_line(capsys, argv, message):
    status, _, err = run(capsys, "lifetime", "--perigee", "400", "--apogee", "400", *argv)
    assert status == 2
    assert message in err and err.count("\n") == 1


def test_cli_msis_constant_and_rule(capsys):
    pytest.importorskip("pymsis")
    base = ["lifetime", "--perigee", "500", "--apogee", "500", "--atmosphere", "msis", "--inclination", "51.6"]
    sat = ["--cx", "2.2", "--mass", "4", "--area", "0.03"]
    status, out, _ = run(
        capsys, *base, *sat, "--f107", "150", "--ap", "15", "--rule", "1", "--method", "curves", "--json"
    )
    result = json.loads(out)
    assert status == 0 and result["days"] > 365.25 and not result["complies"]
    assert result["dv_m_s"] > 0 and 100 < result["new_perigee_km"] < 500
    after = lifetime(
        result["new_perigee_km"],
        500,
        satellite=Satellite(2.2, 4.0, 0.03),
        atmosphere=pytest.importorskip("orbit_env.physics.atmosphere.msis").MsisAtmosphere(150, 150, 15, 51.6),
        method="curves",
    )
    assert after.days <= 365.25
    # More solar activity, shorter life.
    _, out_high, _ = run(capsys, *base, *sat, "--f107", "250", "--method", "curves", "--json")
    assert json.loads(out_high)["days"] < 0.6 * result["days"]


def test_cli_solar_csv(capsys, tmp_path):
    pytest.importorskip("pymsis")
    flux = tmp_path / "flux.csv"
    rows = [f"2024-{m:02d},{160 + 5 * (m % 3)}" for m in range(1, 13)] + ["2025-01,150"]
    flux.write_text("date,f107\n" + "\n".join(rows) + "\n")
    status, out, _ = run(
        capsys, "lifetime", "--perigee", "300", "--apogee", "300", "--atmosphere", "msis", "--solar-csv", str(flux),
        "--inclination", "51.6", "--cx", "2.2", "--mass", "100", "--area", "1",
    )  # fmt: skip
    assert status == 0
    assert "solar table" in out and "from 2024-01-15 in 20-day steps" in out
    # Activity that changes in time: the default method is the time-stepped curves, not the
    # averaged reference (which rebuilds NRLMSIS every day and takes minutes).
    assert "method             curves" in out


def write_catalogue(path, n, seed=0):
    rng = np.random.default_rng(seed)
    hp = rng.uniform(200, 900, n)
    ha = hp + rng.exponential(200, n)
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["name", "perigee_km", "apogee_km", "mass_kg", "area_m2", "cx"])
        for i in range(n):
            writer.writerow([f"sat{i}", f"{hp[i]:.3f}", f"{ha[i]:.3f}", "100", f"{rng.uniform(0.5, 2):.3f}", "2.2"])
    return hp, ha


def test_batch_matches_single_lifetimes_and_reports_bad_rows(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    with open(sats, "w") as handle:
        handle.write("name,perigee_km,apogee_km,mass_kg,area_m2,mass_per_area_kg_m2\n")
        handle.write("a,300,500,100,1,\n")
        handle.write("b,400,400,,,50\n")
        handle.write("c,500,450,100,1,\n")  # apogee below perigee
        handle.write("d,1200,1300,100,1,\n")  # outside the curves
        handle.write("e,abc,300,100,1,\n")
        handle.write("f,350,360,,,\n")  # the CLI's satellite
    out = tmp_path / "out.csv"
    status, stdout, err = run(
        capsys, "lifetime", "--batch", str(sats), "--out", str(out), "--no-progress", "--cx", "2.2"
    )
    # Exit status 1: the file is complete, but 3 rows have no lifetime (one line on stderr says so).
    assert status == 1 and "6 rows" in stdout and "3 with lifetimes" in stdout
    assert err.startswith("orbit-env: 3 of 6 rows have no lifetime (first: line 4: ") and err.count("\n") == 1
    records = list(csv.DictReader(open(out)))
    assert [r["name"] for r in records] == ["a", "b", "c", "d", "e", "f"]
    expected = {
        "a": lifetime(300, 500, satellite=Satellite(2.2, 100, 1), method="curves").days,
        "b": lifetime(400, 400, satellite=Satellite.from_mass_per_area(50, 2.2), method="curves").days,
        "f": lifetime(350, 360, satellite=Satellite(2.2), method="curves").days,
    }
    for record in records:
        if record["name"] in expected:
            assert record["status"] == "ok"
            assert float(record["days"]) == pytest.approx(expected[record["name"]], rel=1e-5)
        else:
            assert record["status"] != "ok" and record["days"] == ""
    assert records[2]["status"] == "line 4: apogee_km=450 is out of range; allowed: perigee_km (500) to 50000 km"
    assert records[3]["status"] == (
        "line 5: perigee_km=1200 is out of range; allowed: at most 1100 km "
        "(the universal curves end there; the averaged ODE goes higher)"
    )
    assert records[4]["status"] == "line 6: perigee_km='abc' is not a number"


def test_batch_rows_with_bad_numbers_name_the_column_and_the_cell(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text(
        "perigee_km,apogee_km,mass_kg,area_m2,mass_per_area_kg_m2,inclination_deg\n"
        "300,500,0,1,,\n"
        "300,500,,,0,\n"
        "300,500,100,1,,200\n"
        "300,nan,100,1,,\n"
        "90,500,100,1,,\n"
        "300,500,100,1,,\n"
    )
    out = tmp_path / "out.csv"
    status, stdout, _ = run(capsys, "lifetime", "--batch", str(sats), "--out", str(out), "--no-progress")
    assert status == 1 and "6 rows" in stdout and "1 with lifetimes" in stdout
    assert [record["status"] for record in csv.DictReader(open(out))] == [
        "line 2: mass_kg=0 is out of range; allowed: above 0 and at most 1000000 kg "
        "(the largest satellite, the ISS, is 4.2e5 kg)",
        "line 3: mass_per_area_kg_m2=0 is out of range; allowed: 0.01 to 100000 kg/m^2 "
        "(ten times beyond a solar sail's 0.1 kg/m^2 and a solid metal body's 1e4 kg/m^2, metres across)",
        "line 4: inclination_deg=200 is out of range; allowed: 0 to 180 deg",
        "line 5: apogee_km=nan is not a finite number; allowed: a finite number",
        "line 6: perigee_km=90 is out of range; allowed: 100 to 50000 km (the decay ends at the re-entry height)",
        "ok",
    ]
    # A refused row's inclination and drag parameter are echoed as the row gave them (they had been blank).
    assert [record["inclination_deg"] for record in csv.DictReader(open(out))][2] == "200"
    bad_drag = tmp_path / "drag.csv"
    bad_drag.write_text("perigee_km,apogee_km,drag_parameter_m2_kg,inclination_deg\n400,420,-1,51.6\n")
    run(capsys, "lifetime", "--batch", str(bad_drag), "--out", str(tmp_path / "drag_out.csv"), "--no-progress")
    (record,) = csv.DictReader(open(tmp_path / "drag_out.csv"))
    assert (record["drag_parameter_m2_kg"], record["inclination_deg"]) == ("-1", "51.6")
    assert record["status"].startswith("line 2: drag_parameter_m2_kg=-1 is out of range")


def test_batch_rule_columns(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text("perigee_km,apogee_km,mass_kg,area_m2\n800,800,100,1\n500,500,100,1\n")
    out = tmp_path / "out.csv"
    status, _, _ = run(
        capsys, "lifetime", "--batch", str(sats), "--out", str(out), "--rule", "25", "--cx", "2.2", "--no-progress"
    )
    assert status == 0
    first, second = csv.DictReader(open(out))
    assert second["complies"] == "true" and float(second["dv_m_s"]) == 0.0
    assert first["complies"] == "false"
    # Independently: the perigee whose lifetime (the API, on the same curves) is 25 years,
    # by root finding, and the retrograde burn at the 800 km apogee that lowers the perigee
    # to it, by vis-viva with the package's fM = 3.986e14 m^3/s^2 and R = 6371 km.
    satellite = Satellite(2.2, 100.0, 1.0)
    exact_km = brentq(
        lambda hp: lifetime(hp, 800.0, satellite=satellite, method="curves").days - 25 * 365.25, 101.0, 800.0, xtol=1e-6
    )

    def lowering_dv_m_s(new_perigee_km):
        mu, ra = 3.986e14, 6371e3 + 800e3
        rp = 6371e3 + new_perigee_km * 1e3
        return math.sqrt(mu / ra) - math.sqrt(mu * (2.0 / ra - 2.0 / (ra + rp)))

    # The rule's search reports a complying perigee at most one step of its resolution,
    # (800 - 100 km) / 17^3 = 0.14 km, below the exact one: the burn is never smaller than
    # the exact burn and at most that step's worth larger (0.04 m/s here). 1e-3 km and
    # 1e-3 m/s cover the CSV's six significant digits.
    step_km = 700.0 / 17**3
    assert exact_km - step_km - 1e-3 <= float(first["new_perigee_km"]) <= exact_km + 1e-3
    dv_m_s = float(first["dv_m_s"])
    assert lowering_dv_m_s(exact_km) - 1e-3 <= dv_m_s <= lowering_dv_m_s(exact_km - step_km) + 1e-3


def test_batch_in_many_blocks_keeps_the_input_order(capsys, tmp_path, monkeypatch):
    # A catalogue is looked up in blocks of BLOCK rows; with blocks of 16, 100 rows make
    # six, and every row must still get its own lifetime, in input order. (The speed of
    # a 10^5-row catalogue is measured in benchmarks/bench_decay.py.)
    from orbit_env.analysis import catalogue

    monkeypatch.setattr(catalogue, "BLOCK", 16)
    sats, out = tmp_path / "sats.csv", tmp_path / "out.csv"
    write_catalogue(sats, 100)
    status, stdout, _ = run(capsys, "lifetime", "--batch", str(sats), "--out", str(out), "--no-progress")
    assert status == 0 and "100 rows" in stdout
    rows = list(csv.DictReader(open(sats)))
    records = list(csv.DictReader(open(out)))
    assert [r["name"] for r in records] == [r["name"] for r in rows]
    for row, record in zip(rows, records, strict=True):
        satellite = Satellite(2.2, 100.0, float(row["area_m2"]))
        expected = lifetime(float(row["perigee_km"]), float(row["apogee_km"]), satellite=satellite, method="curves")
        # 1e-5: the CSV's six significant digits.
        assert float(record["days"]) == pytest.approx(expected.days, rel=1e-5)


@pytest.mark.parametrize("rule", [[], ["--rule", "0.1"]])
def test_a_dated_batch_counts_its_satellites_as_they_re_enter(capsys, tmp_path, monkeypatch, rule):
    # The bar stood at 0 for the whole propagation of a dated batch (3 minutes for 2000 rows), then jumped to
    # the end: it moves now after each chunk, by the satellites re-entered. With --rule it had stood still until
    # the rule's search ended (its decays are a share each now); 0.1 year: most of these lives are longer.
    pytest.importorskip("pymsis")
    positions = []

    class Recorded:  # tqdm's bar as the user sees it: a disabled one (an inner loop's) shows nothing
        def __init__(self, total, disable=False, **kwargs):
            self.n, self.total, self.disable = 0, total, disable

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def update(self, k):
            self.n += k
            if not self.disable:
                positions.append(self.n)

    monkeypatch.setattr("tqdm.tqdm", Recorded)
    flux = tmp_path / "flux.csv"
    flux.write_text("date,f107\n" + "\n".join(f"2024-{m:02d},160" for m in range(1, 13)) + "\n2025-01,150\n")
    sats = tmp_path / "sats.csv"
    heights = np.linspace(250.0, 380.0, 12)  # lives of weeks to months: re-entries in many 20-day chunks
    sats.write_text("perigee_km,apogee_km,mass_kg,area_m2,cx\n" + "".join(f"{h},{h},400,1,2.2\n" for h in heights))
    status, stdout, _ = run(
        capsys, "lifetime", "--batch", str(sats), "--out", str(tmp_path / "out.csv"), "--atmosphere", "msis",
        "--solar-csv", str(flux), "--inclination", "51.6", *rule,
    )  # fmt: skip
    assert status == 0, stdout
    assert positions[-1] == 12 and positions == sorted(positions)
    assert len(set(positions)) >= 4  # several chunks' re-entries counted before the end
