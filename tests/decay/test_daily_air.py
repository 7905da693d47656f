"""The real Sun's air table (`orbit_env.decay.daily_air`): a memo of NRLMSIS, not an approximation.

Its rows must be NRLMSIS's own orbit averages for the day's indices, whichever batch
computed them and whether they came from memory or from the disk cache; the decay's
density ratios read through it must equal those computed from NRLMSIS directly.
Tolerance 1e-12 relative: the same NRLMSIS values summed in another order (a batch
of days against one day; exp of the stored logarithm) differ in the last bits only.
"""

import numpy as np
import pytest

from orbit_env import cache
from orbit_env.decay import daily_air
from orbit_env.decay.chunked import SolarDecayModel, air_table
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


@pytest.mark.parametrize("follow_season", [True, False])
def test_the_decays_density_ratio_equals_nrlmsis_directly(follow_season):
    start = unix_days("2015-03-10")  # the March 2015 storm: indices that change day by day
    model = SolarDecayModel(load_record(), start, 51.6, follow_season=follow_season)
    daily = model.daily_indices(start + np.arange(20.0))
    binned = (130.0, 12.0)
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
