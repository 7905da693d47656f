"""The envs' fast paths give what the general paths give.

The single env steps one orbit in Python floats (``math``, not numpy, on one number),
keeps its cell of the curves' table B between steps as the vector env keeps its
rows' (`UniversalCurves.locate_segments` on two floats), and samples its continuous
action without Gymnasium's general ``Box.sample``. Each is checked against the path
it stands for. Tolerances: ``math`` and numpy's ``exp``/``log``/``sin`` may differ in
the last bit (1e-16 relative), and a trajectory carries that through its steps:
1e-12 relative is a thousand times that, and a wrong cell or formula is off by far more.
"""

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)
from orbit_env.decay.curves import universal_curves
from orbit_env.envs import task as task_model
from orbit_env.envs.config import DensityConfig, OrbitRaisingConfig
from orbit_env.envs.spaces import UniformBox
from orbit_env.envs.state import STATE_FIELDS
from orbit_env.envs.task import Task

ROUND_OFF = 1e-12


@pytest.mark.parametrize(
    ("low", "high", "shape"),
    [
        (-1.0, 1.0, (1,)),
        (-2.0, 3.0, (2, 3)),
        (np.array([-1.0, 0.0, 2.0], np.float32), np.array([1.0, 5.0, 3.0], np.float32), None),
    ],
)
def test_uniform_box_samples_what_box_samples(low, high, shape):
    fast = UniformBox(low, high, shape=shape, dtype=np.float32)
    plain = gym.spaces.Box(low, high, shape=shape, dtype=np.float32)
    assert fast == plain
    fast.seed(7)
    plain.seed(7)
    for _ in range(200):
        a, b = fast.sample(), plain.sample()
        assert a.dtype == b.dtype and a.shape == b.shape
        np.testing.assert_array_equal(a, b)
        assert fast.contains(a)


def test_continuous_action_fast_path_equals_the_general_path():
    task = Task(continuous=True)
    for value in (-2.0, -1.0, -0.3, 0.0, 0.25, 0.999, 1.0, 1.5):
        fast = task.requested_dv(np.array([value], dtype=np.float32))
        general = task.requested_dv(np.array(value, dtype=np.float32))  # a 0-d array: the general path
        assert fast == general == task.config.max_burn_m_s * min(max(float(np.float32(value)), 0.0), 1.0)
    for bad in (np.array([np.nan], dtype=np.float32), np.array(np.nan, dtype=np.float32)):
        with pytest.raises(ValueError, match="action"):
            task.requested_dv(bad)


def test_scalar_locate_segments_equals_the_array_path():
    curves = universal_curves()
    rng = np.random.default_rng(11)
    perigee = rng.uniform(100e3, 1100e3, 200)
    apogee = np.minimum(perigee + rng.uniform(0.0, 3500e3, 200), 4000e3)
    batch, hp, ha, segments = curves.locate_segments(perigee, apogee)
    for i in range(perigee.size):
        point, hp_s, ha_s, segment = curves.locate_segments(float(perigee[i]), float(apogee[i]))
        assert isinstance(point.tau, float) and isinstance(segment, list)
        assert (point.label, point.tau, point.mean_period_s) == pytest.approx(
            (batch.label[i], batch.tau[i], batch.mean_period_s[i]), rel=ROUND_OFF, abs=1e-300
        )
        assert (hp_s, ha_s) == pytest.approx((hp[i], ha[i]), rel=ROUND_OFF)
        assert segment[0] == segments[0, i]
        np.testing.assert_allclose(segment[1:], segments[1:, i], rtol=ROUND_OFF)


def test_single_env_follows_the_vector_env_over_a_mission():
    """From the same pinned starts and actions, the two envs' states stay together step after step."""
    starts_km = [(160.0, 900.0), (250.0, 400.0), (360.0, 700.0), (420.0, 1500.0), (300.0, 3900.0)]
    rng = np.random.default_rng(2)
    actions = rng.integers(0, 4, (120, len(starts_km)))
    actions[rng.random(actions.shape) < 0.8] = 0  # mostly coasting, as a mission is
    task = Task(OrbitRaisingConfig(), DensityConfig(scale_range=(0.5, 2.0), cycle_amplitude=0.5))
    perigee, apogee = (np.array([s[k] for s in starts_km]) for k in range(2))
    options = {"perigee_km": perigee, "apogee_km": apogee, "density_scale": 1.7, "density_phase_rad": 0.4}
    batch = task_model.start(task, np.random.default_rng(0), len(starts_km), options)
    singles = []
    for i in range(len(starts_km)):
        pinned = {"perigee_km": perigee[i], "apogee_km": apogee[i], "density_scale": 1.7, "density_phase_rad": 0.4}
        singles.append(task_model.start(task, np.random.default_rng(0), None, pinned))
    cells_moved = 0
    for row in actions:
        before = batch.segments[0].copy()
        many = task_model.step(task, batch, task.burn_sizes_m_s[row])
        cells_moved += int(np.count_nonzero(batch.segments[0] != before))
        for i, single in enumerate(singles):
            one = task_model.step(task, single, task.config.burn_sizes_m_s[row[i]])
            assert one.reward == pytest.approx(float(many.reward[i]), rel=1e-9)  # a difference of W's
            for name in STATE_FIELDS:
                # A drop is a difference of two heights (up to 4000 km), each to round-off: absolute.
                tolerance = 4000e3 * ROUND_OFF if name.endswith("_drop_m") else 1e-300
                assert getattr(single, name) == pytest.approx(getattr(batch, name)[i], rel=ROUND_OFF, abs=tolerance)
            assert single.segments[0] == batch.segments[0, i]
    assert cells_moved > 10 and np.any(batch.tau == 0.0)  # the test crossed cells and saw a re-entry


def test_lookahead_leaves_a_single_state_and_its_cell_alone():
    task = Task()
    state = task_model.start(task, np.random.default_rng(4), None, {"perigee_km": 300.0, "apogee_km": 800.0})
    segment, tau = list(state.segments), state.tau
    task_model.lookahead(task, state, 0.0, 300.0)  # coasts a copy across many cells
    assert state.segments == segment and state.tau == tau


def test_density_scale_on_floats_equals_the_array_formula():
    for t in (0.0, 17.5, 900.0, 4000.0):
        one = task_model.density_scale_at(1.3, 0.5, 4018.0, 0.7, t)
        many = task_model.density_scale_at(np.array([1.3]), 0.5, 4018.0, np.array([0.7]), np.array([t]))
        assert isinstance(one, float)
        assert one == pytest.approx(float(many[0]), rel=1e-15)
