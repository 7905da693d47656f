"""A catalogue's lifetimes with their uncertainty: each row's Monte Carlo band, seeded by the row alone.

Units: heights in m above the package's 6371 km sphere, as in `orbit_env.analysis.catalogue`.

Every valid row gets its nominal lifetime (`batch_lifetimes`, a curve family per
inclination group, so that no row's lifetime depends on the other rows) and its samples
from `orbit_env.analysis.uncertainty.lifetime_spread`, the one Monte Carlo of
``orbit-env lifetime --uncertainty``, at the same group's inclination (where the air depends
on it: `inclination_group`; a family per value typed had cost 4.8 MB of cache and a fraction
of a second each, per distinct inclination of a catalogue's rows). The samples are seeded by `row_seed`: the base seed
and the row's key (its name or id, orbit, drag parameter and inclination) hashed with
SHA-256. A row's numbers are therefore the same in any file, order, chunk or process, and
the single command with ``--seed`` set to the row's ``uncertainty_seed`` (and ``--inclination``
to its group's) draws the same samples.

Columns added after the nominal ones: ``days_p5``, ``days_p50``, ``days_p95`` (empty where
that share of samples is still in orbit where the time-stepped path stops), with a date
``reentry_date_p5``, ``reentry_date_p50``, ``reentry_date_p95``, with a rule
``compliance_probability`` and ``complies_with_confidence`` (the verdict at
`orbit_env.analysis.uncertainty.RULE_CONFIDENCE`), then ``uncertainty_seed``.
"""

from __future__ import annotations

import hashlib
import math
from typing import Any

import numpy as np

from orbit_env.analysis.catalogue import batch_lifetimes, inclination_group, row_start_days
from orbit_env.analysis.catalogue_io import BatchOrbits, format_value
from orbit_env.analysis.scenario import Scenario
from orbit_env.analysis.uncertainty import PERCENTILES, lifetime_spread, spread_report

#: Row seeds are below 2**52, so that ``--seed`` (checked as a float) gives them back exactly.
SEED_BITS = 52


def row_key(
    row: dict[str, str], perigee_m: float, apogee_m: float, drag_parameter_m2_kg: float, inclination_deg: float
) -> str:
    """What identifies a row for its seed: its name and id cells, and the numbers its lifetime is computed from."""
    numbers = (perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg)
    return "|".join([row.get("name", ""), row.get("id", ""), *(repr(float(x)) for x in numbers)])


def row_seed(seed: int, key: str) -> int:
    """The seed of a row: SHA-256 of the base seed and the row's key, `SEED_BITS` bits of it."""
    digest = hashlib.sha256(f"{seed}\n{key}".encode()).digest()
    return int.from_bytes(digest[:8], "big") >> (64 - SEED_BITS)


def uncertain_lifetimes(
    orbits: BatchOrbits,
    scenario: Scenario,
    *,
    samples: int,
    seed: int,
    rule_years: float | None = None,
    dated: bool = False,
    own_epochs: bool = False,
) -> list[dict[str, Any]]:
    """The batch's records (`batch_lifetimes`) with each valid row's percentiles and rule probability.

    Args:
        orbits: The rows.
        scenario: The air.
        samples: Samples per row.
        seed: The base seed (`row_seed`).
        rule_years: A disposal rule: add its probability and verdict.
        dated: Add the re-entry dates' columns (the air has a date, or the rows have epochs);
            a row's dates count from the air's epoch, else from its own.
        own_epochs: Each row's air (a dated ``scenario``) starts at the row's own epoch
            (`batch_lifetimes`'s ``epoch_days``: a batch of element sets), and so do its dates.
    """
    records, _ = batch_lifetimes(
        orbits.rows,
        orbits.perigee_m,
        orbits.apogee_m,
        orbits.drag_parameter_m2_kg,
        orbits.inclination_deg,
        list(orbits.status),
        scenario,
        rule_years=rule_years,
        progress=False,
        exact_groups=True,
        # Dated: the nominal re-entry's epoch and date columns, as a batch without bands has them.
        epoch_days=row_start_days(orbits, scenario, own_epochs),
    )
    for i, record in enumerate(records):
        status = record.pop("status")
        columns = {f"days_p{p}": "" for p in PERCENTILES}
        if dated:
            columns.update({f"reentry_date_p{p}": "" for p in PERCENTILES})
        if rule_years is not None:
            columns.update(compliance_probability="", complies_with_confidence="")
        columns["uncertainty_seed"] = ""
        if status == "ok":
            air = scenario.at_epoch(float(orbits.epoch_days[i])) if own_epochs else scenario
            columns.update(_row_columns(orbits, i, air, samples, seed, rule_years, dated))
        record.update(columns, status=status)
    return records


def _row_columns(
    orbits: BatchOrbits,
    i: int,
    scenario: Scenario,
    samples: int,
    seed: int,
    rule_years: float | None,
    dated: bool,
) -> dict[str, str]:
    """Row ``i``'s uncertainty columns."""
    inputs = (
        float(orbits.perigee_m[i]),
        float(orbits.apogee_m[i]),
        float(orbits.drag_parameter_m2_kg[i]),
        float(orbits.inclination_deg[i]),
    )
    this_seed = row_seed(seed, row_key(orbits.rows[i], *inputs))
    sigma = float(orbits.drag_sigma[i])
    # At its group's inclination, as its nominal lifetime: a family per 1-degree group, not per value typed.
    spread = lifetime_spread(
        *inputs[:3],
        scenario,
        float(inclination_group(inputs[3])) if scenario.depends_on_inclination else inputs[3],
        samples=samples,
        seed=this_seed,
        **({} if math.isnan(sigma) else {"drag_sigma": sigma}),
    )
    epoch = scenario.epoch_days
    if epoch is None and np.isfinite(orbits.epoch_days[i]):
        epoch = float(orbits.epoch_days[i])
    report = spread_report(spread, epoch if dated else None, rule_years)
    columns = {f"days_p{p}": _text(report["days_percentiles"][str(p)]) for p in PERCENTILES}
    for p, date in report.get("reentry_date_percentiles", {}).items():
        columns[f"reentry_date_p{p}"] = date or ""
    if rule_years is not None:
        columns["compliance_probability"] = format_value(report["compliance_probability"])
        columns["complies_with_confidence"] = str(report["complies_with_confidence"]).lower()
    columns["uncertainty_seed"] = str(this_seed)
    return columns


def _text(days: float | None) -> str:
    return "" if days is None else format_value(days)
