"""A vector environment's step, compiled: loops over the satellites (numba).

`orbit_env.envs.task.step_and_observe` on a `~orbit_env.envs.task.BatchState` runs
here where numba is installed. `burn_rows` burns the satellites that burn (the rocket
equation, the vis-viva burn, the apogee cap, the new drag rates and the new place on the
curves) in one loop instead of some 140 numpy calls on a small subset, each 0.5-1 us
whatever its size; `coast_and_observe` coasts every satellite and computes its reward,
episode end and observation in three loops, with numpy's SIMD ``exp`` and ``log1p``
between them (the C library's, one number at a time in a loop, cost twice as much).
The formulas are `orbit_env.envs.task`'s, in the same order, on the same state array and
the same tables of the universal curves (`orbit_env.decay.curves`). The solar task
(`orbit_env.envs.solar_task`) burns through `burn_rows` too, on its own curves; its month of
decay by the drag clock, its rule and its disposal burn are compiled in
`orbit_env.envs.solar_kernel`, which reads the tables through `tables` and `cell`.

The contract with the task model is declared once: the state's rows are
`orbit_env.envs.state.ROW`, the task's numbers `KernelParameters`, a table's scales
`orbit_env.decay.curves.GridScales`, and where a point falls on a table is
`orbit_env.decay.curves.grid_cell`, the same function the single environment calls.

The numpy task model stays the definition and the fallback: `orbit_env.envs.task` steps
with it when numba is not installed, when ``ORBIT_ENV_JIT=0`` is set, or for more than
`MAX_COMPILED_ROWS` burning satellites (where numpy's SIMD wins). ``tests/envs/test_kernel.py``
steps both side by side through random burns, the apogee cap, empty tanks, re-entries and
restarts of every variant and holds them equal to round-off (the only differences are the
last bits of ``exp``, ``log``, ``expm1`` and ``sin``, the C library's against numpy's; the
single environment's floats differ the same way), and holds every row, parameter and
curve lookup equal.

Compiling takes about 5 seconds once; numba keeps the machine code in its cache
(``__pycache__`` beside this file, or ``NUMBA_CACHE_DIR``), and later processes load it in
a fraction of a second. Numba checks only this file's date for that cache: after changing
the declarations above (in their own modules) without changing this file, clear it.
"""

from __future__ import annotations

import math
import os
from functools import lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import EARTH_RADIUS_M, G0_M_S2, MU_EARTH_M3_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY, TWO_PI
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, E_FLOOR, NU_REF, GridScales, UniversalCurves, grid_cell
from orbit_env.envs.state import ROW, SEGMENT_ROW

FloatArray = NDArray[np.float64]

#: Set to 0 to burn with the numpy task model instead of the compiled loop.
JIT_VARIABLE = "ORBIT_ENV_JIT"
#: Above this many burning satellites in one call the numpy task model burns them (faster there).
MAX_COMPILED_ROWS = 2048


class KernelParameters(NamedTuple):
    """The task's numbers the compiled loops read (`orbit_env.envs.task.kernel_parameters` makes them)."""

    revolutions_per_step: float  # K
    propellant_cost_per_m_s: float  # [days per m/s]
    horizon_steps: float
    nominal_scale_s_per_day: float  # the nominal density scale x one day [s]
    density_varies: float  # 1.0 if the density scale follows the cycle, else 0.0
    cycle_amplitude: float  # A of s(t) = s0 exp(A sin(2 pi t / T + phi))
    cycle_period_days: float  # T
    per_height_scale_m: float  # 1 / HEIGHT_SCALE_M: the observation's scales, from here on
    per_dv_scale_m_s: float  # 1 / DV_SCALE_M_S
    lifetime_scale_days: float
    apogee_drop_scale_m: float
    perigee_drop_scale_m: float


# The places of the state's rows, the task's numbers and a grid's scales in the arrays the loops
# read, each from its one declaration (`PARAMETERS` also the solar task's loops'). Module constants:
# numba freezes them into the machine code.
PARAMETERS = KernelParameters(*range(len(KernelParameters._fields)))
_G = GridScales(*range(len(GridScales._fields)))


def cell(grid: FloatArray, x: float, y: float) -> tuple[int, float, int, float]:
    """`grid_cell` of one point on a grid given by its `GridScales` as an array: row, tx, j, ty."""
    return grid_cell(
        x,
        y,
        ny=grid[_G.ny],
        x_scale=grid[_G.x_scale],
        x_offset=grid[_G.x_offset],
        y_scale=grid[_G.y_scale],
        y_offset=grid[_G.y_offset],
        x_top=grid[_G.x_top],
        y_top=grid[_G.y_top],
    )


def table_a_point(perigee_m: float, apogee_m: float, a_cells: FloatArray, a_grid: FloatArray) -> tuple[float, float]:
    """`UniversalCurves.locate` of one orbit: table A's (label, tau), bilinear (`BilinearGrid.values_scalar`)."""
    rp = EARTH_RADIUS_M + perigee_m
    ra = EARTH_RADIUS_M + apogee_m
    y = math.log(max((ra - rp) / (ra + rp), E_FLOOR))
    row, tx, _, ty = cell(a_grid, perigee_m, y)
    txy = tx * ty
    a0 = a_cells[row, 0, 1] * tx + a_cells[row, 0, 0] + a_cells[row, 0, 2] * ty + a_cells[row, 0, 3] * txy
    a1 = a_cells[row, 1, 1] * tx + a_cells[row, 1, 0] + a_cells[row, 1, 2] * ty + a_cells[row, 1, 3] * txy
    return y + a0, max(a1, 0.0)


def _relocate(
    data: FloatArray,
    k: int,
    apogee_after_m: float,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
) -> None:
    """`task.place_burnt` of row ``k``: moved by table A's difference, then label, tau, nu, period, heights, cell."""
    perigee = data[ROW.perigee_m, k]
    before_label, before_tau = table_a_point(perigee, data[ROW.apogee_m, k], a_cells, a_grid)
    after_label, after_tau = table_a_point(perigee, apogee_after_m, a_cells, a_grid)
    label = data[ROW.label, k] + (after_label - before_label)
    tau = max(data[ROW.tau, k] + (after_tau - before_tau), 0.0)
    data[ROW.label, k] = label
    data[ROW.tau, k] = tau
    data[ROW.nu, k] = NU_REF * math.expm1(tau)
    ty = _new_segment(data, k, b_cells, b_grid, label, tau)
    _heights_on_segment(data, k, label, ty)


def _new_segment(data: FloatArray, k: int, b_cells: FloatArray, b_grid: FloatArray, label: float, tau: float) -> float:
    """`BilinearGrid.segment_scalar` of row ``k`` into its cell rows; returns ty."""
    row, tx, j, ty = cell(b_grid, label, tau)
    data[SEGMENT_ROW, k] = j
    for m in range(3):
        data[SEGMENT_ROW + 1 + m, k] = b_cells[row, m, 1] * tx + b_cells[row, m, 0]
        data[SEGMENT_ROW + 4 + m, k] = b_cells[row, m, 3] * tx + b_cells[row, m, 2]
    return ty


def _heights_on_segment(data: FloatArray, k: int, label: float, ty: float) -> None:
    """`curves._heights` of table B's values ``ty`` across row ``k``'s cell: perigee, apogee, mean period."""
    hp = max(data[SEGMENT_ROW + 4, k] * ty + data[SEGMENT_ROW + 1, k], REENTRY_ALTITUDE_M)
    one_minus_e = 1.0 - math.exp(data[SEGMENT_ROW + 5, k] * ty + data[SEGMENT_ROW + 2, k] + label)
    rp = hp + EARTH_RADIUS_M
    data[ROW.perigee_m, k] = hp
    data[ROW.apogee_m, k] = (rp + rp) / one_minus_e - rp - EARTH_RADIUS_M
    data[ROW.period_s, k] = data[SEGMENT_ROW + 6, k] * ty + data[SEGMENT_ROW + 3, k]


def _perigee_speed_m_s(perigee_m: float, apogee_m: float) -> float:
    """`orbit.perigee_velocity_m_s` of one orbit."""
    rp = EARTH_RADIUS_M + perigee_m
    ra = EARTH_RADIUS_M + apogee_m
    e = (ra - rp) / (ra + rp)
    return math.sqrt(MU_EARTH_M3_S2 / (rp * (1.0 + e))) * (1.0 + e)


def _apogee_after_m(perigee_m: float, apogee_m: float, dv_m_s: float) -> float:
    """`orbit.apogee_after_perigee_burn_m` of one orbit."""
    rp = perigee_m + EARTH_RADIUS_M
    ra = apogee_m + EARTH_RADIUS_M
    v = math.sqrt(2.0 * MU_EARTH_M3_S2 * ra / (rp * (rp + ra))) + dv_m_s
    inverse_a = 2.0 / rp - v * v / MU_EARTH_M3_S2
    return max(2.0 / max(inverse_a, 1e-300) - rp - EARTH_RADIUS_M, apogee_m)


def _update_density(data: FloatArray, k: int, p: FloatArray) -> None:
    """`task.update_density` of row ``k``."""
    scale = data[ROW.density_base, k]
    if p[PARAMETERS.density_varies] != 0.0:
        angle = TWO_PI * data[ROW.time_days, k] / p[PARAMETERS.cycle_period_days] + data[ROW.density_phase_rad, k]
        scale = scale * math.exp(p[PARAMETERS.cycle_amplitude] * math.sin(angle))
    _set_density_scale(data, k, scale)


def _set_density_scale(data: FloatArray, k: int, scale: float) -> None:
    """Row ``k``'s density scale s(t) and its g c s per revolution (`task.update_density`'s last lines)."""
    data[ROW.density_scale, k] = scale
    data[ROW.nu_per_rev, k] = G0_M_S2 * (data[ROW.drag_area_m2, k] / data[ROW.mass_kg, k] * scale)


def burn_row(
    data: FloatArray,
    k: int,
    requested_m_s: float,
    p: FloatArray,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
) -> float:
    """`task.burn` of row ``k`` (asked to burn, and able to).

    `task.perigee_burn`, the new mass, `task.update_satellite` and `task.place_burnt`.
    """
    mass, dry, exhaust = data[ROW.mass_kg, k], data[ROW.dry_mass_kg, k], data[ROW.exhaust_m_s, k]
    perigee, apogee = data[ROW.perigee_m, k], data[ROW.apogee_m, k]
    dv_fuel = exhaust * math.log(mass / dry)
    dv = max(min(requested_m_s, dv_fuel), 0.0)
    apogee_after = _apogee_after_m(perigee, apogee, dv)
    if apogee_after > CURVES_MAX_APOGEE_M:
        dv_cap = _perigee_speed_m_s(perigee, CURVES_MAX_APOGEE_M) - _perigee_speed_m_s(perigee, apogee)
        dv = max(min(dv, dv_cap), 0.0)
        apogee_after = _apogee_after_m(perigee, apogee, dv)
    if not dv > 0.0:
        return 0.0
    mass = dry if dv >= dv_fuel else max(mass / math.exp(dv / exhaust), dry)
    data[ROW.mass_kg, k] = mass
    data[ROW.dv_left_m_s, k] = max(exhaust * math.log(mass / dry), 0.0)
    nominal_scale_s_per_day = p[PARAMETERS.nominal_scale_s_per_day]
    data[ROW.nominal_w_per_day, k] = G0_M_S2 * (data[ROW.drag_area_m2, k] / mass * nominal_scale_s_per_day)
    _update_density(data, k, p)
    _relocate(data, k, min(apogee_after, CURVES_MAX_APOGEE_M), a_cells, a_grid, b_cells, b_grid)
    return dv


def _burn_rows(
    data: FloatArray,
    rows: NDArray[np.intp],
    requested_m_s: FloatArray,
    p: FloatArray,
    a_cells: FloatArray,
    a_grid: FloatArray,
    b_cells: FloatArray,
    b_grid: FloatArray,
    made: FloatArray,
) -> None:
    """`burn_row` of each of ``rows`` (asked to burn and able to), the burn made into ``made``."""
    for k in rows:
        made[k] = burn_row(data, k, requested_m_s[k], p, a_cells, a_grid, b_cells, b_grid)


# fdlibm's reduction by pi/2 (e_rem_pio2.c: 33 bits of pi/2, and the rest) and its sine and cosine
# polynomials on [-pi/4, pi/4] (k_sin.c, k_cos.c).
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_1T = 6.07710050650619224932e-11
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
#: Above this |x| the one-step reduction by pi/2 loses digits: `_sine` calls the C library there.
_SINE_REDUCTION_LIMIT = 1e5


def _sine(x: float) -> float:
    """The sine without a library call or a branch, so that a loop of them compiles to SIMD (the C library's does not).

    fdlibm's method: x = n pi/2 + r, |r| <= pi/4, then its sine or cosine polynomial
    by the quadrant n mod 4. Within 1.2e-16 of the C library's ``sin`` for
    |x| <= `_SINE_REDUCTION_LIMIT` (tests/envs/test_kernel.py); callers take the C library's beyond.
    """
    n = math.floor(x * _INV_PIO2 + 0.5)
    r = (x - n * _PIO2_1) - n * _PIO2_1T
    z = r * r
    sine = r + z * r * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    cosine = 1.0 - (0.5 * z - z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6))))))
    quadrant = int(n) & 3
    value = cosine if quadrant & 1 else sine
    return -value if quadrant & 2 else value


def _modulation_exponents(time_days: FloatArray, phase_rad: FloatArray, p: FloatArray, out: FloatArray) -> None:
    """A sin(2 pi t / T + phi) of every satellite: the exponent of `task.density_scale_at`."""
    # Locals, not reads of p in the loop: ``out`` could alias p, which would keep the loop scalar.
    amplitude, period_days = p[PARAMETERS.cycle_amplitude], p[PARAMETERS.cycle_period_days]
    beyond = 0  # an integer count: a float reduction would not vectorize without fast-math
    for k in range(time_days.size):
        angle = TWO_PI * time_days[k] / period_days + phase_rad[k]
        out[k] = amplitude * _sine(angle)
        beyond += abs(angle) > _SINE_REDUCTION_LIMIT
    if beyond:  # beyond 16,000 periods: the C library's reduction
        for k in range(time_days.size):
            out[k] = amplitude * math.sin(TWO_PI * time_days[k] / period_days + phase_rad[k])


def _coast_start(data: FloatArray, p: FloatArray, modulation: FloatArray, nu_after: FloatArray, x: FloatArray) -> None:
    """`task.update_density` (if the density varies; ``modulation`` = exp of the exponents), then nu after the coast.

    ``x`` gets nu / NU_REF, whose log1p is the new tau (`UniversalCurves._after`).
    """
    for k in range(data.shape[1]):
        if p[PARAMETERS.density_varies] != 0.0:
            _set_density_scale(data, k, data[ROW.density_base, k] * modulation[k])
        nu = max(data[ROW.nu, k] - p[PARAMETERS.revolutions_per_step] * data[ROW.nu_per_rev, k], 0.0)
        nu_after[k] = nu
        x[k] = nu * (1.0 / NU_REF)


def _coast_cells(
    data: FloatArray, b_cells: FloatArray, b_grid: FloatArray, tau: FloatArray, exponent: FloatArray
) -> None:
    """Each orbit's place in its cell of table B at the new tau (a new cell if it left its own): ty into ``tau``.

    ``exponent`` gets ln e - mu + mu along the cell, whose exp is e (`curves._heights`).
    """
    for k in range(data.shape[1]):
        label = data[ROW.label, k]
        ty = tau[k] * b_grid[_G.y_scale]
        if b_grid[_G.y_offset] != 0.0:
            ty -= b_grid[_G.y_offset]
        ty -= data[SEGMENT_ROW, k]
        if ty < 0.0 or ty > 1.0:  # left its cell (or a stale cell, j = -inf)
            ty = _new_segment(data, k, b_cells, b_grid, label, tau[k])
        data[ROW.tau, k] = tau[k]
        tau[k] = ty
        exponent[k] = data[SEGMENT_ROW + 5, k] * ty + data[SEGMENT_ROW + 2, k] + label


def _coast_finish(
    data: FloatArray,
    p: FloatArray,
    nu_after: FloatArray,
    ty_all: FloatArray,
    eccentricity: FloatArray,
    made: FloatArray,
    reward: FloatArray,
    terminated: NDArray[np.bool_],
    truncated: NDArray[np.bool_],
    obs: NDArray[np.float32],
) -> None:
    """The rest of `task.coast` (heights, days, drops, clock), `task.step`'s reward and ends, `task.observe`."""
    for k in range(data.shape[1]):
        ty = ty_all[k]
        nu = nu_after[k]
        hp = max(data[SEGMENT_ROW + 4, k] * ty + data[SEGMENT_ROW + 1, k], REENTRY_ALTITUDE_M)
        rp = hp + EARTH_RADIUS_M
        apogee = (rp + rp) / (1.0 - eccentricity[k]) - rp - EARTH_RADIUS_M
        period = data[SEGMENT_ROW + 6, k] * ty + data[SEGMENT_ROW + 3, k]
        days = (data[ROW.period_s, k] * data[ROW.nu, k] - period * nu) / (data[ROW.nu_per_rev, k] * SECONDS_PER_DAY)
        perigee_drop = data[ROW.perigee_m, k] - hp
        apogee_drop = data[ROW.apogee_m, k] - apogee
        data[ROW.perigee_drop_m, k] = perigee_drop
        data[ROW.apogee_drop_m, k] = apogee_drop
        data[ROW.perigee_m, k] = hp
        data[ROW.apogee_m, k] = apogee
        data[ROW.period_s, k] = period
        data[ROW.nu, k] = nu
        data[ROW.time_days, k] += days
        steps = data[ROW.steps, k] + 1.0
        data[ROW.steps, k] = steps
        cost = p[PARAMETERS.propellant_cost_per_m_s]
        reward[k] = days - cost * made[k] if cost != 0.0 else days
        terminated[k] = data[ROW.tau, k] <= 0.0
        truncated[k] = steps >= p[PARAMETERS.horizon_steps]
        # `task.observation` (a batch's clock is not clamped, as in `task.observe`).
        life = period * nu / data[ROW.nominal_w_per_day, k]
        obs[k, 0] = hp * p[PARAMETERS.per_height_scale_m]
        obs[k, 1] = apogee * p[PARAMETERS.per_height_scale_m]
        obs[k, 2] = data[ROW.dv_left_m_s, k] * p[PARAMETERS.per_dv_scale_m_s]
        obs[k, 3] = steps * (1.0 / p[PARAMETERS.horizon_steps])
        obs[k, 4] = life / (life + p[PARAMETERS.lifetime_scale_days])
        obs[k, 5] = apogee_drop / (apogee_drop + p[PARAMETERS.apogee_drop_scale_m])
        obs[k, 6] = perigee_drop / (perigee_drop + p[PARAMETERS.perigee_drop_scale_m])


class _Kernels(NamedTuple):
    """The compiled loops."""

    burn_rows: Any
    modulation_exponents: Any
    coast_start: Any
    coast_cells: Any
    coast_finish: Any


@lru_cache(maxsize=1)
def compiled() -> _Kernels | None:
    """The compiled loops (numba, compiled on first use and cached on disk), or None without numba.

    None also when the environment variable ``ORBIT_ENV_JIT`` is ``0``.
    """
    if os.environ.get(JIT_VARIABLE, "1").strip() == "0":
        return None
    try:
        import numba
    except ImportError:
        return None
    helpers = (grid_cell, cell, table_a_point, _relocate, _new_segment, _heights_on_segment)
    helpers += (_perigee_speed_m_s, _apogee_after_m, _sine)
    for helper in (*helpers, _set_density_scale, _update_density, burn_row):
        # Callable from the compiled loops, unchanged from Python. Not inlined by numba (that took the
        # first compilation from 4.7 s to 25 s); LLVM inlines the small ones, so the loops stay SIMD.
        numba.extending.register_jitable(helper)
    loops = (_burn_rows, _modulation_exponents, _coast_start, _coast_cells, _coast_finish)
    return _Kernels(*(numba.njit(cache=True, nogil=True)(loop) for loop in loops))


@lru_cache(maxsize=8)
def tables(curves: UniversalCurves) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Tables A and B of the curves as the loops read them: cells (rows, k, 4) and `GridScales` as an array."""
    a, b = curves.table_a, curves.table_b
    return a.cells, np.array(a.scales, dtype=np.float64), b.cells, np.array(b.scales, dtype=np.float64)


def burn_rows(
    state_data: FloatArray,
    rows: NDArray[np.intp],
    requested_dv_m_s: Any,
    parameters: FloatArray,
    curves: UniversalCurves,
) -> FloatArray | None:
    """The burns of ``rows`` of a batch's state array, in place, compiled; None if not compiled here.

    Args:
        state_data: A `~orbit_env.envs.task.BatchState`'s array (fields + cell rows, n).
        rows: The satellites asked to burn and able to (``min(request, dv left) > 0``).
        requested_dv_m_s: The burns asked for [m/s], a number or an array of shape (n,).
        parameters: `orbit_env.envs.task.kernel_parameters` of the task.
        curves: The curves the task steps on.

    Returns:
        The burns made [m/s], shape (n,) (0 off ``rows``), or None: numba missing,
        ``ORBIT_ENV_JIT=0``, or more than `MAX_COMPILED_ROWS` rows (the caller then
        burns with numpy).
    """
    if rows.size > MAX_COMPILED_ROWS:
        return None
    kernels = compiled()
    if kernels is None:
        return None
    n = state_data.shape[1]
    requested = np.asarray(requested_dv_m_s, dtype=np.float64)
    if requested.shape != (n,):
        requested = np.full(n, float(requested))
    made = np.zeros(n)
    kernels.burn_rows(state_data, rows, requested, parameters, *tables(curves), made)
    return made


def coast_and_observe(
    state_data: FloatArray, made_m_s: FloatArray, parameters: FloatArray, curves: UniversalCurves
) -> tuple[FloatArray, NDArray[np.bool_], NDArray[np.bool_], NDArray[np.float32]]:
    """The rest of a batch's step after its burns, compiled: density, coast, reward, ends, observation.

    ``exp``, ``log1p`` and ``exp`` run as numpy's SIMD calls between the loops: the C
    library's, one number at a time in a compiled loop, cost twice as much.

    Args:
        state_data: A `~orbit_env.envs.task.BatchState`'s array, updated in place.
        made_m_s: The burns made in this step [m/s], shape (n,).
        parameters: `orbit_env.envs.task.kernel_parameters` of the task.
        curves: The curves the task steps on.

    Returns:
        (reward, terminated, truncated, observation (n, 7) float32).
    """
    kernels = compiled()
    assert kernels is not None, "coast_and_observe needs the compiled loops"
    n = state_data.shape[1]
    _, _, b_cells, b_grid = tables(curves)
    first, second = np.empty(n), np.empty(n)
    if parameters[PARAMETERS.density_varies] != 0.0:
        kernels.modulation_exponents(state_data[ROW.time_days], state_data[ROW.density_phase_rad], parameters, first)
        np.exp(first, out=first)
    nu_after = np.empty(n)
    kernels.coast_start(state_data, parameters, first, nu_after, second)
    np.log1p(second, out=second)  # tau
    kernels.coast_cells(state_data, b_cells, b_grid, second, first)
    np.exp(first, out=first)  # e
    reward, obs = np.empty(n), np.empty((n, 7), dtype=np.float32)
    terminated, truncated = np.empty(n, dtype=np.bool_), np.empty(n, dtype=np.bool_)
    kernels.coast_finish(state_data, parameters, nu_after, second, first, made_m_s, reward, terminated, truncated, obs)
    return reward, terminated, truncated, obs
