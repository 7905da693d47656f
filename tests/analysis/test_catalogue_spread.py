"""A catalogue spread over inclinations in NRLMSIS: one curve family and a density ratio, against a family per group."""

import numpy as np
import pytest

pytest.importorskip("pymsis")

from orbit_env.analysis.air import MsisAir, PaperAir
from orbit_env.analysis.catalogue import batch_lifetimes
from orbit_env.analysis.inclination_spread import PATH_NODES, _spread_days, inclination_log_ratio
from orbit_env.analysis.scenario import Scenario
from orbit_env.decay.density_multiplier import SPREAD_MAX_SPAN_M
from orbit_env.decay.solar import ConstantActivity

#: The accuracy the docs state for the curves against the averaged ODE in NRLMSIS (0.5%); the one-family
#: path must stay within it of the family per group (measured on 10^4 rows: max 0.39%, median 0.02%).
TOLERANCE = 5e-3


def catalogue(n, span_km, seed=2):
    rng = np.random.default_rng(seed)
    perigee_km = rng.uniform(250.0, 900.0, n)
    apogee_km = perigee_km + rng.uniform(0.0, span_km, n)
    inclination = rng.choice([0.0, 28.0, 51.0, 51.0, 75.0, 98.0], n)
    c = 2.2 / rng.uniform(20.0, 200.0, n)
    return perigee_km * 1e3, apogee_km * 1e3, c, inclination


def days_of(scenario, orbits, **options):
    hp, ha, c, inclination = orbits
    rows = [{} for _ in hp]
    records, summary = batch_lifetimes(
        rows, hp, ha, c, inclination, ["ok"] * hp.size, scenario, progress=False, **options
    )
    return np.array([float(r["days"]) for r in records]), summary.groups


@pytest.mark.parametrize("rotating", [False, True])
def test_one_family_and_a_ratio_match_a_family_per_inclination(rotating):
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)), rotating_atmosphere=rotating)
    orbits = catalogue(300, SPREAD_MAX_SPAN_M / 1e3)
    one, families_one = days_of(scenario, orbits)
    exact, families_exact = days_of(scenario, orbits, exact_groups=True)
    assert families_one == 1
    assert families_exact == 5
    assert one == pytest.approx(exact, rel=TOLERANCE)
    # The family's own inclination (the most common, 51 deg) takes it unchanged.
    at_reference = orbits[3] == 51.0
    assert one[at_reference] == pytest.approx(exact[at_reference], rel=1e-9)
    # The ratio does work: the equatorial orbits' lifetimes differ from the family's own by more than it.
    equatorial = orbits[3] == 0.0
    family_only, _ = days_of(scenario, (orbits[0], orbits[1], orbits[2], np.full(orbits[0].size, 51.0)))
    assert np.max(np.abs(family_only[equatorial] / exact[equatorial] - 1.0)) > 10 * TOLERANCE


@pytest.mark.parametrize("rotating", [False, True])
def test_wide_orbits_on_one_family_match_a_family_per_inclination(rotating):
    # Orbits 100-1500 km wide: the multiplier is the ratio of the rates at which the life left falls
    # (catalogue._life_rate_ratio); one density multiplier at the perigee is off by more than the tolerance.
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)), rotating_atmosphere=rotating)
    hp, ha, c, inclination = catalogue(300, 100.0, seed=4)
    ha = hp + np.random.default_rng(5).uniform(SPREAD_MAX_SPAN_M, 1500e3, hp.size)
    one, families = days_of(scenario, (hp, ha, c, inclination))
    exact, _ = days_of(scenario, (hp, ha, c, inclination), exact_groups=True)
    assert families == 1
    assert one == pytest.approx(exact, rel=TOLERANCE)
    reference = 51.0
    curves = scenario.curves(reference)
    log_ratio = inclination_log_ratio(scenario, reference, inclination)
    one_multiplier = _spread_days(
        curves, scenario, reference, log_ratio, inclination, hp, ha, c, PATH_NODES, wide=False
    )
    assert np.max(np.abs(one_multiplier / exact - 1.0)) > 2 * TOLERANCE


def test_the_ratio_is_zero_at_the_reference_and_grows_with_the_distance_from_it():
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    log_ratio = inclination_log_ratio(scenario, 51.0, np.array([51.0, 60.0, 90.0]))
    assert log_ratio[0] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.abs(log_ratio[1]) <= np.abs(log_ratio[2]) + 1e-12)
    # Still air in the paper's law does not depend on the inclination.
    assert not np.any(inclination_log_ratio(Scenario(PaperAir()), 51.0, np.array([0.0, 98.0])))


def test_the_rule_on_one_family_matches_a_family_per_inclination():
    """`--rule` on a spread catalogue searches the lowered perigee on the one family.

    Verdicts agree wherever the life is more than 1% (twice the 0.5% tolerance) from the
    rule's limit; the lowered perigees within 1 km: a life 0.5% off moves the perigee by
    the local density scale height (at most ~70 km at these heights) times 0.005, 0.35 km,
    and the search's own bracket is (perigee - 100 km) / 17^3 < 0.2 km.
    """
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    hp, ha, c, inclination = catalogue(300, SPREAD_MAX_SPAN_M / 1e3, seed=6)
    rows = [{} for _ in hp]

    def run(**options):
        records, summary = batch_lifetimes(
            rows, hp, ha, c, inclination, ["ok"] * hp.size, scenario, progress=False, rule_years=5.0, **options
        )
        return records, summary.groups

    one, families_one = run()
    exact, families_exact = run(exact_groups=True)
    assert (families_one, families_exact) == (1, 5)
    days = np.array([float(r["days"]) if r["days"] else np.inf for r in exact])
    clear = np.abs(days / (5.0 * 365.25) - 1.0) > 2 * TOLERANCE
    verdict_one = np.array([r["complies"] == "true" for r in one])
    verdict_exact = np.array([r["complies"] == "true" for r in exact])
    assert verdict_one[clear].tolist() == verdict_exact[clear].tolist()
    assert 20 < verdict_exact.sum() < hp.size - 20  # both verdicts occur
    lowered = ~verdict_exact & ~verdict_one
    new_one = np.array([float(r["new_perigee_km"]) for r in one])[lowered]
    new_exact = np.array([float(r["new_perigee_km"]) for r in exact])[lowered]
    np.testing.assert_allclose(new_one, new_exact, atol=1.0)


def stepped_orbits(n, wide, seed=7):
    """Low orbits, so that their lives (days to a few years from 2024) keep the time-stepped runs short."""
    rng = np.random.default_rng(seed)
    hp = rng.uniform(200.0, 330.0, n) * 1e3
    ha = hp + (rng.uniform(SPREAD_MAX_SPAN_M, 1000e3, n) if wide else rng.uniform(0.0, SPREAD_MAX_SPAN_M, n))
    inclination = rng.choice([0.0, 28.0, 51.0, 51.0, 75.0, 98.0], n)
    return hp, ha, 2.2 / rng.uniform(20.0, 200.0, n), inclination


@pytest.mark.parametrize("wide", [False, True])
def test_a_stepped_catalogue_on_one_family_matches_a_family_per_inclination(wide):
    """The time-stepped path (an epoch, the solar record) spread over inclinations takes one family too.

    Each row's inclination is a density multiplier in every chunk (NRLMSIS every 10 deg at
    the chunk's mean indices and middle day, `orbit_env.decay.chunked.propagate`), against
    a family per group. Near-circular rows: within the 0.5% the chunked path holds of its
    daily reference for lives of 10 days and more (measured on these rows: 0.25%); shorter
    lives, decided by a storm's days that the chunk's mean indices average, within 1.5%
    (measured 1.04% near-circular, 1.01% wide, lives of 2-10 days; the near-circular rows
    took 0.86% with quarter-day steps in the last days instead of the midpoint rule, and
    1.44% with two midpoint half-days a day: the integration of the last days moves these
    lives' differences by about 0.5% either way, so they are the chunk's mean indices, not
    the steps; against the daily reference the rows of a family per group are 0.04-0.32% off
    there). Wide rows: within 1% for lives of
    10 days and more (measured 0.62%; not within 0.5%: each new
    bin re-locates a row from its place on the family's curve, which has its life left
    under the old bin's air but not its eccentricity, docs/validation-modern.md section 7).
    Without the multiplier the equatorial rows are 16-20% off.
    """
    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    scenario = Scenario(MsisAir(load_record(), unix_days("2024-01-01")))
    orbits = stepped_orbits(40, wide)
    one, families_one = days_of(scenario, orbits)
    exact, families_exact = days_of(scenario, orbits, exact_groups=True)
    assert (families_one, families_exact) == (1, 5)
    error = np.abs(one / exact - 1.0)
    assert np.max(error[exact >= 10.0]) < (2 * TOLERANCE if wide else TOLERANCE)
    assert np.max(error) < 3 * TOLERANCE
    at_reference = orbits[3] == 51.0
    assert one[at_reference] == pytest.approx(exact[at_reference], rel=1e-9)
    equatorial = orbits[3] == 0.0
    family_only, _ = days_of(scenario, (*orbits[:3], np.full(orbits[0].size, 51.0)))
    assert np.max(np.abs(family_only[equatorial] / exact[equatorial] - 1.0)) > 10 * TOLERANCE


def test_own_inclinations_need_the_time_stepped_path():
    scenario = Scenario(MsisAir(ConstantActivity(150.0, 150.0, 15.0)))
    with pytest.raises(ValueError, match="time-stepped"):
        scenario.lifetime_days(400e3, 450e3, 0.01, 51.0, own_inclination_deg=0.0)
