"""The solar task's figures (``orbit_env.agents.solar_maps``): the recorded flights, the phases, the maps, the PNGs."""

from __future__ import annotations

import numpy as np
import pytest

from orbit_env.agents import solar_maps as sm
from orbit_env.agents.solar import Flown, Never, PerigeeThreshold, by_observation, fly, starts
from orbit_env.agents.solar_dp import SolarDP
from orbit_env.decay.solar import unix_days
from orbit_env.envs import solar_task as st

TEST_TASK = st.SolarTask(mission=st.SolarMission(solar_split="test"))
#: Four missions from the rise of cycle 24 (2011-2013), low to high: without burns the three lowest
#: re-enter within the mission and the highest needs a disposal burn; the perigee rule burns on the
#: three lowest, and two of them then need a disposal burn.
START_DATES = ("2011-06-01", "2011-09-09", "2012-03-27", "2013-01-21")
PERIGEES_KM = np.array([380.0, 400.0, 450.0, 540.0])
RULES = {"never": Never(TEST_TASK), "perigee_threshold": PerigeeThreshold(TEST_TASK, 420.0, 40.0)}


@pytest.fixture(scope="module")
def missions() -> dict[str, np.ndarray]:
    """The start options of the four missions (`fly` reads the start day)."""
    days = [float(TEST_TASK.clock.day_of(unix_days(date))) for date in START_DATES]
    return {"start_day": np.array(days), "perigee_km": PERIGEES_KM, "apogee_km": PERIGEES_KM + 10.0}


@pytest.fixture(scope="module")
def recorded(missions) -> dict[str, tuple[Flown, sm.Flights]]:
    """Each rule's missions flown by `fly` and recorded by `fly_recorded`."""
    return {
        name: (
            fly(TEST_TASK, missions, by_observation(TEST_TASK, rule)),
            sm.fly_recorded(TEST_TASK, missions, by_observation(TEST_TASK, rule)),
        )
        for name, rule in RULES.items()
    }


@pytest.mark.parametrize("rule", list(RULES))
def test_the_recorded_flights_are_the_missions_flown(recorded, missions, rule) -> None:
    plain, flights = recorded[rule]
    np.testing.assert_array_equal(flights.flown.returns, plain.returns)
    horizon = TEST_TASK.config.horizon_steps
    assert flights.perigee_km.shape == flights.dv_left_m_s.shape == (4, horizon + 1) == (4, 62)
    assert flights.burn_m_s.shape == (4, horizon)
    # The burns made, month by month, and the disposal add up to the delta-v the mission spent ...
    spent = np.nansum(flights.burn_m_s, axis=1) + flights.disposal_m_s
    np.testing.assert_allclose(spent, plain.dv_m_s, atol=1e-9)
    # ... and are what the tank lost from the start to the last month recorded.
    last = np.array([np.flatnonzero(~np.isnan(row))[-1] for row in flights.dv_left_m_s])
    lost = flights.dv_left_m_s[:, 0] - flights.dv_left_m_s[np.arange(4), last]
    np.testing.assert_allclose(lost, spent, atol=1e-9)
    # A mission flown to its end has all 61 months; one that re-entered none after the month it fell in.
    months = (~np.isnan(flights.burn_m_s)).sum(axis=1)
    np.testing.assert_array_equal(months == horizon, ~plain.reentered)
    np.testing.assert_array_equal(last, np.where(plain.reentered, months - 1, horizon))
    fell = plain.reentered
    np.testing.assert_array_equal(months[fell], np.ceil(plain.days_in_orbit[fell] / TEST_TASK.mission.block_days))
    recorded_heights = ~np.isnan(flights.perigee_km)
    assert (flights.perigee_km[recorded_heights] <= flights.apogee_km[recorded_heights] + 1e-9).all()
    start = st.start(TEST_TASK, np.random.default_rng(0), 4, missions)
    np.testing.assert_allclose(flights.perigee_km[:, 0], start.perigee_m / 1e3)
    np.testing.assert_allclose(flights.step_days(TEST_TASK)[:, -1], start.start_day + TEST_TASK.mission_days)


def test_the_missions_hold_what_the_checks_need(recorded) -> None:
    never, burner = recorded["never"][1], recorded["perigee_threshold"][1]
    np.testing.assert_array_equal(never.flown.reentered, [True, True, True, False])
    assert never.disposal_m_s[3] > 0.0 and (np.nan_to_num(never.burn_m_s) == 0.0).all()
    np.testing.assert_array_equal(np.nansum(burner.burn_m_s, axis=1) > 0.0, [True, True, True, False])
    assert (burner.disposal_m_s[1:] > 0.0).all()


def test_the_optimum_is_flown_as_the_evaluation_flies_it() -> None:
    options = starts(TEST_TASK, 1, 2024)
    flights = sm.fly_optimum(TEST_TASK, options)
    plain = fly(TEST_TASK, options, SolarDP(TEST_TASK, float(options["start_day"][0])).burns_m_s)
    assert flights.flown.returns[0] == plain.returns[0]
    assert np.nansum(flights.burn_m_s) + flights.disposal_m_s[0] == pytest.approx(plain.dv_m_s[0], abs=1e-9)


def test_the_solar_phase_counts_from_the_last_minimum() -> None:
    clock = TEST_TASK.clock

    def day(date: str) -> float:
        return float(clock.day_of(unix_days(date)))

    years = sm.years_since_minimum(TEST_TASK, np.array([day("2008-12-15"), day("2019-12-14"), day("2019-12-15")]))
    np.testing.assert_allclose(years, [0.0, 4016.0 / 365.25, 0.0])  # cycle 24 lasted 4017 days
    assert sm.years_since_minimum(TEST_TASK, np.array([day("2014-06-15")]))[0] == pytest.approx(5.5, abs=0.01)
    with pytest.raises(ValueError, match="before the first minimum"):
        sm.years_since_minimum(TEST_TASK, np.array([day("1954-01-01")]))


def test_the_f107_phase_is_what_the_agent_observes(recorded, missions) -> None:
    flights = recorded["never"][1]
    start = st.start(TEST_TASK, np.random.default_rng(0), 4, missions)
    observed = st.observe(TEST_TASK, start)[:, st.SOLAR_OBS_INDEX["f107_mean_81d"]] * st.SOLAR_INDEX_SCALE
    # float32 observations: 1e-6 relative.
    np.testing.assert_allclose(sm.step_phases(TEST_TASK, flights)["f107"][:, 0], observed, rtol=1e-6)


def test_the_burn_maps_count_every_month_with_propellant_once(recorded) -> None:
    flights = {name: one for name, (_, one) in recorded.items()}
    maps = sm.burn_maps(TEST_TASK, flights)
    for name, flown in flights.items():
        can_burn = ~np.isnan(flown.burn_m_s) & (flown.dv_left_m_s[:, :-1] > 0.0)
        assert set(maps[name]) == set(sm.PHASE_LABELS)
        for one in maps[name].values():
            # Every phase's bins hold every month the satellite flew with propellant, once.
            assert one.months.sum() == can_burn.sum() > 0
            assert one.burns.sum() == (flown.burn_m_s > 0.0).sum()
            assert one.dv_m_s.sum() == pytest.approx(np.nansum(flown.burn_m_s))
            share = one.share
            assert np.isnan(share[one.months < sm.MIN_MONTHS]).all()
            assert ((share >= 0.0) & (share <= 1.0))[one.months >= sm.MIN_MONTHS].all()
    assert maps["perigee_threshold"]["month"].burns.sum() == 12  # 4 burns on each of the three lowest
    years = sm.step_phases(TEST_TASK, flights["never"])["years"]
    edges = maps["never"]["years"].phase_edges
    assert edges[0] == 0.0 and edges[-1] - 1.0 < years.max() <= edges[-1]


def test_a_burn_map_puts_each_month_in_its_cell() -> None:
    # Two missions of two months: perigees and phases chosen to fall in known cells, the last out of range.
    flown = Flown(*(np.zeros(2) for _ in range(4)), np.ones(2, dtype=bool), np.zeros(2, dtype=bool))
    flights = sm.Flights(
        start_day=np.zeros(2),
        perigee_km=np.array([[150.0, 150.0, 150.0], [305.0, 900.0, 900.0]]),
        apogee_km=np.full((2, 3), 1000.0),
        dv_left_m_s=np.array([[10.0, 0.0, 0.0], [10.0, 5.0, 5.0]]),  # mission 0's tank empty in month 1
        burn_m_s=np.array([[10.0, 0.0], [5.0, 0.0]]),
        disposal_m_s=np.zeros(2),
        flown=flown,
    )
    one = sm.burn_map(
        flights, np.array([[0.5, 0.5], [2.5, 40.0]]), np.array([0.0, 1.0, 2.0, 3.0]), np.array([140.0, 300.0, 500.0])
    )
    np.testing.assert_array_equal(one.months, [[1, 0, 0], [0, 0, 2]])
    np.testing.assert_array_equal(one.burns, [[1, 0, 0], [0, 0, 1]])
    np.testing.assert_array_equal(one.dv_m_s, [[10.0, 0.0, 0.0], [0.0, 0.0, 5.0]])


def test_the_figures_are_written(recorded, tmp_path) -> None:
    both = {name: flights for name, (_, flights) in recorded.items()}
    mission, maps = tmp_path / "mission.png", tmp_path / "maps.png"
    sm.plot_mission(TEST_TASK, {name: f.take(np.array([0])) for name, f in both.items()}, "one mission", str(mission))
    sm.plot_burn_maps(sm.burn_maps(TEST_TASK, both), "maps", str(maps))
    for path in (mission, maps):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 20_000


def test_the_command_draws_both_figures(tmp_path, capsys) -> None:
    pytest.importorskip("stable_baselines3")
    mission, maps = tmp_path / "mission.png", tmp_path / "maps.png"
    sm.main(["--episodes", "2", "--out-mission", str(mission), "--out-maps", str(maps)])
    assert mission.is_file() and maps.is_file()
    out = capsys.readouterr().out
    assert "2 test missions (seed 12345)" in out and "test mission" in out
    with pytest.raises(ValueError, match="--mission=2 is invalid"):
        sm.main(["--episodes", "2", "--mission", "2"])
