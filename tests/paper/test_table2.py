"""The paper's results: Table II and the worked examples of section 4, through the averaged equations."""

import numpy as np
import pytest

from orbit_env.analysis.lifetime import lifetime
from orbit_env.paper.table2 import calibrate_rho100, compare_table2
from orbit_env.physics.atmosphere import RHO100_CALIBRATED_KG_M3


def test_table2_with_one_calibrated_rho1():
    # Table II is the paper's Euler solution (steps of 5-10 km in p) with misprints;
    # the bar: median |error| <= 5%, 90th percentile <= 10% over all 351 cells.
    comparison = compare_table2()
    summary = comparison.summary()
    assert summary["cells"] == 351
    assert summary["median_abs_rel_error"] <= 0.05
    assert summary["p90_abs_rel_error"] <= 0.10
    flagged = {(r["perigee_km"], r["apogee_km"]) for r in comparison.rows() if r["nu_misprint"]}
    # The known misprints: perigee 320 km, apogee 1100 and 1300 km.
    assert {(320.0, 1100.0), (320.0, 1300.0)} <= flagged
    assert len(flagged) <= 10


def test_the_papers_euler_scheme_explains_most_of_the_deviation():
    # Repeating the authors' Euler steps (5/10 km in p) on our rates halves the median
    # error: evidence that the derived equations are theirs and the rest is their
    # integrator. Measured: median 1.9%, p90 4.9%; bars 2.5% and 6%.
    summary = compare_table2().summary()
    assert summary["paper_scheme_median_abs_rel_error"] <= 0.025
    assert summary["paper_scheme_p90_abs_rel_error"] <= 0.06
    assert summary["paper_scheme_median_abs_rel_error"] < 0.6 * summary["median_abs_rel_error"]


def test_shipped_rho1_is_the_least_squares_fit():
    assert calibrate_rho100() == pytest.approx(RHO100_CALIBRATED_KG_M3, rel=5e-3)


# Section 4's worked examples. The tolerance is Table II's own 90th percentile (10%):
# the examples are Table II cells read by the authors.
@pytest.mark.parametrize(("hp", "ha", "nu_paper"), [(360, 800, 2760.0), (500, 1500, 66600.0), (200, 400, 16.8)])
def test_worked_examples_nu(hp, ha, nu_paper):
    assert lifetime(hp, ha).nu == pytest.approx(nu_paper, rel=0.10)


def test_worked_example_revolutions_and_days_for_the_sphere():
    result = lifetime(360, 800, method="averaged")  # the paper's 0.5 m, 10 kg sphere, c_x = 2; the reference
    assert result.revolutions == pytest.approx(7200, rel=0.10)
    # The paper divides N by 16 revolutions a day; we integrate the period (a mean of
    # some 94 min here, not 90), which adds 4.6% on top of nu's agreement: 12% in all.
    assert result.days == pytest.approx(450, rel=0.12)
    # Days are the sum of the periods over the revolutions. Recomputed here from the
    # history's heights with Kepler's third law, P = 2 pi sqrt(a^3 / fM), fM = 3.986e14
    # m^3/s^2 and a = R + (h_p + h_a) / 2 on the paper's sphere R = 6371 km, summed by the
    # trapezoidal rule over the 200 recorded orbits. The rule's error is second order:
    # 8e-7 relative here, 3e-6 with every other orbit; 1e-5 leaves room and still fails
    # on a period 0.001% off (16 revolutions a day would be 5% off).
    history = result.history
    a_m = 6371e3 + 0.5e3 * (history.perigee_km + history.apogee_km)
    period_s = 2.0 * np.pi * np.sqrt(a_m**3 / 3.986e14)
    summed_s = np.sum(0.5 * (period_s[1:] + period_s[:-1]) * np.diff(history.revolutions))
    assert result.days == pytest.approx(summed_s / 86400.0, rel=1e-5)
    # The period falls as the orbit decays: the mean lies between the first and the last.
    mean_period_s = result.days * 86400.0 / result.revolutions
    assert period_s[-1] < mean_period_s < period_s[0]
    assert lifetime(200, 400).revolutions == pytest.approx(44, rel=0.10)


def test_elongated_orbit_multiplies_lifetime_by_2_2():
    # Section 4: 360 x 700 -> 360 x 1000 km multiplies the lifetime by 2.2.
    ratio = lifetime(360, 1000).days / lifetime(360, 700).days
    assert ratio == pytest.approx(2.2, rel=0.10)
