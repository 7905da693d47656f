"""The drag an element set carries: B* read against SGP4's density, calibrated to the prediction's air, histories."""

import dataclasses
import math

import numpy as np
import pytest

pytest.importorskip("sgp4")

from sgp4.api import WGS72, Satrec

from orbit_env.analysis.air import MsisAir, PaperAir, ProfileAir
from orbit_env.analysis.drag_calibration import (
    air_drag_rate,
    calibrate,
    fit_history,
    sgp4_density_kg_m3,
)
from orbit_env.analysis.elements import ElementSet
from orbit_env.analysis.scenario import Scenario
from orbit_env.constants import MU_EARTH_M3_S2
from orbit_env.decay.solar import ConstantActivity
from orbit_env.physics.atmosphere import FunctionAtmosphere


def satrec_at(height_km, bstar, eccentricity=0.0005):
    satrec = Satrec()
    n_rad_min = math.sqrt(398600.8 / (6378.135 + height_km) ** 3) * 60.0
    satrec.sgp4init(WGS72, "i", 1, 24000.0, bstar, 0.0, 0.0, eccentricity, 0.5, math.radians(51.6), 0.2, n_rad_min, 0.7)
    return satrec


def sgp4_mean_a_m(satrec, days):
    satrec.sgp4(satrec.jdsatepoch, satrec.jdsatepochF + days)
    return satrec.am * satrec.radiusearthkm * 1e3


@pytest.mark.parametrize(("height_km", "bstar"), [(140.0, 5e-6), (250.0, 2e-5), (400.0, 1e-4), (550.0, 3e-4)])
def test_bstar_against_our_reading_of_sgp4s_density_gives_sgp4s_own_decay(height_km, bstar):
    # SGP4's mean semi-major axis falls by some 40-100 m a day here; our reading of B* (C_D A/m = 2 B*/rho0
    # with SGP4's power-law density, rho0 at 120 km, s lowered under a 156 km perigee) and the orbit average
    # da/dt = -(a^2/mu) c <rho v^3> give the same drop within 1-2% (measured). 5% holds that; a wrong
    # reference density, exponent or s moves it by far more (s = 78 km at 140 km: a factor of ~3).
    satrec = satrec_at(height_km, bstar)
    drop_m = sgp4_mean_a_m(satrec, 0.0) - sgp4_mean_a_m(satrec, 1.0 if height_km > 200 else 0.2)
    days = 1.0 if height_km > 200 else 0.2
    a_m, e = satrec.a * satrec.radiusearthkm * 1e3, satrec.ecco
    sgp4_air = Scenario(ProfileAir(FunctionAtmosphere(lambda h: sgp4_density_kg_m3(h + 6371e3, a_m * (1 - e)))))
    c = 2.0 * bstar / 0.15696615
    ours_m = a_m * a_m / MU_EARTH_M3_S2 * c * air_drag_rate(sgp4_air, a_m, e, 51.6, None) * 86400.0 * days
    assert drop_m == pytest.approx(ours_m, rel=0.05)


def test_calibration_makes_the_air_reproduce_the_sets_decay():
    # Whatever the air, the calibrated c times the air's drag rate is 2 B*/rho0 times SGP4's: the set's decay.
    elements = ElementSet("test", 19000.0, 6378.137 + 500.0, 0.001, 97.5, 2e-4, 1, 1e-5, "99999")
    for scenario in (
        Scenario(PaperAir()),
        Scenario(MsisAir(ConstantActivity(70.0, 70.0, 5.0))),
        Scenario(MsisAir(ConstantActivity(250.0, 250.0, 30.0)), density_scale=2.0),
    ):
        result = calibrate(elements, scenario)
        flown_a_m = (elements.semi_major_axis_km + elements.flown_offset_km) * 1e3
        ours = result.drag_parameter_m2_kg * air_drag_rate(scenario, flown_a_m, 0.001, 97.5, 19000.0)
        q = elements.semi_major_axis_km * 1e3 * 0.999
        sgp4_air = Scenario(ProfileAir(FunctionAtmosphere(lambda h, q=q: sgp4_density_kg_m3(h + 6371e3, q))))
        sgp4 = elements.drag_parameter_m2_kg * air_drag_rate(
            sgp4_air, elements.semi_major_axis_km * 1e3, 0.001, 97.5, None
        )
        assert ours == pytest.approx(sgp4, rel=1e-9)
    # In a quiet Sun at 500 km SGP4's static density is several times the real air's: the calibration
    # raises c by that factor (the reason the raw 2 B*/rho0 puts re-entries centuries late).
    quiet = calibrate(elements, Scenario(MsisAir(ConstantActivity(70.0, 70.0, 5.0))))
    assert quiet.density_ratio > 3.0 and quiet.drag_parameter_m2_kg > 3.0 * elements.drag_parameter_m2_kg


def _decay_sets(scenario, c_true, a0_km, days=range(0, 31, 3)):
    """Element sets of one object (11111) made from the model's own decay: a dropped by c times the air's rate."""
    sets, a_km = [], a0_km
    for k, day in enumerate(days):
        sets.append(ElementSet("x", 20000.0 + day, a_km, 0.0005, 51.6, 1e-4, 1, 1e-5, "11111"))
        if k + 1 < len(days):
            flown_a_m = (a_km + sets[-1].flown_offset_km) * 1e3
            rate = flown_a_m**2 / MU_EARTH_M3_S2 * air_drag_rate(scenario, flown_a_m, 0.0005, 51.6, None)
            a_km -= c_true * rate * (days[k + 1] - day) * 86400.0 / 1e3
    return sets


def test_a_history_fit_recovers_the_drag_of_a_decay_made_in_the_same_air():
    # Element sets made from the model's own decay (the semi-major axis dropped by c times the air's rate)
    # give back c; the fit's residual is then zero.
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    c_true, a0_km = 0.02, 6378.137 + 400.0
    sets = _decay_sets(scenario, c_true, a0_km)
    fit = fit_history(sets, scenario)
    # The fit interpolates a between the sets and steps daily: within 1%.
    assert fit.drag_parameter_m2_kg == pytest.approx(c_true, rel=0.01)
    assert fit.sets == 11 and fit.span_days == pytest.approx(30.0)
    with pytest.raises(ValueError, match="of 11111, 22222"):
        fit_history([*sets, ElementSet("y", 20001.0, a0_km, 0.0005, 51.6, 1e-4, 1, 1e-5, "22222")], scenario)
    rising = [ElementSet("x", 20000.0 + k, a0_km + k, 0.0005, 51.6, 1e-4, 1, 1e-5, "11111") for k in range(3)]
    with pytest.raises(ValueError, match="does not fall"):
        fit_history(rising, scenario)


def test_a_history_fit_weighs_the_first_set_as_any_other():
    # Every set's semi-major axis is a measurement with its error, the first one's too: the fit takes the start
    # as a parameter rather than the first set as exact. In an air held constant the sets, 3 days apart, have
    # nearly symmetric leverage, so an error of +50 m in the first set moves c as an error of -50 m in the last
    # does: within 5% (3.1% measured: the rate rises a little as a falls, so the model's drop is not quite
    # linear in time). Held as exact, the first set's error moved c 5.5 times as much as the last set's (the
    # old estimator, measured on these sets), which is what this test tells apart.
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    sets = _decay_sets(scenario, 0.02, 6378.137 + 400.0)
    first = [dataclasses.replace(sets[0], semi_major_axis_km=sets[0].semi_major_axis_km + 0.05), *sets[1:]]
    last = [*sets[:-1], dataclasses.replace(sets[-1], semi_major_axis_km=sets[-1].semi_major_axis_km - 0.05)]
    exact = fit_history(sets, scenario).drag_parameter_m2_kg
    shift_first = fit_history(first, scenario).drag_parameter_m2_kg - exact
    shift_last = fit_history(last, scenario).drag_parameter_m2_kg - exact
    assert shift_first > 0.0 and shift_last > 0.0
    assert shift_first == pytest.approx(shift_last, rel=0.05)


def test_a_history_fit_is_the_same_with_half_its_steps_in_a_forked_child(request, monkeypatch):
    # fit_history hands half of its daily steps' air to a forked child (`in_two_processes`): each step is
    # computed on its own, so the fit is the same bit for bit as in one process. BEESAT-4's last four sets
    # (45 daily steps, under the record's Sun).
    from orbit_env import workers
    from orbit_env.analysis.elements import read_tle
    from orbit_env.decay.solar_record import load_record

    sets = read_tle(next(DATA.glob("41619_*.tle")))[-4:]
    scenario = Scenario(MsisAir(load_record(), sets[-1].epoch_days), rotating_atmosphere=True)
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", "off")  # else the second fit reads the first's air from disk
    monkeypatch.setattr(workers, "can_fork", lambda: False)
    alone = fit_history(sets, scenario)
    monkeypatch.undo()
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", "off")
    request.getfixturevalue("forking")
    forks = []
    original = workers.Forked.__init__
    monkeypatch.setattr(workers.Forked, "__init__", lambda self, *a, **k: forks.append(1) or original(self, *a, **k))
    split = fit_history(sets, scenario)
    assert forks  # the steps were split
    assert split == alone


def test_a_history_fits_air_is_kept_on_disk_under_a_key_of_all_it_reads(monkeypatch, tmp_path):
    # A fit's daily air (NRLMSIS over the orbit, about 30 ms a step) is kept in the disk cache: the same
    # sets in the same air are fitted again without NRLMSIS, to the same bit; a scale, another Sun or
    # other sets are another key (each computed afresh, and the scale's fit exactly what it must be).
    from orbit_env import workers
    from orbit_env.analysis.elements import read_tle
    from orbit_env.decay.solar_record import load_record

    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path))
    from orbit_env.decay.chunked import SolarDecayModel

    monkeypatch.setattr(workers, "can_fork", lambda: False)  # every step's air in this process, counted
    calls = []
    original = SolarDecayModel.density_on_day_kg_m3
    monkeypatch.setattr(SolarDecayModel, "density_on_day_kg_m3", lambda *a, **k: calls.append(1) or original(*a, **k))
    sets = read_tle(next(DATA.glob("41619_*.tle")))[-4:]
    scenario = Scenario(MsisAir(load_record(), sets[-1].epoch_days), rotating_atmosphere=True)
    first = fit_history(sets, scenario)
    steps = len(calls)
    assert steps == 45 and len(list(tmp_path.glob("v-*/fit-*.npz"))) == 1  # 45 daily steps over 44.2 days
    assert fit_history(sets, scenario) == first and len(calls) == steps  # read back, no NRLMSIS
    scaled = fit_history(sets, Scenario(scenario.air, density_scale=2.0, rotating_atmosphere=True))
    assert len(calls) == 2 * steps
    assert scaled.drag_parameter_m2_kg == pytest.approx(first.drag_parameter_m2_kg / 2.0, rel=1e-12)
    quiet = MsisAir(ConstantActivity(70.0, 70.0, 4.0), sets[-1].epoch_days)
    assert fit_history(sets, Scenario(quiet, rotating_atmosphere=True)) != first and len(calls) == 3 * steps
    fit_history(sets[1:], scenario)
    assert len(calls) > 3 * steps and len(list(tmp_path.glob("v-*/fit-*.npz"))) == 4


def test_a_history_fit_reads_each_days_own_air_as_the_decay_does(monkeypatch):
    # Each daily step of the fit is flown in its calendar day's air, the row the decay reads on that day
    # (until 2026-12-07 the mean of the 5 days before the step, the one-set calibration's window: the air lagged
    # by two days). So a Sun changed on the days before the first set's does not move the fit, one changed on
    # a day between the sets does. BEESAT-4's last four sets; the record's indices, with no 3-hourly ap.
    from orbit_env.analysis.elements import read_tle
    from orbit_env.decay.solar_record import load_record

    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", "off")
    record = load_record()
    sets = read_tle(next(DATA.glob("41619_*.tle")))[-4:]
    first_day = math.floor(sets[0].epoch_days)

    class Changed:
        """The record's indices, F10.7 x 1.5 on the days ``low`` to ``high`` (calendar days)."""

        def __init__(self, low: float, high: float) -> None:
            self.low, self.high = low, high

        def indices(self, days):
            f107, f107a, ap = record.indices(days)
            day = np.floor(days)
            return np.where((day >= self.low) & (day <= self.high), 1.5 * f107, f107), f107a, ap

    def fit(activity):
        return fit_history(sets, Scenario(MsisAir(activity, sets[-1].epoch_days), rotating_atmosphere=True))

    plain = fit(Changed(0.0, -1.0))
    assert fit(Changed(first_day - 4.0, first_day - 1.0)) == plain
    inside = fit(Changed(first_day + 10.0, first_day + 13.0))
    assert inside.drag_parameter_m2_kg < 0.99 * plain.drag_parameter_m2_kg  # denser days: less drag to fit


def test_ndot_and_bstar_agree_when_the_set_is_self_consistent():
    # A set whose ndot is SGP4's own decay rate of B* gives the same calibrated c from either.
    satrec = satrec_at(400.0, 1e-4)
    a0, a1 = sgp4_mean_a_m(satrec, 0.0), sgp4_mean_a_m(satrec, 1.0)
    n = lambda a: math.sqrt(MU_EARTH_M3_S2 / a**3) * 86400.0 / (2 * math.pi)  # noqa: E731
    ndot = n(a1) - n(a0)  # rev/day^2 over one day
    a_km = satrec.a * satrec.radiusearthkm
    elements = ElementSet("t", 20000.0, a_km, satrec.ecco, 51.6, 1e-4, 1, ndot, "1")
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    from_bstar = calibrate(elements, scenario).drag_parameter_m2_kg
    from_ndot = calibrate(elements, scenario, source="ndot_calibrated").drag_parameter_m2_kg
    # The two differ by the 1-2% between SGP4's decay and our reading of it (test above): 5%.
    assert from_ndot == pytest.approx(from_bstar, rel=0.05)
    assert np.isfinite(from_bstar)


# ---- the command line on real element sets (benchmarks/data/reentry_tles, sources in its README)

DATA = __import__("pathlib").Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "reentry_tles"


def real_sets(norad, last, count):
    """The ``count`` sets of object ``norad`` ending with its ``last``-th set (negative: from the end), as text."""
    from orbit_env.analysis.elements import read_tle

    path = next(DATA.glob(f"{norad}_*.tle"))
    lines = path.read_text().splitlines()
    sets = read_tle(path)
    end = len(sets) + last + 1 if last < 0 else last + 1
    chosen = sets[end - count : end]
    return "\n".join(f"{lines[s.line - 1]}\n{lines[s.line]}" for s in chosen) + "\n", chosen[-1]


def run_json(capsys, *argv):
    import json

    from orbit_env.cli import main

    status = main(["lifetime", *argv, "--json"])
    out, err = capsys.readouterr()
    return status, (json.loads(out) if status == 0 else None), err


@pytest.mark.parametrize(
    ("norad", "reentry", "count"),
    [
        # BEESAT-4: SATCAT decay 2023-09-23; its last sets, 34-78 days before (objects.csv).
        (41619, "2023-09-23T12:00", 4),
        # CZ-5B Y2 core stage: 2021-05-09T02:14Z (18 SPCS); its sets 7.6-9.7 days before.
        (48275, "2021-05-09T02:14", 8),
        # AAUSAT 4: SATCAT decay 2023-09-06; its last sets.
        (41460, "2023-09-06T12:00", 4),
    ],
)
def test_real_reentries_from_one_set_and_from_a_history(capsys, tmp_path, norad, reentry, count):
    # The re-entry goal of issue 27 for a history is +-25% of the remaining life for 90% of the cases and
    # for one set a median of 20%: each of these three, predicted from the latest set (one set) and from
    # the history of the last sets, lands within +-25% of the observed remaining life.
    from orbit_env.decay.solar import unix_days

    text, latest = real_sets(norad, -1, count)
    history = tmp_path / "history.tle"
    history.write_text(text)
    one = tmp_path / "one.tle"
    one.write_text("\n".join(text.splitlines()[-2:]) + "\n")
    observed = unix_days(reentry) - latest.epoch_days
    status, result, err = run_json(capsys, "--tle", str(history))
    assert status == 0, err
    assert result["drag_parameter_source"] == "history_fit" and result["drag_fit"]["sets"] >= 2
    assert result["days"] == pytest.approx(observed, rel=0.25)
    status, result, err = run_json(capsys, "--tle", str(one))
    if latest.bstar_per_earth_radius > 0:
        assert status == 0, err
        assert result["drag_parameter_source"] == "bstar_calibrated"
        assert result["days"] == pytest.approx(observed, rel=0.25)


def test_several_objects_in_one_file_are_an_error_naming_them(capsys, tmp_path):
    first, _ = real_sets(41619, -1, 1)
    second, _ = real_sets(41460, -1, 1)
    path = tmp_path / "two.tle"
    path.write_text(first + second)
    status, _, err = run_json(capsys, "--tle", str(path))
    assert status == 2
    assert "2 objects (41460, 41619)" in err and "--batch" in err


@pytest.mark.parametrize("uncertainty", [False, True])
def test_a_batch_of_element_sets_starts_each_object_at_its_own_epoch_in_the_real_suns_air(
    capsys, tmp_path, uncertainty
):
    # What --tle does for one object, --batch does for each: NRLMSIS under the record's Sun from the object's
    # latest set (the paper's undated air was the batch's default), each object's sets its history.
    import csv

    from orbit_env.analysis.lifetime import iso_datetime
    from orbit_env.cli import main

    beesat, beesat_latest = real_sets(41619, -1, 4)  # a history of four sets (the how-to's example)
    other, other_latest = real_sets(41460, -1, 1)  # AAUSAT 4, one set: B* calibrated
    path = tmp_path / "two.tle"
    path.write_text(beesat + other)
    out = tmp_path / "out.csv"
    extra = ["--uncertainty", "--samples", "20", "--workers", "1"] if uncertainty else []
    status = main(["lifetime", "--batch", str(path), "--out", str(out), "--no-progress", *extra])
    text, _ = capsys.readouterr()
    assert status == 0
    assert "NRLMSIS 2.1, CelesTrak space weather" in text and "from each row's epoch (its latest element set)" in text
    rows = {row["name"]: row for row in csv.DictReader(out.open())}
    for latest, sets in ((beesat_latest, beesat), (other_latest, other)):
        one = tmp_path / f"{latest.catalogue_number}.tle"
        one.write_text(sets)
        _, single, _ = run_json(capsys, "--tle", str(one))
        row = rows[latest.name]
        assert single["drag_parameter_source"] in ("history_fit", "bstar_calibrated")
        # The same drag parameter (the same calibration or fit, in the same air at the same dates).
        assert float(row["drag_parameter_m2_kg"]) == pytest.approx(single["drag_parameter_m2_kg"], rel=1e-5)
        # The same decay but for the batch's inclination groups (INCLINATION_STEP_DEG; measured 0.06-0.08% on
        # two 2013 objects) and for where its steps fall (the objects of all epochs share one run, each joining it
        # at its own: within 0.26% on twelve orbits, docs/how-to/catalogue.md): within 0.5%.
        assert float(row["days"]) == pytest.approx(single["days"], rel=5e-3)
        assert row["epoch"] == iso_datetime(latest.epoch_days)
        assert row["reentry_date"] == iso_datetime(latest.epoch_days + float(row["days"]))
        if uncertainty:
            assert row["reentry_date_p5"] < row["reentry_date_p50"] < row["reentry_date_p95"]
            assert row["reentry_date_p5"] > row["epoch"]


def test_a_history_with_no_set_near_its_latest_falls_back_on_the_latest_set_and_says_so(capsys, tmp_path):
    # AggieSat 4's file: its latest set (2018-02-15) has no other within HISTORY_SPAN_DAYS, so there is no
    # decay to fit. The prediction is the latest set's alone (B* calibrated), as from a file of that set,
    # and the report says why (it was an error, in a batch a row without a lifetime).
    import csv

    from orbit_env.analysis.drag_calibration import NoHistoryToFit
    from orbit_env.analysis.elements import read_tle
    from orbit_env.cli import main

    path = next(DATA.glob("41313_*.tle"))
    sets = read_tle(path)
    assert len(sets) > 1
    with pytest.raises(NoHistoryToFit):
        fit_history(sets, Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0))))
    latest, _ = real_sets(41313, -1, 1)
    one = tmp_path / "latest.tle"
    one.write_text(latest)
    status, history, _ = run_json(capsys, "--tle", str(path))
    _, alone, _ = run_json(capsys, "--tle", str(one))
    assert status == 0 and history["drag_parameter_source"] == "bstar_calibrated"
    assert history["drag_note"].startswith("no history fit: a drag fit needs sets at least a day apart")
    assert history["days"] == alone["days"] and "drag_note" not in alone
    out = tmp_path / "out.csv"
    assert main(["lifetime", "--batch", str(path), "--out", str(out), "--no-progress"]) == 0
    (row,) = csv.DictReader(out.open())
    # The file's numbers carry six digits.
    assert row["status"] == "ok" and float(row["drag_parameter_m2_kg"]) == pytest.approx(
        alone["drag_parameter_m2_kg"], rel=1e-5
    )


@pytest.mark.slow
def test_real_reentries_from_element_sets_meet_the_goals():
    # benchmarks/validate_element_sets.py over the 32 objects (72 cases, 3-13 minutes on 2 cores, as warm as
    # its disk cache): measured on 2026-12-07 one set median |error| 14.2%, history 7.8% with 93.8% of cases
    # within +-25%, band coverage 90.1% and 93.8%. Held to issue 27's goals: one set median <= 20%, history
    # median <= 10% and 90% within +-25%, the 90% band holding >= 85% (the history's median was held to 12%
    # while it missed its goal: 11.3% before its fit flew each day in that day's air).
    import benchmark_scripts

    script = benchmark_scripts.load("validate_element_sets")
    objects = [o for o in script.load_objects() if not o.flagged]
    cases = script.run_cases(objects, history=True, samples=200, limit=None)
    summary = script.summarize(cases)
    one, history = summary["one set"]["all"], summary["history"]["all"]
    assert one["median_abs_error"] <= 0.20
    assert one["band_coverage"] >= 0.85
    assert history["median_abs_error"] <= 0.10
    assert history["within_25"] >= 0.90
    assert history["band_coverage"] >= 0.85
