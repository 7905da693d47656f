"""The compiled loops (`orbit_env.envs.kernel`) against the numpy task model they compile.

`orbit_env.envs.task.step_and_observe` (compiled burns, coast and observation) and
numpy's `step` and `observe` step copies of the same `BatchState` through random burns (of every size,
the tank emptied, the 4000 km apogee cap reached), re-entries and restarts, and must
agree at every step. Tolerance, and why: the loops call the C library's ``exp``,
``log``, ``expm1`` and ``sqrt`` on one number at a time and their own sine (fdlibm's
polynomials, within 1.2e-16 of the C library's: ``test_sine``), numpy its SIMD
versions on arrays; the two may differ in the last bit (the same difference as the
single environment's floats against the vector environment's, see
``tests/envs/test_envs.py``). A step's days are a difference of two W values up to 10^4
times larger, which amplifies a last-bit difference to about 1e-12 relative; the
test allows 1e-10 relative on the float64 state and rewards (and 1e-9 day absolute on
the rewards, as ``tests/envs/test_envs.py``), and 1e-6 m on the heights' drops
over a step (differences of two heights of ~1e6 m, each good to 1e-12 relative). The float32 observations may
round a value that sits on a float32 boundary either way: 1e-6 (16 ulps of float32).
The cells of table B (which cell each orbit is in) and the episode ends must be equal.
"""

from __future__ import annotations

import inspect
import math

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.constants import EARTH_RADIUS_M, SECONDS_PER_DAY, TWO_PI
from orbit_env.decay.curves import GridScales, grid_cell, universal_curves
from orbit_env.envs import ENV_IDS, DensityConfig, OrbitRaisingConfig
from orbit_env.envs import kernel as kernel_module
from orbit_env.envs import task as task_model
from orbit_env.envs.kernel import KernelParameters
from orbit_env.envs.state import ROW, SEGMENT_ROW, SEGMENT_ROWS, STATE_FIELDS, StateFields
from orbit_env.envs.task import Task

pytestmark = pytest.mark.skipif(kernel_module.compiled() is None, reason="needs numba (and ORBIT_ENV_JIT not 0)")

TASKS = {
    "v0": Task.of(),
    "continuous": Task.of(continuous=True),
    "uncertain": Task.of(density=DensityConfig(scale_range=(0.5, 2.0), cycle_amplitude=0.3)),
    # Cheap propellant and big burns: the apogee cap and empty tanks in most episodes.
    "cap": Task.of(OrbitRaisingConfig(propellant_cost_per_m_s=0.0, burn_sizes_m_s=(0.0, 300.0, 900.0))),
}


def _requests(task: Task, rng: np.random.Generator, n: int) -> np.ndarray:
    if task.continuous:
        return task.requested_dvs(rng.uniform(-1.0, 1.0, (n, 1)).astype(np.float32), n)
    return task.requested_dvs(rng.integers(0, len(task.config.burn_sizes_m_s), n), n)


def test_every_state_row_is_its_fields() -> None:
    """The rows the loops read (`state.ROW`) are the rows `BatchState` keeps each field in."""
    assert STATE_FIELDS == StateFields._fields and len(set(ROW)) == len(STATE_FIELDS)
    state = task_model.start(TASKS["uncertain"], np.random.default_rng(2), 5)
    for name in STATE_FIELDS:
        row = getattr(ROW, name)
        assert np.shares_memory(getattr(state, name), state.data[row]), name
        np.testing.assert_array_equal(getattr(state, name), state.data[row], err_msg=name)
    assert np.shares_memory(state.segments, state.data[SEGMENT_ROW:])
    assert state.data.shape[0] == SEGMENT_ROW + SEGMENT_ROWS == len(STATE_FIELDS) + 1 + 2 * 3  # j, 3 bases, 3 slopes


@pytest.mark.parametrize("name", list(TASKS))
def test_every_kernel_parameter_is_the_tasks(name: str) -> None:
    task = TASKS[name]
    config, density = task.config, task.density
    expected = {
        "revolutions_per_step": config.revolutions_per_step,
        "propellant_cost_per_m_s": config.propellant_cost_per_m_s,
        "horizon_steps": config.horizon_steps,
        "nominal_scale_s_per_day": density.nominal_scale * SECONDS_PER_DAY,
        "density_varies": float(density.varies),
        "cycle_amplitude": density.cycle_amplitude,
        "cycle_period_days": density.cycle_period_days,
        "per_height_scale_m": 1.0 / task_model.HEIGHT_SCALE_M,
        "per_dv_scale_m_s": 1.0 / task_model.DV_SCALE_M_S,
        "lifetime_scale_days": task_model.LIFETIME_SCALE_DAYS,
        "apogee_drop_scale_m": task_model.APOGEE_DROP_SCALE_M,
        "perigee_drop_scale_m": task_model.PERIGEE_DROP_SCALE_M,
    }
    parameters = task_model.kernel_parameters(task)
    assert parameters.dtype == np.float64 and parameters.shape == (len(KernelParameters._fields),)
    assert KernelParameters(*parameters.tolist())._asdict() == expected
    for field, value in expected.items():  # at the index the loops read it from
        assert parameters[getattr(kernel_module.PARAMETERS, field)] == value, field


def test_every_grid_scale_is_the_grids() -> None:
    curves = universal_curves()
    for grid in (curves.table_a, curves.table_b):
        scales = kernel_module.tables(curves)[1 if grid is curves.table_a else 3]
        for field in GridScales._fields:
            assert scales[getattr(kernel_module._G, field)] == getattr(grid, field), field
    # grid_cell takes a GridScales after (x, y), in its order (``grid_cell(x, y, *scales)``).
    assert tuple(inspect.signature(grid_cell).parameters)[2:] == GridScales._fields


@pytest.fixture(scope="module")
def compiled_lookups():
    """The loops' lookups on one point, compiled alone: where it falls, table A's point, a new cell of table B."""
    numba = pytest.importorskip("numba")
    kernel_module.compiled()  # registers the helpers the lookups call

    def cell(grid, x, y):
        return kernel_module.cell(grid, x, y)

    def table_a_point(perigee_m, apogee_m, cells, grid):
        return kernel_module.table_a_point(perigee_m, apogee_m, cells, grid)

    def new_segment(data, cells, grid, label, tau):
        return kernel_module._new_segment(data, 0, cells, grid, label, tau)

    return tuple(numba.njit(f) for f in (cell, table_a_point, new_segment))


def test_the_curve_lookups_agree_bit_for_bit(compiled_lookups) -> None:
    """The one-point lookups of the single env (Python), the vector env's loops (numba) and numpy's, equal.

    `grid_cell` is written once (Python and compiled); the bilinear forms after it are written
    in `BilinearGrid` (numpy and scalar) and in the loops: held equal here, bit for bit, at
    random points inside the tables and beyond their edges (clamped).
    """
    cell, table_a_point, new_segment = compiled_lookups
    rng = np.random.default_rng(12)
    curves = universal_curves()
    a, b = curves.table_a, curves.table_b
    a_cells, a_scales, b_cells, b_scales = kernel_module.tables(curves)
    n = 3000
    # Table A over (perigee, ln e); table B over (label, tau): a margin beyond each edge.
    hp = rng.uniform(50e3, 1300e3, n)
    e = np.exp(rng.uniform(-35.0, np.log(0.3), n))
    apogee = (EARTH_RADIUS_M + hp) * (1.0 + e) / (1.0 - e) - EARTH_RADIUS_M
    label = rng.uniform(curves.labels[0] - 1.0, curves.labels[-1] + 1.0, n)
    tau = rng.uniform(-1.0, 28.0, n)
    for grid, scales, xs, ys in ((a, a_scales, hp, np.log(e)), (b, b_scales, label, tau)):
        many = grid.values(xs, ys)
        for i in range(n):
            x, y = float(xs[i]), float(ys[i])
            assert cell(scales, x, y) == grid_cell(x, y, *grid.scales)
            assert grid.values_scalar(x, y) == [float(v[i]) for v in many]
    located = curves.locate(hp, apogee)
    data = np.zeros((SEGMENT_ROW + SEGMENT_ROWS, 1))
    segments, ty = b.segments(label, tau)
    for i in range(n):
        point = curves.locate(float(hp[i]), float(apogee[i]))
        assert (point.label, point.tau) == (float(located.label[i]), float(located.tau[i]))
        assert table_a_point(float(hp[i]), float(apogee[i]), a_cells, a_scales) == (point.label, point.tau)
        segment, ty_scalar = b.segment_scalar(float(label[i]), float(tau[i]))
        assert segment == segments[:, i].tolist() and ty_scalar == ty[i]
        assert new_segment(data, b_cells, b_scales, float(label[i]), float(tau[i])) == ty_scalar
        assert data[SEGMENT_ROW:, 0].tolist() == segment


def _numpy_step(task: Task, state: task_model.BatchState, requested: np.ndarray) -> task_model.StepResult:
    """`task.step` with numpy's burns (no batch small enough for the compiled loop)."""
    limit = kernel_module.MAX_COMPILED_ROWS
    kernel_module.MAX_COMPILED_ROWS = -1
    try:
        return task_model.step(task, state, requested)
    finally:
        kernel_module.MAX_COMPILED_ROWS = limit


@pytest.mark.parametrize("name", list(TASKS))
def test_compiled_burns_equal_the_task_model(name: str) -> None:
    task = TASKS[name]
    rng = np.random.default_rng(7)
    n, steps = 512, 400
    numpy_state = task_model.start(task, rng, n)
    compiled_state = numpy_state.copy()
    ends = 0
    burned = 0
    for _ in range(steps):
        requested = _requests(task, rng, n)
        expected = _numpy_step(task, numpy_state, requested)
        expected_obs = task_model.observe(task, numpy_state)
        got, obs = task_model.step_and_observe(task, compiled_state, requested)
        for field, want, have in zip(("reward", "terminated", "truncated", "burn"), expected, got, strict=True):
            if want.dtype == np.bool_:
                np.testing.assert_array_equal(have, want, err_msg=field)
            else:
                # A step's days are a difference of two W values worth up to 1e4 days: 1e-9 day absolute.
                np.testing.assert_allclose(have, want, rtol=1e-10, atol=1e-9, err_msg=field)
        for row, field in enumerate(STATE_FIELDS):
            # A drop is a difference of two heights of ~1e6 m: their 1e-12 relative is 1e-6 m.
            atol = 1e-6 if field.endswith("_drop_m") else 1e-12
            np.testing.assert_allclose(
                compiled_state.data[row], numpy_state.data[row], rtol=1e-10, atol=atol, err_msg=field
            )
        np.testing.assert_array_equal(compiled_state.segments[0], numpy_state.segments[0])  # the cells of table B
        np.testing.assert_allclose(obs, expected_obs, rtol=1e-6, atol=1e-7)
        burned += int(np.count_nonzero(expected.burn_m_s))
        done = np.flatnonzero(expected.terminated | expected.truncated)
        if done.size:  # restart them in both, with the same fresh missions
            ends += done.size
            fresh = task_model.start(task, rng, done.size)
            numpy_state.put(done, fresh)
            compiled_state.put(done, fresh)
    # The run exercised what it is meant to: many burns and many episode ends.
    assert burned > 1000 and ends > 100, (burned, ends)


def test_sine() -> None:
    """The loops' sine against the C library's: within 1.2e-16 (half an ulp at 1 is 1.1e-16; measured 1.1e-16)."""
    rng = np.random.default_rng(11)
    x = np.concatenate([rng.uniform(-1e5, 1e5, 100_000), rng.uniform(-10.0, 10.0, 100_000)])
    x = np.concatenate([x, np.arange(-40, 41) * (np.pi / 2), [2e5, -3e7, 1e12]])  # quadrant edges; far out
    period_days = 365.0
    time_days = x * (period_days / TWO_PI)
    angle = TWO_PI * time_days / period_days  # the loop's angle, as it computes it (phase 0)
    parameters = np.array(
        KernelParameters(**dict.fromkeys(KernelParameters._fields, 0.0))._replace(
            cycle_amplitude=1.0,  # the exponent is the sine itself
            cycle_period_days=period_days,
        )
    )
    near, far = slice(0, -3), slice(-3, None)
    for part in (near, far):
        out = np.empty(time_days[part].size)
        kernel_module.compiled().modulation_exponents(time_days[part], np.zeros_like(out), parameters, out)
        if part is near:
            np.testing.assert_allclose(out, np.sin(angle[part]), rtol=0, atol=1.2e-16)
        else:  # beyond the reduction's range (1e5): the C library's sine itself
            np.testing.assert_array_equal(out, [math.sin(v) for v in angle[part]])


def test_the_vector_env_steps_the_same_without_numba(monkeypatch: pytest.MonkeyPatch) -> None:
    """The fallback (no numba, or ORBIT_ENV_JIT=0) is the task model itself: the same episodes."""
    actions = np.random.default_rng(3).integers(0, 4, (300, 64))

    def rollout() -> list[np.ndarray]:
        env = gym.make_vec(ENV_IDS[0], num_envs=64)
        obs, _ = env.reset(seed=5)
        out = [obs]
        for a in actions:
            obs, reward, *_ = env.step(a)
            out += [obs, reward]
        return out

    compiled = rollout()
    monkeypatch.setattr(kernel_module, "compiled", lambda: None)
    fallback = rollout()
    for have, want in zip(compiled, fallback, strict=True):
        np.testing.assert_allclose(have, want, rtol=1e-6, atol=1e-7)


def test_jit_can_be_switched_off(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(kernel_module.JIT_VARIABLE, "0")
    kernel_module.compiled.cache_clear()
    try:
        assert kernel_module.compiled() is None
    finally:
        monkeypatch.delenv(kernel_module.JIT_VARIABLE)
        kernel_module.compiled.cache_clear()
    assert kernel_module.compiled() is not None
