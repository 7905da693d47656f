"""The pure parts of benchmarks/validate_element_sets.py: case selection, histories, metrics, the data's reading.

No prediction is run here (a case costs seconds to a minute); the script's own run is the measurement.
"""

from __future__ import annotations

import datetime as dt
import math

import benchmark_scripts
import pytest


@pytest.fixture(scope="module")
def v():
    return benchmark_scripts.load("validate_element_sets")


def test_selection_takes_latest_quarter_and_earliest_inside_the_window(v):
    # Leads in days, oldest set first: 1200 and 1100 are beyond 3 years, 6 and 2 closer than 7 days.
    leads = [1200.0, 1100.0, 800.0, 400.0, 210.0, 150.0, 30.0, 7.5, 6.0, 2.0]
    chosen = v.choose_sets(leads)
    # earliest in the window: 800 (index 2); 25% of 800 = 200 -> 210 (index 4); latest >= 7 d: 7.5 (index 7)
    assert chosen == [2, 4, 7]
    assert all(v.MIN_LEAD_DAYS <= leads[k] <= v.MAX_LEAD_DAYS for k in chosen)


def test_selection_at_the_window_edges(v):
    # Exactly 7 d and exactly 1096 d are inside; just outside them is not.
    assert v.choose_sets([1096.0, 7.0]) == [0, 1]
    assert v.choose_sets([1096.01, 6.99]) == []
    assert v.choose_sets([]) == []


def test_selection_deduplicates_small_objects(v):
    assert v.choose_sets([100.0]) == [0]
    # two sets: the quarter of 100 (25) is closest to the latest one, so two cases, not three
    assert v.choose_sets([100.0, 20.0]) == [0, 1]
    # a tie for the quarter (25 +- 5) goes to the earlier set (the longer lead)
    assert v.choose_sets([100.0, 30.0, 20.0, 10.0]) == [0, 1, 3]


def test_history_takes_60_days_up_to_the_chosen_set_at_most_30(v):
    epochs = [0.0, 10.0, 50.0, 70.0, 100.0, 130.0, 140.0]
    assert v.history_indices(epochs, 4) == [2, 3, 4]  # 40 <= epoch <= 100; never a later set
    assert v.history_indices(epochs, 0) == [0]
    dense = [0.5 * k for k in range(200)]  # 200 sets in 100 days
    picked = v.history_indices(dense, 150)  # epoch 75: sets from 15 d on, 121 of them
    assert len(picked) == v.HISTORY_MAX_SETS
    assert picked[-1] == 150 and dense[picked[0]] == pytest.approx(15.0)
    assert picked == sorted(set(picked))


def test_metric_of_a_perfect_prediction_is_zero(v):
    assert v.relative_error(100.0, 100.0) == 0.0
    assert v.relative_error(150.0, 100.0) == pytest.approx(0.5)
    assert v.relative_error(50.0, 100.0) == pytest.approx(-0.5)
    m = v.error_metrics([0.0, 0.0, 0.0], [True, True, None])
    assert m["median_abs_error"] == 0.0 and m["p90_abs_error"] == 0.0 and m["within_25"] == 1.0
    assert m["band_cases"] == 2 and m["band_coverage"] == 1.0


def test_metrics_on_hand_made_errors(v):
    # |errors| 0.1, 0.2, 0.3, 0.4, 1.0 (NaN left out): median 0.3; 90th percentile 0.4 + 0.6 * 0.6 = 0.76
    m = v.error_metrics([-0.1, 0.2, -0.3, 0.4, 1.0, math.nan], [True, False, False, None])
    assert m["cases"] == 5
    assert m["median_abs_error"] == pytest.approx(0.3)
    assert m["p90_abs_error"] == pytest.approx(0.76)
    assert m["within_25"] == pytest.approx(2 / 5)
    assert m["band_coverage"] == pytest.approx(1 / 3)


def test_band_membership(v):
    assert v.inside_band(100.0, (90.0, 110.0))
    assert not v.inside_band(100.0, (101.0, 110.0))
    assert v.inside_band(100.0, (100.4, 110.0), 0.5)  # a day-only date meets the band by its half day
    assert not v.inside_band(100.0, (100.6, 110.0), 0.5)
    assert not v.inside_band(120.0, (90.0, 110.0), 0.5)
    assert v.inside_band(5000.0, (90.0, math.inf))  # an upper edge beyond the horizon


def test_lead_buckets(v):
    assert [v.lead_bucket(x) for x in (7.0, 29.9, 30.0, 179.9, 180.0, 1096.0)] == [
        "<30 d",
        "<30 d",
        "30-180 d",
        "30-180 d",
        ">180 d",
        ">180 d",
    ]


def test_summary_counts_only_predicted_cases(v):
    epoch = dt.datetime(2020, 1, 1, tzinfo=dt.UTC)
    common = {"norad": 1, "name": "X", "epoch": epoch, "observed_uncertainty_days": 0.5, "sets_used": 1}
    cases = [
        v.Case(**common, mode="one set", lead_days=20.0, status="ok", predicted_days=20.0, band_days=(15.0, 25.0)),
        v.Case(**common, mode="one set", lead_days=100.0, status="ok", predicted_days=200.0, band_days=(150.0, 250)),
        v.Case(**common, mode="history", lead_days=100.0, status=v.HISTORY_NOT_SUPPORTED),
    ]
    s = v.summarize(cases)
    assert s["one set"]["all"]["cases"] == 2
    assert s["one set"]["all"]["median_abs_error"] == pytest.approx(0.5)
    assert s["one set"]["all"]["band_coverage"] == pytest.approx(0.5)
    assert s["one set"]["by_lead"]["<30 d"]["median_abs_error"] == 0.0
    assert s["history"]["statuses"] == {v.HISTORY_NOT_SUPPORTED: 1}
    assert s["history"]["all"]["cases"] == 0


def test_reading_the_data_set(v):
    objects = {o.norad: o for o in v.load_objects()}
    assert {n for n, o in objects.items() if o.flagged} == {41479, 41480}
    tiangong = objects[37820]
    assert tiangong.reentry == dt.datetime(2018, 4, 2, 0, 16, tzinfo=dt.UTC)
    assert tiangong.reentry_uncertainty_days == 0.0
    techedsat = objects[38854]  # SATCAT day only: noon, +-0.5 d; README: 42.0 days before
    assert techedsat.reentry == dt.datetime(2013, 5, 5, 12, tzinfo=dt.UTC)
    assert techedsat.reentry_uncertainty_days == 0.5
    assert techedsat.lead_days(0) == pytest.approx(42.0, abs=0.05)
    assert len(objects[32789].sets) == 2656
    for o in objects.values():
        assert list(o.sets) == sorted(o.sets, key=lambda s: s.epoch), o.norad  # oldest first
        assert v.choose_sets([o.lead_days(k) for k in range(len(o.sets))]), o.norad
