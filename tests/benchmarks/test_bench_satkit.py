"""orbit_env's dated lifetime against satkit's numerical propagator on one short case (benchmarks/bench_satkit.py).

satkit is a benchmark dependency (the ``bench`` extra), not installed by the README's
commands, so this module usually skips.
"""

import pytest

pytest.importorskip("satkit")
pytest.importorskip("satkit_data")

import benchmark_scripts

#: The 45-day case of docs/validation-modern/speed.md: a 3U cubesat at 300 x 350 km (mean
#: elements), 51.6 deg, from 2024-01-01, NRLMSISE-00 on both sides. Measured: orbit_env
#: 44.60 days, satkit 45.13 days, ratio 0.988. The tolerance, 3%, is that 1.2% with room for
#: what the two models do differently (daily against 3-hourly Ap; the orbit average against
#: EGM2008 4 x 4, Sun and Moon) to move with a satkit release; the errors it is meant to
#: catch are larger: NRLMSIS 2.1 in place of 00 (lives 1.05-1.2 times as long, the table of
#: docs/how-to/lifetime.md), mean elements taken for the orbit flown (-22% to +11%, issue 27).
TOLERANCE = 0.03


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    module = benchmark_scripts.load("bench_satkit")
    module.use_shipped_data(str(tmp_path_factory.mktemp("satkit-data")))
    return module


def test_a_short_dated_lifetime_agrees_with_satkit(bench):
    (case,) = [c for c in bench.CASES if c.name == "iss-2024"]
    lines, elements = bench.element_set(case)
    assert elements.perigee_km == pytest.approx(case.perigee_km, abs=0.01)
    assert elements.apogee_km == pytest.approx(case.apogee_km, abs=0.01)
    satkit_days, _ = bench.satkit_lifetime(lines)
    days, _ = bench.orbit_env_in_process(case, elements)
    assert days / satkit_days == pytest.approx(1.0, abs=TOLERANCE)


def test_the_element_set_starts_both_on_the_same_orbit(bench):
    """satkit's mean radius over the first revolutions is orbit_env's orbit flown, J2's offset included.

    At the equator the offset is -9.8 km (the mean elements' radius is not the one flown);
    measured: satkit 380.0 km, orbit_env 380.2 km above the equatorial radius.
    """
    (case,) = [c for c in bench.CASES if c.name == "equator-2001"]
    lines, elements = bench.element_set(case)
    flown_km = (elements.flown_perigee_km + elements.flown_apogee_km) / 2
    flown_km += elements.semi_major_axis_km * elements.eccentricity**2 / 2
    assert elements.flown_offset_km < -9.0
    assert bench.satkit_start_height_km(lines) == pytest.approx(flown_km, abs=1.0)
