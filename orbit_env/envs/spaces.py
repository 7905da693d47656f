"""The environments' spaces: a float `gymnasium.spaces.Box` whose ``sample`` is one uniform draw."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray


class UniformBox(spaces.Box):
    """A float `gymnasium.spaces.Box` bounded on every side, whose ``sample`` is one uniform draw.

    Gymnasium's ``Box.sample`` sorts the coordinates into bounded, half-bounded and
    unbounded ones with a dozen numpy calls (about 20 us, three CartPole steps). For a
    float box bounded on every side that comes down to one uniform draw, made here
    directly: the same numbers from the same generator (``tests/envs/test_fast_paths.py``
    compares them with ``Box.sample``'s). Bounds equal on every coordinate are
    passed as two floats, with which numpy's ``uniform`` is five times faster
    than with arrays.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        assert self.is_bounded("both") and self.dtype.kind == "f", "a float box bounded on every side"
        low, high = np.unique(self.low), np.unique(self.high)
        self._bounds = (float(low[0]), float(high[0])) if low.size == high.size == 1 else (self.low, self.high)

    def sample(self, mask: None = None, probability: None = None) -> NDArray[Any]:
        """A point drawn uniformly in the box (masks are Box's: unsupported)."""
        if mask is not None or probability is not None:
            return super().sample(mask, probability)
        low, high = self._bounds
        return self.np_random.uniform(low, high, self.shape).astype(self.dtype)
