"""A catalogue's CSV file in and out: the rows read and checked, the results written whole or not at all.

Input columns (a header row; names case-insensitive, any order, extra columns ignored):

| column | meaning |
|---|---|
| ``perigee_km`` | perigee height (required) |
| ``apogee_km`` | apogee height (required) |
| ``mass_kg``, ``area_m2`` | mass and reference area (together), or |
| ``mass_kg``, ``form_factor`` | mass and a CubeSat's form factor (``3U``: its tumbling envelope's area), or |
| ``mass_per_area_kg_m2`` | transverse load G/F, or |
| ``drag_parameter_m2_kg`` | c = c_x A / m directly; a missing value: the CLI's satellite (``--mass``, ``--cx``, ...) |
| ``cx`` | drag coefficient (default: ``--cx``) |
| ``inclination_deg`` | inclination (default: ``--inclination``) |
| ``name`` or ``id`` | copied to the output |

Output columns: ``name``/``id`` (if given), ``perigee_km``, ``apogee_km``,
``inclination_deg``, ``drag_parameter_m2_kg``, ``days``, ``years``, with a rule
also ``complies``, ``new_perigee_km``, ``dv_m_s``; and ``status``: ``ok``, or why
the row has no lifetime (unreadable, invalid heights, outside the curves' domain,
still in orbit at the time-stepped path's cap). A bad row never stops the batch.
The lifetimes themselves: `orbit_env.analysis.catalogue`.
"""

from __future__ import annotations

import csv
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy as np
from numpy.typing import NDArray

from orbit_env.analysis.lifetime import (
    AREA_RANGE_M2,
    DRAG_COEFFICIENT_RANGE,
    DRAG_PARAMETER_RANGE_M2_KG,
    MASS_PER_AREA_RANGE_KG_M2,
    MASS_RANGE_KG,
)
from orbit_env.checks import InputError, check_number
from orbit_env.csvfile import cell_value, read_csv
from orbit_env.decay.curves import UniversalCurves

FloatArray = NDArray[np.float64]

#: Columns copied to the output to name a row.
ID_COLUMNS = ("name", "id")
#: A batch of element sets' column saying where each row's drag came from (JSON's ``drag_parameter_source``).
DRAG_SOURCE_KEY = "drag_parameter_source"

#: Key of a row's physical line in the rows of `read_batch` (a header name is stripped of
#: spaces, so no column can be called this).
LINE_KEY = " line"


@dataclass(frozen=True)
class BatchOrbits:
    """A batch file's rows as the decay takes them (heights above the 6371 km sphere).

    Attributes:
        rows: The rows' cells (`read_batch`; an element set's: its name).
        perigee_m: Perigee heights [m].
        apogee_m: Apogee heights [m].
        drag_parameter_m2_kg: c = c_x A / m.
        inclination_deg: Inclinations.
        status: ``ok``, or why a row has no lifetime.
        drag_sigma: Log-normal sigma of each row's drag parameter for ``--uncertainty`` (NaN:
            a satellite of known mass and area, `orbit_env.analysis.uncertainty.DRAG_COEFFICIENT_SIGMA`).
        epoch_days: Each row's element-set epoch [unix days] (NaN: none), which dates its
            re-entry when the air has no date.
    """

    rows: list[dict[str, str]]
    perigee_m: FloatArray
    apogee_m: FloatArray
    drag_parameter_m2_kg: FloatArray
    inclination_deg: FloatArray
    status: list[str]
    drag_sigma: FloatArray
    epoch_days: FloatArray

    def part(self, start: int, stop: int) -> BatchOrbits:
        """Rows ``start`` to ``stop`` (excluded)."""
        return BatchOrbits(
            self.rows[start:stop],
            self.perigee_m[start:stop],
            self.apogee_m[start:stop],
            self.drag_parameter_m2_kg[start:stop],
            self.inclination_deg[start:stop],
            self.status[start:stop],
            self.drag_sigma[start:stop],
            self.epoch_days[start:stop],
        )


def _number(row: dict[str, str], key: str, **bounds: Any) -> float | None:
    """The cell ``key`` as a number checked against ``bounds`` (see `check_number`); None if empty."""
    text = row.get(key, "")
    if text == "":
        return None
    return check_number(cell_value(text), key, **bounds)  # a text cell is refused, named with its column


def _bounded(row: dict[str, str], key: str, unit: str, bounds: tuple[float, float, str]) -> float | None:
    """The cell ``key`` within ``bounds`` (low, high, why; the satellite's bounds of the API)."""
    low, high, why = bounds
    return _number(row, key, unit=unit, low=low, high=high, low_inclusive=low > 0.0, why=why)


def _drag_parameter(row: dict[str, str], default_cx: float, default_c: float) -> float:
    cx = _bounded(row, "cx", "", DRAG_COEFFICIENT_RANGE)
    cx = default_cx if cx is None else cx
    c = _bounded(row, "drag_parameter_m2_kg", "m^2/kg", DRAG_PARAMETER_RANGE_M2_KG)
    load = _bounded(row, "mass_per_area_kg_m2", "kg/m^2", MASS_PER_AREA_RANGE_KG_M2)
    mass, area = _bounded(row, "mass_kg", "kg", MASS_RANGE_KG), _bounded(row, "area_m2", "m^2", AREA_RANGE_M2)
    form_factor = row.get("form_factor", "").strip()
    if form_factor:  # a CubeSat's envelope tumbling at random gives the area; c_x is the row's (or --cx)
        from orbit_env.analysis.shapes import cubesat

        if area is not None:
            raise ValueError("the area is given twice (area_m2; form_factor): give one of them")
        if mass is None:
            raise ValueError("form_factor gives the area: give mass_kg with it")
        area = cubesat(form_factor).reference_area_m2
    given = [
        name
        for name, present in (
            ("drag_parameter_m2_kg", c is not None),
            ("mass_per_area_kg_m2", load is not None),
            (
                "mass_kg and area_m2" if not form_factor else "mass_kg and form_factor",
                mass is not None or area is not None,
            ),
        )
        if present
    ]
    if len(given) > 1:  # alternatives: which one a row means is not for the batch to guess
        raise ValueError(f"the satellite is given twice ({'; '.join(given)}): give one of them")
    if c is not None:
        value = c
    elif load is not None:
        value = cx / load
    elif mass is not None and area is not None:
        low, high, why = MASS_PER_AREA_RANGE_KG_M2
        check_number(mass / area, "mass_kg / area_m2", unit="kg/m^2", low=low, high=high, why=why)
        value = cx * area / mass
    elif mass is not None or area is not None:
        raise ValueError("give mass_kg and area_m2 together")
    else:
        value = default_c * (cx / default_cx)
    # Factors within their bounds give c within its bounds; checked again in case of a new source.
    low, high, why = DRAG_PARAMETER_RANGE_M2_KG
    return check_number(value, "drag parameter c_x A / m", unit="m^2/kg", low=low, high=high, why=why)


def read_batch(
    path: str | Path, default_cx: float, default_c: float, default_inclination_deg: float
) -> tuple[list[dict[str, str]], FloatArray, FloatArray, FloatArray, FloatArray, list[str]]:
    """Rows, perigee [m], apogee [m], drag parameter [m^2/kg], inclination [deg], status per row.

    Raises:
        ValueError: the header lacks ``perigee_km`` or ``apogee_km``, or there are no rows.
        OSError: the file cannot be read.
    """
    table = read_csv(path)
    table.require("perigee_km", "apogee_km", what="the batch file")
    if not table.rows:
        raise ValueError(f"{table.source}: the batch file has a header but no rows")
    rows = [{**row.cells, LINE_KEY: str(row.line)} for row in table.rows]
    lines = [row.line for row in table.rows]
    n = len(rows)
    hp_km, ha_km, c, inc = (np.full(n, np.nan) for _ in range(4))
    status = ["ok"] * n
    for i, (row, record) in enumerate(zip(rows, table.rows, strict=True)):
        try:
            if record.extra:
                raise ValueError(
                    f"{len(table.header) + len(record.extra)} cells, but the header has {len(table.header)} "
                    f"columns (extra: {', '.join(record.extra)[:40]})"
                )
            perigee, apogee = _number(row, "perigee_km"), _number(row, "apogee_km")
            if perigee is None or apogee is None:
                raise ValueError("perigee_km and apogee_km are required")
            inclination = _number(row, "inclination_deg", unit="deg", low=0.0, high=180.0)
            inclination = default_inclination_deg if inclination is None else inclination
            hp_km[i], ha_km[i] = perigee, apogee
            c[i] = _drag_parameter(row, default_cx, default_c)
            inc[i] = inclination
        except ValueError as error:
            status[i] = f"line {lines[i]}: {error}"
    # Heights in the curves' domain, checked a block at a time; a failing block row by row,
    # so every bad row gets its own message.
    readable = np.flatnonzero([s == "ok" for s in status])
    for block in np.array_split(readable, max(1, readable.size // 1000)):
        try:
            UniversalCurves.check_domain_km(hp_km[block], ha_km[block])
        except InputError:
            for i in block:
                try:
                    UniversalCurves.check_domain_km(hp_km[i], ha_km[i])
                except InputError as error:
                    status[i] = f"line {lines[i]}: {error}"
    return rows, hp_km * 1e3, ha_km * 1e3, c, inc, status


def format_value(value: float) -> str:
    """A number as the results file writes it: six significant digits, empty if not finite."""
    return "" if not np.isfinite(value) else f"{value:.6g}"


@contextmanager
def atomic_text(path: str | Path, *, replace: bool = True) -> Iterator[TextIO]:
    """A text file written whole or not at all: a temporary file beside ``path``, renamed to it once complete.

    A reader never sees half a file, and a failure leaves any earlier file as it was; an error of the
    disk (full) names ``path``. ``replace=False``: a file that appeared at ``path`` meanwhile (another
    command's) is kept, and this one's text is left beside it under a name the ValueError gives.
    """
    out = Path(path)
    handle = tempfile.NamedTemporaryFile(
        "w", newline="", encoding="utf-8", dir=out.parent, prefix=f".{out.name}.", suffix=".tmp", delete=False
    )
    try:
        try:
            with handle:
                yield handle
        except OSError as error:
            if error.filename is None:  # a write's error (a full disk) names no file: this one's
                raise OSError(error.errno, error.strerror, str(out)) from None
            raise
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(handle.name, 0o666 & ~umask)  # a temporary file is private; the results are not
        if replace:
            os.replace(handle.name, out)
        else:
            _place_new(Path(handle.name), out)
    except BaseException:
        Path(handle.name).unlink(missing_ok=True)
        raise


def _place_new(written: Path, out: Path) -> None:
    """Rename ``written`` to ``out`` unless a file is there (a link fails on one: no check-then-write race).

    A link at ``out`` to nothing (which the command's checks let through) is replaced, as a rename replaces it.
    """
    if out.is_symlink() and not out.exists():
        os.replace(written, out)
        return
    try:
        os.link(written, out)
    except FileExistsError:
        _keep_beside(written, out)
    except OSError:  # a file system without hard links: checked, then renamed
        if out.exists():
            _keep_beside(written, out)
        os.replace(written, out)
        return
    written.unlink()


def _keep_beside(written: Path, out: Path) -> None:
    """Keep ``written`` under a name beside ``out`` (which another command wrote) and say so."""
    kept = out.with_name(f"{out.name}.{os.getpid()}.new")
    os.replace(written, kept)
    raise ValueError(
        f"{out} appeared while this command ran (another command wrote it) and is kept; this command's "
        f"results are in {kept}"
    )


def write_records(path: str | Path, records: list[dict[str, Any]], *, replace: bool = True) -> None:
    """Write output records as CSV with LF line endings, atomically (`atomic_text`, and its ``replace``)."""
    with atomic_text(path, replace=replace) as handle:
        writer = csv.DictWriter(handle, fieldnames=list(records[0]), lineterminator="\n")
        writer.writeheader()
        writer.writerows(records)
