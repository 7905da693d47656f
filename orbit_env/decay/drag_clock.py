"""The real Sun's air for one orbit plane as a drag clock: the days of drag each calendar day is worth.

Under a density that is a fixed profile times a multiplier s(t), the universal curves'
weighted time W = Int P dnu falls by g c s dt (Eq. 4.1 with dnu = g c s dN and dt = P dN):
the orbit moves along its curve by the *drag clock* C(t) = Int s dt, whatever the
calendar. A `DragClock` holds, for one inclination, the curves of a reference NRLMSIS
profile and the cumulative C_h(d) of each day's multiplier s_h(d): the day's
orbit-averaged NRLMSIS density (the shipped record's F10.7, 81-day mean, Ap and day of
the year; `orbit_env.decay.daily_air`) over the reference profile's, at each height h
of `orbit_env.decay.density_multiplier.RATIO_GRID_M`. A decay over days [d0, d1) at perigee h then
drops W by g c (C_h(d1) - C_h(d0)) days: two lookups, whatever the span.

The multiplier is taken at the perigee, where a near-circular orbit meets its drag and an
elongated one most of it, and held at the perigee of the span's start: what the solar
decision task (`orbit_env.envs.solar_task`) steps on, month by month. Its agreement with
the package's dated lifetime (`orbit_env.decay.chunked`, bins of the profile's shape and
the ratio over the orbit) is measured in the task's manual (docs/solar-task.md).

Units: SI inside (m, s); spans in whole days since the record's first day.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.decay.chunked import SolarDecayModel, bin_indices, cached_curves
from orbit_env.decay.curves import UniversalCurves
from orbit_env.decay.density_multiplier import RATIO_GRID_M
from orbit_env.decay.solar import F107A_WINDOW_DAYS
from orbit_env.decay.solar_record import RecordActivity, shipped_record
from orbit_env.physics.atmosphere.msis import DEFAULT_MSIS_VERSION

FloatArray = NDArray[np.float64]

#: The reference profile's 81-day mean F10.7 and Ap (binned as a dated decay bins them): near the
#: record's median conditions (median 81-day F10.7 of 1957-2026: about 120 sfu), so that the
#: multiplier stays of order 1 (5-95%: 0.16-2.0 at 400 km) and the curves' shape is a typical one.
REFERENCE_F107_SFU = 120.0
REFERENCE_AP = 12.0
#: Days of the trailing means an operator computes from the observed F10.7.
TRAILING_DAYS = (F107A_WINDOW_DAYS, 365)


@dataclass(frozen=True)
class DragClock:
    """The drag clock of one orbit plane under the shipped space-weather record (see the module).

    Args:
        inclination_deg: The orbit's inclination (the latitudes NRLMSIS is averaged over,
            and the co-rotating air's speed).
        version: NRLMSIS version of the profile and the days' densities.
    """

    inclination_deg: float = 53.0
    version: float = DEFAULT_MSIS_VERSION

    @cached_property
    def record(self) -> RecordActivity:
        """The shipped space-weather record (never a user's import: a task must be the same everywhere)."""
        return shipped_record()

    @cached_property
    def _model(self) -> SolarDecayModel:
        return SolarDecayModel(
            self.record,
            self.record.start_days,
            float(self.inclination_deg),
            rotating_atmosphere=True,
            version=self.version,
            storm_ap=False,  # the task's air as its baselines were measured in: the daily Ap every day
        )

    @cached_property
    def reference(self) -> tuple[float, float]:
        """The reference profile's binned (81-day F10.7, Ap)."""
        return bin_indices(REFERENCE_F107_SFU, REFERENCE_AP, self._model.bin_step, self._model.ap_bins)

    @cached_property
    def curves(self) -> UniversalCurves:
        """The universal curves of the reference profile (co-rotating air, this inclination)."""
        return cached_curves(self._model.bin_model(self.reference))

    @property
    def start_days(self) -> float:
        """Unix day of the clock's day 0 (the record's first day)."""
        return self.record.start_days

    @cached_property
    def days(self) -> int:
        """Days the clock covers: the record, its forecast and one repeated cycle (beyond: an error)."""
        return int(self.record.end_days - self.record.start_days) + int(self.record.repeat_days)

    @cached_property
    def cumulative_days(self) -> FloatArray:
        """C_h(d): drag-days from day 0 to the start of day d, shape (heights, days + 1)."""
        log_ratio = self._model.log_ratios_by_day(0, self.days, self.reference)  # (days, heights)
        out = np.zeros((RATIO_GRID_M.size, self.days + 1))
        np.cumsum(np.exp(log_ratio).T, axis=1, out=out[:, 1:])
        return out

    @cached_property
    def daily_indices(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Per day (from day 0): observed F10.7, its trailing 81-day and 365-day means, and Ap."""
        f107, _, ap = self.record.indices(self.start_days + np.arange(self.days, dtype=np.float64))
        means = [_trailing_mean(f107, window) for window in TRAILING_DAYS]
        return f107, means[0], means[1], ap

    def drag_days(self, perigee_m: ArrayLike, first_day: ArrayLike, last_day: ArrayLike) -> FloatArray:
        """Drag-days of days [first_day, last_day) at the perigee heights (arrays broadcast).

        Interpolated between the table's heights linearly in ln (the multiplier is near
        exponential in height); heights beyond the table take its end rows.
        """
        return drag_days(self.cumulative_days, perigee_m, first_day, last_day)

    def day_of(self, date_days: float) -> int:
        """The clock's day of a Unix day."""
        return round(date_days - self.start_days)


def _trailing_mean(values: FloatArray, window: int) -> FloatArray:
    """Mean of the ``window`` days up to and including each day (fewer at the record's start)."""
    total = np.concatenate([[0.0], np.cumsum(values)])
    end = np.arange(1, values.size + 1)
    begin = np.maximum(end - window, 0)
    return (total[end] - total[begin]) / (end - begin)


#: `RATIO_GRID_M` as the drag-days lookups read it: its first height, its spacing [m], the highest row coordinate.
GRID_FIRST_M = float(RATIO_GRID_M[0])
GRID_STEP_M = float(RATIO_GRID_M[1] - RATIO_GRID_M[0])
GRID_TOP = RATIO_GRID_M.size - 1.000001


def drag_days(cumulative: FloatArray, perigee_m: ArrayLike, first_day: ArrayLike, last_day: ArrayLike) -> FloatArray:
    """`DragClock.drag_days` on a clock's ``cumulative_days`` table (rows on `RATIO_GRID_M`)."""
    x = np.clip((np.asarray(perigee_m, dtype=np.float64) - GRID_FIRST_M) / GRID_STEP_M, 0.0, GRID_TOP)
    row = x.astype(np.intp)
    w = x - row
    d0 = np.asarray(first_day, dtype=np.intp)
    d1 = np.asarray(last_day, dtype=np.intp)
    low = cumulative[row, d1] - cumulative[row, d0]
    high = cumulative[row + 1, d1] - cumulative[row + 1, d0]
    # Both positive for a span of a day or more; a span of none is 0 drag-days.
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(low > 0.0, low * np.exp(w * (np.log(high) - np.log(low))), 0.0)
    return np.asarray(out, dtype=np.float64)


@lru_cache(maxsize=4)
def drag_clock(inclination_deg: float = 53.0, version: float = DEFAULT_MSIS_VERSION) -> DragClock:
    """The process's drag clock of an orbit plane (one per inclination and version)."""
    return DragClock(float(inclination_deg), float(version))


def drag_days_at(cumulative: FloatArray, perigee_m: float, first_day: float, last_day: float) -> float:
    """`drag_days` of one orbit in plain floats (the same operations), for the compiled solar task.

    ``orbit_env.envs.solar_kernel`` compiles it with numba; ``tests/envs/test_solar_task.py`` holds it
    equal to the array form.
    """
    x = min(max((perigee_m - GRID_FIRST_M) / GRID_STEP_M, 0.0), GRID_TOP)
    row = int(x)
    w = x - row
    d0, d1 = int(first_day), int(last_day)
    low = cumulative[row, d1] - cumulative[row, d0]
    if not low > 0.0:
        return 0.0
    high = cumulative[row + 1, d1] - cumulative[row + 1, d0]
    return low * math.exp(w * (math.log(high) - math.log(low)))
