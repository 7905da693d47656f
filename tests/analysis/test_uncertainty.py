"""Lifetime uncertainty: seeded samples, closed forms on a fixed profile, the solar interpolation, the CLI keys."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.stats import norm

from orbit_env.analysis import uncertainty as U
from orbit_env.analysis.air import MsisAir, PaperAir
from orbit_env.analysis.scenario import Scenario
from orbit_env.cli import main

SIGMA = math.hypot(U.DENSITY_MODEL_SIGMA, U.DRAG_COEFFICIENT_SIGMA)


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_seeded_samples_repeat():
    a, b = U.sample_factors(500, 7), U.sample_factors(500, 7)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not np.array_equal(U.sample_factors(500, 8)[1], a[1])


def test_fixed_profile_percentiles_and_probability_from_the_log_normal():
    # Paper's atmosphere: one lifetime d0 divided by each sample's log-normal factor (exact, Eq. 3.4),
    # so ln(days) ~ N(ln d0, SIGMA^2).
    scenario = Scenario(PaperAir())
    c = 2.0 * 0.19635 / 10.0
    d0 = float(scenario.lifetime_days(360e3, 800e3, c, 0.0)[0])
    spread = U.lifetime_spread(360e3, 800e3, c, scenario, 0.0, samples=20_000, seed=1)
    p = spread.percentiles_days()
    # Sampling error of a 5% quantile with 20 000 samples: about 0.015 sigma in ln; 1% is 4 of them.
    assert p["50"] == pytest.approx(d0, rel=0.01)
    assert p["5"] == pytest.approx(d0 * math.exp(-norm.ppf(0.95) * SIGMA), rel=0.01)
    assert p["95"] == pytest.approx(d0 * math.exp(norm.ppf(0.95) * SIGMA), rel=0.01)
    rule_days = 1.1 * d0
    expected = norm.cdf(math.log(rule_days / d0) / SIGMA)
    binomial = math.sqrt(expected * (1 - expected) / 20_000)
    assert spread.compliance_probability(rule_days / 365.25) == pytest.approx(expected, abs=4 * binomial)
    assert "solar_forecast" not in spread.sources  # a constant activity has no forecast to vary
    # Sample by sample: a denser air or a larger drag parameter shortens the life (the decay rate is linear
    # in rho c, Eq. 3.4), so each life is d0 / (density factor x drag factor), not d0 times it (the
    # percentiles above cannot tell the two apart: the factors are log-normal around 1).
    _, density, drag = U.sample_factors(20_000, 1)
    np.testing.assert_allclose(spread.days, d0 / (density * drag), rtol=1e-12)


@pytest.mark.slow
def test_solar_interpolation_against_samples_propagated_one_by_one():
    pytest.importorskip("pymsis")
    from orbit_env.decay.chunked import propagate
    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    record = load_record()
    # A 250 km cubesat from the end of the observations: a life of weeks, all of it in the forecast.
    start = record.observed_end_days
    scenario = Scenario(MsisAir(record, start), rotating_atmosphere=True)
    hp, c = 257e3, 0.0165
    spread = U.lifetime_spread(hp, hp, c, scenario, 51.6, samples=40, seed=3)
    z, density, drag = U.sample_factors(40, 3)
    base = scenario.solar_model(51.6)
    for k in range(4):
        factor = math.exp(U.SOLAR_FORECAST_SIGMA * z[k])
        model = replace(base, activity=U.ScaledForecast(record, factor, record.observed_end_days))
        direct = float(propagate(hp, hp, c, model, density_scale=density[k] * drag[k]).days[0])
        # Interpolation in z between nodes 1 apart: measured within 1.5% on a 420 km, 1-2 year case.
        assert spread.days[k] == pytest.approx(direct, rel=0.02)
    assert start > unix_days("2026-01-01")


def test_cli_reports_percentiles_dates_and_the_rule_as_a_probability(capsys):
    pytest.importorskip("pymsis")
    argv = ["lifetime", "--perigee", "300", "--apogee", "300", "--mass", "4", "--area", "0.03", "--cx", "2.2"]
    argv += ["--epoch", "2015-05-01", "--inclination", "51.6", "--uncertainty", "--samples", "200", "--seed", "5"]
    status, out, _ = run(capsys, *argv, "--rule", "0.1", "--json")
    first = json.loads(out)
    assert status == 0
    assert set(first["days_percentiles"]) == {"5", "50", "95"}
    assert set(first["reentry_date_percentiles"]) == {"5", "50", "95"}
    low, mid, high = (first["days_percentiles"][k] for k in ("5", "50", "95"))
    assert low < mid < high and mid == pytest.approx(first["days"], rel=0.05)
    assert 0.0 <= first["compliance_probability"] <= 1.0
    assert first["rule_verdict"].startswith(("complies: re-enters within 0.1 years", "does not comply"))
    status, out, _ = run(capsys, *argv, "--rule", "0.1", "--json")
    assert json.loads(out)["days_percentiles"] == first["days_percentiles"]  # seeded: the same twice


def test_a_bad_seed_names_the_flag(capsys):
    status, _, err = run(capsys, "lifetime", "--perigee", "300", "--apogee", "300", "--uncertainty", "--seed", "-1")
    assert status == 2 and err == "orbit-env: error: --seed -1 is out of range; allowed: an integer at least 0\n"


def test_each_node_propagates_only_its_samples_with_the_same_lifetimes():
    # lifetime_spread propagates at each solar node only the samples interpolated from it; the
    # satellites of one propagation do not affect each other, so every sample's lifetime must be
    # exactly the one from propagating all samples at every node (bit for bit).
    pytest.importorskip("pymsis")
    from orbit_env.decay.chunked import propagate
    from orbit_env.decay.solar_record import load_record

    record = load_record()
    # From a month after the last observed day: all of the life in the forecast, which the nodes scale.
    start = record.observed_end_days + 30.0
    scenario = Scenario(MsisAir(record, start), rotating_atmosphere=True)
    hp, c, n = 300e3, 0.0165, 60
    spread = U.lifetime_spread(hp, hp, c, scenario, 51.6, samples=n, seed=11)
    z, density, drag = U.sample_factors(n, 11)
    base = scenario.solar_model(51.6)
    log_days = []
    for node in U.SOLAR_NODES:
        factor = math.exp(U.SOLAR_FORECAST_SIGMA * node)
        model = replace(base, activity=U.ScaledForecast(record, factor, record.observed_end_days))
        days = propagate(np.full(n, hp), np.full(n, hp), c, model, density_scale=density * drag).days
        log_days.append(np.log(days))
    nodes = np.array(U.SOLAR_NODES)
    right = np.clip(np.searchsorted(nodes, z), 1, nodes.size - 1)
    w = (z - nodes[right - 1]) / (nodes[right] - nodes[right - 1])
    cols = np.arange(n)
    expected = np.exp(np.array(log_days)[right - 1, cols] * (1.0 - w) + np.array(log_days)[right, cols] * w)
    assert np.all(spread.reentered)
    assert set(np.unique(right)) == {1, 2, 3, 4}  # samples in every interval between the nodes
    assert np.ptp(np.array(log_days)[:, 0]) > 0.01  # the nodes differ: the forecast's factor matters
    np.testing.assert_array_equal(spread.days, expected)


@pytest.mark.parametrize("forked", [True, False])
def test_nodes_in_worker_processes_give_the_same_lifetimes_and_hand_back_their_air(
    tmp_path, monkeypatch, request, forked
):
    # --workers runs the solar nodes after the first in worker processes (forked where this process may fork,
    # else spawned): the same lifetimes bit for bit, and the rows of the real Sun's air they computed come back
    # to this process's tables (else the next run would compute them again: a forked worker writes no table).
    pytest.importorskip("pymsis")
    from orbit_env import workers
    from orbit_env.decay import daily_air
    from orbit_env.decay.solar_record import load_record

    if forked:
        request.getfixturevalue("forking")
    else:
        monkeypatch.setattr(workers, "can_fork", lambda: False)
    methods = []
    pool = workers._pool
    monkeypatch.setattr(
        workers, "_pool", lambda processes, how, **kw: methods.append(how) or pool(processes, how, **kw)
    )
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path))  # the workers find no air on disk
    record = load_record()
    # Scaled forecasts no other test of this process has met.
    start = record.observed_end_days + (45.0 if forked else 75.0)
    scenario = Scenario(MsisAir(record, start), rotating_atmosphere=True)
    hp, c, n = 300e3, 0.0165, 60
    parallel = U.lifetime_spread(hp, hp, c, scenario, 51.6, samples=n, seed=13, workers=2)

    def no_nrlmsis(*args, **kwargs):
        raise AssertionError("a row the workers computed was not handed back")

    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", no_nrlmsis)
    serial = U.lifetime_spread(hp, hp, c, scenario, 51.6, samples=n, seed=13, workers=1)
    assert methods == ["fork" if forked else "spawn"]
    np.testing.assert_array_equal(parallel.days, serial.days)
    np.testing.assert_array_equal(parallel.reentered, serial.reentered)
    assert np.all(serial.reentered)


@pytest.mark.parametrize("workers", [1, 2])
def test_the_nodes_show_a_bar_on_a_terminal_only_and_clear_it(monkeypatch, workers):
    # A cold --uncertainty over decades computes each node's air: tens of seconds that showed nothing. The
    # command line asks for a bar of the nodes; tqdm draws it on a terminal only and clears it at the end, so
    # the printed results are those of a run without it.
    import io
    import sys

    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    pytest.importorskip("pymsis")

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    scenario = Scenario(MsisAir(load_record(), unix_days("2024-01-01")), rotating_atmosphere=True)
    runs = {}
    for progress in (False, True):
        screen = Terminal()
        monkeypatch.setattr(sys, "stderr", screen)
        spread = U.lifetime_spread(300e3, 320e3, 0.0165, scenario, 51.6, samples=50, workers=workers, progress=progress)
        runs[progress] = (spread.days, screen.getvalue())
    assert runs[False][1] == ""
    assert "samples' solar nodes:   0%" in runs[True][1] and runs[True][1].endswith("\r")
    np.testing.assert_array_equal(runs[True][0], runs[False][0])
