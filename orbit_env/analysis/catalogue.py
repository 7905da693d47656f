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

With NRLMSIS the profile depends on the inclination (and in co-rotating air the
drag does): rows are grouped by inclination rounded to ``INCLINATION_STEP_DEG``
(1 deg moves a lifetime by about 0.5%, measured at 50 deg and 400 km, so rounding
costs at most 0.25%). Up to ``MAX_FAMILIES`` groups get a curve family each (0.9 s
to build). In a catalogue spread over more groups, every row takes one family, that
of the most common inclination, and its own inclination as a density multiplier along
its decay: NRLMSIS at the row's inclination against the family's (computed every
``ANCHOR_STEP_DEG`` in one NRLMSIS call and interpolated in inclination). Near-circular
rows (apogee at most ``SPREAD_MAX_SPAN_M`` above perigee) take the ratio of the two
densities weighted over the orbit as drag weights it
(`orbit_env.decay.chunked.orbit_ratio`), times that of the co-rotating air's drag; wider
rows the ratio of the rates at which the life left falls (``_life_rate_ratio``), which a
profile of another shape moves through the eccentricity as well as the perigee. The time
is Int dW / (g c s) along the family's curve. On 10^4 rows over 0-98 deg this stays
within the 0.5% the curves hold of a family per 1-degree group, at the cost measured
by ``benchmarks/bench_catalogue.py`` (docs/validation-modern.md section 7). A disposal
rule searches its lowered perigees on the same family (`check_disposal_rule` with these
lifetimes). A dated catalogue (the time-stepped path) spread over more groups also takes
one family, that of the most common group, through its chunks, each row's inclination a
density multiplier in every chunk (`orbit_env.decay.chunked.propagate`), and the rule's
search on those lifetimes. The paper's and the exponential law in still air do not
depend on the inclination: one group.
"""

from __future__ import annotations

import csv
import os
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

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
from orbit_env.decay.chunked import (
    RATIO_NODES,
    SPREAD_MAX_SPAN_M,
    SPREAD_QUADRATURE_POINTS,
    corotation_factor,
    inclination_anchors,
    inclination_basis,
    interpolate_rows_with_slope,
    life_rate_ratio,
    orbit_ratio,
)
from orbit_env.decay.curves import NU_REF, UniversalCurves, days_from_weighted_s

FloatArray = NDArray[np.float64]

#: Inclination bins of NRLMSIS batches [deg].
INCLINATION_STEP_DEG = 1.0
#: A catalogue with more inclination groups than this takes one curve family and a density ratio.
MAX_FAMILIES = 2
#: Heights [m] of the ratio (uniform: the rows' tables are read by index).
RATIO_HEIGHTS_M = np.arange(100e3, 1200e3 + 1.0, 25e3)
#: Points along each decay (equal steps of the curves' tau) where the multiplier is taken.
PATH_NODES = 48
#: Points along each decay of a wide row (on the rows of SPREAD_QUADRATURE_POINTS in co-rotating air:
#: 24 leave up to 0.59%, 32 0.45%).
WIDE_PATH_NODES = 32
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


def _spread_batch(
    scenario: Scenario,
    members: NDArray[np.intp],
    group_of: FloatArray,
    inputs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    days: FloatArray,
    reentered: NDArray[np.bool_],
    bar: Any,
) -> float:
    """Lifetimes of ``members`` on one curve family and a ratio (module docstring); returns its inclination."""
    reference, lifetimes = _spread_lifetimes(scenario, members, group_of, inputs)
    for block in np.array_split(np.arange(members.size), max(1, members.size // BLOCK)):
        rows = members[block]
        days[rows], reentered[rows] = lifetimes(inputs[0][rows], inputs[1][rows], block)
        bar.update(rows.size)
    return reference


def _most_common(groups: FloatArray) -> float:
    """The inclination group with the most rows (the one family's)."""
    values, counts = np.unique(groups, return_counts=True)
    return float(values[np.argmax(counts)])


def _spread_lifetimes(
    scenario: Scenario,
    members: NDArray[np.intp],
    group_of: FloatArray,
    inputs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    max_days: float | None = None,
) -> tuple[float, Any]:
    """The one family's inclination, and the lifetimes of ``members`` at other heights on it.

    The function takes heights and the positions (in ``members``) of the rows they
    belong to, as `check_disposal_rule`'s ``lifetime_days``; a life beyond ``max_days``
    counts as not re-entered (as the time-stepped path's cap).
    """
    _, _, drag_parameter_m2_kg, inclination_deg = inputs
    reference = _most_common(group_of[members])
    curves = scenario.curves(reference)
    log_ratio = inclination_log_ratio(scenario, reference, inclination_deg[members])

    def lifetimes(perigee_m: FloatArray, apogee_m: FloatArray, which: NDArray[np.intp]) -> Any:
        rows = members[which]
        d = spread_lifetime_days(
            curves,
            scenario,
            reference,
            log_ratio[which],
            inclination_deg[rows],
            perigee_m,
            apogee_m,
            drag_parameter_m2_kg[rows],
        )
        return d, (np.ones(d.size, dtype=bool) if max_days is None else d <= max_days)

    return reference, lifetimes


def _spread_rule(
    scenario: Scenario,
    reference_deg: float,
    inputs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    members: NDArray[np.intp],
    spread: Any,
    rule_years: float,
    cap_days: float,
) -> Any:
    """`check_disposal_rule` of ``members`` on the one family, with two evaluations of their own lifetimes each.

    The search for the lowered perigee evaluates some 49 lifetimes a row: on the
    family's curves those cost one lookup each, the rows' own (``spread``, the family
    with the row's density multiplier along its decay) fifty times more. So the search
    runs on the family's lifetimes times each row's ratio to them, taken where it is
    exact: at the row's perigee (so its lifetime and verdict are the row's own), then
    also at the perigee a first search found, the ratio linear in perigee between the
    two, and the search run again. Against the family's own search per 1-degree group:
    the same verdicts and lowered perigees within 0.2 km on 10^4 rows (docs/validation-modern.md).
    """
    perigee_m, apogee_m, drag_parameter_m2_kg, _ = inputs
    hp, ha, c = perigee_m[members], apogee_m[members], drag_parameter_m2_kg[members]
    index = np.arange(members.size)
    own, _ = spread(hp, ha, index)
    family, _ = scenario.lifetime_days(hp, ha, c, reference_deg)
    at = [(hp, own / family)]  # (perigee, ratio) where the ratio is exact

    def lifetimes(h: FloatArray, a: FloatArray, which: NDArray[np.intp]) -> Any:
        (h0, r0), (h1, r1) = at[0], at[-1]
        span = h1[which] - h0[which]
        slope = np.divide(r1[which] - r0[which], span, out=np.zeros(which.size), where=span != 0.0)
        days = scenario.lifetime_days(h, a, c[which], reference_deg)[0] * (r0[which] + slope * (h - h0[which]))
        return days, days <= cap_days

    first = check_disposal_rule(hp, ha, rule_years, lifetimes)
    lowered = np.flatnonzero(~first.complies)
    if lowered.size == 0:
        return first
    h1, r1 = hp.copy(), at[0][1].copy()
    own_1, _ = spread(first.new_perigee_m[lowered], ha[lowered], lowered)
    family_1, _ = scenario.lifetime_days(first.new_perigee_m[lowered], ha[lowered], c[lowered], reference_deg)
    h1[lowered], r1[lowered] = first.new_perigee_m[lowered], own_1 / family_1
    at.append((h1, r1))
    return check_disposal_rule(hp, ha, rule_years, lifetimes)


def _stepped_spread(
    scenario: Scenario,
    members: NDArray[np.intp],
    group_of: FloatArray,
    inputs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    rule_years: float | None,
    cap_days: float | None,
    outputs: tuple[FloatArray, NDArray[np.bool_], NDArray[np.bool_], FloatArray, FloatArray],
) -> float:
    """Lifetimes (and the rule) of ``members`` on the time-stepped path, one family; returns its inclination.

    The family is that of the most common inclination group; every row keeps its own
    inclination as a density multiplier (`orbit_env.decay.chunked.propagate`).
    """
    perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg = inputs
    days, reentered = outputs[:2]
    reference = _most_common(group_of[members])
    c, own = drag_parameter_m2_kg[members], inclination_deg[members]
    if rule_years is None:
        days[members], reentered[members] = scenario.lifetime_days(
            perigee_m[members], apogee_m[members], c, reference, own_inclination_deg=own
        )
        return reference

    def lifetimes(hp: FloatArray, ha: FloatArray, which: NDArray[np.intp]) -> Any:
        return scenario.lifetime_days(hp, ha, c[which], reference, max_days=cap_days, own_inclination_deg=own[which])

    _store_check(outputs, members, check_disposal_rule(perigee_m[members], apogee_m[members], rule_years, lifetimes))
    return reference


def _store_check(
    outputs: tuple[FloatArray, NDArray[np.bool_], NDArray[np.bool_], FloatArray, FloatArray],
    rows: NDArray[np.intp],
    check: Any,
) -> None:
    """Write a rule check's lifetimes, verdicts, lowered perigees and burns into the batch's columns at ``rows``."""
    days, reentered, complies, new_hp, dv = outputs
    days[rows], reentered[rows] = check.lifetime_days, check.reentered
    complies[rows], new_hp[rows], dv[rows] = check.complies, check.new_perigee_m, check.dv_m_s


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
    exact_groups: bool = False,
) -> tuple[list[dict[str, Any]], BatchSummary]:
    """Lifetimes (and the rule check) of every valid row; output records in input order.

    ``exact_groups`` builds a curve family per inclination group however many there
    are (the reference the one-family path of a spread catalogue is measured against).
    """
    n = len(rows)
    ok = np.array([s == "ok" for s in status])
    days = np.full(n, np.nan)
    reentered = np.zeros(n, dtype=bool)
    complies = np.zeros(n, dtype=bool)
    new_hp = np.full(n, np.nan)
    dv = np.full(n, np.nan)
    depends_on_inclination = scenario.depends_on_inclination
    if depends_on_inclination:
        group_of = np.round(inclination_deg / INCLINATION_STEP_DEG) * INCLINATION_STEP_DEG
    else:
        group_of = np.zeros(n)
    groups = np.unique(group_of[ok])
    cap_days = None if rule_years is None else (rule_years + 1.0) * 365.25
    one_family = depends_on_inclination and not exact_groups and groups.size > MAX_FAMILIES
    by_groups = ok.copy()
    families: set[float] = set()
    inputs = (perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg)
    outputs = (days, reentered, complies, new_hp, dv)
    with tqdm(total=int(ok.sum()), disable=not progress, unit="sat", desc="lifetimes") as bar:
        if one_family:
            members = np.flatnonzero(ok)
            if scenario.time_varying:
                families.add(_stepped_spread(scenario, members, group_of, inputs, rule_years, cap_days, outputs))
                bar.update(members.size)
            elif rule_years is None:
                families.add(_spread_batch(scenario, members, group_of, inputs, days, reentered, bar))
            else:  # the rule's search for the lowered perigee on the same family
                reference, lifetimes = _spread_lifetimes(scenario, members, group_of, inputs)
                families.add(reference)
                check = _spread_rule(scenario, reference, inputs, members, lifetimes, rule_years, cap_days)
                _store_check(outputs, members, check)
                bar.update(members.size)
            by_groups[:] = False
        for group in np.unique(group_of[by_groups]):
            families.add(float(group))
            members = np.flatnonzero(by_groups & (group_of == group))
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

                    _store_check(
                        outputs, block, check_disposal_rule(perigee_m[block], apogee_m[block], rule_years, lifetimes)
                    )
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
            perigee_km=format_value(perigee_m[i] / 1e3),
            apogee_km=format_value(apogee_m[i] / 1e3),
            inclination_deg=format_value(inclination_deg[i]),
            drag_parameter_m2_kg=format_value(drag_parameter_m2_kg[i]),
            days=format_value(days[i]) if status[i] == "ok" and reentered[i] else "",
            years=format_value(days[i] / 365.25) if status[i] == "ok" and reentered[i] else "",
        )
        if rule_years is not None:
            good = status[i] == "ok"
            record.update(
                complies=str(bool(complies[i])).lower() if good else "",
                new_perigee_km=format_value(new_hp[i] / 1e3) if good else "",
                dv_m_s=format_value(dv[i]) if good else "",
            )
        record["status"] = status[i]
        records.append(record)
    n_ok = sum(1 for s in status if s == "ok")
    return records, BatchSummary(rows=n, ok=n_ok, groups=len(families))


def inclination_log_ratio(scenario: Scenario, reference_deg: float, inclination_deg: FloatArray) -> FloatArray:
    """ln(the air's density at each inclination / at ``reference_deg``) on ``RATIO_HEIGHTS_M``, shape (n, heights).

    Zero for an air that does not depend on the inclination. NRLMSIS is averaged over the
    year at every ``ANCHOR_STEP_DEG`` spanning the inclinations, in one call, and its
    logarithm interpolated in inclination by a cubic spline.
    """
    inclination = np.asarray(inclination_deg, dtype=np.float64)
    zero = np.zeros((inclination.size, RATIO_HEIGHTS_M.size))
    if not scenario.air.depends_on_inclination:
        return zero
    anchors = inclination_anchors(inclination, reference_deg)
    if anchors.size < 2:
        return zero
    # The chunks' nodes (6 x 6): against 12 x 6, ln ratio within 2e-4 at 150-1200 km.
    rho = scenario.air.mean_density_over_inclinations_kg_m3(RATIO_HEIGHTS_M, anchors, **RATIO_NODES)
    return np.asarray(inclination_basis(anchors, inclination, reference_deg) @ np.log(rho), dtype=np.float64)


def spread_lifetime_days(
    curves: UniversalCurves,
    scenario: Scenario,
    reference_deg: float,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    drag_parameter_m2_kg: FloatArray,
) -> FloatArray:
    """Days to re-entry on the curves of ``reference_deg`` with each row's density multiplier along its decay.

    Row k's multiplier at an orbit is its profile's (the reference's times
    exp(``log_ratio[k]``) at each height) over the reference's: for near-circular
    rows (apogee at most `SPREAD_MAX_SPAN_M` above perigee) the ratio weighted over
    the orbit (`orbit_ratio`), for wider rows the ratio of the rates at which the life
    left falls (``_life_rate_ratio``); in co-rotating air times the drag of the air's
    speed at the perigee, ((v_p - Omega r_p cos i) / (v_p - Omega r_p cos i_ref))^2.
    The time is Int dW / (g c s) along the reference curve, by the trapezoidal rule at
    `PATH_NODES` (`WIDE_PATH_NODES`) equal steps of tau; with s = 1 it is the curves'
    own lifetime exactly.
    """
    perigee_m, apogee_m = np.asarray(perigee_m, dtype=np.float64), np.asarray(apogee_m, dtype=np.float64)
    days = np.empty(perigee_m.size)
    wide = apogee_m - perigee_m > SPREAD_MAX_SPAN_M
    for rows, nodes in ((np.flatnonzero(~wide), PATH_NODES), (np.flatnonzero(wide), WIDE_PATH_NODES)):
        if rows.size:
            days[rows] = _spread_days(
                curves,
                scenario,
                reference_deg,
                log_ratio[rows],
                np.asarray(inclination_deg, dtype=np.float64)[rows],
                perigee_m[rows],
                apogee_m[rows],
                np.asarray(drag_parameter_m2_kg, dtype=np.float64)[rows],
                nodes,
                wide=nodes == WIDE_PATH_NODES,
            )
    return days


def _spread_days(
    curves: UniversalCurves,
    scenario: Scenario,
    reference_deg: float,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    drag_parameter_m2_kg: FloatArray,
    nodes: int,
    *,
    wide: bool,
) -> FloatArray:
    """`spread_lifetime_days` of rows all near-circular or all wide (``wide``), at ``nodes`` steps."""
    point = curves.locate(perigee_m, apogee_m)
    steps = np.linspace(0.0, 1.0, nodes + 1)
    tau = point.tau[:, None] * steps[None, :]
    label = np.broadcast_to(point.label[:, None], tau.shape)
    hp, ha, q = curves.at(label, tau)
    weighted = q * (NU_REF * np.expm1(tau))
    if wide:
        ratio = _life_rate_ratio(curves, log_ratio, inclination_deg, hp, ha, weighted)
    else:
        log_value, log_slope = interpolate_rows_with_slope(log_ratio, RATIO_HEIGHTS_M, hp)
        ratio = np.exp(log_value)
        if scenario.air.depends_on_inclination:
            from orbit_env.decay.chunked import log_density_slope_per_m
            from orbit_env.physics.atmosphere.msis import ALTITUDE_GRID_M, MsisAtmosphere

            atmosphere = curves.model.atmosphere
            assert isinstance(atmosphere, MsisAtmosphere)
            density_slope = np.interp(hp, ALTITUDE_GRID_M, log_density_slope_per_m(atmosphere))
            ratio = orbit_ratio(ratio, log_slope, density_slope, hp, ha)
    if scenario.rotating_atmosphere and not wide:  # the wide rows' rates carry their air's speed
        ratio = ratio * corotation_factor(hp, ha, np.asarray(inclination_deg, dtype=np.float64)[:, None], reference_deg)
    inverse = 1.0 / ratio
    time_gcs = np.sum(np.diff(weighted, axis=1) * 0.5 * (inverse[:, 1:] + inverse[:, :-1]), axis=1)
    return days_from_weighted_s(time_gcs, drag_parameter_m2_kg, scenario.density_scale)


def _life_rate_ratio(
    curves: UniversalCurves,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    weighted: FloatArray,
) -> FloatArray:
    """dW/dnu of each row's air over the reference's, at orbits (rows, nodes) on the reference curves.

    `orbit_env.decay.chunked.life_rate_ratio` with `SPREAD_QUADRATURE_POINTS` anomalies,
    in co-rotating air at the row's inclination. One multiplier of the density at the
    perigee (`orbit_ratio`) moves p and e alike, where a profile of another shape moves
    the eccentricity otherwise: on orbits up to 1500 km wide it came out up to 2.3% off
    a family per inclination, this within 0.46% (docs/validation-modern.md, section 7).
    At re-entry (the first node) the next node's ratio.
    """
    ratio = life_rate_ratio(
        curves,
        log_ratio,
        RATIO_HEIGHTS_M,
        perigee_m,
        apogee_m,
        quadrature_points=SPREAD_QUADRATURE_POINTS,
        inclination_deg=inclination_deg,
        weighted=weighted,
    )
    ratio[:, 0] = ratio[:, 1]
    return ratio


def format_value(value: float) -> str:
    """A number as the results file writes it: six significant digits, empty if not finite."""
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


@contextmanager
def atomic_text(path: str | Path) -> Iterator[TextIO]:
    """A text file written whole or not at all: a temporary file beside ``path``, renamed to it once complete.

    A reader never sees half a file, and a failure leaves any earlier file as it was.
    """
    out = Path(path)
    handle = tempfile.NamedTemporaryFile(
        "w", newline="", encoding="utf-8", dir=out.parent, prefix=f".{out.name}.", suffix=".tmp", delete=False
    )
    try:
        with handle:
            yield handle
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(handle.name, 0o666 & ~umask)  # a temporary file is private; the results are not
        os.replace(handle.name, out)
    except BaseException:
        Path(handle.name).unlink(missing_ok=True)
        raise


def write_records(path: str | Path, records: list[dict[str, Any]]) -> None:
    """Write output records as CSV with LF line endings, atomically (`atomic_text`)."""
    with atomic_text(path) as handle:
        writer = csv.DictWriter(handle, fieldnames=list(records[0]), lineterminator="\n")
        writer.writeheader()
        writer.writerows(records)
