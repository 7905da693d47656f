"""Lifetimes of a catalogue of satellites from a CSV file, through the universal curves.

Input columns (a header row; names case-insensitive, any order, extra columns ignored):

| column | meaning |
|---|---|
| ``perigee_km`` | perigee height (required) |
| ``apogee_km`` | apogee height (required) |
| ``mass_kg``, ``area_m2`` | mass and reference area (together), or |
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

With NRLMSIS the profile depends on the inclination: rows are grouped by
inclination rounded to ``INCLINATION_STEP_DEG`` (1 deg moves a lifetime by about
0.5%, measured at 50 deg and 400 km, so rounding costs at most 0.25%), one curve
family per group (0.9 s to build). The paper's and the exponential law in still air
do not depend on it: one group.
"""

from __future__ import annotations

import csv
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from tqdm import tqdm

from orbit_env.analysis.disposal import check_disposal_rule
from orbit_env.analysis.lifetime import (
    AREA_RANGE_M2,
    DRAG_COEFFICIENT_RANGE,
    DRAG_PARAMETER_RANGE_M2_KG,
    MASS_PER_AREA_RANGE_KG_M2,
    MASS_RANGE_KG,
    MAX_LIFETIME_YEARS,
    check_lifetime_days,
)
from orbit_env.analysis.scenario import Scenario
from orbit_env.checks import InputError, check_number
from orbit_env.csvfile import cell_value, read_csv
from orbit_env.decay.curves import UniversalCurves

FloatArray = NDArray[np.float64]

#: Inclination bins of NRLMSIS batches [deg].
INCLINATION_STEP_DEG = 1.0
#: Satellites per progress-bar step on the fixed-profile path.
BLOCK = 20_000
_ID_COLUMNS = ("name", "id")
#: Key of a row's physical line in the rows of `read_batch` (a header name is stripped of
#: spaces, so no column can be called this).
LINE_KEY = " line"


@dataclass(frozen=True)
class BatchSummary:
    """What a batch did: rows read, rows with a lifetime, groups (curve families) used."""

    rows: int
    ok: int
    groups: int


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


def batch_lifetimes(
    rows: Sequence[dict[str, str]],
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    drag_parameter_m2_kg: FloatArray,
    inclination_deg: FloatArray,
    status: list[str],
    scenario: Scenario,
    *,
    rule_years: float | None = None,
    progress: bool = True,
) -> tuple[list[dict[str, Any]], BatchSummary]:
    """Lifetimes (and the rule check) of every valid row; output records in input order."""
    n = len(rows)
    ok = np.array([s == "ok" for s in status])
    days = np.full(n, np.nan)
    reentered = np.zeros(n, dtype=bool)
    complies = np.zeros(n, dtype=bool)
    new_hp = np.full(n, np.nan)
    dv = np.full(n, np.nan)
    depends_on_inclination = scenario.atmosphere == "msis" or scenario.rotating_atmosphere
    if depends_on_inclination:
        group_of = np.round(inclination_deg / INCLINATION_STEP_DEG) * INCLINATION_STEP_DEG
    else:
        group_of = np.zeros(n)
    groups = np.unique(group_of[ok])
    cap_days = None if rule_years is None else (rule_years + 1.0) * 365.25
    with tqdm(total=int(ok.sum()), disable=not progress, unit="sat", desc="lifetimes") as bar:
        for group in groups:
            members = np.flatnonzero(ok & (group_of == group))
            inclination = float(group) if depends_on_inclination else float(inclination_deg[members[0]])
            blocks = [members] if scenario.time_varying else np.array_split(members, max(1, members.size // BLOCK))
            for block in blocks:
                if rule_years is None:
                    d, r = scenario.lifetime_days(
                        perigee_m[block], apogee_m[block], drag_parameter_m2_kg[block], inclination
                    )
                    days[block], reentered[block] = d, r
                else:
                    c_block = drag_parameter_m2_kg[block]

                    def lifetimes(hp: FloatArray, ha: FloatArray, which: NDArray[np.intp]) -> Any:
                        return scenario.lifetime_days(hp, ha, c_block[which], inclination, max_days=cap_days)  # noqa: B023

                    check = check_disposal_rule(perigee_m[block], apogee_m[block], rule_years, lifetimes)
                    days[block], reentered[block] = check.lifetime_days, check.reentered
                    complies[block], new_hp[block], dv[block] = check.complies, check.new_perigee_m, check.dv_m_s
                bar.update(block.size)
    for i in np.flatnonzero(ok & ~reentered):
        if rule_years is None:
            status[i] = f"still in orbit after {scenario.max_years:g} years (the time-stepped path stops there)"
    for i in np.flatnonzero(ok & reentered & ~(days <= MAX_LIFETIME_YEARS * 365.25)):
        try:
            check_lifetime_days(float(days[i]))
        except ValueError as error:
            line = rows[i].get(LINE_KEY)
            status[i] = f"line {line}: {error}" if line else str(error)
    records = []
    for i, row in enumerate(rows):
        record: dict[str, Any] = {key: row[key] for key in _ID_COLUMNS if key in row}
        record.update(
            perigee_km=_fmt(perigee_m[i] / 1e3),
            apogee_km=_fmt(apogee_m[i] / 1e3),
            inclination_deg=_fmt(inclination_deg[i]),
            drag_parameter_m2_kg=_fmt(drag_parameter_m2_kg[i]),
            days=_fmt(days[i]) if status[i] == "ok" and reentered[i] else "",
            years=_fmt(days[i] / 365.25) if status[i] == "ok" and reentered[i] else "",
        )
        if rule_years is not None:
            good = status[i] == "ok"
            record.update(
                complies=str(bool(complies[i])).lower() if good else "",
                new_perigee_km=_fmt(new_hp[i] / 1e3) if good else "",
                dv_m_s=_fmt(dv[i]) if good else "",
            )
        record["status"] = status[i]
        records.append(record)
    n_ok = sum(1 for s in status if s == "ok")
    return records, BatchSummary(rows=n, ok=n_ok, groups=int(groups.size))


def _fmt(value: float) -> str:
    return "" if not np.isfinite(value) else f"{value:.6g}"


def check_output(path: str | Path, input_path: str | Path, *, force: bool = False) -> None:
    """Refuse, before any computing, an output that would replace the input, or an existing file, or cannot be written.

    Args:
        path: The results file.
        input_path: The catalogue it is computed from.
        force: Replace an existing results file (never the input).

    Raises:
        ValueError: ``path`` is the input file (also through a link), exists and
            ``force`` is off, is a directory, or its directory is missing or not writable.
    """
    out, source = Path(path), Path(input_path)
    if (out.exists() and source.exists() and os.path.samefile(out, source)) or out.resolve() == source.resolve():
        raise ValueError(f"--out {path} is the input file; the results go to another file")
    if out.is_dir():
        raise ValueError(f"--out {path} is a directory; give a file name")
    if out.exists() and not force:
        raise ValueError(f"--out {path} exists; give --force to replace it, or another file name")
    folder = out.parent
    if not folder.is_dir():
        raise ValueError(f"--out {path}: the folder {folder} does not exist")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise ValueError(f"--out {path}: cannot write in {folder} ({error.strerror or error})") from None


def write_records(path: str | Path, records: list[dict[str, Any]]) -> None:
    """Write output records as CSV with LF line endings, atomically.

    The rows go to a temporary file beside ``path``, renamed to ``path`` once
    complete: a reader never sees half a file, and a failure leaves any earlier
    file as it was.
    """
    out = Path(path)
    handle = tempfile.NamedTemporaryFile(
        "w", newline="", encoding="utf-8", dir=out.parent, prefix=f".{out.name}.", suffix=".tmp", delete=False
    )
    try:
        with handle:
            writer = csv.DictWriter(handle, fieldnames=list(records[0]), lineterminator="\n")
            writer.writeheader()
            writer.writerows(records)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(handle.name, 0o666 & ~umask)  # a temporary file is private; the results are not
        os.replace(handle.name, out)
    except BaseException:
        Path(handle.name).unlink(missing_ok=True)
        raise
