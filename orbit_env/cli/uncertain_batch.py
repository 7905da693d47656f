"""``orbit-env lifetime --batch FILE --uncertainty``: a catalogue's bands in chunks, over processes or Ray, resumable.

The rows' numbers come from `orbit_env.analysis.catalogue_uncertainty` (each row seeded
by itself), the chunks, processes and parts from `orbit_env.analysis.catalogue_parts`.
The fingerprint of the parts covers the batch file's and the solar table's bytes, the
package's source code and every option but those in `NOT_IN_FINGERPRINT`: the same
command resumes, another one is refused (``--force`` deletes the other run's parts and
starts this one).
"""

from __future__ import annotations

import argparse
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from orbit_env.analysis.catalogue_io import BatchOrbits
from orbit_env.analysis.catalogue_parts import JoinedParts, chunk_rows, fingerprint, require_ray, run_in_parts
from orbit_env.analysis.catalogue_uncertainty import uncertain_lifetimes
from orbit_env.analysis.scenario import Scenario
from orbit_env.analysis.uncertainty import check_samples
from orbit_env.cache import source_digest
from orbit_env.checks import check_number
from orbit_env.cli.orbit_inputs import records_in_reference, resolve_uncertainty_options

#: Options that change no result (where the results go, how they are shown, where they run), and the batch
#: file's element sets as `orbit_inputs.prepare` read them (the file's bytes are in the fingerprint).
NOT_IN_FINGERPRINT = frozenset(
    {"out", "force", "no_progress", "workers", "address", "no_cache", "func", "batch_sets", "batch_bad_sets"}
    # The input files' bytes are hashed, not how their paths are spelled (./a.csv is a.csv).
    | {"batch", "solar_csv"}
)


@dataclass(frozen=True)
class ChunkRecords:
    """The records of rows ``start`` to ``stop`` of a batch: what each worker process is handed once."""

    orbits: BatchOrbits
    scenario: Scenario
    samples: int
    seed: int
    rule_years: float | None
    dated: bool
    height_reference: str
    own_epochs: bool = False

    def __call__(self, start: int, stop: int) -> list[dict[str, Any]]:
        """The records of rows ``start`` to ``stop``, heights above the command's reference."""
        records = uncertain_lifetimes(
            self.orbits.part(start, stop),
            self.scenario,
            samples=self.samples,
            seed=self.seed,
            rule_years=self.rule_years,
            dated=self.dated,
            own_epochs=self.own_epochs,
        )
        return records_in_reference(records, self.height_reference)


def check_options(args: argparse.Namespace) -> None:
    """Refuse ``--workers`` without ``--uncertainty``, ``--address`` without ``--batch --uncertainty``; check the rest.

    Raises:
        ValueError: as said.
    """
    resolve_uncertainty_options(args)
    if args.workers is not None and not args.uncertainty:
        raise ValueError("--workers goes with --uncertainty (its solar nodes, or with --batch its chunks of rows)")
    if args.address is not None and not (args.batch and args.uncertainty):
        raise ValueError("--address goes with --batch FILE --uncertainty (the rows' bands run in chunks)")
    if args.workers is not None and args.address is not None:
        raise ValueError("give --workers or --address, not both (on Ray, the cluster's CPUs run the chunks)")
    if args.address is not None:
        require_ray()
    if args.batch and args.uncertainty:
        check_samples(args.samples)
        check_number(args.seed, "seed", low=0, integer=True)
        if args.rule is not None:
            check_number(args.rule, "rule_years", unit="years", low=0.0, low_inclusive=False)


def run(args: argparse.Namespace, orbits: BatchOrbits, scenario: Scenario) -> JoinedParts:
    """Compute the bands of every row of ``orbits`` in ``scenario`` (heights above the sphere); write ``args.out``."""
    workers = args.workers
    lines = []
    if workers is None and args.address is None:
        workers = os.cpu_count() or 1
        lines.append(f"workers: {workers} (the default: all cores; --workers N to change)")

    def report(line: str) -> None:  # once the parts folder is checked: an error comes alone
        print(*lines, line, sep="\n")

    size = chunk_rows(len(orbits.rows), scenario.time_varying)
    files = [args.batch] + ([args.solar_csv] if getattr(args, "solar_csv", None) else [])
    options = {name: value for name, value in sorted(vars(args).items()) if name not in NOT_IN_FINGERPRINT}
    options.update(source=source_digest(), chunk_rows=size)  # parts of other code are not reused
    job = ChunkRecords(
        orbits,
        scenario,
        int(args.samples),
        int(args.seed),
        None if args.rule is None else float(args.rule),
        scenario.epoch_days is not None or bool(np.isfinite(orbits.epoch_days).any()),
        args.height_reference,
        bool(getattr(args, "rows_own_epochs", False)),
    )
    return run_in_parts(
        args.out,
        fingerprint(files, options),
        len(orbits.rows),
        size,
        job,
        workers=workers or 1,
        address=args.address,
        progress=not args.no_progress,
        restart=args.force,
        report=report,
    )
