"""Checks of the real element sets of objects that re-entered uncontrolled (benchmarks/data/reentry_tles).

Every line must carry a valid mod-10 checksum, every set must parse and propagate at its epoch with sgp4, the
catalogue numbers must match objects.csv, the re-entry dates must parse, every object must have at least one set
between 7 days and 3 years before re-entry, and provenance.csv (with sources.csv) must name the source of every set.
"""

import csv
import datetime as dt
from pathlib import Path

import pytest
from sgp4.api import Satrec

DATA = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "reentry_tles"
UTC = dt.UTC
MIN_BEFORE = dt.timedelta(days=7)
MAX_BEFORE = dt.timedelta(days=3 * 365.25)


def checksum_ok(line: str) -> bool:
    """Mod-10 checksum of a TLE line: digits count their value, '-' counts 1, the rest 0."""
    if len(line) != 69 or not line[68].isdigit():
        return False
    total = sum(int(c) if c.isdigit() else (1 if c == "-" else 0) for c in line[:68])
    return total % 10 == int(line[68])


def read_sets(path: Path) -> list[tuple[str, str]]:
    """Two-line sets of a file, in order; an optional name line before a set is skipped."""
    lines = [raw.rstrip("\r\n").rstrip() for raw in path.read_text(encoding="ascii").splitlines()]
    lines = [ln for ln in lines if ln]
    sets, i = [], 0
    while i < len(lines):
        if lines[i].startswith("1 ") and i + 1 < len(lines) and lines[i + 1].startswith("2 "):
            sets.append((lines[i], lines[i + 1]))
            i += 2
        elif not lines[i].startswith(("1 ", "2 ")):
            i += 1  # name line
        else:
            raise AssertionError(f"{path.name}: unpaired element line {i + 1}: {lines[i]!r}")
    return sets


def epoch(line1: str) -> dt.datetime:
    """Epoch of a set from line 1 (two-digit year: 57-99 -> 19xx, 00-56 -> 20xx)."""
    yy = int(line1[18:20])
    year = yy + (1900 if yy >= 57 else 2000)
    return dt.datetime(year, 1, 1, tzinfo=UTC) + dt.timedelta(days=float(line1[20:32]) - 1)


def reentry_bounds(text: str) -> tuple[dt.datetime, dt.datetime]:
    """Earliest and latest re-entry instants a value allows: a bare date means any time in that UTC day."""
    if "T" in text:
        when = dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
        assert when.tzinfo is not None, text
        return when, when
    day = dt.datetime.fromisoformat(text).replace(tzinfo=UTC)
    return day, day + dt.timedelta(days=1)


def objects() -> list[dict[str, str]]:
    with (DATA / "objects.csv").open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def tle_file(norad: str) -> Path:
    found = sorted(DATA.glob(f"{norad}_*.tle"))
    assert len(found) == 1, f"expected one file {norad}_*.tle, found {found}"
    return found[0]


OBJECTS = objects()
IDS = [row["norad"] for row in OBJECTS]


def test_every_file_has_a_row_and_every_row_a_file():
    files = {p.name.split("_", 1)[0] for p in DATA.glob("*.tle")}
    assert files == set(IDS)
    assert len(IDS) == len(set(IDS))


def test_checksum_detects_corruption():
    line = "1 37820U 11053A   18046.58112813  .00094150  12300-4  13743-3 0  9998"
    assert checksum_ok(line)
    assert not checksum_ok(line[:-1] + "7")
    assert not checksum_ok(line.replace("46.58", "46.59"))


@pytest.mark.parametrize("norad", IDS)
def test_lines_checksums_and_catalogue_numbers(norad):
    sets = read_sets(tle_file(norad))
    assert sets
    for l1, l2 in sets:
        assert checksum_ok(l1), l1
        assert checksum_ok(l2), l2
        assert int(l1[2:7]) == int(norad), l1
        assert int(l2[2:7]) == int(norad), l2


@pytest.mark.parametrize("norad", IDS)
def test_sets_parse_and_propagate_with_sgp4(norad):
    for l1, l2 in read_sets(tle_file(norad)):
        sat = Satrec.twoline2rv(l1, l2)
        assert sat.error == 0, l1
        err, _, _ = sat.sgp4(sat.jdsatepoch, sat.jdsatepochF)
        assert err == 0, (err, l1)


@pytest.mark.parametrize("row", OBJECTS, ids=IDS)
def test_set_in_window_and_sorted(row):
    earliest, latest = reentry_bounds(row["reentry_utc"])
    epochs = [epoch(l1) for l1, _ in read_sets(tle_file(row["norad"]))]
    assert epochs == sorted(epochs), "sets must be oldest first"
    usable = [e for e in epochs if latest - MAX_BEFORE <= e <= earliest - MIN_BEFORE]
    assert usable, f"{row['norad']}: no set between 7 days and 3 years before {row['reentry_utc']}"
    assert all(e < earliest for e in epochs), "a set after the re-entry"


@pytest.mark.parametrize("row", OBJECTS, ids=IDS)
def test_row_fields(row):
    reentry_bounds(row["reentry_utc"])
    assert 1957 < dt.date.fromisoformat(row["reentry_utc"][:10]).year
    for field in ("name", "cospar", "reentry_source", "tle_source", "notes"):
        assert row[field].strip(), field
    if row["reentry_uncertainty_hours"]:
        assert float(row["reentry_uncertainty_hours"]) > 0
    if row["mass_kg"] or row["area_m2"]:
        assert row["mass_area_source"].strip()


def test_provenance_accounts_for_every_set():
    with (DATA / "sources.csv").open(newline="", encoding="utf-8") as f:
        sources = {row["source_id"]: row for row in csv.DictReader(f)}
    for row in sources.values():
        assert row["repo"].count("/") == 1 and row["path"], row
        assert len(row["commit"]) == 40 and int(row["commit"], 16) >= 0, row
    with (DATA / "provenance.csv").open(newline="", encoding="utf-8") as f:
        prov = list(csv.DictReader(f))
    listed: dict[str, list[str]] = {}
    for p in prov:
        assert p["source_id"] in sources, p
        listed.setdefault(p["norad"], []).append(p["epoch_field"])
    for norad in IDS:
        in_file = [l1[18:32] for l1, _ in read_sets(tle_file(norad))]
        assert listed.get(norad) == in_file, norad
