"""Solar and geomagnetic activity over a satellite's life: F10.7, its 81-day mean, Ap.

Time is counted in days since 1970-01-01 ("unix days", float); indices are in solar
flux units (sfu = 1e-22 W m^-2 Hz^-1) and Ap in its own units. Three sources, all
with the same vectorized method ``indices(unix_days) -> (f107, f107a, ap)``:

* `ConstantActivity`: fixed values.
* `TableActivity`: a user's table by date (`read_solar_csv`), linearly
  interpolated, the first/last row held outside it.
* `CycleActivity`: a smooth, periodic solar cycle with a phase, for
  planning decades ahead when no forecast is at hand.

The CSV format (``read_solar_csv``): a header row, then one row per date::

    date,f107,f107a,ap
    2013-10-01,132.0,125.3,9
    2013-10-02,...

``date`` is ``YYYY-MM-DD`` (or ``YYYY-MM``, read as the 15th). ``f107`` (observed
daily F10.7, sfu) is required. ``f107a`` (81-day centred mean) is optional: without
it, it is computed as the 81-day centred mean of the ``f107`` column (days outside
the table take the nearest row). ``ap`` (daily Ap) is optional: without it the
``default_ap`` given to the reader is used. Monthly rows work too (then ``f107`` is
a monthly mean and the computed ``f107a`` a ~3-month mean).
"""

from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import InputError, check_array, check_number, format_number
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.csvfile import cell_value, read_csv
from orbit_env.physics.atmosphere.msis import AP_RANGE, F107_RANGE_SFU

FloatArray = NDArray[np.float64]

#: Days in the 81-day centred mean of F10.7.
F107A_WINDOW_DAYS = 81
#: Default daily Ap where none is given (near the long-term median of daily Ap).
DEFAULT_AP = 12.0
#: Dates a solar table may hold: daily F10.7 is measured since 1947; no use here reaches past 2200.
SOLAR_TABLE_DATES = ("1947-01-01", "2200-12-31")
#: Mean length of the solar cycle [days] (11.0 years).
SOLAR_CYCLE_DAYS = 11.0 * DAYS_PER_YEAR


def unix_days(date: str | _dt.date | np.datetime64) -> float:
    """Days since 1970-01-01 of an ISO date (``YYYY-MM-DD``, ``YYYY-MM`` = the 15th, or with a time).

    A time may carry its zone (``Z``, ``+02:00``), as element sets' epochs are printed: it is
    converted to UTC; a time without one is UTC. A ``datetime.date``, a ``datetime`` (its zone,
    UTC if none) or a ``numpy.datetime64`` is read as the time it is, to its fractions of a second
    (numpy's ``datetime64('2024-01')`` is the 1st).

    Raises:
        ValueError: the date cannot be read (a datetime64 NaT).
    """
    if isinstance(date, np.datetime64):
        if np.isnat(date):
            raise ValueError("NaT is not a date")
        return float((date - np.datetime64(0, "s")) / np.timedelta64(1, "D"))
    if isinstance(date, _dt.date):
        moment = date if isinstance(date, _dt.datetime) else _dt.datetime(date.year, date.month, date.day)
        if moment.tzinfo is None or moment.utcoffset() is None:
            moment = moment.replace(tzinfo=_dt.UTC)
        return (moment - _dt.datetime(1970, 1, 1, tzinfo=_dt.UTC)) / _dt.timedelta(days=1)
    typed = text = str(date).strip()
    if len(text) == 7 and text[4] == "-":
        text += "-15"  # a month: its middle (monthly tables' values are the month's)
    try:
        if text.isdigit() and len(text) != 4:  # numpy reads 20200101 as the year 20200101
            raise ValueError("not a four-digit year")
        if "T" in text and (text.endswith(("Z", "z")) or "+" in text[10:] or "-" in text[10:]):
            moment = _dt.datetime.fromisoformat(text[:-1] + "Z" if text.endswith("z") else text)
            seconds = (moment - _dt.datetime(1970, 1, 1, tzinfo=_dt.UTC)).total_seconds()
            return seconds / 86400.0
        value = np.datetime64(text, "s")
    except ValueError as error:
        raise ValueError(
            f"cannot read the date {typed!r}; expected YYYY-MM-DD, YYYY-MM or YYYY-MM-DDTHH:MM[:SS] (UTC, or with "
            "its zone: Z, +HH:MM)"
        ) from error
    return float(value.astype(np.int64)) / 86400.0


def iso_date(days: float) -> str:
    """ISO date (``YYYY-MM-DD``) of a number of unix days."""
    return str(np.datetime64(math.floor(days), "D"))


def day_of_year(days: ArrayLike) -> FloatArray:
    """Day of the year, 1 to 366 (fractional), of unix days."""
    d = np.asarray(days, dtype=np.float64)
    whole = np.floor(d).astype("int64").astype("datetime64[D]")
    year_start = whole.astype("datetime64[Y]").astype("datetime64[D]")
    return (whole - year_start).astype(np.float64) + 1.0 + (d - np.floor(d))


def calendar_day(unix_days: ArrayLike) -> FloatArray:
    """The start of the calendar (UT) day that holds each of ``unix_days``: the day whose record row it reads.

    The dated decay samples the record there (`orbit_env.decay.chunked.SolarDecayModel.chunk_samples`):
    a record's rows are calendar days, and its indices between two rows are no day's.
    """
    return np.floor(np.asarray(unix_days, dtype=np.float64))


@runtime_checkable
class SolarActivity(Protocol):
    """Anything that gives the indices at given times."""

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """F10.7 [sfu], its 81-day mean [sfu] and Ap at unix days (arrays of ``days``' shape)."""
        ...


@dataclass(frozen=True)
class ConstantActivity:
    """The same F10.7, 81-day mean and Ap at all times."""

    f107_sfu: float
    f107a_sfu: float
    ap: float

    def __post_init__(self) -> None:
        check_number(self.f107_sfu, "f107_sfu", unit="sfu", low=F107_RANGE_SFU[0], high=F107_RANGE_SFU[1])
        check_number(self.f107a_sfu, "f107a_sfu", unit="sfu", low=F107_RANGE_SFU[0], high=F107_RANGE_SFU[1])
        check_number(self.ap, "ap", low=AP_RANGE[0], high=AP_RANGE[1])

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The constant indices, broadcast to the shape of ``days``."""
        shape = np.shape(days)
        return np.full(shape, self.f107_sfu), np.full(shape, self.f107a_sfu), np.full(shape, self.ap)


class SolarTableWarning(UserWarning):
    """A decay ran beyond a solar table's rows, on its edge rows held (`TableActivity.held_outside`)."""


@dataclass(frozen=True, eq=False)
class TableActivity:
    """Indices by date, linearly interpolated; the first and last rows are held outside.

    Attributes:
        days: Unix days of the rows, strictly increasing.
        f107_sfu: Daily (or monthly mean) F10.7.
        f107a_sfu: 81-day centred mean of F10.7.
        ap: Daily Ap.
        source: Where the table came from (for messages).
    """

    days: FloatArray
    f107_sfu: FloatArray
    f107a_sfu: FloatArray
    ap: FloatArray
    source: str = field(default="table")

    def __post_init__(self) -> None:
        if self.days.size < 1:
            raise ValueError(f"{self.source}: the solar table has no rows")
        if np.any(np.diff(self.days) <= 0):
            raise ValueError(f"{self.source}: dates must be strictly increasing")
        for name, values, unit, (low, high) in (
            ("f107", self.f107_sfu, "sfu", F107_RANGE_SFU),
            ("f107a", self.f107a_sfu, "sfu", F107_RANGE_SFU),
            ("ap", self.ap, "", AP_RANGE),
        ):
            try:
                check_array(values, name, unit=unit, low=low, high=high)
            except InputError as error:
                row = error.index[0] if error.index else 0
                value = f"{format_number(error.value)} on {iso_date(self.days[row])}"
                raise ValueError(f"{self.source}: {error.message(value_text=value, show_index=False)}") from None

    @property
    def start_days(self) -> float:
        """Unix day of the first row."""
        return float(self.days[0])

    @property
    def end_days(self) -> float:
        """Unix day of the last row."""
        return float(self.days[-1])

    def held_outside(self, first_day: float, last_day: float) -> str | None:
        """Why a decay from ``first_day`` to ``last_day`` [unix days] is not covered by the table, or None if it is.

        Outside its rows the first or last row is held; the sentence gives the dates and says so.
        """
        held = []
        if first_day < self.start_days - 1.0:
            held.append(f"starts on {iso_date(self.start_days)}, after the epoch {iso_date(first_day)}")
        if math.isfinite(last_day) and last_day > self.end_days + 1.0:
            held.append(
                f"ends on {iso_date(self.end_days)}, {last_day - self.end_days:.0f} days before the re-entry on "
                f"{iso_date(last_day)}"
            )
        if not held:
            return None
        return (
            f"the solar table {self.source} {' and '.join(held)}; its edge rows were held constant outside it "
            "(no record or forecast beyond the table is used)"
        )

    def indices(self, days: ArrayLike, ap_days: ArrayLike | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Indices interpolated at ``days`` (held at the edges); the Ap at ``ap_days`` if given."""
        t = np.asarray(days, dtype=np.float64)
        return (
            np.interp(t, self.days, self.f107_sfu),
            np.interp(t, self.days, self.f107a_sfu),
            np.interp(t if ap_days is None else np.asarray(ap_days, dtype=np.float64), self.days, self.ap),
        )


def centred_mean(days: FloatArray, values: FloatArray, window_days: float = F107A_WINDOW_DAYS) -> FloatArray:
    """Centred running mean over ``window_days`` of a series sampled at ``days`` (edges held)."""
    half = 0.5 * window_days
    grid = np.arange(np.floor(days[0] - half), np.ceil(days[-1] + half) + 1.0)
    daily = np.interp(grid, days, values)
    cumulative = np.concatenate([[0.0], np.cumsum(daily)])
    # Mean of the daily values whose day lies in [t - half, t + half].
    lo = np.clip(np.searchsorted(grid, days - half, side="left"), 0, grid.size)
    hi = np.clip(np.searchsorted(grid, days + half, side="right"), 0, grid.size)
    return (cumulative[hi] - cumulative[lo]) / np.maximum(hi - lo, 1)


def read_solar_csv(path: str | Path, default_ap: float = DEFAULT_AP) -> TableActivity:
    """Read a table of F10.7 (and optionally its 81-day mean and Ap) by date.

    The format is in the module docstring.

    Raises:
        ValueError: a missing column, an unreadable number or date, dates out of
            order, or indices out of range; the message names the file and row.
        OSError: the file cannot be read.
    """
    table = read_csv(path)
    source = table.source
    table.require("date", "f107", what="the solar table")
    if not table.rows:
        raise ValueError(f"{source}: the solar table has a header but no rows")
    n = len(table.rows)
    days = np.empty(n)
    f107 = np.empty(n)
    f107a = np.full(n, np.nan)
    ap = np.full(n, float(default_ap))
    first, last = unix_days(SOLAR_TABLE_DATES[0]), unix_days(SOLAR_TABLE_DATES[1])
    for i, row in enumerate(table.rows):
        cells = row.cells
        try:
            if row.extra:
                raise ValueError(f"more cells than the header has columns (extra: {', '.join(row.extra)[:40]})")
            days[i] = unix_days(cells["date"])
            if not first <= days[i] <= last:
                raise ValueError(
                    f"date={cells['date']!r} is out of range; allowed: {SOLAR_TABLE_DATES[0]} to "
                    f"{SOLAR_TABLE_DATES[1]} (F10.7 is measured since 1947)"
                )
            f107[i] = check_number(cell_value(cells["f107"]), "f107", unit="sfu")
            if cells.get("f107a"):
                f107a[i] = check_number(cell_value(cells["f107a"]), "f107a", unit="sfu")
            if cells.get("ap"):
                ap[i] = check_number(cell_value(cells["ap"]), "ap")
        except ValueError as error:
            raise ValueError(f"{row.where(source)}: {error}") from None
    for i in np.flatnonzero(np.diff(days) <= 0):
        raise ValueError(
            f"{table.rows[i + 1].where(source)}: the date is not after line {table.rows[i].line}'s; "
            "dates must be strictly increasing"
        )
    missing = np.isnan(f107a)
    if missing.any():
        f107a[missing] = centred_mean(days, f107)[missing]
    return TableActivity(days, f107, f107a, ap, source=source)


def _cycle_shape(phase: FloatArray, peak_phase: float) -> FloatArray:
    """A smooth cycle on [0, 1): 0 at the minima, 1 at ``peak_phase``; zero slope at both ends.

    sin^2(pi x^k) with x^k = 1/2 at the peak: rises faster than it falls, as solar
    cycles do, and joins the next cycle with a continuous derivative.
    """
    k = math.log(0.5) / math.log(peak_phase)
    return np.sin(np.pi * np.power(phase, k)) ** 2


@dataclass(frozen=True)
class CycleActivity:
    """A smooth, periodic solar cycle (no forecast skill: a planning climatology).

    F10.7 (daily and 81-day mean alike) runs from ``f107_min_sfu`` at each minimum
    to ``f107_max_sfu`` at ``peak_phase`` of the cycle; Ap follows the same shape
    between ``ap_min`` and ``ap_max``. The phase is set by a date of minimum.

    Defaults: the minimum of December 2019 that began solar cycle 25 (as announced
    by the NASA/NOAA Solar Cycle 25 Prediction Panel), an 11-year period, a peak
    4.4 years after the minimum; F10.7 from 68 sfu (the 2008-09 and 2019 minima's
    monthly means) to 150 sfu (a mid-sized cycle: cycle 24's smoothed maximum was
    about 120-145 sfu, cycle 23's about 190 sfu); Ap from 6 to 15 (yearly means
    near minimum and maximum).

    Args:
        minimum_days: Unix days of a solar minimum.
        period_days: Cycle length.
        peak_phase: Fraction of the cycle from the minimum to the maximum.
        f107_min_sfu: F10.7 at minimum.
        f107_max_sfu: F10.7 at maximum.
        ap_min: Ap at minimum.
        ap_max: Ap at maximum.
    """

    minimum_days: float = field(default_factory=lambda: unix_days("2019-12-15"))
    period_days: float = SOLAR_CYCLE_DAYS
    peak_phase: float = 0.4
    f107_min_sfu: float = 68.0
    f107_max_sfu: float = 150.0
    ap_min: float = 6.0
    ap_max: float = 15.0

    def __post_init__(self) -> None:
        check_number(self.minimum_days, "minimum_days", unit="unix days")
        check_number(self.period_days, "period_days", unit="days", low=365.0, high=40 * DAYS_PER_YEAR)
        check_number(self.peak_phase, "peak_phase", low=0.1, high=0.9)
        low, high = F107_RANGE_SFU
        check_number(self.f107_min_sfu, "f107_min_sfu", unit="sfu", low=low, high=high)
        check_number(
            self.f107_max_sfu, "f107_max_sfu", unit="sfu", low=self.f107_min_sfu, high=high, low_name="f107_min_sfu"
        )
        check_number(self.ap_min, "ap_min", low=AP_RANGE[0], high=AP_RANGE[1])
        check_number(self.ap_max, "ap_max", low=self.ap_min, high=AP_RANGE[1], low_name="ap_min")

    @classmethod
    def with_phase(cls, phase: float, at_days: float, **kwargs: float) -> CycleActivity:
        """The cycle that is at ``phase`` (0 = minimum, ``peak_phase`` = maximum) on ``at_days``."""
        phase = check_number(phase, "phase", low=0.0, high=1.0)
        period = float(kwargs.get("period_days", SOLAR_CYCLE_DAYS))
        return cls(minimum_days=at_days - phase * period, **kwargs)

    def phase(self, days: ArrayLike) -> FloatArray:
        """Fraction of the cycle elapsed since the last minimum, in [0, 1)."""
        return np.mod((np.asarray(days, dtype=np.float64) - self.minimum_days) / self.period_days, 1.0)

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Indices of the smooth cycle at ``days``."""
        shape = _cycle_shape(self.phase(days), self.peak_phase)
        f107 = self.f107_min_sfu + (self.f107_max_sfu - self.f107_min_sfu) * shape
        return f107, f107.copy(), self.ap_min + (self.ap_max - self.ap_min) * shape
