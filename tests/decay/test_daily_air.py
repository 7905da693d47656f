"""The real Sun's air table (`orbit_env.decay.daily_air`): a memo of NRLMSIS, not an approximation.

Its rows must be NRLMSIS's own orbit averages for the day's indices, whichever batch
computed them and whether they came from memory or from the disk cache; the decay's
density ratios read through it must equal those computed from NRLMSIS directly.
Tolerance 1e-12 relative: the same NRLMSIS values summed in another order (a batch
of days against one day; exp of the stored logarithm) differ in the last bits only.
"""

import time
from pathlib import Path

import numpy as np
import pytest
from msis_reference import pymsis_orbit_mean

from orbit_env import cache
from orbit_env.decay import daily_air
from orbit_env.decay.chunked import STORM_AP, SolarDecayModel, air_table
from orbit_env.decay.daily_air import DailyAirTable
from orbit_env.decay.density_multiplier import RATIO_GRID_M, RATIO_NODES
from orbit_env.decay.solar import unix_days
from orbit_env.decay.solar_record import load_record
from orbit_env.physics.atmosphere.msis import (
    SEASON_NODES,
    mean_density_kg_m3,
    mean_density_over_days_kg_m3,
    orbit_mean_density_by_day_kg_m3,
)

HEIGHTS_M = np.array([200e3, 400e3, 700e3])
KEYS = [(150.0, 140.0, 15.0, 80.0), (70.0, 72.0, 4.0, 172.0), (250.0, 200.0, 120.0, 300.0)]
RTOL = 1e-12


def table(tmp_path, monkeypatch, inclination_deg=51.6, node=None):
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path))
    return DailyAirTable(HEIGHTS_M, inclination_deg, node, 2.1, 4, 4)


def direct(key, inclination_deg=51.6, node=None):
    return orbit_mean_density_by_day_kg_m3(
        HEIGHTS_M, *([v] for v in key), inclination_deg, node, latitude_nodes=4, local_time_nodes=4, version=2.1
    )[0]


@pytest.mark.parametrize("node", [None, 10.5])
def test_rows_are_nrlmsis_own_orbit_averages(tmp_path, monkeypatch, node):
    rows = table(tmp_path, monkeypatch, 97.5 if node else 51.6, node).log_density(KEYS)
    for key, row in zip(KEYS, rows, strict=True):
        np.testing.assert_allclose(np.exp(row), direct(key, 97.5 if node else 51.6, node), rtol=RTOL)


def test_a_row_does_not_depend_on_the_batch_it_was_computed_in(tmp_path, monkeypatch):
    alone = table(tmp_path / "a", monkeypatch).log_density(KEYS[:1])
    ahead = table(tmp_path / "b", monkeypatch).log_density(KEYS[:1], ahead=lambda: KEYS[1:])
    np.testing.assert_allclose(alone, ahead, rtol=RTOL)


def test_prefetched_days_are_held_and_asked_days_are_not_computed_twice(tmp_path, monkeypatch):
    air = table(tmp_path, monkeypatch)
    air.log_density(KEYS[:1], ahead=lambda: KEYS[1:] + KEYS[:1])
    assert len(air) == 3
    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", pytest.fail)
    np.testing.assert_allclose(np.exp(air.log_density(KEYS[::-1])[0]), direct(KEYS[2]), rtol=RTOL)


def test_years_of_air_computed_a_part_at_a_time_are_the_rows_of_one_call(tmp_path, monkeypatch):
    # A first use of years of days (the solar task's table) is computed in parts with a progress bar; NRLMSIS is
    # pointwise and each row a day's own mean, so the parts give the rows of one call, to the bit, daily and
    # storm days alike (a storm key's 27 ap after its four indices).
    storm = (*KEYS[2], *np.linspace(20.0, 200.0, 27))
    keys = [*KEYS, storm, (90.0, 95.0, 7.0, 40.0)]
    whole = table(tmp_path / "whole", monkeypatch).log_density(keys)
    monkeypatch.setattr(daily_air, "PROGRESS_DAYS", 3)
    monkeypatch.setattr(daily_air, "PROGRESS_PART", 2)
    parts = table(tmp_path / "parts", monkeypatch).log_density(keys)
    np.testing.assert_array_equal(parts, whole)


def test_a_new_process_reads_the_table_from_the_disk_cache_without_nrlmsis(tmp_path, monkeypatch):
    first = table(tmp_path, monkeypatch).log_density(KEYS)
    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", pytest.fail)
    again = table(tmp_path, monkeypatch)
    assert len(again) == 3
    np.testing.assert_array_equal(again.log_density(KEYS), first)


def test_tables_of_other_orbits_are_kept_apart(tmp_path, monkeypatch):
    table(tmp_path, monkeypatch).log_density(KEYS)
    assert len(table(tmp_path, monkeypatch, inclination_deg=28.5)) == 0
    assert len(DailyAirTable(HEIGHTS_M, 51.6, None, 0.0, 4, 4)) == 0  # NRLMSISE-00


def test_without_a_disk_cache_the_table_works_in_memory(monkeypatch):
    monkeypatch.setattr(cache, "_disabled", True)  # what `orbit-env --no-cache` sets
    rows = DailyAirTable(HEIGHTS_M, 51.6, None, 2.1, 4, 4).log_density(KEYS)
    np.testing.assert_allclose(np.exp(rows[1]), direct(KEYS[1]), rtol=RTOL)


@pytest.mark.parametrize(("follow_season", "storm_ap"), [(True, False), (False, False), (True, True), (False, True)])
def test_the_decays_density_ratio_equals_nrlmsis_directly(follow_season, storm_ap):
    start = unix_days("2015-03-10")  # the March 2015 storm: indices that change day by day
    model = SolarDecayModel(load_record(), start, 51.6, follow_season=follow_season, storm_ap=storm_ap)
    daily = model.daily_indices(start + np.arange(20.0))
    assert any(len(key) > 4 for key in daily) == storm_ap
    binned = (130.0, 12.0)
    if storm_ap:  # each row on its own: the storm days' in NRLMSIS's storm-time mode
        exact = np.mean([direct_row(key, RATIO_GRID_M, 51.6, **RATIO_NODES) for key in daily], axis=0)
    else:
        f107, f107a, ap, doy = (np.array(c) for c in zip(*daily, strict=True))
        exact = mean_density_over_days_kg_m3(RATIO_GRID_M, f107, f107a, ap, doy, 51.6, None, **RATIO_NODES)
    bin_rho = mean_density_kg_m3(RATIO_GRID_M, *binned[:1] * 2, binned[1], 51.6, None, None, **RATIO_NODES)
    np.testing.assert_allclose(model.log_ratio(daily, binned), np.log(exact / bin_rho), rtol=1e-10, atol=1e-12)
    assert len(air_table(51.6, None, model.version)) >= len(set(daily)) + SEASON_NODES


def test_the_table_is_rewritten_when_it_has_grown_by_a_quarter_and_at_the_end(tmp_path, monkeypatch):
    days = [(100.0 + k, 100.0, 10.0, 100.0) for k in range(40)]
    table(tmp_path, monkeypatch).log_density(days[:20])  # an empty table grows: written
    air = table(tmp_path, monkeypatch)
    air.log_density(days[20:24])  # 24 < 1.25 x 20 rows: not written yet
    assert len(table(tmp_path, monkeypatch)) == 20
    air.log_density(days[24:26])  # 26 >= 25: written
    assert len(table(tmp_path, monkeypatch)) == 26
    air.log_density(days[26:27])
    daily_air._store_all()  # what the end of the process runs
    assert len(table(tmp_path, monkeypatch)) == 27


def test_rows_computed_to_fewer_heights_are_those_heights_of_the_full_rows_and_deepen_on_demand(tmp_path, monkeypatch):
    """``columns``: a decay below a height computes the first heights only; asked for more, a row is deepened."""
    full = table(tmp_path / "full", monkeypatch).log_density([*KEYS, STORM_KEY])
    air = table(tmp_path / "part", monkeypatch)
    first = air.log_density([*KEYS[:2], STORM_KEY], columns=2)
    np.testing.assert_array_equal(first[:, :2], full[[0, 1, 3], :2])  # NRLMSIS is pointwise: the same values
    assert np.all(np.isnan(first[:, 2:]))
    daily_air._store_all()
    again = table(tmp_path / "part", monkeypatch)  # a new process: the shallow rows from the disk cache
    calls = []
    original = daily_air.orbit_mean_density_by_day_kg_m3
    monkeypatch.setattr(
        daily_air, "orbit_mean_density_by_day_kg_m3", lambda *a, **k: calls.append(a[0].size) or original(*a, **k)
    )
    np.testing.assert_array_equal(again.log_density(KEYS[:2], columns=1), first[:2])  # held: no NRLMSIS
    assert calls == []
    deeper = again.log_density([*KEYS, STORM_KEY])  # all heights: the three rows deepened, one row new
    np.testing.assert_array_equal(deeper, full)
    assert sorted(calls) == [3, 3]  # one call for the daily-Ap days, one for the storm day, at every height
    assert len(again) == 4


@pytest.mark.parametrize("order", ["shallow first", "deep first"])
def test_two_processes_writing_one_table_keep_both_their_rows(tmp_path, monkeypatch, order):
    """Each catalogue worker writes its table as it ends: the second write keeps the first one's rows.

    Two tables read from the same empty cache (two processes), each computes other days (one
    also a day the other holds to fewer heights), each writes; the table read afterwards holds
    all of them, each as deep as either had it (without the merge under the lock it held the
    last writer's only, and the next run computed the others again: the constellation screen of
    docs/how-to/catalogue.md took 17.5 s on its second run against 5.5 s on its third).
    """
    shallow, deep = table(tmp_path, monkeypatch), table(tmp_path, monkeypatch)
    rows_shallow = shallow.log_density(KEYS[:2], columns=1)
    rows_deep = deep.log_density([KEYS[0], KEYS[2]])
    for writer in (shallow, deep) if order == "shallow first" else (deep, shallow):
        writer.store()
    calls = []
    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", lambda *a, **k: calls.append(a) or 1 / 0)
    after = table(tmp_path, monkeypatch)
    assert len(after) == 3
    np.testing.assert_array_equal(after.log_density([KEYS[0], KEYS[2]]), rows_deep)
    np.testing.assert_array_equal(after.log_density(KEYS[1:2], columns=1), rows_shallow[1:])
    assert calls == []


def test_a_table_no_other_process_wrote_is_not_read_again_before_a_write(tmp_path, monkeypatch):
    # `store` takes in what other processes wrote; where the file is the one this process read or
    # wrote last (the same inode and time), it writes without reading it (a cold run writes often).
    air = table(tmp_path, monkeypatch)
    air.log_density(KEYS[:1])
    air.store()
    loads = []
    original = cache.load
    monkeypatch.setattr(cache, "load", lambda *a, **k: loads.append(a[0]) or original(*a, **k))
    air.log_density(KEYS[1:2])
    air.store()
    assert loads == []
    other = table(tmp_path, monkeypatch)  # reads the file (one load)
    other.log_density(KEYS[2:])
    other.store()
    air.log_density([(100.0, 100.0, 8.0, 200.0)])  # a new row: the file is now the other's, so it is read first
    air.store()
    assert loads.count("airdays") == 2
    assert len(table(tmp_path, monkeypatch)) == 4


def test_rows_a_worker_deepened_go_back_to_its_parent(tmp_path, monkeypatch):
    """A row read shallow from the disk cache and deepened in a worker is in the worker's `new_rows`.

    Else the parent never holds (nor writes) the deeper row, and every later run's workers call
    NRLMSIS for it again: measured on the 550 km uncertainty run after a 350 km one in the same
    cache, nine NRLMSIS calls a run.
    """
    table(tmp_path, monkeypatch).log_density(KEYS[:2], columns=1)  # a lower orbit's rows
    daily_air._store_all()
    parent, worker = table(tmp_path, monkeypatch), table(tmp_path, monkeypatch)
    deeper = worker.log_density(KEYS)  # two rows deepened, one new
    keys, rows = worker.new_rows()
    assert sorted(keys) == sorted(KEYS)
    calls = []
    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", lambda *a, **k: calls.append(a) or 1 / 0)
    parent.merge(keys, rows)
    np.testing.assert_array_equal(parent.log_density(KEYS), deeper)
    assert calls == []


#: A storm day's key: its indices, then the 27 3-hourly ap from 57 h before its first slot to its last: those
#: of 2003-10-26 (from its sixth slot) to 2003-10-29 in CelesTrak's SW-All.txt (tests/decay/test_solar_record.py).
STORM_KEY = (
    *(270.9, 144.8, 204.0, 302.0),
    *(4.0, 18.0, 22.0, 22.0, 18.0, 18.0, 7.0, 7.0, 9.0, 5.0, 4.0),
    *(15.0, 39.0, 22.0, 39.0, 12.0, 27.0, 18.0, 27.0),
    *(39.0, 27.0, 400.0, 207.0, 179.0, 179.0, 300.0, 300.0),
)


def direct_row(key, heights_m=HEIGHTS_M, inclination_deg=51.6, latitude_nodes=4, local_time_nodes=4):
    """A day's row from pymsis itself: a storm key through the day's eight 3-hour slots in storm-time mode."""
    if len(key) == 4:
        return orbit_mean_density_by_day_kg_m3(
            heights_m,
            *([v] for v in key),
            inclination_deg,
            None,
            latitude_nodes=latitude_nodes,
            local_time_nodes=local_time_nodes,
        )[0]
    f107, f107a, ap, doy = key[:4]
    ap3 = np.array(key[4:])
    slots = []
    for slot in range(8):
        now = 19 + slot  # the slot's place in the 27
        # pymsis.calculate's docstring: daily Ap; ap now, 3, 6 and 9 h before; means of 12-33 h and 36-57 h before.
        history = [
            ap,
            *ap3[[now, now - 1, now - 2, now - 3]],
            ap3[now - 11 : now - 3].mean(),
            ap3[now - 19 : now - 11].mean(),
        ]
        slots.append((1.5 + 3.0 * slot, history))  # the slot's middle
    return pymsis_orbit_mean(
        heights_m, inclination_deg, None, doy, f107, f107a, slots, latitude_nodes, local_time_nodes
    )


def test_a_storm_days_row_is_nrlmsis_storm_time_mode_through_its_slots(tmp_path, monkeypatch):
    rows = table(tmp_path, monkeypatch).log_density([*KEYS, STORM_KEY])
    np.testing.assert_allclose(np.exp(rows[-1]), direct_row(STORM_KEY), rtol=RTOL)
    # The storm-time mode is what the row holds: the Halloween storm's history against the daily Ap alone.
    daily = direct_row(STORM_KEY[:4])
    assert np.all(np.abs(np.exp(rows[-1]) / daily - 1.0) > 0.02)


def test_daily_rows_are_unchanged_bit_for_bit_by_storm_rows_beside_them(tmp_path, monkeypatch):
    alone = table(tmp_path / "a", monkeypatch).log_density(KEYS)
    mixed = table(tmp_path / "b", monkeypatch).log_density([KEYS[0], STORM_KEY, *KEYS[1:]])
    np.testing.assert_array_equal(mixed[[0, 2, 3]], alone)
    for key, row in zip(KEYS, alone, strict=True):
        np.testing.assert_allclose(np.exp(row), direct(key), rtol=RTOL)


def test_storm_rows_come_back_from_the_disk_cache_under_their_own_keys(tmp_path, monkeypatch):
    first = table(tmp_path, monkeypatch)
    rows = first.log_density([*KEYS, STORM_KEY])
    first.store()
    monkeypatch.setattr(daily_air, "orbit_mean_density_by_day_kg_m3", pytest.fail)
    again = table(tmp_path, monkeypatch)
    assert len(again) == 4
    np.testing.assert_array_equal(again.log_density([STORM_KEY, *KEYS]), rows[[3, 0, 1, 2]])


def test_storm_days_are_those_whose_3_hourly_ap_reach_the_threshold():
    record = load_record()
    start = unix_days("2003-10-20")
    days = start + np.arange(20.0)
    storm = SolarDecayModel(record, start, 28.5).daily_indices(days)
    plain = SolarDecayModel(record, start, 28.5, storm_ap=False).daily_indices(days)
    history = record.ap_history(days)
    for key, quiet, ap3 in zip(storm, plain, history, strict=True):
        assert len(quiet) == 4 and key[:4] == quiet
        if ap3.max() >= STORM_AP:
            assert key[4:] == tuple(ap3)
        else:
            assert key == quiet  # a quiet day keeps its daily-Ap key: the same row as before
    assert 0 < sum(len(key) > 4 for key in storm) < len(storm)


@pytest.mark.usefixtures("forking")
def test_the_days_after_come_from_a_forked_process_and_equal_the_foreground_rows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``after``'s rows are computed by a child (this process's NRLMSIS calls do not count them), bit for bit."""
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path))
    heights = np.linspace(150e3, 600e3, 7)
    keys = [(120.0 + day, 130.0, 8.0, 2.0 * day + 1.0) for day in range(12)]
    calls = []
    original = daily_air.orbit_mean_density_by_day_kg_m3
    monkeypatch.setattr(
        daily_air, "orbit_mean_density_by_day_kg_m3", lambda *a, **k: calls.append(1) or original(*a, **k)
    )
    table = daily_air.DailyAirTable(heights, 51.6, None, 2.1, 3, 3)
    table.log_density(keys[:2], after=lambda: keys[2:])
    assert len(calls) == 1  # the two days asked for; the ten after in the child
    child = table._pending[1]
    while child.running():  # asked for before it has finished, its unfinished days would be computed here
        time.sleep(0.01)
    later = table.log_density(keys[2:])
    assert len(calls) == 1, "the days after were computed in this process"
    monkeypatch.setenv("ORBIT_ENV_CACHE_DIR", str(tmp_path / "other"))
    fresh = daily_air.DailyAirTable(heights, 51.6, None, 2.1, 3, 3)
    np.testing.assert_array_equal(later, fresh.log_density(keys[2:]))
    assert len(calls) == 2
