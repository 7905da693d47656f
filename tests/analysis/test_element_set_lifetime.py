"""A lifetime from element sets in one Python call gives the command line's numbers for the same inputs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orbit_env.analysis.drag_source import SatelliteInputs
from orbit_env.analysis.element_set_lifetime import check_flown, element_set_lifetime
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


def test_what_the_command_refuses_the_call_refuses_in_the_same_terms():
    from orbit_env.analysis.air import MsisAir
    from orbit_env.analysis.elements import mean_elements
    from orbit_env.analysis.scenario import Scenario
    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    later = Scenario(MsisAir(load_record(), unix_days("2014-01-01")))
    with pytest.raises(ValueError, match=r"scenario starts at 2014-01-01T00:00:00Z: the decay starts at the element"):
        element_set_lifetime(ONE_SET, scenario=later)
    own = element_set_lifetime(ONE_SET)
    scaled = Scenario(MsisAir(load_record(), own.result.epoch_days), density_scale=2.0)
    with pytest.raises(ValueError, match="a density scale of 2 changes nothing when the drag is calibrated"):
        element_set_lifetime(ONE_SET, scenario=scaled)
    with pytest.raises(ValueError, match="without an epoch"):
        element_set_lifetime([mean_elements(6800.0, 0.001, 51.6)])
    low = mean_elements(6440.0, 0.001, 51.6)  # flown below the re-entry height
    with pytest.raises(ValueError, match=r"the element set \(a = 6440.000 km, e = 0.0010000\) is flown .* re-ent"):
        check_flown(low)


def test_a_shape_in_a_sun_synchronous_air_is_the_command_line(capsys):
    """The node's local time reaches the shape's drag coefficient (the gas at the perigee's local times)."""
    from orbit_env.analysis.air import MsisAir
    from orbit_env.analysis.scenario import Scenario
    from orbit_env.decay.solar import unix_days
    from orbit_env.decay.solar_record import load_record

    own = element_set_lifetime(ONE_SET)
    epoch = own.elements.epoch_iso.rstrip("Z")
    air = Scenario(MsisAir(load_record(), unix_days(epoch), ascending_node_local_time_h=10.0))
    satellite = SatelliteInputs(mass_kg=4.0, shape="sphere", diameter_m=0.3)
    found = element_set_lifetime(ONE_SET, satellite, scenario=air)
    flags = ("--mass", "4", "--shape", "sphere", "--diameter-m", "0.3", "--node-local-time", "10")
    assert found.to_dict() == _cli(capsys, "--tle", str(ONE_SET), *flags)


def test_the_band_is_the_commands(capsys):
    """``spread`` samples what ``--uncertainty`` samples: the same percentiles (one set's wide drag spread)."""
    from orbit_env.analysis.uncertainty import spread_report

    found = element_set_lifetime(ONE_SET)
    report = spread_report(found.spread(samples=40, seed=3, workers=2), found.result.epoch_days, None)
    cli = _cli(capsys, "--tle", str(ONE_SET), "--uncertainty", "--samples", "40", "--seed", "3")
    assert report == {key: cli[key] for key in report}  # the percentiles, dates, samples, seed and sigmas
