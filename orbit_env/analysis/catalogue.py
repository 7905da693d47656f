"""Lifetimes of a catalogue of satellites (a CSV file's rows), through the universal curves.

The file in and out: `orbit_env.analysis.catalogue_io`. With NRLMSIS the profile depends
on the inclination (and in co-rotating air the drag does): rows are grouped by
inclination rounded to ``INCLINATION_STEP_DEG`` (1 deg moves a lifetime by about 0.5%,
measured at 50 deg and 400 km, so rounding costs at most 0.25%). Up to ``MAX_FAMILIES``
groups get a curve family each (0.9 s to build). In a catalogue spread over more groups,
every row takes one family, that of the most common inclination, and its own
inclination as a density multiplier along its decay
(`orbit_env.analysis.inclination_spread`). A disposal rule searches its lowered perigees
on the same family (`check_disposal_rule` with these lifetimes). A dated catalogue (the
time-stepped path) spread over more groups also takes one family, that of the most
common group, through its chunks, each row's inclination a density multiplier in every
chunk (`orbit_env.decay.chunked.propagate`), and the rule's search on those lifetimes.
Rows of different dates (a batch of element sets, each from its own epoch) share one
time-stepped run from the first, each joining it at its own date (``start_days``).
The paper's and the exponential law in still air do not depend on the inclination: one
group.
"""

from __future__ import annotations

import contextlib
import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.analysis.catalogue_io import DRAG_SOURCE_KEY, ID_COLUMNS, LINE_KEY, format_value
from orbit_env.analysis.disposal import PASSES, check_disposal_rule
from orbit_env.analysis.inclination_spread import inclination_log_ratio, spread_lifetime_days
from orbit_env.analysis.lifetime import (
    MAX_LIFETIME_YEARS,
    check_lifetime_days,
)
from orbit_env.analysis.scenario import Scenario
from orbit_env.constants import DAYS_PER_YEAR

FloatArray = NDArray[np.float64]

#: Inclination bins of NRLMSIS batches [deg].
INCLINATION_STEP_DEG = 1.0
#: A catalogue with more inclination groups than this takes one curve family and a density ratio.
MAX_FAMILIES = 2
#: Satellites per progress-bar step on the fixed-profile path.
BLOCK = 20_000


@dataclass(frozen=True)
class BatchSummary:
    """What a batch did: rows read, rows with a lifetime, groups (curve families) used."""

    rows: int
    ok: int
    groups: int


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
    bar: Any = None,
    start_days: FloatArray | None = None,
) -> float:
    """Lifetimes (and the rule) of ``members`` on the time-stepped path, one family; returns its inclination.

    The family is that of the most common inclination group; every row keeps its own
    inclination as a density multiplier (`orbit_env.decay.chunked.propagate`). ``bar`` (tqdm)
    counts the satellites as they re-enter, and all of them at the end. ``start_days``: each
    row's start (`batch_lifetimes`).
    """
    perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg = inputs
    days, reentered = outputs[:2]
    reference = _most_common(group_of[members])
    c, own = drag_parameter_m2_kg[members], inclination_deg[members]
    start = None if start_days is None else start_days[members]
    if rule_years is None:
        days[members], reentered[members] = scenario.lifetime_days(
            perigee_m[members],
            apogee_m[members],
            c,
            reference,
            own_inclination_deg=own,
            progress=None if bar is None else _counting(bar, members.size),
            start_days=start,
        )
        return reference

    decays = None if bar is None else _rule_progress(_counting(bar, members.size))

    def lifetimes(hp: FloatArray, ha: FloatArray, which: NDArray[np.intp]) -> Any:
        return scenario.lifetime_days(
            hp,
            ha,
            c[which],
            reference,
            max_days=cap_days,
            own_inclination_deg=own[which],
            progress=None if decays is None else decays(),
            start_days=None if start is None else start[which],
        )

    _store_check(outputs, members, check_disposal_rule(perigee_m[members], apogee_m[members], rule_years, lifetimes))
    return reference


def _counting(bar: Any, size: int) -> Callable[[float], None]:
    """``size`` satellites' share of ``bar`` (tqdm), from where it stands: called with the share done (1.0: all).

    A `propagate` progress callback (the share re-entered), or called once with 1.0 when they are done.
    """
    start = bar.n

    def reentering(fraction: float) -> None:
        bar.update(start + int(fraction * size) - bar.n)

    return reentering


def _rule_progress(counted: Callable[[float], None]) -> Callable[[], Callable[[float], None]]:
    """The progress callbacks of a rule check's decays, each its share of ``counted`` (see `_counting`).

    `check_disposal_rule` decays the orbits once, then once a pass of its search (`disposal.PASSES`):
    each call of the returned function gives the next decay's callback, which moves the bar over that
    decay's equal share as its satellites re-enter (a dated catalogue's bar had stood still until the rule's
    end: 7 s for 1000 rows, minutes for a large one).
    """
    calls = itertools.count()

    def next_decay() -> Callable[[float], None]:
        share = next(calls)
        return lambda fraction: counted((share + fraction) / (1 + PASSES))

    return next_decay


def _store_check(
    outputs: tuple[FloatArray, NDArray[np.bool_], NDArray[np.bool_], FloatArray, FloatArray],
    rows: NDArray[np.intp],
    check: Any,
) -> None:
    """Write a rule check's lifetimes, verdicts, lowered perigees and burns into the batch's columns at ``rows``."""
    days, reentered, complies, new_hp, dv = outputs
    days[rows], reentered[rows] = check.lifetime_days, check.reentered
    complies[rows], new_hp[rows], dv[rows] = check.complies, check.new_perigee_m, check.dv_m_s


def row_start_days(orbits: Any, scenario: Scenario, own_epochs: bool) -> FloatArray | None:
    """`batch_lifetimes`'s ``epoch_days`` of a batch: each row's start, or None for an undated batch.

    Each row's own epoch with ``own_epochs`` (a batch of element sets), else the scenario's for every row
    when it is dated (its rows then gain the nominal dates).
    """
    if own_epochs:
        return orbits.epoch_days
    return None if scenario.epoch_days is None else np.full(len(orbits.rows), scenario.epoch_days)


def inclination_group(inclination_deg: ArrayLike) -> FloatArray:
    """The inclination a row's decay is computed at: its own rounded to `INCLINATION_STEP_DEG` (its group)."""
    return np.round(np.asarray(inclination_deg, dtype=np.float64) / INCLINATION_STEP_DEG) * INCLINATION_STEP_DEG


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
    epoch_days: FloatArray | None = None,
    bar: Any = None,
    start_days: FloatArray | None = None,
) -> tuple[list[dict[str, Any]], BatchSummary]:
    """Lifetimes (and the rule check) of every valid row; output records in input order.

    ``exact_groups`` builds a curve family per inclination group however many there
    are (the reference the one-family path of a spread catalogue is measured against).
    ``epoch_days`` (a dated ``scenario`` only): each row's own start [unix days], the
    epoch of its object's latest element set; the scenario moves to the first of them
    (`Scenario.at_epoch`), every row starts at its own (``start_days``), and the records
    gain ``epoch`` and ``reentry_date``. ``start_days`` (a dated ``scenario`` only): each
    row's start, days after the scenario's epoch: the rows of all dates share the chunks
    (`orbit_env.decay.chunked.propagate`). ``bar``: a progress bar (tqdm) to move instead of
    one of its own (``progress`` is then unused).
    """
    if epoch_days is not None:
        return _from_own_epochs(
            rows,
            (perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg),
            status,
            scenario,
            epoch_days,
            rule_years=rule_years,
            progress=progress,
            exact_groups=exact_groups,
        )
    n = len(rows)
    ok = np.array([s == "ok" for s in status])
    days = np.full(n, np.nan)
    reentered = np.zeros(n, dtype=bool)
    complies = np.zeros(n, dtype=bool)
    new_hp = np.full(n, np.nan)
    dv = np.full(n, np.nan)
    depends_on_inclination = scenario.depends_on_inclination
    if depends_on_inclination:
        group_of = inclination_group(inclination_deg)
    else:
        group_of = np.zeros(n)
    groups = np.unique(group_of[ok])
    cap_days = None if rule_years is None else (rule_years + 1.0) * DAYS_PER_YEAR
    one_family = depends_on_inclination and not exact_groups and groups.size > MAX_FAMILIES
    by_groups = ok.copy()
    families: set[float] = set()
    inputs = (perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg)
    outputs = (days, reentered, complies, new_hp, dv)
    from tqdm import tqdm  # here, not at the top: a command that runs no catalogue does not import it

    own = tqdm(total=int(ok.sum()), disable=not progress, unit="sat", desc="lifetimes") if bar is None else None
    with own if own is not None else contextlib.nullcontext(bar) as bar:
        if one_family:
            members = np.flatnonzero(ok)
            if scenario.time_varying:
                counted = _counting(bar, members.size)
                families.add(
                    _stepped_spread(scenario, members, group_of, inputs, rule_years, cap_days, outputs, bar, start_days)
                )
                counted(1.0)
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
                counted = _counting(bar, block.size)
                start = None if start_days is None else start_days[block]
                if rule_years is None:
                    moving = counted if scenario.time_varying else None
                    d, r = scenario.lifetime_days(
                        perigee_m[block],
                        apogee_m[block],
                        drag_parameter_m2_kg[block],
                        inclination,
                        progress=moving,
                        start_days=start,
                    )
                    days[block], reentered[block] = d, r
                else:
                    c_block = drag_parameter_m2_kg[block]
                    decays = _rule_progress(counted) if scenario.time_varying else None

                    def lifetimes(hp: FloatArray, ha: FloatArray, which: NDArray[np.intp]) -> Any:
                        moving = None if decays is None else decays()  # noqa: B023
                        c = c_block[which]  # noqa: B023
                        begin = None if start is None else start[which]  # noqa: B023
                        angle = inclination  # noqa: B023
                        return scenario.lifetime_days(
                            hp, ha, c, angle, max_days=cap_days, progress=moving, start_days=begin
                        )

                    _store_check(
                        outputs, block, check_disposal_rule(perigee_m[block], apogee_m[block], rule_years, lifetimes)
                    )
                counted(1.0)
    for i in np.flatnonzero(ok & ~reentered):
        if rule_years is None:
            why = f"still in orbit after {scenario.max_years:g} years (the time-stepped path stops there)"
            line = rows[i].get(LINE_KEY)
            status[i] = f"line {line}: {why}" if line else why
    for i in np.flatnonzero(ok & reentered & ~(days <= MAX_LIFETIME_YEARS * DAYS_PER_YEAR)):
        try:
            check_lifetime_days(float(days[i]))
        except ValueError as error:
            line = rows[i].get(LINE_KEY)
            status[i] = f"line {line}: {error}" if line else str(error)
    records = []
    for i, row in enumerate(rows):
        record: dict[str, Any] = {key: row[key] for key in ID_COLUMNS if key in row}
        record.update(
            perigee_km=format_value(perigee_m[i] / 1e3),
            apogee_km=format_value(apogee_m[i] / 1e3),
            # A number the row was refused on (or never read, the row refused before it) as the row gave it.
            inclination_deg=format_value(inclination_deg[i]) or _given_number(row, "inclination_deg"),
            drag_parameter_m2_kg=format_value(drag_parameter_m2_kg[i]) or _given_number(row, "drag_parameter_m2_kg"),
        )
        if DRAG_SOURCE_KEY in row:  # element sets: where the row's drag came from
            record[DRAG_SOURCE_KEY] = row[DRAG_SOURCE_KEY]
        record.update(
            days=format_value(days[i]) if status[i] == "ok" and reentered[i] else "",
            years=format_value(days[i] / DAYS_PER_YEAR) if status[i] == "ok" and reentered[i] else "",
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


def _given_number(row: dict[str, str], key: str) -> str:
    """A row's cell as it gave it if it is a finite number (a refused value the status names), else empty."""
    text = row.get(key, "")
    try:
        return format_value(float(text))
    except ValueError:
        return ""


def _from_own_epochs(
    rows: Sequence[dict[str, str]],
    inputs: tuple[FloatArray, FloatArray, FloatArray, FloatArray],
    status: list[str],
    scenario: Scenario,
    epoch_days: FloatArray,
    **options: Any,
) -> tuple[list[dict[str, Any]], BatchSummary]:
    """`batch_lifetimes` of every row from its own date, in the scenario moved to the first; records in input order.

    The rows of all dates share one run (`batch_lifetimes`'s ``start_days``): a snapshot of element
    sets at as many epochs as objects costs one catalogue's run, not one per object.
    """
    from orbit_env.analysis.lifetime import iso_datetime

    valid = np.array([s == "ok" for s in status], dtype=bool) & np.isfinite(epoch_days)
    air, start_days = scenario, None
    if valid.any():
        first = float(np.min(epoch_days[valid]))
        air, start_days = scenario.at_epoch(first), np.where(valid, epoch_days - first, 0.0)
    records, summary = batch_lifetimes(rows, *inputs, status, air, start_days=start_days, **options)
    for i, record in enumerate(records):
        days = record.get("days", "")
        record_date = {"epoch": iso_datetime(float(epoch_days[i])) if np.isfinite(epoch_days[i]) else ""}
        record_date["reentry_date"] = iso_datetime(float(epoch_days[i]) + float(days)) if days else ""
        status_i = record.pop("status")
        records[i] = {**record, **record_date, "status": status_i}
    return records, summary
