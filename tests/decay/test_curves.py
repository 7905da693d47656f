"""The universal curves against the averaged ODE they tabulate."""

import numpy as np
import pytest

from orbit_env.decay.averaged import integrate_averaged
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M, universal_curves

# The target: interpolation error <= 0.5% against the ODE (DOP853, rtol 1e-9),
# for lifetimes nu >= 0.1 (Table II's smallest cell is 0.121). Measured: <= 0.06%.
TOLERANCE = 5e-3


@pytest.fixture(scope="module")
def curves():
    return universal_curves()


def random_orbits(n, seed):
    rng = np.random.default_rng(seed)
    hp = rng.uniform(140e3, CURVES_MAX_PERIGEE_M, n)
    ha = hp + rng.uniform(0, 1, n) ** 2 * (CURVES_MAX_APOGEE_M - hp)
    return hp, ha


def test_lifetime_matches_the_ode_on_random_orbits(curves):
    hp, ha = random_orbits(40, seed=1)
    hp = np.concatenate([hp, [150e3, 1000e3, 400e3, 120e3, 300e3]])
    ha = np.concatenate([ha, [150e3, 1000e3, 400e3, 3000e3, 4000e3]])
    nu_curves = curves.locate(hp, ha).nu
    nu_ode = np.array([integrate_averaged(a, b).nu[-1] for a, b in zip(hp, ha, strict=True)])
    check = nu_ode >= 0.1
    assert check.sum() >= 40
    assert np.max(np.abs(nu_curves[check] / nu_ode[check] - 1)) <= TOLERANCE


def test_lifetime_matches_the_ode_at_the_top_corner_of_the_domain(curves):
    """Perigee 1080-1100 km, apogee up to 4000 km: where curves once stopped before the table's top.

    Rows of table A with no crossing there held their last value, and lifetimes at perigee
    1095-1100 km came out 4-6 times too short (found by `tests/cli/test_cli.py`'s property test).
    Measured since: within 0.05% of the ODE here; the module's tolerance applies.
    """
    hp, ha = (g.ravel() for g in np.meshgrid([1080e3, 1094e3, 1096e3, 1100e3], [1500e3, 2350e3, 4000e3]))
    nu_curves = curves.locate(hp, ha).nu
    nu_ode = np.array([integrate_averaged(a, b).nu[-1] for a, b in zip(hp, ha, strict=True)])
    assert np.max(np.abs(nu_curves / nu_ode - 1)) <= TOLERANCE


def test_time_matches_the_ode(curves):
    hp, ha = random_orbits(15, seed=2)
    weighted = curves.locate(hp, ha).weighted_s
    ode = np.array([integrate_averaged(a, b).weighted_s[-1] for a, b in zip(hp, ha, strict=True)])
    np.testing.assert_allclose(weighted, ode, rtol=TOLERANCE)


def test_advance_follows_the_ode_trajectory(curves):
    hp, ha = random_orbits(12, seed=3)
    for a, b in zip(hp, ha, strict=True):
        path = integrate_averaged(a, b, samples=9)
        start = curves.locate(a, b)
        total = path.nu[-1]
        for k in (2, 4, 6):
            moved = curves.advance(start, path.nu[k])
            here = curves.locate(path.perigee_m[k], path.apogee_m[k])
            # Remaining lifetime after advancing equals the ODE's, to the tolerance of
            # the whole lifetime (what is left is a difference of two interpolations).
            assert abs(moved.nu - here.nu) <= TOLERANCE * total
            hp_c, ha_c, _ = curves.at(moved.label, moved.tau)
            if path.nu[k] < 0.9 * total:
                assert abs(hp_c - path.perigee_m[k]) < 2e3 and abs(ha_c - path.apogee_m[k]) < 10e3


def test_circular_and_near_circular_orbits(curves):
    heights = np.array([150e3, 300e3, 700e3])
    circular = curves.locate(heights, heights).nu
    nearly = curves.locate(heights, heights + 1.0).nu  # 1 m of eccentricity
    ode = np.array([integrate_averaged(h, h).nu[-1] for h in heights])
    np.testing.assert_allclose(circular, ode, rtol=TOLERANCE)
    np.testing.assert_allclose(nearly, circular, rtol=1e-4)


def test_lifetime_rises_with_perigee_and_apogee(curves):
    hp = np.linspace(150e3, 1000e3, 200)
    assert np.all(np.diff(curves.locate(hp, hp + 300e3).nu) > 0)
    ha = np.linspace(300e3, 4000e3, 200)
    assert np.all(np.diff(curves.locate(np.full_like(ha, 300e3), ha).nu) > 0)


def test_advance_to_reentry_clamps(curves):
    start = curves.locate(300e3, 500e3)
    end = curves.advance(start, 10 * start.nu)
    assert end.nu == 0.0
    hp, ha, _ = curves.at(end.label, end.tau)
    assert hp == pytest.approx(100e3) and ha >= hp


def test_domain_errors_name_the_value(curves):
    why = "(the universal curves end there; the averaged ODE goes higher)"
    with pytest.raises(ValueError) as info:
        curves.check_domain(1200e3, 1300e3)
    assert str(info.value) == f"perigee_m=1200000 is out of range; allowed: at most 1100000 m {why}"
    with pytest.raises(ValueError) as info:
        curves.check_domain_km(300, 5000)
    assert str(info.value) == f"apogee_km=5000 is out of range; allowed: at most 4000 km {why}"
    hp, ha = curves.check_domain_km(300, 4000)  # the bounds are allowed; metres come back
    assert (float(hp), float(ha)) == (300e3, 4000e3)


def test_row_splines_are_scipys_cubic_spline():
    # The build's spline (numpy, all rows at once) against scipy's CubicSpline (not-a-knot ends) on
    # ragged rows of uneven knots, down to the four a cubic needs. Both solve the same tridiagonal
    # system for the knots' slopes (Thomas against LAPACK's banded LU), so they differ by round-off:
    # 1e-12 of the row's largest value (measured: 3e-15).
    from scipy.interpolate import CubicSpline

    from orbit_env.decay.curves import _spline_rows

    rng = np.random.default_rng(4)
    rows, size = 40, 25
    counts = np.concatenate([[4, 5, size], rng.integers(4, size + 1, rows - 3)])
    x = np.full((rows, size), np.nan)
    y = np.full((2, rows, size), np.nan)
    for r, n in enumerate(counts):
        x[r, :n] = np.cumsum(rng.uniform(0.01, 3.0, n))
        y[:, r, :n] = np.cumsum(rng.normal(size=(2, n)), axis=1)
    query = np.linspace(-1.0, 80.0, 500)
    ours = _spline_rows(x, y, counts, query)
    for r, n in enumerate(counts):
        inside = np.clip(query, x[r, 0], x[r, n - 1])
        theirs = CubicSpline(x[r, :n], y[:, r, :n], axis=1)(inside)
        assert np.max(np.abs(ours[:, r] - theirs)) <= 1e-12 * np.max(np.abs(y[:, r, :n]))


def test_lookups_before_the_cells_are_built_equal_those_after_bit_for_bit():
    from orbit_env.decay.curves import BilinearGrid

    # Until something asks for the cells, values() forms each point's coefficients from its
    # four corners; the arithmetic is the same, so the results must be identical (no tolerance).
    rng = np.random.default_rng(1)
    tables = rng.normal(size=(3, 50, 40))
    lazy, built = BilinearGrid(tables, 1.0, 0.5, -2.0, 0.25), BilinearGrid(tables, 1.0, 0.5, -2.0, 0.25)
    assert built.cells.shape == (50 * 40, 3, 4)
    x, y = rng.uniform(-1.0, 30.0, (20, 50)), rng.uniform(-3.0, 10.0, (20, 50))  # clamped edges included
    for a, b in zip(lazy.values(x, y), built.values(x, y), strict=True):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(lazy.values(3.3, y), built.values(3.3, y), strict=True):  # a scalar against an array
        np.testing.assert_array_equal(a, b)
    # One orbit's lookups in plain floats, from the corners too.
    points = list(zip(x[1].tolist(), y[1].tolist(), strict=True))
    assert [lazy.values_scalar(u, v) for u, v in points] == [built.values_scalar(u, v) for u, v in points]
    assert [lazy.segment_scalar(u, v) for u, v in points] == [built.segment_scalar(u, v) for u, v in points]
    assert "cells" not in lazy.__dict__
    from orbit_env.decay.curves import CORNER_LOOKUPS

    for _ in range(CORNER_LOOKUPS):  # a grid looked up this often builds its cells
        lazy.values(x[0], y[0])
    assert "cells" in lazy.__dict__
    np.testing.assert_array_equal(np.array(lazy.values(x, y)), np.array(built.values(x, y)))
    scalar = [lazy.values_scalar(float(u), float(v)) for u, v in zip(x[0], y[0], strict=True)]
    np.testing.assert_array_equal(np.array(scalar).T, np.array(lazy.values(x[0], y[0])))


def test_a_few_points_looked_up_one_by_one_equal_the_array_lookup_bit_for_bit():
    from orbit_env.decay.curves import SCALAR_POINTS, BilinearGrid

    # Up to SCALAR_POINTS points take values_scalar one by one; the floats must be the array path's.
    rng = np.random.default_rng(2)
    grid = BilinearGrid(rng.normal(size=(3, 50, 40)), 1.0, 0.5, -2.0, 0.25)
    x, y = rng.uniform(-1.0, 30.0, 2 * SCALAR_POINTS), rng.uniform(-3.0, 10.0, 2 * SCALAR_POINTS)
    whole = grid.values(x, y)  # more points than SCALAR_POINTS: the array path
    for n in range(1, SCALAR_POINTS + 1):
        few = grid.values(x[:n], y[:n])
        assert all(a.shape == (n,) for a in few)
        for a, b in zip(few, whole, strict=True):
            np.testing.assert_array_equal(a, b[:n])
    square = grid.values(x[:4].reshape(2, 2), y[:4].reshape(2, 2))  # any shape of a few points
    np.testing.assert_array_equal(np.array(square), np.array(whole)[:, :4].reshape(3, 2, 2))
    point = grid.values(np.float64(x[0]), np.float64(y[0]))  # 0-d in, 0-d out
    assert point[0].shape == () and [float(v) for v in point] == [float(b[0]) for b in whole]


@pytest.mark.usefixtures("forking")
def test_curves_integrated_in_two_processes_are_the_curves_integrated_together(monkeypatch):
    """Half the curves in a forked child (`orbit_env.workers.in_two_processes`): the same numbers, bit for bit."""
    from orbit_env import workers
    from orbit_env.decay import curves as curves_module

    forks = []

    class Counted(workers.Forked):
        def __init__(self, *args, **kwargs):
            forks.append(args[1])
            super().__init__(*args, **kwargs)

    curves = universal_curves()
    monkeypatch.setattr(workers, "Forked", Counted)
    tau = np.arange(0.0, curves_module._TAU_TOP + curves_module._DTAU, curves_module._DTAU)
    split = curves._integrate(tau, curves.labels)
    assert forks == [(curves.labels.size - curves.labels.size // 2, 3, tau.size)]
    together = curves._integrate_curves(tau, curves.labels)
    for a, b in zip(split, together, strict=True):
        np.testing.assert_array_equal(a, b)
