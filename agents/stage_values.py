"""The DP's values of every stage, compressed: each stage as the change from the stage before.

A stage $k$ holds $V_k$ on the decision states of stage k, a prefix of the state
vector that grows by one life level per stage (`orbit_env.agents.dp`), as uint16
in steps of the values' quantum. $V_k$ differs little from $V_{k-1}$ on their common
prefix: one more step left adds at most about a day (100 quanta), and nothing
where the satellite cannot live to the mission's end. So a stage is stored as
its increments over the stage before, as uint8 (the new life level's values as
uint16); every ``KEYFRAME_STAGES``-th stage, and any whose increments do not fit
a uint8, is stored whole. Each part is compressed with Zstandard (level 1).

Measured on the default task (grid (192, 1, 1): 412.6 million values, 825 MB
as uint16), as increments only: 96 MB; compressing takes 0.7 s and decompressing every
stage 0.2 s on one core, against 4.0 s and 1.4 s for zlib at its fastest level
(99 MB), which is why the DP depends on ``zstandard``. With a keyframe every
``KEYFRAME_STAGES`` stages, the default task's solution takes 122 MB.

A stage is read from a neighbour read just before it, by adding its increments
to the stage below or taking the stage above's increments away
($V_{k-1} = V_k - (V_k - V_{k-1})$, exact in integers), or else from the keyframe at or below it.
Only the last two stages read are kept decoded (about 10 MB on the default grid,
whatever the number of solutions held, as the oracle's nine), so the DP policy,
which reads one stage a step in descending order (two with a look-ahead of two),
decodes one increment a stage. Stages read far apart cost a decode from their keyframe
each (up to 15 increments, a few milliseconds on the default grid): so `evaluate` and
the certificate let the policy act only on the episodes still scored, not on those a
vector env has restarted at other stages.
"""

from __future__ import annotations

import numpy as np
import zstandard
from numpy.typing import NDArray

#: A stage stored whole every this many stages (and the first).
KEYFRAME_STAGES = 16
#: Zstandard's level: its fastest ratio-keeping level (3 gains 9% in size at 1.7x the time).
ZSTD_LEVEL = 1
#: The largest increment a uint8 holds.
_DELTA_MAX = np.iinfo(np.uint8).max

Values = NDArray[np.uint16]


class StageValues:
    """Compressed uint16 values of stages 1..n, added in order, read in any order.

    Args:
        sizes: The number of values of each stage, ``sizes[k]`` for stage k
            (``sizes[0]``, stage 0, is not stored); non-decreasing from stage 1.
    """

    def __init__(self, sizes: NDArray[np.int64]) -> None:
        self.sizes = np.asarray(sizes, dtype=np.int64)
        assert np.all(np.diff(self.sizes[1:]) >= 0), "stage k's states are a prefix of stage k+1's"
        # Every compressed part in one growing buffer, read through (start, end) spans: a list of
        # zstandard's outputs would leave a freed hole of the compressor's bound (the size of the
        # input) behind each one in the heap, 2 MB a stage (measured: 420 MB over a solve).
        self._data = bytearray()
        self._view: memoryview | None = None
        self._blobs: list[tuple[int, int]] = [(0, 0)]
        self._tails: list[tuple[int, int]] = [(0, 0)]
        self._keyframe = np.zeros(self.sizes.size, dtype=bool)
        self._last: Values | None = None
        self._recent: list[tuple[int, Values]] = []  # the last two stages read, the newest last
        self._compressor = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
        self._decompressor = zstandard.ZstdDecompressor()

    @property
    def stages(self) -> int:
        """Stages stored so far (1..stages)."""
        return len(self._blobs) - 1

    @property
    def nbytes(self) -> int:
        """Bytes the compressed stages take."""
        return len(self._data)

    def append(self, values: Values) -> None:
        """Store the next stage's values (``sizes[stage]`` of them)."""
        k = len(self._blobs)
        assert values.dtype == np.uint16 and values.shape == (self.sizes[k],)
        previous = self._last
        delta = None
        if previous is not None and (k - 1) % KEYFRAME_STAGES != 0:
            common = values[: previous.size]
            # Values grow with the steps left; a stage where they do not (or grow by more than
            # a uint8 holds) is stored whole.
            if np.all(common >= previous) and int((common - previous).max(initial=0)) <= _DELTA_MAX:
                delta = (common - previous).astype(np.uint8)
        if delta is None:
            self._keyframe[k] = True
            self._blobs.append(self._put(values))
            self._tails.append((0, 0))
        else:
            self._blobs.append(self._put(delta))
            self._tails.append(self._put(values[previous.size :]))  # type: ignore[union-attr]
        self._last = values.copy()

    def _put(self, array: np.ndarray) -> tuple[int, int]:
        """Compress ``array`` onto the buffer; its span."""
        start = len(self._data)
        self._data += self._compressor.compress(array.tobytes())
        self._view = None
        return start, len(self._data)

    def _part(self, span: tuple[int, int], dtype: type) -> np.ndarray:
        if self._view is None:
            self._view = memoryview(self._data)
        return np.frombuffer(self._decompressor.decompress(self._view[span[0] : span[1]]), dtype=dtype)

    def finish(self) -> None:
        """Done adding: drop the last stage's uncompressed copy."""
        self._last = None

    def get(self, stage: int) -> Values:
        """The values of ``stage`` (1..stages), uint16 quanta."""
        if not 1 <= stage <= self.stages:
            raise IndexError(f"stage {stage} is not stored; stored: 1 to {self.stages}")
        for k, values in self._recent:
            if k == stage:
                return values
        values = self._from_recent(stage)
        if values is None:
            start = stage
            while not self._keyframe[start]:
                start -= 1
            values = self._part(self._blobs[start], np.uint16)
            for k in range(start + 1, stage + 1):
                values = self._up(values, k)
        self._recent = [*self._recent[-1:], (stage, values)]
        return values

    def _from_recent(self, stage: int) -> Values | None:
        """``stage`` from a neighbouring stage read last: one increment added or taken away; None if none is."""
        for k, values in reversed(self._recent):
            if k == stage - 1 and not self._keyframe[stage]:
                return self._up(values, stage)
            if k == stage + 1 and not self._keyframe[k]:
                return values[: self.sizes[stage]] - self._part(self._blobs[k], np.uint8)
        return None

    def _up(self, values: Values, stage: int) -> Values:
        """Stage ``stage`` from the stage below it (``values``), ``stage`` not a keyframe."""
        if self._keyframe[stage]:
            return self._part(self._blobs[stage], np.uint16)
        delta, tail = self._part(self._blobs[stage], np.uint8), self._part(self._tails[stage], np.uint16)
        return np.concatenate([values + delta, tail])

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The compressed stages as arrays (for the disk cache)."""
        spans = np.array([*self._blobs, *self._tails], dtype=np.int64)
        data = np.frombuffer(self._data, dtype=np.uint8)
        return {"sizes": self.sizes, "keyframe": self._keyframe, "spans": spans, "data": data}

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray]) -> StageValues:
        """The stages `to_arrays` wrote."""
        store = cls(arrays["sizes"])
        spans = [(int(a), int(b)) for a, b in arrays["spans"]]
        half = len(spans) // 2
        store._blobs, store._tails = spans[:half], spans[half:]
        store._data = bytearray(arrays["data"])
        store._keyframe = np.asarray(arrays["keyframe"], dtype=bool)
        return store
