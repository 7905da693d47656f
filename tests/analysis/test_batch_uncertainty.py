"""``orbit-env lifetime --batch --uncertainty``: bands seeded by the row, chunks over processes, resumed runs."""

import csv
import json
import os
import re
import sys

import numpy as np
import pytest
from test_elements import CUBESAT, ISS

from orbit_env.analysis import catalogue_parts
from orbit_env.analysis.air import PaperAir
from orbit_env.analysis.catalogue_uncertainty import row_key, row_seed
from orbit_env.analysis.scenario import Scenario
from orbit_env.analysis.uncertainty import RULE_CONFIDENCE, lifetime_spread
from orbit_env.cli import main, uncertain_batch

SATELLITES = """name,perigee_km,apogee_km,mass_kg,area_m2,cx
sphere,360,800,10,0.1963,2
cubesat-300,300,300,4,0.03,2.2
cubesat-450,450,460,4,0.03,2.2
cubesat-500,500,500,4,0.03,2.2
bad,50,800,10,0.1963,2
cubesat-550,550,560,4,0.03,2.2
cubesat-600,600,600,4,0.03,2.2
cubesat-650,650,650,4,0.03,2.2
cubesat-700,700,700,4,0.03,2.2
"""
BANDS = ["days_p5", "days_p50", "days_p95"]


def run(capsys, *argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def batch(capsys, tmp_path, text=SATELLITES, name="sats.csv", out="out.csv", *options):
    sats = tmp_path / name
    sats.write_text(text)
    status, stdout, err = run(
        capsys, "lifetime", "--batch", sats, "--out", tmp_path / out, "--uncertainty", "--no-progress", *options
    )
    return status, stdout, err, tmp_path / out


def records(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_columns_bands_rule_and_bad_rows(capsys, tmp_path):
    status, _, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 200, "--rule", 5)
    assert status == 1 and "1 of 9 rows have no lifetime" in err
    header = next(csv.reader(open(out)))
    assert header[header.index("days") :] == [
        "days",
        "years",
        "complies",
        "new_perigee_km",
        "dv_m_s",
        *BANDS,
        "compliance_probability",
        "complies_with_confidence",
        "uncertainty_seed",
        "status",
    ]
    assert "reentry_date_p50" not in header  # the paper's air has no date
    rows = records(out)
    bad = [row for row in rows if row["name"] == "bad"]
    assert bad[0]["status"].startswith("line 6: perigee_km=50 is out of range")
    assert all(bad[0][key] == "" for key in [*BANDS, "compliance_probability", "uncertainty_seed"])
    good = [row for row in rows if row["name"] != "bad"]
    probabilities = []
    for row in good:
        p5, p50, p95 = (float(row[key]) for key in BANDS)
        assert p5 <= p50 <= p95
        # A log-normal band around the nominal life: p50 within 5 standard errors of the median
        # (1.25 x sigma / sqrt(200) in ln days, sigma = hypot(0.15, 0.10)).
        assert np.log(p50 / float(row["days"])) == pytest.approx(0.0, abs=5 * 1.25 * 0.18 / np.sqrt(200))
        probability = float(row["compliance_probability"])
        probabilities.append(probability)
        assert 0.0 <= probability <= 1.0
        assert row["complies_with_confidence"] == str(probability >= RULE_CONFIDENCE).lower()
        # The fraction of samples within 5 years follows the band (one sample's share of slack for
        # the percentiles' interpolation between samples).
        rule_days = 5 * 365.25
        for quantile, value in ((0.05, p5), (0.5, p50), (0.95, p95)):
            if value <= rule_days:
                assert probability >= quantile - 1 / 200
            else:
                assert probability <= quantile + 1 / 200
    assert 0.0 < max(probabilities) and min(probabilities) < 1.0  # the screen has both sides
    assert any(0.0 < p < 1.0 for p in probabilities)  # and a satellite on the edge


def test_a_row_is_the_single_command_with_its_seed(capsys, tmp_path):
    _, _, _, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 100, "--seed", 3)
    row = records(out)[0]
    seed = int(row["uncertainty_seed"])
    single = ["lifetime", "--perigee", 360, "--apogee", 800, "--mass", 10, "--area", 0.1963, "--cx", 2]
    status, stdout, _ = run(capsys, *single, "--uncertainty", "--samples", 100, "--seed", seed, "--json")
    assert status == 0
    band = json.loads(stdout)["days_percentiles"]
    for p in ("5", "50", "95"):
        assert float(row[f"days_p{p}"]) == pytest.approx(band[p], rel=1e-5)  # the file's six digits
    # The same from the API: the row's key and seed, and lifetime_spread.
    c = 2 * 0.1963 / 10
    assert seed == row_seed(3, row_key({"name": "sphere"}, 360e3, 800e3, c, 0.0))
    spread = lifetime_spread(360e3, 800e3, c, Scenario(PaperAir()), 0.0, samples=100, seed=seed)
    assert float(row["days_p50"]) == pytest.approx(spread.percentiles_days()["50"], rel=1e-5)


def test_row_seeds_depend_on_the_row_and_the_base_seed():
    key = row_key({"name": "a"}, 400e3, 420e3, 0.01, 51.6)
    assert row_seed(0, key) == row_seed(0, key) < 2**52
    assert row_seed(1, key) != row_seed(0, key)
    assert row_seed(0, row_key({"name": "b"}, 400e3, 420e3, 0.01, 51.6)) != row_seed(0, key)
    assert row_seed(0, row_key({"name": "a"}, 400e3, 421e3, 0.01, 51.6)) != row_seed(0, key)
    # Stability: parts and files of earlier runs stay valid only if the derivation does not change.
    assert row_seed(0, "x") == 4408842719232104


def test_shuffled_rows_and_workers_give_the_same_numbers(capsys, tmp_path):
    lines = SATELLITES.splitlines()
    shuffled = "\n".join([lines[0], *reversed(lines[1:])]) + "\n"
    options = ("--samples", 100, "--rule", 25)
    _, _, _, one = batch(capsys, tmp_path, SATELLITES, "sats.csv", "one.csv", *options, "--workers", 1)
    _, stdout, _, two = batch(capsys, tmp_path, SATELLITES, "sats.csv", "two.csv", *options, "--workers", 2)
    assert "2 workers" in stdout
    assert one.read_bytes() == two.read_bytes()
    _, _, _, back = batch(capsys, tmp_path, shuffled, "shuffled.csv", "back.csv", *options, "--workers", 2)

    def by_name(path):  # the bad row's status names its line, which moved
        return {row["name"]: row for row in records(path) if row["name"] != "bad"}

    assert by_name(back) == by_name(one)
    _, _, _, other = batch(capsys, tmp_path, SATELLITES, "sats.csv", "other.csv", *options, "--seed", 1)
    assert by_name(other)["sphere"]["days_p5"] != by_name(one)["sphere"]["days_p5"]


def test_resumed_run_ends_with_the_same_file(capsys, tmp_path, monkeypatch):
    options = ("--samples", 50, "--rule", 25, "--workers", 1)
    _, _, _, whole = batch(capsys, tmp_path, SATELLITES, "sats.csv", "whole.csv", *options)
    computed = []
    call = uncertain_batch.ChunkRecords.__call__

    def stopped(self, start, stop):
        if start >= 5:
            raise KeyboardInterrupt  # Ctrl-C in the sixth chunk (one row each)
        computed.append(start)
        return call(self, start, stop)

    monkeypatch.setattr(uncertain_batch.ChunkRecords, "__call__", stopped)
    status, _, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", *options)
    assert status == 130 and "the same command resumes" in err and not out.exists()
    parts = sorted(catalogue_parts.parts_folder(out).glob("*.csv"))
    assert len(parts) == 5
    parts[2].unlink()  # and a part lost
    computed.clear()

    def counted(self, start, stop):
        computed.append(start)
        return call(self, start, stop)

    monkeypatch.setattr(uncertain_batch.ChunkRecords, "__call__", counted)
    status, stdout, _, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", *options)
    assert status == 1 and "4 already in" in stdout
    assert computed == [2, 5, 6, 7, 8]  # only the chunks without a part
    assert out.read_bytes() == whole.read_bytes()
    assert not catalogue_parts.parts_folder(out).exists()


def stopped_at_the_fourth_chunk(capsys, tmp_path, monkeypatch):
    """``sats.csv`` to ``out.csv`` with 50 samples, interrupted (Ctrl-C) at its fourth chunk: three parts kept."""
    call = uncertain_batch.ChunkRecords.__call__

    def stopped(self, start, stop):
        if start >= 3:
            raise KeyboardInterrupt
        return call(self, start, stop)

    monkeypatch.setattr(uncertain_batch.ChunkRecords, "__call__", stopped)
    batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 50, "--workers", 1)
    monkeypatch.setattr(uncertain_batch.ChunkRecords, "__call__", call)


def test_parts_of_another_command_are_refused_or_replaced(capsys, tmp_path, monkeypatch):
    _, _, _, fresh = batch(capsys, tmp_path, SATELLITES, "sats.csv", "fresh.csv", "--samples", 60, "--workers", 1)
    stopped_at_the_fourth_chunk(capsys, tmp_path, monkeypatch)
    status, stdout, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 60)
    assert status == 2 and "holds the parts of another run" in err and not out.exists()
    assert "workers:" not in stdout  # the refusal comes alone, not after a line about a run that does not start
    status, stdout, _, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 60, "--force")
    assert status == 1 and out.read_bytes() == fresh.read_bytes()
    assert re.search(r"\(\d+ parts? of another run deleted\)", stdout), stdout  # --force says what it deleted


def test_element_sets_are_dated_by_their_epochs(capsys, tmp_path):
    text = "\n".join([*CUBESAT, "ISS (ZARYA)", *ISS]) + "\n"
    status, _, _, out = batch(
        capsys, tmp_path, text, "sets.tle", "out.csv", "--atmosphere", "paper", "--samples", 50, "--rule", 25
    )
    cubesat, iss = records(out)
    assert status == 1 and iss["status"].startswith("line 5: B* = -1.1606e-05 /ER") and iss["reentry_date_p50"] == ""
    # The set's epoch 2024-04-09T12:00Z plus the life's percentiles (written to six digits: some 2300
    # days to 0.005 day, 7 minutes).
    epoch = np.datetime64("2024-04-09T12:00")
    for p in ("5", "50", "95"):
        date = np.datetime64(cubesat[f"reentry_date_p{p}"].rstrip("Z"))
        minutes = (date - epoch) / np.timedelta64(1, "m")
        assert minutes == pytest.approx(float(cubesat[f"days_p{p}"]) * 1440, abs=8)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--samples", "5"], "--samples 5 is out of range"),
        (["--rule", "0"], "--rule 0 is out of range"),
        (["--seed", "-1"], "--seed -1 is out of range"),
    ],
)
def test_bad_options_are_one_line_errors(capsys, tmp_path, options, message):
    status, _, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", *options)
    assert status == 2 and message in err and err.count("\n") == 1 and not out.exists()
    assert not catalogue_parts.parts_folder(out).exists()


def test_workers_need_uncertainty_and_the_address_a_batch(capsys, tmp_path):
    sats = tmp_path / "sats.csv"
    sats.write_text(SATELLITES)
    out = tmp_path / "out.csv"
    with pytest.raises(SystemExit) as stop:  # argparse's own error
        run(capsys, "lifetime", "--batch", sats, "--out", out, "--uncertainty", "--workers", 0)
    assert stop.value.code == 2
    assert "argument --workers: must be a positive integer, got 0" in capsys.readouterr().err
    status, _, err = run(capsys, "lifetime", "--batch", sats, "--out", out, "--workers", 2)
    assert status == 2 and "--workers goes with --uncertainty" in err
    status, _, err = run(capsys, "lifetime", "--perigee", 400, "--apogee", 400, "--workers", 2)
    assert status == 2 and "--workers goes with --uncertainty" in err
    status, _, err = run(capsys, "lifetime", "--perigee", 400, "--apogee", 400, "--uncertainty", "--address", "local")
    assert status == 2 and "--address goes with --batch FILE --uncertainty" in err
    # One orbit's band takes --workers (its solar nodes' processes; a fixed profile has none to share).
    status, out_text, _ = run(capsys, "lifetime", "--perigee", 400, "--apogee", 400, "--uncertainty", "--workers", 2)
    assert status == 0 and "lifetime 5/50/95%" in out_text


def test_dated_rows_repeat_across_workers_and_order(capsys, tmp_path):
    pytest.importorskip("pymsis")
    text = """name,perigee_km,apogee_km,mass_kg,area_m2,cx,inclination_deg
a,300,310,4,0.03,2.2,51.6
b,320,340,4,0.03,2.2,97.5
c,280,420,10,0.2,2.2,30
"""
    lines = text.splitlines()
    options = ("--epoch", "2024-01-01", "--samples", 10, "--rule", 1)
    _, _, _, one = batch(capsys, tmp_path, text, "dated.csv", "one.csv", *options, "--workers", 1)
    _, _, _, two = batch(capsys, tmp_path, text, "dated.csv", "two.csv", *options, "--workers", 2)
    assert one.read_bytes() == two.read_bytes()
    back_text = "\n".join([lines[0], *reversed(lines[1:])]) + "\n"
    _, _, _, back = batch(capsys, tmp_path, back_text, "back.csv", "back_out.csv", *options, "--workers", 1)
    assert sorted(records(back), key=lambda r: r["name"]) == records(one)
    for row in records(one):
        assert row["reentry_date_p5"] <= row["reentry_date_p50"] <= row["reentry_date_p95"]
        assert row["reentry_date_p5"] >= "2024-01-01"


def test_address_without_ray_names_the_extra(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray fails
    status, _, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--address", "local")
    message = "orbit-env: error: --address runs the chunks on Ray: pip install 'orbit-env[cluster]'\n"
    assert status == 2 and err == message
    assert not catalogue_parts.parts_folder(out).exists()
    status, _, err, _ = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--address", "x", "--workers", 2)
    assert status == 2 and "give --workers or --address, not both" in err


@pytest.mark.slow
def test_local_ray_writes_the_same_file(capsys, tmp_path):
    pytest.importorskip("ray")
    options = ("--samples", 50, "--rule", 25)
    _, _, _, here = batch(capsys, tmp_path, SATELLITES, "sats.csv", "here.csv", *options, "--workers", 1)
    status, stdout, _, ray = batch(capsys, tmp_path, SATELLITES, "sats.csv", "ray.csv", *options, "--address", "local")
    assert status == 1 and "Ray at local" in stdout
    assert ray.read_bytes() == here.read_bytes()


class DiesAt:
    """A chunk computation whose worker process dies at row ``row`` (as one killed by the system)."""

    def __init__(self, row):
        self.row = row

    def __call__(self, start, stop):
        if start <= self.row < stop:
            os._exit(1)
        return [{"name": f"r{i}", "days": str(i + 1), "status": "ok"} for i in range(start, stop)]


def test_a_lost_worker_keeps_the_finished_chunks(tmp_path):
    from concurrent.futures.process import BrokenProcessPool

    out = tmp_path / "out.csv"
    whole = tmp_path / "whole.csv"
    catalogue_parts.run_in_parts(whole, "0" * 16, 40, 5, DiesAt(-1), workers=1, progress=False, report=print)
    with pytest.raises(BrokenProcessPool):
        catalogue_parts.run_in_parts(out, "0" * 16, 40, 5, DiesAt(37), workers=2, progress=False, report=print)
    # The eighth chunk is sent once four have finished (four at most waiting on two workers): those are kept.
    assert not out.exists() and len(list(catalogue_parts.parts_folder(out).iterdir())) >= 4
    joined = catalogue_parts.run_in_parts(out, "0" * 16, 40, 5, DiesAt(-1), workers=2, progress=False, report=print)
    assert out.read_bytes() == whole.read_bytes() and (joined.rows, joined.ok, joined.max_days) == (40, 40, 40.0)


def test_parts_are_resumed_whatever_the_spelling_of_the_inputs_path(capsys, tmp_path, monkeypatch):
    # The path's text was in the fingerprint: ./sats.csv after sats.csv was "another run" (and --force would
    # have deleted the finished parts). The file's bytes are what identify the input.
    stopped_at_the_fourth_chunk(capsys, tmp_path, monkeypatch)
    monkeypatch.chdir(tmp_path)
    status, stdout, err = run(
        capsys, "lifetime", "--batch", "./sats.csv", "--out", "out.csv", "--uncertainty", "--no-progress",
        "--samples", 50, "--workers", 1,
    )  # fmt: skip
    assert status == 1 and "already in" in stdout, err


def test_a_rows_band_is_computed_at_its_inclination_group_as_its_nominal_life(monkeypatch):
    # The band at each row's own inclination had built a curve family (4.8 MB of cache, a fraction of a
    # second) per distinct value: 20 000 rows with two-decimal inclinations filled 18 GB within minutes. In
    # still air the inclination changes nothing: one family for every row.
    from orbit_env.analysis import catalogue_uncertainty
    from orbit_env.analysis.catalogue_io import BatchOrbits

    seen = []
    real = catalogue_uncertainty.lifetime_spread

    def spy(*args, **keywords):
        seen.append(args[4])
        return real(*args, **keywords)

    monkeypatch.setattr(catalogue_uncertainty, "lifetime_spread", spy)
    inclinations = np.array([33.21, 33.46, 32.7])
    n = inclinations.size
    orbits = BatchOrbits(
        [{"name": f"r{k}"} for k in range(n)],
        np.full(n, 400e3),
        np.full(n, 420e3),
        np.full(n, 0.0165),
        inclinations,
        ["ok"] * n,
        np.full(n, np.nan),
        np.full(n, np.nan),
    )
    rotating = Scenario(PaperAir(), rotating_atmosphere=True)
    catalogue_uncertainty.uncertain_lifetimes(orbits, rotating, samples=10, seed=0)
    assert seen == [33.0, 33.0, 33.0]  # the groups batch_lifetimes computes the nominal lives at
    seen.clear()
    catalogue_uncertainty.uncertain_lifetimes(orbits, Scenario(PaperAir()), samples=10, seed=0)
    assert seen == [33.21, 33.46, 32.7]  # where the inclination changes nothing, the row's own
    still = Scenario(PaperAir())
    assert {still.decay_model(i) for i in seen} == {still.decay_model(0.0)}  # one model, so one curve family


def test_a_second_command_on_the_same_results_is_refused_while_the_first_computes(capsys, tmp_path):
    # Both had computed every chunk, and the second ended in "no such file" once the first had joined the parts.
    import fcntl

    out = tmp_path / "out.csv"
    folder = catalogue_parts.parts_folder(out)
    folder.mkdir()
    with open(folder / catalogue_parts.LOCK_NAME, "a") as held:  # the first command's hold
        fcntl.flock(held, fcntl.LOCK_EX)
        status, _, err, _ = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 10)
    assert status == 2 and f"another command is computing the parts of {out} in {folder} now" in err
    status, _, _, _ = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 10, "--workers", 1)
    assert status == 1 and out.exists() and not folder.exists()  # released: the lock file goes with the folder


def test_a_full_disk_names_the_file_and_the_parts_kept(capsys, tmp_path, monkeypatch):
    import errno

    write = catalogue_parts.write_records
    written = []

    def full(path, records, **keywords):
        if len(written) == 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        written.append(path)
        write(path, records, **keywords)

    monkeypatch.setattr(catalogue_parts, "write_records", full)
    status, _, err, out = batch(capsys, tmp_path, SATELLITES, "sats.csv", "out.csv", "--samples", 10, "--workers", 1)
    assert status == 2 and "no space left on device" in err  # it had said "[Errno 28] No space left on device"
    assert f"the finished chunks are kept in {catalogue_parts.parts_folder(out)}" in err
    assert len(list(catalogue_parts.parts_folder(out).glob("*.csv"))) == 2
