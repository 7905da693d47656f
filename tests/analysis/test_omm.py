"""Element sets as OMM records (JSON, CSV, XML): the same orbits, drag and lifetimes as the same sets as TLEs.

The one set read in all forms is MARIO (catalogue number 55123) as CelesTrak served it in TLE, XML and CSV
form (``gp.php?CATNR=55123``), copied in sgp4's own tests (sgp4 2.27, ``sgp4/tests.py``, MIT licence; read
from the installed package here, not copied). Its JSON forms are that CSV record serialised: every value
as text (as Space-Track writes JSON) and the numbers as numbers (as CelesTrak writes it). The histories
are real TLE files of this repository (benchmarks/data/reentry_tles, sources.csv) written as OMM records
by sgp4's exporter (``sgp4.exporter.export_omm``): a change of form, the same elements.
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from orbit_env.analysis.elements import holds_element_sets, parse_element_sets, read_tle
from orbit_env.cli import main

sgp4_tests = pytest.importorskip("sgp4.tests")
SETS = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "reentry_tles"
#: ElementSet's fields that say what the set is (not where it stood in its file).
ELEMENTS = ("epoch_days", "semi_major_axis_km", "eccentricity", "inclination_deg", "bstar_per_earth_radius")


def mario_records() -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(sgp4_tests.MARIO_CSV)))


def as_numbers(record: dict[str, str]) -> dict[str, object]:
    text = ("OBJECT_NAME", "OBJECT_ID", "EPOCH", "CLASSIFICATION_TYPE")
    return {
        key: value if key in text else json.loads(value if value[0] != "." else "0" + value)
        for key, value in record.items()
    }


def test_one_set_reads_the_same_as_tle_xml_csv_and_json():
    (tle,) = parse_element_sets(sgp4_tests.MARIO_TLE, "mario.tle")
    forms = {
        "xml": sgp4_tests.MARIO_XML,
        "csv": sgp4_tests.MARIO_CSV,
        "json, values as text": json.dumps(mario_records()),
        "json, numbers": json.dumps([as_numbers(r) for r in mario_records()]),
        "json, one object": json.dumps(as_numbers(mario_records()[0])),
    }
    for form, text in forms.items():
        (omm,) = parse_element_sets(text, form)
        for field in ELEMENTS:
            assert getattr(omm, field) == getattr(tle, field), (form, field)
        assert omm.ndot_rev_day2 == tle.ndot_rev_day2 == pytest.approx(2 * 0.00787702, rel=1e-12)
        assert (omm.name, omm.catalogue_number) == ("MARIO", "55123")
    assert parse_element_sets(sgp4_tests.MARIO_CSV, "m.csv")[0].where == "line 2"
    assert parse_element_sets(sgp4_tests.MARIO_XML, "m.xml")[0].where == "record 1"


def omm_file(tle_files: list[str], path: Path) -> Path:
    """The sets of these TLE files as one OMM JSON file (sgp4's exporter), oldest first per file."""
    from sgp4.api import Satrec
    from sgp4.exporter import export_omm

    records = []
    for name in tle_files:
        lines = [line.strip() for line in (SETS / name).read_text().splitlines() if line.strip()]
        for line1, line2 in zip(lines[0::2], lines[1::2], strict=True):
            records.append(export_omm(Satrec.twoline2rv(line1, line2), name.split(".")[0]))
    path.write_text(json.dumps(records, indent=1))
    return path


def test_a_history_in_omm_flies_as_its_tles(capsys, tmp_path):
    pytest.importorskip("pymsis")
    omm = omm_file(["41619_beesat4.tle"], tmp_path / "beesat4.json")
    # The exporter writes the epoch to the microsecond (a TLE's day fraction has eight digits, 0.86 ms) and
    # SGP4 keeps it as a Julian day and a fraction: within 2 us of each other.
    as_tle = [s.epoch_days for s in read_tle(SETS / "41619_beesat4.tle")]
    assert [s.epoch_days for s in read_tle(omm)] == pytest.approx(as_tle, rel=0.0, abs=2e-6 / 86400)
    results = []
    for path in (SETS / "41619_beesat4.tle", omm):
        assert main(["lifetime", "--tle", str(path), "--json"]) == 0
        results.append(json.loads(capsys.readouterr().out))
    tle, from_omm = results
    assert from_omm["drag_parameter_source"] == tle["drag_parameter_source"] == "history_fit"
    # Those microseconds move the fit and the life by about 1e-12 (measured); 1e-9 holds them and nothing more.
    for key, value in tle["drag_fit"].items():
        assert from_omm["drag_fit"][key] == (value if isinstance(value, int) else pytest.approx(value, rel=1e-9)), key
    assert from_omm["days"] == pytest.approx(tle["days"], rel=1e-9)


def test_a_batch_of_omm_records_is_the_batch_of_the_same_tles(capsys, tmp_path):
    pytest.importorskip("pymsis")
    files = ["41460_aausat4.tle", "43617_elfin_a.tle"]
    tles = tmp_path / "sets.tle"
    tles.write_text("".join((SETS / name).read_text() for name in files))
    omm = omm_file(files, tmp_path / "sets.json")
    assert holds_element_sets(omm) and holds_element_sets(tles)
    rows = []
    for path in (tles, omm):
        out = tmp_path / f"{path.suffix[1:]}.csv"
        assert main(["lifetime", "--batch", str(path), "--out", str(out), "--no-progress"]) == 0
        capsys.readouterr()
        rows.append(list(csv.DictReader(out.open())))
    assert [r["id"] for r in rows[1]] == [str(int(r["id"])) for r in rows[0]] == ["41460", "43617"]
    for from_tle, from_omm in zip(*rows, strict=True):
        assert from_omm["days"] == from_tle["days"] and from_omm["status"] == from_tle["status"] == "ok"


def test_a_record_that_does_not_read_is_named_by_its_place_and_field(capsys, tmp_path):
    good = as_numbers(mario_records()[0])
    cases = [
        ([{k: v for k, v in good.items() if k != "BSTAR"}], "x.json, record 1: the record has no BSTAR"),
        ([good, {**good, "ECCENTRICITY": 1.2}], "x.json, record 2: ECCENTRICITY is 1.2; allowed: 0 to 1 (1 excluded)"),
        ([{**good, "INCLINATION": "abc"}], "x.json, record 1: INCLINATION reads 'abc', not a number"),
        ([{**good, "EPOCH": "25 April 2023"}], "x.json, record 1: EPOCH reads '25 April 2023', not a UTC date"),
        ([{**good, "EPOCH": "2023-04-25T10:45:30+02:00"}], "x.json, record 1: EPOCH '2023-04-25T10:45:30+02:00' has"),
        ([{**good, "EPOCH": "1950-01-01T00:00:00"}], "x.json, record 1, EPOCH: the epoch is 1950-01-01T00:00:00Z"),
        ([1], "x.json, record 1: an OMM record is an object of named fields"),
        ([], "x.json: no element set found"),
    ]
    for records, message in cases:
        with pytest.raises(ValueError, match="^" + message.replace("(", r"\(").replace(")", r"\)").replace("+", r"\+")):
            parse_element_sets(json.dumps(records), "x.json")
    with pytest.raises(ValueError, match=r"^x\.json: not a JSON text"):
        parse_element_sets("[{", "x.json")
    with pytest.raises(ValueError, match=r"^x\.xml: not an XML text"):
        parse_element_sets("<ndm><omm>", "x.xml")
    # In a batch the object with a record that does not read is its row's status; the others are computed.
    path = tmp_path / "two.json"
    path.write_text(json.dumps([good, {**good, "NORAD_CAT_ID": 7, "OBJECT_NAME": "BROKEN", "MEAN_MOTION": "x"}]))
    out = tmp_path / "out.csv"
    assert main(["lifetime", "--batch", str(path), "--out", str(out), "--no-progress"]) == 1
    capsys.readouterr()
    rows = {row["id"]: row for row in csv.DictReader(out.open())}
    assert rows["55123"]["status"] == "ok"
    assert rows["7"]["name"] == "BROKEN" and rows["7"]["status"] == "record 2: MEAN_MOTION reads 'x', not a number"


def test_a_catalogue_csv_is_not_taken_for_omm_records(tmp_path):
    catalogue = tmp_path / "orbits.csv"
    catalogue.write_text("name,perigee_km,apogee_km,epoch\nsat,400,420,2024-01-01\n")
    assert not holds_element_sets(catalogue)
    # A catalogue that carries each row's catalogue number and epoch is still a catalogue of orbits.
    catalogue.write_text("name,norad_cat_id,epoch,perigee_km,apogee_km\nsat,25544,2024-01-01,400,420\n")
    assert not holds_element_sets(catalogue)
    records = tmp_path / "records.csv"
    records.write_text(sgp4_tests.MARIO_CSV)
    assert holds_element_sets(records)
