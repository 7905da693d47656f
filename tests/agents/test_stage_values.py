"""The DP's compressed stage store gives back exactly the values it was given, in any order."""

import numpy as np
import pytest

from orbit_env.agents.stage_values import KEYFRAME_STAGES, StageValues


def _stages(rng: np.random.Generator, count: int) -> tuple[np.ndarray, list[np.ndarray]]:
    """Stages that grow by a plane of states each, with values that mostly grow by < 256."""
    plane = 97
    sizes = np.array([0] + [plane * (k + 1) for k in range(1, count + 1)], dtype=np.int64)
    stages, previous = [], np.zeros(0, np.uint16)
    for k in range(1, count + 1):
        values = np.empty(sizes[k], np.uint16)
        values[: previous.size] = previous + rng.integers(0, 120, previous.size)
        values[previous.size :] = rng.integers(0, 30000, sizes[k] - previous.size)
        if k == 7:  # a stage that drops somewhere: stored whole
            values[3] = 0
        if k == 11:  # an increment a uint8 does not hold: stored whole
            values[5] = min(int(values[5]) + 1000, 65535)
        stages.append(values)
        previous = values
    return sizes, stages


def test_every_stage_comes_back_exactly_in_any_order():
    rng = np.random.default_rng(3)
    count = 3 * KEYFRAME_STAGES + 5
    sizes, stages = _stages(rng, count)
    store = StageValues(sizes)
    for values in stages:
        store.append(values)
    store.finish()
    assert store.stages == count
    # Keyframes where they are due and where an increment does not fit a uint8.
    assert store._keyframe[[1, 7, 11, KEYFRAME_STAGES + 1]].all()
    # Random order (from keyframes), descending and ascending (from the neighbour read last),
    # and two neighbours at a time (the DP policy with a look-ahead of two).
    pairs = [k for j in range(count, 1, -1) for k in (j, j - 1)]
    for k in [*rng.permutation(count) + 1, *range(count, 0, -1), *range(1, count + 1), *pairs]:
        np.testing.assert_array_equal(store.get(int(k)), stages[k - 1])
    again = StageValues.from_arrays(store.to_arrays())
    for k in range(1, count + 1):
        np.testing.assert_array_equal(again.get(k), stages[k - 1])
    # Smaller than the values themselves (these are random, so little).
    assert store.nbytes < sum(s.nbytes for s in stages)


def test_stages_out_of_range_are_refused():
    store = StageValues(np.array([0, 4]))
    store.append(np.arange(4, dtype=np.uint16))
    with pytest.raises(IndexError, match="stage 2"):
        store.get(2)
    with pytest.raises(IndexError, match="stage 0"):
        store.get(0)
