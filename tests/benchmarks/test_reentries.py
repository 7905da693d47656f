"""The hindcasts of benchmarks/validate_reentries.py, held against the OBSERVED re-entries.

Every tolerance is on predicted / observed - 1, the observed life being the documented
re-entry date minus the start (benchmarks/reentry_cases.csv), never the code's own output:

* a case not listed in KNOWN_MISSES must be within +-25% of its observed life (the
  issue's goal for 90% of the cases);
* a known miss is outside +-25% (if it comes inside, the list and the docs are out of
  date) and below its stated ceiling: the miss measured when docs/validation-modern.md
  was written plus about 10 points, so it cannot grow unnoticed while numerical
  refinements (0.1-0.5% on lifetimes, docs section 3) pass;
* over all cases, the median |error| and its 90th percentile stay below ceilings set the
  same way. The issue's goal (median 10%, 90th percentile 25%) is NOT met: measured
  11.0% and 45%, see the docs for the misses and their likely reasons;
* the 90% band of ``--uncertainty`` (`band`): the observed life inside it for every case
  but those in OUTSIDE_BAND (12 of 15 when the docs were written), and `band` is the band
  the command line's Monte Carlo reports (GOCE, 1000 samples).
"""

from __future__ import annotations

import json

import benchmark_scripts
import pytest

pytest.importorskip("pymsis")


@pytest.fixture(scope="module")
def validation():
    return benchmark_scripts.load("validate_reentries")


#: Within +-25% of the observed life unless listed: the known misses, each with its ceiling (measured miss).
#: (San Marco 4, +26.4% under the daily Ap, came inside at +24.8% with storm days in NRLMSIS's storm-time mode,
#: and went out again at +25.3% when a launch's time of day came to read the record's calendar days, 2026-12-07.)
KNOWN_MISSES = {
    "Sputnik 1": 1.00,  # +85.8%; +86.2% on 2026-12-07
    "San Marco 2": 0.60,  # +45.8%; +46.2%
    "San Marco 3": 0.55,  # +44.2%; +44.5%
    "Starshine 2": 0.45,  # +33.2%; +34.2%
    "Explorer 32": 0.45,  # +31.6%; +28.8%
    "San Marco 4": 0.35,  # +25.3%
}
WITHIN = 0.25
#: The cases whose observed life lies outside the 90% band (measured: Sputnik 1 91.7 d against
#: 125.1-229.6 d, San Marco 2 176.1 against 198.9-327.4, San Marco 3 218.2 against 242.2-405.6).
OUTSIDE_BAND = {"Sputnik 1", "San Marco 2", "San Marco 3"}
#: Ceilings over all cases (measured: median 11.0%, 90th percentile 45.2%).
MEDIAN_CEILING = 0.15
P90_CEILING = 0.55
#: The quick subset (~15 s): the record's first months (Sputnik 1), a 1960s sphere within the goal
#: (San Marco 1), the slender GOCE and the modern miss (Starshine 2).
QUICK = ("Sputnik 1", "San Marco 1", "Starshine 2", "GOCE")


def check(rows, band=False):
    for row in rows:
        if band:
            assert row.inside_band == (row.name not in OUTSIDE_BAND), (row.name, row.observed_days, row.band_days)
        error = row.model_days / row.observed_days - 1.0
        if row.name in KNOWN_MISSES:
            assert WITHIN < abs(error) <= KNOWN_MISSES[row.name], (row.name, error)
        else:
            assert abs(error) <= WITHIN, (row.name, error)


def test_cases_come_from_the_sourced_table(validation):
    # At least 12 documented decays (the count), every one with its sources, from 1957 on.
    cases = validation.CASES
    assert len(cases) >= 12
    assert all(case.source for case in cases)
    assert min(case.start for case in cases) < "1958"
    assert set(KNOWN_MISSES) <= {case.name for case in cases}


def test_quick_cases_against_their_observed_lives(validation):
    check(validation.run([c for c in validation.CASES if c.name in QUICK], first_choice=False))


def test_the_band_is_the_command_lines_monte_carlo(validation, capsys):
    # GOCE (20 days): the band's two propagations against --uncertainty's 1000 samples. The
    # samples' 5th and 95th percentiles scatter by about 1.2% (standard error of a 5% quantile of
    # 1000 log-normal samples with sigma 0.18), so 4% is over three standard errors.
    from orbit_env.cli import main

    activity = validation.load_record()
    goce = next(c for c in validation.CASES if c.name == "GOCE")
    cd = validation.drag_coefficient(goce, activity)[0]
    low, high = validation.band(goce, activity, cd)
    argv = ["lifetime", "--perigee", str(goce.perigee_km), "--apogee", str(goce.apogee_km), "--cx", str(cd)]
    argv += ["--mass", str(goce.mass_kg), "--area", str(goce.shape.reference_area_m2), "--epoch", goce.start]
    argv += ["--inclination", str(goce.inclination_deg), "--node-local-time", str(goce.node_local_time_h)]
    argv += ["--rotating-atmosphere"]  # heights: the command line's default, above the equatorial radius
    assert main([*argv, "--uncertainty", "--json", "--no-progress"]) == 0
    percentiles = json.loads(capsys.readouterr().out)["days_percentiles"]
    assert percentiles["5"] == pytest.approx(low, rel=0.04)
    assert percentiles["95"] == pytest.approx(high, rel=0.04)


@pytest.mark.slow
def test_all_cases_against_their_observed_lives(validation):
    rows = validation.run(validation.CASES, first_choice=False, with_band=True)
    check(rows, band=True)
    median, p90, within = validation.summary([row.model_days / row.observed_days - 1.0 for row in rows])
    assert median <= MEDIAN_CEILING
    assert p90 <= P90_CEILING
    assert within == len(rows) - len(KNOWN_MISSES)
