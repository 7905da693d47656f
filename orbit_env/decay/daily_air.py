"""The real Sun's air as a table: each day's orbit-averaged NRLMSIS density, computed once and kept on disk.

A decay under changing activity (`orbit_env.decay.chunked`) needs, for every day it
crosses, NRLMSIS averaged over the orbit's latitudes and local times at that day's
indices (F10.7, its 81-day mean, Ap, the day of the year), on the heights of
`orbit_env.decay.density_multiplier.RATIO_GRID_M`. Those rows depend on the day's indices, the
inclination, the Sun-synchronous node (if any) and the NRLMSIS version, never on the
satellite: a `DailyAirTable` holds them per (inclination, node, version), keyed by the
indices as the decay rounds them (0.1 sfu, 0.1 Ap, the day of the year to 2 days), so
the same row serves every satellite, every date with the same indices, the shipped
record, an imported table and the uncertainty's scaled forecasts alike.

A row is computed the first time it is asked for, together with the rows of the days
ahead the caller names (half a year, one NRLMSIS call, split over two processes where it may
fork: `orbit_env.workers.in_two_processes`), while a forked process computes the days after
those the caller names too (``after``; `orbit_env.workers.Forked`, 30 days at a time), taken
in when the caller first asks for one of them: on a cold run the decay integrates a bin's
curves meanwhile. A forked process still running then is stopped and its finished days
kept; the caller computes the rest. The table is written to the disk cache (`orbit_env.cache`, kind
``"airdays"``) when it has grown by a quarter since it was last written, and when the
process ends: a later run, in any process, reads it in milliseconds and calls NRLMSIS
only for days it has never seen. (Written at every growth, the uncertainty's samples,
whose scaled forecasts are days never seen, rewrote a growing table hundreds of times.)
The rows are NRLMSIS's own values for those indices (a memo, not an interpolation), so
results do not change with what is cached. A caller may ask for the first heights only
(``columns``: a decay reads no air above its orbits): a row is then computed to those heights,
NaN above, and deepened when a later caller asks for more. Forked worker processes (the uncertainty's
solar nodes) hand the rows they computed or deepened back to their parent (`new_rows`, `merge_rows`),
which writes them with its own. Processes that each write (the catalogue's spawned workers, two
commands at once) write under the table's lock (`orbit_env.cache.locked`), each taking in first the
rows the others wrote since it read the table: none loses another's rows.
Units: SI (m, kg/m^3).

**Storm days.** A day the decay counts as a storm day (`orbit_env.decay.chunked.STORM_AP`)
has a longer key: its four indices, then the 27 3-hourly ap NRLMSIS's storm-time mode
reads on it (`orbit_env.decay.solar_record.RecordActivity.ap_history`). Its row is NRLMSIS
in that mode at each of the day's eight 3-hour slots, each with its own ap history
(`orbit_env.physics.atmosphere.msis.ap_histories`), averaged over the slots as well as the
orbit. The key holds all the row depends on, so a storm row is never another day's, nor a
daily-Ap row (a key of four); the table stores the keys padded with NaN to one width.
"""

from __future__ import annotations

import atexit
import weakref
from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from orbit_env import cache
from orbit_env.physics.atmosphere.msis import ap_histories, orbit_mean_density_by_day_kg_m3
from orbit_env.workers import Forked, can_fork

FloatArray = NDArray[np.float64]
#: A day's indices as the decay rounds them: (F10.7 [sfu], 81-day mean [sfu], Ap, day of the year 1-366), then
#: on a storm day the 27 3-hourly ap of its storm-time history (the module docstring).
DayKey = tuple[float, ...]
#: Length of a daily-Ap day's key; a storm day's is `DAILY_KEY` + `STORM_AP_SLOTS`.
DAILY_KEY = 4
#: The 3-hourly ap a storm day's key holds: 57 h before its first slot to its last.
STORM_AP_SLOTS = 27
#: Days a forked process computes at a time (`DailyAirTable.log_density`'s ``after``): the rows it has finished
#: are kept when it is stopped.
BACKGROUND_PART = 30
#: Days computed at once from which `DailyAirTable` shows a progress bar on a terminal (a first use of the
#: solar task's table: every day since 1957, about 15 s on two cores), computing them this many at a time.
PROGRESS_DAYS = 3000
PROGRESS_PART = 1000
#: A table is written again when it holds this many times the rows it held when last written (or read).
STORE_GROWTH = 1.25
_TABLES: weakref.WeakSet[DailyAirTable] = weakref.WeakSet()


class DailyAirTable:
    """ln of the orbit-averaged NRLMSIS density [kg/m^3] per day's indices, on fixed heights (grown on demand).

    Args:
        heights_m: Heights above the package's 6371 km sphere (the table's columns).
        inclination_deg: The orbit's inclination (its latitudes).
        ascending_node_local_time_h: Sun-synchronous orbits: the node's local time (None: local
            times uniform).
        version: NRLMSIS version (`orbit_env.physics.atmosphere.msis.MSIS_VERSIONS`).
        latitude_nodes: Latitude samples of the orbit average.
        local_time_nodes: Local-time samples of the orbit average.
    """

    def __init__(
        self,
        heights_m: FloatArray,
        inclination_deg: float,
        ascending_node_local_time_h: float | None,
        version: float,
        latitude_nodes: int,
        local_time_nodes: int,
    ) -> None:
        self.heights_m = np.asarray(heights_m, dtype=np.float64)
        self.inclination_deg = float(inclination_deg)
        self.ascending_node_local_time_h = ascending_node_local_time_h
        self.version = float(version)
        self.latitude_nodes, self.local_time_nodes = latitude_nodes, local_time_nodes
        self._description = cache.describe(
            (
                tuple(self.heights_m.tolist()),
                self.inclination_deg,
                ascending_node_local_time_h,
                self.version,
                latitude_nodes,
                local_time_nodes,
            )
        )
        self._disk = cache.stamp("airdays", self._description)  # the file read (`store` reads it again if replaced)
        stored = cache.load("airdays", self._description)
        if stored is None:
            self._keys = np.empty((0, 4))
            self._log_rho = np.empty((0, self.heights_m.size))
        else:
            self._keys, self._log_rho = stored["keys"], stored["log_density"]
        self._row_of: dict[DayKey, int] = {key: row for row, key in enumerate(map(_unpadded, self._keys.tolist()))}
        self._columns = _computed_columns(self._log_rho)  # per row: its leading columns NRLMSIS has filled
        self._stored_rows = self._read_rows = len(self._row_of)
        self._deepened: set[int] = set()  # rows read from the disk cache that this process has deepened
        self._changes = 0  # rows added or deepened since the table was last written (or read)
        self._pending: tuple[list[DayKey], Forked] | None = None  # rows a forked process computes
        _TABLES.add(self)

    def __len__(self) -> int:
        """The number of days' indices held."""
        return len(self._row_of)

    def log_density(
        self,
        keys: Sequence[DayKey],
        ahead: Callable[[], Sequence[DayKey]] | None = None,
        after: Callable[[], Sequence[DayKey]] | None = None,
        columns: int | None = None,
    ) -> FloatArray:
        """The rows of ``keys``, shape (len(keys), heights): ln(density [kg/m^3]).

        Rows not held yet are computed in one NRLMSIS call with those of ``ahead()`` (the
        days the caller will want next); the rows of ``after()`` (the days after those) are
        then computed by a forked process (`orbit_env.workers.Forked`, where it may fork)
        while the caller goes on, and taken in at the next row not held. With ``columns``,
        only the first ``columns`` heights need be there (a decay below a height reads no
        air above it; NRLMSIS's cost is per height): a row is computed, or deepened, to
        them, and the columns beyond may be NaN.
        """
        columns = self.heights_m.size if columns is None else min(int(columns), self.heights_m.size)
        missing = self._not_held(keys, columns)
        if missing:
            if self._pending_has(missing):
                self._collect()
                missing = self._not_held(missing, columns)
            if missing:
                self._add([*missing, *(ahead() if ahead is not None else ())], columns)
            if after is not None:
                self._start_background(after(), columns)
        return self._log_rho[[self._row_of[key] for key in keys]]

    def _not_held(self, keys: Iterable[DayKey], columns: int) -> list[DayKey]:
        """The keys (each once, in order) whose rows are not held with their first ``columns`` heights."""
        row_of, held = self._row_of, self._columns
        return list(dict.fromkeys(key for key in keys if (row := row_of.get(key)) is None or held[row] < columns))

    def _add(self, keys: Sequence[DayKey], columns: int) -> None:
        new = self._not_held(keys, columns)
        if new:
            self.merge(*self._computed(new, columns))

    def _computed(self, new: list[DayKey], columns: int) -> tuple[list[DayKey], FloatArray]:
        """The keys ``new`` (daily-Ap days first, then storm days) and their rows to ``columns`` heights, by NRLMSIS.

        The rows are NaN beyond ``columns``.
        """
        # Daily-Ap days in one NRLMSIS call, storm days (longer keys) in another.
        new = sorted(new, key=len)
        if len(new) >= PROGRESS_DAYS:  # years of air: a part at a time, with a bar (NRLMSIS is pointwise: same rows)
            from tqdm import tqdm  # here: a command that computes no years of air does not import it

            desc = "NRLMSIS air by day (computed once, then kept in the disk cache)"
            rows = []
            with tqdm(total=len(new), unit="day", desc=desc, disable=None, leave=False) as bar:
                for start in range(0, len(new), PROGRESS_PART):
                    rows.append(self._computed(new[start : start + PROGRESS_PART], columns)[1])
                    bar.update(len(rows[-1]))
            return new, np.concatenate(rows)
        daily = sum(len(key) == DAILY_KEY for key in new)
        rho = np.full((len(new), self.heights_m.size), np.nan)
        for part, storm in ((slice(0, daily), False), (slice(daily, None), True)):
            if not new[part]:
                continue
            values = np.array(new[part], dtype=np.float64)
            f107, f107a, ap, doy = values[:, :DAILY_KEY].T
            rho[part, :columns] = orbit_mean_density_by_day_kg_m3(
                self.heights_m[:columns],
                f107,
                f107a,
                ap,
                doy,
                self.inclination_deg,
                self.ascending_node_local_time_h,
                latitude_nodes=self.latitude_nodes,
                local_time_nodes=self.local_time_nodes,
                version=self.version,
                ap_history=ap_histories(ap, values[:, DAILY_KEY:]) if storm else None,
            )
        return new, np.log(rho)

    def _start_background(self, keys: Sequence[DayKey], columns: int) -> None:
        """Have a forked process compute the rows of ``keys`` not held (if this process may fork), a part at a time."""
        new = self._not_held(keys, columns)
        if not new or self._pending is not None or not can_fork():
            return
        new.sort(key=len)  # `_computed`'s order, so that each part keeps it

        def fill(out: FloatArray, mark: Callable[[int], None]) -> None:
            for start in range(0, len(new), BACKGROUND_PART):
                stop = min(start + BACKGROUND_PART, len(new))
                out[start:stop] = self._computed(new[start:stop], columns)[1]
                mark(stop)

        try:
            self._pending = (new, Forked(fill, (len(new), self.heights_m.size)))
        except OSError:  # no fork to be had: the days are computed here when asked for
            return

    def _pending_has(self, keys: Sequence[DayKey]) -> bool:
        """Whether the forked process computes one of ``keys``."""
        return self._pending is not None and not set(keys).isdisjoint(self._pending[0])

    def _collect(self) -> None:
        """Hold the rows a forked process has computed so far (it is stopped if still running: no waiting for it)."""
        if self._pending is not None:
            keys, child = self._pending
            self._pending = None
            log_rho, done = child.stop()
            if done:
                self.merge(keys[:done], log_rho[:done])

    def _append(self, new: list[DayKey], log_rho: FloatArray) -> None:
        """Hold the rows ``log_rho`` of the keys ``new`` (none held yet)."""
        start = len(self._row_of)
        width = max(self._keys.shape[1], max(map(len, new)))
        added = np.full((len(new), width), np.nan)
        for row, key in enumerate(new):
            added[row, : len(key)] = key
        held = np.pad(self._keys, ((0, 0), (0, width - self._keys.shape[1])), constant_values=np.nan)
        self._keys = np.concatenate([held, added])
        self._log_rho = np.concatenate([self._log_rho, log_rho])
        self._columns = np.concatenate([self._columns, _computed_columns(log_rho)])
        self._row_of.update({key: start + k for k, key in enumerate(new)})

    def close(self) -> None:
        """Keep the rows a forked process has finished (it is stopped if still running), and write the table."""
        self._collect()
        self.store()

    def settings(self) -> tuple[tuple[float, ...], float, float | None, float, int, int]:
        """The arguments of `daily_air_table` that give this table (in any process)."""
        heights = tuple(self.heights_m.tolist())
        node = self.ascending_node_local_time_h
        return heights, self.inclination_deg, node, self.version, self.latitude_nodes, self.local_time_nodes

    def new_rows(self) -> tuple[list[DayKey], FloatArray]:
        """The keys and rows this process added to the table since it read it from the disk cache, or deepened.

        A row read shallow (computed for a lower orbit) and deepened here is handed back too: else a
        worker would deepen it again on every run.
        """
        keys = list(self._row_of)  # in row order: rows are only appended
        rows = [*sorted(self._deepened), *range(self._read_rows, len(keys))]
        return [keys[row] for row in rows], self._log_rho[rows]

    def merge(self, keys: Sequence[DayKey], log_rho: FloatArray) -> None:
        """Hold rows computed here or by another process (`new_rows` of a worker's table).

        A key not held is added; one held with fewer columns than its new row is deepened (the
        columns it had are NRLMSIS's same values); the table is written when it has changed by
        a quarter.
        """
        self._changes += self._hold(keys, log_rho)
        if self._changes and self._stored_rows + self._changes >= STORE_GROWTH * self._stored_rows:
            self.store()

    def _hold(self, keys: Sequence[DayKey], log_rho: FloatArray) -> int:
        """`merge`'s rows taken in, without writing: how many were added or deepened."""
        log_rho = np.asarray(log_rho)
        columns = _computed_columns(log_rho)
        fresh, deeper = [], []
        for k, key in enumerate(map(tuple, keys)):
            row = self._row_of.get(key)
            if row is None:
                fresh.append(k)
            elif self._columns[row] < columns[k]:
                deeper.append(k)
        if fresh:
            self._append([tuple(keys[k]) for k in fresh], log_rho[fresh])
        for k in deeper:
            row = self._row_of[tuple(keys[k])]
            self._log_rho[row] = log_rho[k]
            self._columns[row] = columns[k]
            if row < self._read_rows:
                self._deepened.add(row)
        return len(fresh) + len(deeper)

    def store(self) -> None:
        """Write the table to the disk cache if it holds rows not written yet.

        With the rows another process has written since this one read the table taken in first
        (under the table's lock, `orbit_env.cache.locked`): the catalogue's worker processes each
        write their table as they end, and a plain write would keep only the last one's rows.
        """
        if self._changes:
            with cache.locked("airdays", self._description):
                if cache.stamp("airdays", self._description) != self._disk:  # another process wrote it
                    stored = cache.load("airdays", self._description)
                    if stored is not None:
                        self._hold(list(map(_unpadded, stored["keys"].tolist())), stored["log_density"])
                # Uncompressed: read back in milliseconds (a solar cycle's days are about 1 MB).
                arrays = {"keys": self._keys, "log_density": self._log_rho}
                cache.store("airdays", self._description, arrays, compress=False)
                self._disk = cache.stamp("airdays", self._description)
            self._stored_rows = len(self)
            self._changes = 0


def _computed_columns(log_rho: FloatArray) -> NDArray[np.intp]:
    """Per row, how many leading columns hold a value (NRLMSIS's are never NaN; a column not computed is)."""
    finite = np.isfinite(log_rho)
    return np.where(finite.all(axis=1), log_rho.shape[1], np.argmin(finite, axis=1))


def _unpadded(stored: list[float]) -> DayKey:
    """A key as the table stores it (NaN-padded to the widest key) back to its own length."""
    key = tuple(stored)
    return key if len(key) == DAILY_KEY or not np.isnan(key[DAILY_KEY]) else key[:DAILY_KEY]


#: The new rows of a process's tables (`new_rows`): each table's `DailyAirTable.settings`, keys and rows.
NewRows = list[tuple[tuple[tuple[float, ...], float, float | None, float, int, int], list[DayKey], FloatArray]]


def new_rows() -> NewRows:
    """Every table's rows this process has added: what a worker process hands back to its parent (`merge_rows`)."""
    rows = [(table.settings(), *table.new_rows()) for table in list(_TABLES)]
    return [row for row in rows if row[1]]


def merge_rows(rows: NewRows) -> None:
    """Hold in this process's tables the rows other processes computed (`new_rows`); written to disk as any."""
    for settings, keys, log_rho in rows:
        daily_air_table(*settings).merge(keys, log_rho)


@atexit.register
def _store_all() -> None:
    for table in list(_TABLES):
        table.close()


@lru_cache(maxsize=64)
def daily_air_table(
    heights_m: tuple[float, ...],
    inclination_deg: float,
    ascending_node_local_time_h: float | None,
    version: float,
    latitude_nodes: int,
    local_time_nodes: int,
) -> DailyAirTable:
    """The process's one `DailyAirTable` of these settings (read from the disk cache the first time)."""
    return DailyAirTable(
        np.array(heights_m), inclination_deg, ascending_node_local_time_h, version, latitude_nodes, local_time_nodes
    )
