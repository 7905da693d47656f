"""A lifetime from element sets in one Python call gives the command line's numbers for the same inputs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orbit_env.analysis.drag_source import SatelliteInputs
from orbit_env.analysis.element_set_lifetime import element_set_lifetime
from orbit_env.cli import main

SETS = Path(__file__).parents[2] / "benchmarks" / "data" / "reentry_tles"
HISTORY = SETS / "41619_beesat4.tle"  # 15 sets of BEESAT-4 (a history)
ONE_SET = SETS / "38852_raiko.tle"  # one set of RAIKO


def _cli(capsys, *argv: str) -> dict:
    assert main(["lifetime", *argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    out.pop("atmosphere")  # the command's line about the air: the one key the Python result does not carry
    return out


@pytest.mark.parametrize(
    ("path", "satellite", "flags", "source"),
    [
        (HISTORY, None, (), "history_fit"),
        (ONE_SET, None, (), "bstar_calibrated"),
        (
            ONE_SET,
            SatelliteInputs(mass_kg=1.0, area_m2=0.01, drag_coefficient=2.2),
            ("--mass", "1", "--area", "0.01", "--cx", "2.2"),
            "satellite",
        ),
    ],
)
def test_the_python_call_is_the_command_line(capsys, path, satellite, flags, source):
    found = element_set_lifetime(path, satellite)
    assert found.drag.source == source
    assert found.to_dict() == _cli(capsys, "--tle", str(path), *flags)  # every number, to the last bit


def test_pasted_lines_and_parsed_sets_are_the_file():
    text = ONE_SET.read_text().splitlines()
    pasted = ["   " + line + "  " for line in text if line.strip()]  # indented, trailing spaces, no name line
    assert element_set_lifetime(pasted).result == element_set_lifetime(ONE_SET).result
    assert element_set_lifetime("\r\n".join(pasted)).result == element_set_lifetime(ONE_SET).result  # the text


def test_sets_of_two_objects_or_none_are_refused():
    lines = HISTORY.read_text().splitlines()[-2:] + ONE_SET.read_text().splitlines()[-2:]
    with pytest.raises(ValueError, match=r"element sets of 2 objects \(38852, 41619\); one object's sets"):
        element_set_lifetime(lines)
    with pytest.raises(ValueError, match="no element sets given"):
        element_set_lifetime([])
