"""The documented re-entries of benchmarks/validate_reentries.py, pinned so they cannot drift silently.

Each prediction is held to the value measured when docs/validation-modern.md was
written (predicted / observed - 1, in the table of section 5) within 3 points.
Why 3: the chunking, binning and curve interpolation were measured to move
lifetimes by 0.1-0.5% (section 3) and GRACE's lifetime moves about twice as much
as the density (C_D +5% gives -10%), so numerical refinements stay inside 3 points
while a change to the physics (the atmosphere's averaging, the drag model, the
solar record, a case's inputs) does not. The issue's bar (+-30%) is asserted
separately, case by case, so a miss cannot be hidden by moving a pinned value.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

pytest.importorskip("pymsis")

SCRIPT = Path(__file__).resolve().parent.parent / "benchmarks" / "validate_reentries.py"


@pytest.fixture(scope="module")
def validation():
    spec = importlib.util.spec_from_file_location("validate_reentries", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look the module up by name
    spec.loader.exec_module(module)
    return module


#: predicted / observed - 1 with the drag model, and its drag coefficient, as measured (docs table).
MEASURED = {
    "GFZ-1": (+0.114, 2.12),
    "Starshine 1": (+0.028, 2.13),
    "Starshine 2": (+0.337, 2.13),
    "Starshine 3": (+0.007, 2.14),
    "GOCE": (-0.053, 3.87),
    "GRACE-2": (+0.056, 3.42),
    "GRACE-1": (+0.042, 3.42),
}
#: Known outside the +-30% bar (docs/validation-modern.md says why).
KNOWN_MISSES = {"Starshine 2"}
#: The quick subset: three cases of three shapes and lives from 3 weeks to 9 months (~6 s).
QUICK = ("Starshine 1", "Starshine 2", "GOCE")


def check(rows):
    for row in rows:
        error = row.model_days / row.observed_days - 1.0
        pinned, cd = MEASURED[row.name]
        assert error == pytest.approx(pinned, abs=0.03), row.name
        assert row.drag_coefficient == pytest.approx(cd, abs=0.01), row.name
        assert (abs(error) <= 0.30) == (row.name not in KNOWN_MISSES), row.name


def test_quick_cases_pinned(validation):
    cases = [c for c in validation.CASES if c.name in QUICK]
    check(validation.run(cases, first_choice=False))


@pytest.mark.slow
def test_all_cases_pinned_and_within_the_bar(validation):
    rows = validation.run(validation.CASES, first_choice=False)
    check(rows)
    # The target: at least three independent satellites within +-30% (GRACE-1/2 are twins).
    independent = {row.name.split("-")[0] for row in rows if abs(row.model_days / row.observed_days - 1) <= 0.30}
    assert len(independent) >= 3, independent
