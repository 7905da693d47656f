"""The solar task's step, month of decay, rule and disposal burn, compiled: loops over the orbits (numba).

The one implementation of `orbit_env.envs.solar_task`'s step (`_step_row`: the perigee burn,
`orbit_env.envs.kernel.burn_row`, then the month's coast) and observation (`_observe_row`),
of its coast (`coast_block`), of the rule's judgement (`life_margin_days`) and of the
cheapest compliant disposal burn (`disposal`): plain-float functions of one orbit, compiled
by numba into loops over arrays (`step_rows`, `observe_rows`, both in one loop for the
environments, `step_observe_rows`, and for the single environment's one orbit
`step_observe_one`; with ``ORBIT_ENV_JIT=0`` the same functions run uncompiled, slowly). An orbit's month is
a handful of table lookups; the rule at a mission's end decays it (and each candidate
disposal) month by month over five years, which numpy spent in thousands of small calls.

They read the tables the rest of the package reads: table A (where heights fall on the
curves) and table B (heights and period along a curve) of the drag clock's universal
curves as `orbit_env.envs.kernel` reads them (`orbit_env.envs.kernel.tables`, its
`orbit_env.envs.kernel.cell`), and the clock's cumulative drag-days
(`orbit_env.decay.drag_clock.drag_days_at`). ``tests/envs/test_solar_task.py`` holds the
compiled loops equal to the uncompiled functions and the coast equal to the array
lookups of `orbit_env.decay.curves.UniversalCurves` (``weighted_at``, ``move_to_weight``).

Units: SI (m, s); days for spans and the calendar (whole days since the record's first).
"""

from __future__ import annotations

import math
import os
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import EARTH_RADIUS_M, G0_M_S2, MU_EARTH_M3_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY, TWO_PI
from orbit_env.decay.curves import NU_REF
from orbit_env.decay.drag_clock import DragClock, drag_days_at
from orbit_env.envs.kernel import JIT_VARIABLE, PARAMETERS, burn_row, cell, table_a_point, tables
from orbit_env.envs.kernel import compiled as kernel_loops
from orbit_env.envs.state import ROW, SEGMENT_ROW, STALE_SEGMENT

FloatArray = NDArray[np.float64]

#: The lowest rate W may fall at when the rule's years end with the orbit still up (per day, relative).
MIN_RATE = 1e-9


class SolarTables(NamedTuple):
    """What the loops read: tables A and B of the clock's curves (cells and scales) and its drag-days."""

    a_cells: FloatArray
    a_grid: FloatArray
    b_cells: FloatArray
    b_grid: FloatArray
    cumulative: FloatArray
    indices: FloatArray  # (4, days): the clock's `DragClock.daily_indices` as rows


@lru_cache(maxsize=4)
def solar_tables(clock: DragClock) -> SolarTables:
    """The tables of a drag clock (built once per clock)."""
    return SolarTables(*tables(clock.curves), clock.cumulative_days, np.array(clock.daily_indices))


def _curve_at(label: float, tau: float, b_cells: FloatArray, b_grid: FloatArray) -> tuple[float, float, float]:
    """`UniversalCurves.at` of one point: perigee [m], apogee [m], mean period left [s] (the same operations)."""
    row, tx, _, ty = cell(b_grid, label, tau)
    txy = tx * ty
    b0 = b_cells[row, 0, 1] * tx + b_cells[row, 0, 0] + b_cells[row, 0, 2] * ty + b_cells[row, 0, 3] * txy
    b1 = b_cells[row, 1, 1] * tx + b_cells[row, 1, 0] + b_cells[row, 1, 2] * ty + b_cells[row, 1, 3] * txy
    q = b_cells[row, 2, 1] * tx + b_cells[row, 2, 0] + b_cells[row, 2, 2] * ty + b_cells[row, 2, 3] * txy
    hp = max(b0, REENTRY_ALTITUDE_M)
    one_minus_e = 1.0 - math.exp(b1 + label)
    rp = hp + EARTH_RADIUS_M
    return hp, (rp + rp) / one_minus_e - rp - EARTH_RADIUS_M, q


def _kepler_period_s(perigee_m: float, apogee_m: float) -> float:
    """`orbit.period_s` of `orbit.elements_from_heights`: the osculating ellipse's period [s]."""
    rp = EARTH_RADIUS_M + perigee_m
    ra = EARTH_RADIUS_M + apogee_m
    e = (ra - rp) / (ra + rp)
    a = rp * (1.0 + e) / (1.0 - e * e)
    return TWO_PI * math.sqrt(a * a * a / MU_EARTH_M3_S2)


def _nu_at_weight(
    label: float,
    nu: float,
    weighted: float,
    target: float,
    perigee_m: float,
    apogee_m: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
) -> float:
    """`UniversalCurves.move_to_weight`'s nu of one orbit, every lookup: Newton on W(nu) = target, dW/dnu = P."""
    nu = max(nu - (weighted - target) / _kepler_period_s(perigee_m, apogee_m), 0.0)
    for _ in range(3):
        hp, ha, q = _curve_at(label, math.log1p(nu / NU_REF), b_cells, b_grid)
        nu = max(nu - (q * nu - target) / _kepler_period_s(hp, ha), 0.0)
    return nu


def _coast(
    label: float,
    nu: float,
    perigee_m: float,
    apogee_m: float,
    gc: float,
    first_day: float,
    days: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> tuple[float, float, float, float, float, float, float]:
    """One orbit's `coast_block`: (days lived, nu, tau, perigee, apogee, period, the span's mean multiplier).

    W = Int P dnu falls by g c x the drag-days of the span at the perigee of its start; an orbit
    whose W runs out re-enters at that fraction of the span (the span's mean rate).
    """
    _, _, q = _curve_at(label, math.log1p(nu / NU_REF), b_cells, b_grid)
    return _coast_from(label, nu, q, perigee_m, apogee_m, gc, first_day, days, b_cells, b_grid, cumulative)


def _coast_from(
    label: float,
    nu: float,
    q: float,
    perigee_m: float,
    apogee_m: float,
    gc: float,
    first_day: float,
    days: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> tuple[float, float, float, float, float, float, float]:
    """`_coast` of an orbit whose mean period left ``q`` (W / nu) is known: the period a coast before it returned."""
    weighted = q * nu
    whole = math.ceil(days)
    drag = drag_days_at(cumulative, perigee_m, first_day, first_day + whole) * (days / whole)
    drop = gc * drag * SECONDS_PER_DAY
    target = weighted - drop
    if target > 0.0:
        lived = days
        nu = _nu_at_weight(label, nu, weighted, target, perigee_m, apogee_m, b_cells, b_grid)
    else:
        lived = days * weighted / max(drop, 1e-300)
        nu = 0.0
    tau = math.log1p(nu / NU_REF)
    hp, ha, period = _curve_at(label, tau, b_cells, b_grid)
    return lived, nu, tau, hp, ha, period, drag / days


def _life_margin(
    label: float,
    nu: float,
    perigee_m: float,
    apogee_m: float,
    gc: float,
    first_day: float,
    block_days: float,
    horizon_days: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> float:
    """Re-entry day after ``first_day`` minus ``horizon_days`` (<= 0 complies), by coasts of ``block_days``.

    An orbit still up at the horizon gets its W left over its last span's rate (the days it
    would still live at that rate, > 0).
    """
    if nu <= 0.0:
        return -horizon_days
    t = 0.0
    rate = 0.0
    _, _, q = _curve_at(label, math.log1p(nu / NU_REF), b_cells, b_grid)
    while t < horizon_days:
        span = min(block_days, horizon_days - t)
        # Each coast's closing lookup (its nu's period) is the next one's opening lookup: taken along.
        lived, nu, _, perigee_m, apogee_m, q, rate = _coast_from(
            label, nu, q, perigee_m, apogee_m, gc, first_day + t, span, b_cells, b_grid, cumulative
        )
        if nu <= 0.0:
            return t + lived - horizon_days
        t += span
    return q * nu / (gc * max(rate, MIN_RATE) * SECONDS_PER_DAY)


def _candidate_margin(
    perigee_m: float,
    apogee_m: float,
    gc: float,
    first_day: float,
    block_days: float,
    horizon_days: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> float:
    """`_life_margin` of the orbit a disposal burn leaves: located on the curves (table A), read back (table B)."""
    label, tau = table_a_point(perigee_m, apogee_m, a_cells, a_grid)
    hp, ha, _ = _curve_at(label, tau, b_cells, b_grid)
    nu = NU_REF * math.expm1(tau)
    return _life_margin(label, nu, hp, ha, gc, first_day, block_days, horizon_days, b_cells, b_grid, cumulative)


def _disposal_perigee(
    label: float,
    nu: float,
    perigee_m: float,
    apogee_m: float,
    gc: float,
    first_day: float,
    block_days: float,
    horizon_days: float,
    candidates: int,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> float:
    """The highest perigee [m] a disposal burn may leave one orbit for it to comply (its own if it complies).

    Two passes over ``candidates`` + 1 perigees evenly from 100 km (re-enters at once:
    compliant) to the orbit's own (not compliant); each finds the highest compliant one by
    bisection (compliance is monotone in the perigee) and the next pass searches between it
    and the next. The cheapest compliant burn lowers the perigee to the last one found.
    """
    margin = _life_margin(
        label, nu, perigee_m, apogee_m, gc, first_day, block_days, horizon_days, b_cells, b_grid, cumulative
    )
    if not margin > 0.0:
        return perigee_m
    low, high = REENTRY_ALTITUDE_M, perigee_m
    for _ in range(2):
        ok, bad = 0, candidates  # candidate indices: ok complies, bad does not
        step = (high - low) / candidates
        while bad - ok > 1:
            middle = (ok + bad) // 2
            m = _candidate_margin(
                low + step * middle,
                apogee_m,
                gc,
                first_day,
                block_days,
                horizon_days,
                a_cells,
                a_grid,
                b_cells,
                b_grid,
                cumulative,
            )
            if m <= 0.0:
                ok = middle
            else:
                bad = middle
        low, high = low + step * ok, low + step * (ok + 1)
    return low


def _coast_rows(
    label: FloatArray,
    nu: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    gc: FloatArray,
    first_day: FloatArray,
    days: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    out: FloatArray,
) -> None:
    """`_coast` of every orbit into ``out`` (7, n), rows as `Coast`'s fields."""
    for k in range(label.size):
        result = _coast(
            label[k], nu[k], perigee_m[k], apogee_m[k], gc[k], first_day[k], days, b_cells, b_grid, cumulative
        )
        for m in range(7):
            out[m, k] = result[m]


def _life_margin_rows(
    label: FloatArray,
    nu: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    gc: FloatArray,
    first_day: FloatArray,
    block_days: float,
    horizon_days: float,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    out: FloatArray,
) -> None:
    """`_life_margin` of every orbit into ``out``."""
    for k in range(label.size):
        out[k] = _life_margin(
            label[k],
            nu[k],
            perigee_m[k],
            apogee_m[k],
            gc[k],
            first_day[k],
            block_days,
            horizon_days,
            b_cells,
            b_grid,
            cumulative,
        )


def _disposal_rows(
    label: FloatArray,
    nu: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    gc: FloatArray,
    first_day: FloatArray,
    block_days: float,
    horizon_days: float,
    candidates: int,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    out: FloatArray,
) -> None:
    """`_disposal_perigee` of every orbit into ``out``."""
    for k in range(label.size):
        out[k] = _disposal_perigee(
            label[k],
            nu[k],
            perigee_m[k],
            apogee_m[k],
            gc[k],
            first_day[k],
            block_days,
            horizon_days,
            candidates,
            a_cells,
            a_grid,
            b_cells,
            b_grid,
            cumulative,
        )


def _step_row(
    data: FloatArray,
    k: int,
    requested_m_s: float,
    p: FloatArray,
    block_days: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
) -> tuple[float, float, bool, bool]:
    """A step of row ``k`` of a batch's state array, in place: the perigee burn asked for, then a month's `_coast`.

    The burn is `orbit_env.envs.kernel.burn_row` (the known-density task's); the reward is the
    days lived less the propellant's cost; the ends are re-entry and the horizon's step.

    Returns:
        (the burn made [m/s], the reward [days], terminated, truncated).
    """
    dv = 0.0
    if min(requested_m_s, data[ROW.dv_left_m_s, k]) > 0.0:
        dv = burn_row(data, k, requested_m_s, p, a_cells, a_grid, b_cells, b_grid)
    gc = G0_M_S2 * (data[ROW.drag_area_m2, k] / data[ROW.mass_kg, k])
    day = data[ROW.start_day, k] + data[ROW.steps, k] * block_days
    perigee, apogee = data[ROW.perigee_m, k], data[ROW.apogee_m, k]
    lived, nu, tau, hp, ha, period, ratio = _coast(
        data[ROW.label, k], data[ROW.nu, k], perigee, apogee, gc, day, block_days, b_cells, b_grid, cumulative
    )
    data[ROW.perigee_drop_m, k] = perigee - hp
    data[ROW.apogee_drop_m, k] = apogee - ha
    data[ROW.nu, k] = nu
    data[ROW.tau, k] = tau
    data[ROW.perigee_m, k] = hp
    data[ROW.apogee_m, k] = ha
    if nu > 0.0:
        data[ROW.period_s, k] = period  # a re-entered orbit keeps its last period
    data[SEGMENT_ROW, k] = STALE_SEGMENT  # the known-density task's kept cell: not this task's
    data[ROW.density_scale, k] = ratio
    data[ROW.time_days, k] += lived
    steps = data[ROW.steps, k] + 1.0
    data[ROW.steps, k] = steps
    reward = lived - p[PARAMETERS.propellant_cost_per_m_s] * dv
    return dv, reward, nu <= 0.0, steps >= p[PARAMETERS.horizon_steps] and nu > 0.0


def _step_rows(
    data: FloatArray,
    requested_m_s: FloatArray,
    p: FloatArray,
    block_days: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    made: FloatArray,
    reward: FloatArray,
    terminated: NDArray[np.bool_],
    truncated: NDArray[np.bool_],
) -> int:
    """`_step_row` of every row of a batch's state array, in place; returns how many rows were truncated."""
    ending = 0
    for k in range(data.shape[1]):
        made[k], reward[k], terminated[k], truncated[k] = _step_row(
            data, k, requested_m_s[k], p, block_days, a_cells, a_grid, b_cells, b_grid, cumulative
        )
        ending += truncated[k]
    return ending


def _observe_row(
    data: FloatArray,
    k: int,
    p: FloatArray,
    block_days: float,
    index_scale: float,
    indices: FloatArray,
    low: FloatArray,
    high: FloatArray,
    obs: NDArray[np.float32],
) -> None:
    """The observation of row ``k`` into ``obs[k]``: the orbit, tank, clock, predicted life; the Sun yesterday.

    The predicted life is W over the last span's mean multiplier at the perigee; the Sun's
    indices (``indices`` rows: F10.7, its 81- and 365-day means, Ap) are the day's before the
    step's first, over ``index_scale``; each component clipped to [low, high].
    """
    steps = data[ROW.steps, k]
    yesterday = int(data[ROW.start_day, k] + steps * block_days - 1.0)
    gc = G0_M_S2 * (data[ROW.drag_area_m2, k] / data[ROW.mass_kg, k])
    life = data[ROW.period_s, k] * data[ROW.nu, k] / (gc * max(data[ROW.density_scale, k], 1e-9) * SECONDS_PER_DAY)
    apogee_drop = max(data[ROW.apogee_drop_m, k], 0.0)
    perigee_drop = max(data[ROW.perigee_drop_m, k], 0.0)
    values = (
        data[ROW.perigee_m, k] * p[PARAMETERS.per_height_scale_m],
        data[ROW.apogee_m, k] * p[PARAMETERS.per_height_scale_m],
        data[ROW.dv_left_m_s, k] * p[PARAMETERS.per_dv_scale_m_s],
        min(steps / p[PARAMETERS.horizon_steps], 1.0),
        life / (life + p[PARAMETERS.lifetime_scale_days]),
        apogee_drop / (apogee_drop + p[PARAMETERS.apogee_drop_scale_m]),
        perigee_drop / (perigee_drop + p[PARAMETERS.perigee_drop_scale_m]),
        indices[0, yesterday] / index_scale,
        indices[1, yesterday] / index_scale,
        indices[2, yesterday] / index_scale,
        indices[3, yesterday] / index_scale,
    )
    for m in range(len(values)):
        obs[k, m] = min(max(values[m], low[m]), high[m])


def _observe_rows(
    data: FloatArray,
    p: FloatArray,
    block_days: float,
    index_scale: float,
    indices: FloatArray,
    low: FloatArray,
    high: FloatArray,
    obs: NDArray[np.float32],
) -> None:
    """`_observe_row` of every row into ``obs`` (n, 11)."""
    for k in range(data.shape[1]):
        _observe_row(data, k, p, block_days, index_scale, indices, low, high, obs)


def _step_observe_rows(
    data: FloatArray,
    requested_m_s: FloatArray,
    p: FloatArray,
    block_days: float,
    index_scale: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    indices: FloatArray,
    low: FloatArray,
    high: FloatArray,
    made: FloatArray,
    reward: FloatArray,
    terminated: NDArray[np.bool_],
    truncated: NDArray[np.bool_],
    obs: NDArray[np.float32],
) -> int:
    """`_step_row`, then `_observe_row`, of every row (what an environment's step does in one call).

    Returns:
        How many rows were truncated (the mission's end: their rule is judged next).
    """
    ending = 0
    for k in range(data.shape[1]):
        made[k], reward[k], terminated[k], truncated[k] = _step_row(
            data, k, requested_m_s[k], p, block_days, a_cells, a_grid, b_cells, b_grid, cumulative
        )
        ending += truncated[k]
        _observe_row(data, k, p, block_days, index_scale, indices, low, high, obs)
    return ending


def _step_observe_one(
    data: FloatArray,
    requested_m_s: float,
    p: FloatArray,
    block_days: float,
    index_scale: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    cumulative: FloatArray,
    indices: FloatArray,
    low: FloatArray,
    high: FloatArray,
) -> tuple[NDArray[np.float32], float, float, bool, bool]:
    """`_step_observe_rows` of a batch of one (the single environment: no arrays to allocate around the call).

    Returns:
        (the observation (components,), the burn made [m/s], the reward [days], terminated, truncated).
    """
    obs = np.empty((1, low.size), dtype=np.float32)
    dv, reward, terminated, truncated = _step_row(
        data, 0, requested_m_s, p, block_days, a_cells, a_grid, b_cells, b_grid, cumulative
    )
    _observe_row(data, 0, p, block_days, index_scale, indices, low, high, obs)
    return obs[0], dv, reward, terminated, truncated


class _Loops(NamedTuple):
    """The loops over orbits (compiled, or the plain functions with ``ORBIT_ENV_JIT=0``)."""

    coast_rows: Any
    life_margin_rows: Any
    disposal_rows: Any
    step_rows: Any
    observe_rows: Any
    step_observe_rows: Any
    step_observe_one: Any


_PLAIN = _Loops(
    _coast_rows, _life_margin_rows, _disposal_rows, _step_rows, _observe_rows, _step_observe_rows, _step_observe_one
)


@lru_cache(maxsize=1)
def loops() -> _Loops:
    """The loops, compiled by numba on first use (cached on disk); uncompiled with ``ORBIT_ENV_JIT=0``."""
    if os.environ.get(JIT_VARIABLE, "1").strip() == "0":
        return _PLAIN
    import numba

    kernel_loops()  # registers the known-density loops' helpers (burn_row and what it calls)
    helpers = (drag_days_at, _curve_at, _kepler_period_s, _nu_at_weight, _coast_from, _coast, _step_row, _observe_row)
    for helper in (*helpers, _life_margin, _candidate_margin, _disposal_perigee):
        numba.extending.register_jitable(helper)
    return _Loops(*(numba.njit(cache=True, nogil=True)(loop) for loop in _PLAIN))


def _float_rows(*arrays: Any) -> list[FloatArray]:
    """The arguments broadcast together, as contiguous 1-d float64 arrays."""
    return [np.ascontiguousarray(a, dtype=np.float64).ravel() for a in np.broadcast_arrays(*arrays)]


def coast_rows(
    clock: DragClock,
    label: Any,
    nu: Any,
    perigee_m: Any,
    apogee_m: Any,
    gc: Any,
    first_day: Any,
    days: float,
) -> FloatArray:
    """Orbits (arrays that broadcast) coasted ``days`` from ``first_day``: a (7, n) array, rows as `Coast`."""
    t = solar_tables(clock)
    rows = _float_rows(label, nu, perigee_m, apogee_m, gc, first_day)
    out = np.empty((7, rows[0].size))
    loops().coast_rows(*rows, float(days), t.b_cells, t.b_grid, t.cumulative, out)
    return out


def life_margin_rows(
    clock: DragClock,
    label: Any,
    nu: Any,
    perigee_m: Any,
    apogee_m: Any,
    gc: Any,
    first_day: Any,
    block_days: float,
    horizon_days: float,
) -> FloatArray:
    """`_life_margin` of orbits (arrays that broadcast), 1-d [days]."""
    t = solar_tables(clock)
    rows = _float_rows(label, nu, perigee_m, apogee_m, gc, first_day)
    out = np.empty(rows[0].size)
    loops().life_margin_rows(*rows, float(block_days), float(horizon_days), t.b_cells, t.b_grid, t.cumulative, out)
    return out


def disposal_perigee_rows(
    clock: DragClock,
    label: Any,
    nu: Any,
    perigee_m: Any,
    apogee_m: Any,
    gc: Any,
    first_day: Any,
    block_days: float,
    horizon_days: float,
    candidates: int,
) -> FloatArray:
    """`_disposal_perigee` of orbits (arrays that broadcast), 1-d [m]."""
    t = solar_tables(clock)
    rows = _float_rows(label, nu, perigee_m, apogee_m, gc, first_day)
    out = np.empty(rows[0].size)
    loops().disposal_rows(
        *rows,
        float(block_days),
        float(horizon_days),
        int(candidates),
        t.a_cells,
        t.a_grid,
        t.b_cells,
        t.b_grid,
        t.cumulative,
        out,
    )
    return out


def _step_arrays(
    n: int, requested_m_s: Any
) -> tuple[FloatArray, FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.bool_]]:
    """A step's burns asked for as an array of ``n``, and its outputs' arrays: made, reward, terminated, truncated."""
    requested = np.asarray(requested_m_s, dtype=np.float64)
    if requested.shape != (n,):
        requested = np.full(n, float(requested))
    made, reward = np.empty(n), np.empty(n)
    return requested, made, reward, np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_)


def step_rows(
    t: SolarTables,
    data: FloatArray,
    requested_m_s: FloatArray,
    parameters: FloatArray,
    block_days: float,
) -> tuple[FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.bool_], int]:
    """`_step_rows` of a batch's state array: (burns made, reward, terminated, truncated, how many truncated)."""
    requested, made, reward, terminated, truncated = _step_arrays(data.shape[1], requested_m_s)
    ending = loops().step_rows(
        data,
        requested,
        parameters,
        float(block_days),
        t.a_cells,
        t.a_grid,
        t.b_cells,
        t.b_grid,
        t.cumulative,
        made,
        reward,
        terminated,
        truncated,
    )
    return made, reward, terminated, truncated, ending


def step_observe_rows(
    t: SolarTables,
    data: FloatArray,
    requested_m_s: FloatArray,
    parameters: FloatArray,
    block_days: float,
    index_scale: float,
    bounds: FloatArray,
) -> tuple[FloatArray, FloatArray, NDArray[np.bool_], NDArray[np.bool_], int, NDArray[np.float32]]:
    """`_step_observe_rows` of a batch's state array: `step_rows`'s five, then the observations (n, components)."""
    requested, made, reward, terminated, truncated = _step_arrays(data.shape[1], requested_m_s)
    obs = np.empty((data.shape[1], bounds.shape[1]), dtype=np.float32)
    ending = loops().step_observe_rows(
        data,
        requested,
        parameters,
        float(block_days),
        float(index_scale),
        t.a_cells,
        t.a_grid,
        t.b_cells,
        t.b_grid,
        t.cumulative,
        t.indices,
        bounds[0],
        bounds[1],
        made,
        reward,
        terminated,
        truncated,
        obs,
    )
    return made, reward, terminated, truncated, ending, obs


def observe_rows(
    t: SolarTables,
    data: FloatArray,
    parameters: FloatArray,
    block_days: float,
    index_scale: float,
    bounds: FloatArray,
) -> NDArray[np.float32]:
    """`_observe_rows` of a batch's state array: (n, components) float32; ``bounds`` (2, components): low, high."""
    obs = np.empty((data.shape[1], bounds.shape[1]), dtype=np.float32)
    loops().observe_rows(data, parameters, float(block_days), float(index_scale), t.indices, bounds[0], bounds[1], obs)
    return obs


def step_observe_one(
    t: SolarTables,
    data: FloatArray,
    requested_m_s: float,
    parameters: FloatArray,
    block_days: float,
    index_scale: float,
    bounds: FloatArray,
) -> tuple[NDArray[np.float32], float, float, bool, bool]:
    """`_step_observe_one` of a batch of one: (observation, burn made, reward, terminated, truncated)."""
    return loops().step_observe_one(
        data,
        requested_m_s,
        parameters,
        block_days,
        index_scale,
        t.a_cells,
        t.a_grid,
        t.b_cells,
        t.b_grid,
        t.cumulative,
        t.indices,
        bounds[0],
        bounds[1],
    )
