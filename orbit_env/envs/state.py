"""The task's state: its fields, declared once; one satellite's as floats, many satellites' as array rows.

`TaskState` holds the fields as Python floats (the single environment), `BatchState` as the
rows of one (fields + segment rows, n) float64 array (the vector environment, the DP and the
policies), and the compiled loops of `orbit_env.envs.kernel` read that array by the row
numbers `ROW` gives. All three take the fields from `StateFields`, so a field added or moved
there moves everywhere. The task functions that move a state are `orbit_env.envs.task`'s.
SI units (m, kg, s, m/s); days only in the mission's clock.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


class StateFields(NamedTuple):
    """The fields of a satellite's state, in the order of a batch's rows (each value: that field's row)."""

    label: int  # mu, the universal curve the orbit decays along
    tau: int  # ln(1 + nu / NU_REF), the position along it
    nu: int  # universal lifetime left [m^3/(kg s^2)]
    period_s: int  # mean period over the rest of the decay, W / nu [s]
    perigee_m: int  # heights as the curves give the point [m]
    apogee_m: int
    perigee_drop_m: int  # drops over the last coast [m] (0 at the start)
    apogee_drop_m: int
    mass_kg: int
    dry_mass_kg: int
    exhaust_m_s: int  # effective exhaust velocity Isp g0 [m/s]
    drag_area_m2: int  # c_x F
    density_base: int  # s0, the episode's density scale
    density_phase_rad: int  # phi of the solar-cycle-like modulation
    density_scale: int  # s(t), held over the coming step
    nu_per_rev: int  # g c s per revolution [m^3/(kg s^2)]
    nominal_w_per_day: int  # g c s_nominal x 1 day: W over it is the predicted lifetime [days]
    dv_left_m_s: int  # delta-v the propellant on board still gives [m/s]
    time_days: int  # mission time [days]
    steps: int  # steps taken (whole numbers, exact in float64)
    start_day: int  # the solar task's first day of the mission, days since its record's first (else 0)


#: The names of the fields, in the order of a batch's rows.
STATE_FIELDS: tuple[str, ...] = StateFields._fields
#: The row of each field in a batch's array (``ROW.mass_kg``).
ROW = StateFields(*range(len(STATE_FIELDS)))
#: The first row below the fields: each orbit's cell of the curves' table B
#: (`orbit_env.decay.curves.BilinearGrid.segments`: the cell index j, then the three
#: values' bases, then their slopes), kept between steps so a coast needs no gather.
SEGMENT_ROW = len(STATE_FIELDS)
#: Rows of the cell of table B.
SEGMENT_ROWS = 7

#: A cell index no orbit is in: the next coast makes the orbit's cell afresh.
STALE_SEGMENT = -np.inf


class TaskState:
    """The state of one satellite: every field of `STATE_FIELDS` a Python float.

    The single environment steps one of these; the task functions read and assign
    its attributes exactly as they do a `BatchState`'s.
    """

    # point: the CurvePoint of (label, tau, period_s, nu), kept by the task functions that move the
    # orbit so that a step builds no second one. segments: the orbit's cell of the curves' table B,
    # a list (UniversalCurves.locate_segments), as a batch keeps its rows' cells.
    __slots__ = (*STATE_FIELDS, "point", "segments")

    def copy(self) -> TaskState:
        """An independent copy."""
        other = TaskState()
        for name in self.__slots__:
            setattr(other, name, getattr(self, name))
        other.segments = list(self.segments)  # renewed in place by a coast
        return other


class BatchState:
    """The states of many satellites: the rows of one (fields + segments, n) float64 array.

    Each field is a row view, and assigning a field writes into its row, so the task
    functions' ``state.perigee_m = ...`` updates the array in place; copying whole
    missions (an automatic reset, a subset that burns) is one column assignment.

    Args:
        data: The (len(STATE_FIELDS) + SEGMENT_ROWS, n) array to view, or the number
            of satellites for a new array of zeros.
    """

    def __init__(self, data: FloatArray | int) -> None:
        if isinstance(data, (int, np.integer)):
            data = _staggered_rows(int(data))
            data[SEGMENT_ROW] = STALE_SEGMENT
        assert data.shape[0] == SEGMENT_ROW + SEGMENT_ROWS
        views = self.__dict__
        views.update(zip(STATE_FIELDS, data, strict=False))  # the rows as views, iterated in C
        views["segments"] = data[SEGMENT_ROW:]
        views["data"] = data

    def __setattr__(self, name: str, value: Any) -> None:
        row = self.__dict__[name]
        if value is not row:  # an augmented assignment (state.x += y) has already written the row
            row[...] = value

    def __getstate__(self) -> tuple[FloatArray]:
        return (self.data,)  # the array once, not its row views (which would unpickle as copies)

    def __setstate__(self, state: tuple[FloatArray]) -> None:
        data = _staggered_rows(state[0].shape[1])  # pickle stores the rows without their padding
        data[...] = state[0]
        self.__init__(data)

    @property
    def size(self) -> int:
        """Number of satellites."""
        return int(self.data.shape[1])

    def take(self, index: Any) -> BatchState:
        """A copy of the satellites at ``index`` (an index array or a boolean mask)."""
        if isinstance(index, np.ndarray) and index.dtype == np.bool_:
            index = np.flatnonzero(index)
        return BatchState(self.data.take(index, axis=1))

    def put(self, index: Any, other: BatchState | FloatArray) -> None:
        """Write ``other``'s satellites (a `BatchState` or its data) into the places ``index``.

        ``index``: positions (non-negative), a slice or a boolean mask, as numpy takes them.
        """
        values = other.data if isinstance(other, BatchState) else other
        data = self.data
        size = data.itemsize
        if isinstance(index, np.ndarray) and index.ndim == 1 and index.dtype.kind == "i" and data.strides[1] == size:
            # One scatter into the rows as one flat run (their padding included, `_staggered_rows`):
            # a third of the time of data[:, index] = values.
            rows, n = data.shape
            row_stride = data.strides[0] // size
            flat = np.lib.stride_tricks.as_strided(data, shape=((rows - 1) * row_stride + n,), strides=(size,))
            flat[(np.arange(0, rows * row_stride, row_stride)[:, None] + index).ravel()] = values.ravel()
        else:
            data[:, index] = values

    def copy(self) -> BatchState:
        """An independent copy (rows staggered as a new batch's)."""
        data = _staggered_rows(self.size)
        data[...] = self.data
        return BatchState(data)


def _staggered_rows(n: int) -> FloatArray:
    """A (fields + segments, n) array of zeros whose rows begin in different sets of the L1 cache.

    Rows of a power-of-two length (4096 satellites: 32 KiB) begin a multiple of 4 KiB
    apart, so every row of a column falls in the same set of the 8-way L1 cache, and a
    loop over the satellites that reads and writes some 30 rows evicts its own lines at
    every satellite: the compiled coast of 4096 satellites took 226 us against 41 us
    for 4104 (measured on the 2-core AMD EPYC machine, 2026-12-03). Each row here is a
    view into a wider array whose row length is an odd number of 64-byte lines, which
    spreads consecutive rows over distinct sets.
    """
    rows = SEGMENT_ROW + SEGMENT_ROWS
    line = 64 // np.dtype(np.float64).itemsize
    width = -(-n // line) * line
    if (width // line) % 2 == 0:
        width += line
    return np.zeros((rows, width))[:, :n]


AnyState = TaskState | BatchState
