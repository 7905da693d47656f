"""Shapes as an analyst gives them: a sphere, and a box, a cylinder or a CubeSat tumbling at random."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from orbit_env.analysis.shapes import CUBESAT_FORM_FACTORS_M, box, cubesat, cylinder, make_shape, sphere
from orbit_env.cli import main
from orbit_env.physics.drag import panel_drag_area_m2


def test_a_tumbling_body_flies_a_quarter_of_its_surface():
    # Surfaces by hand: a 0.1 x 0.2 x 0.3 m box 2 (0.02 + 0.06 + 0.03) = 0.22 m^2; Explorer 1's
    # 2.03 m x 0.152 m cylinder pi 0.152 2.03 + 2 pi 0.076^2 = 1.0057 m^2; a 3U CubeSat's envelope,
    # 100 x 100 x 340.5 mm, 2 (0.01 + 2 x 0.03405) = 0.1562 m^2.
    assert box((0.1, 0.2, 0.3)).reference_area_m2 == pytest.approx(0.22 / 4, rel=1e-12)
    explorer = cylinder(0.152, 2.03)
    assert explorer.reference_area_m2 == pytest.approx((math.pi * 0.152 * 2.03 + 2 * math.pi * 0.076**2) / 4)
    assert cubesat("3U").reference_area_m2 == pytest.approx(0.1562 / 4, rel=1e-12)
    assert all(shape.sphere for shape in (box((0.1, 0.2, 0.3)), explorer, cubesat("3U")))
    assert cubesat("6U").description == "6U CubeSat (0.2263 x 0.1 x 0.366 m), tumbling"
    assert make_shape("cylinder", diameter_m=0.152, length_m=2.03) == explorer
    assert make_shape("sphere", diameter_m=0.3) == sphere(0.3)


def test_a_tumbling_box_drags_as_its_faces_averaged_over_all_directions():
    # The claim behind every tumbling shape, checked on an elongated box (a 3U CubeSat), not only a cube:
    # the six faces' Sentman drag averaged over random flow directions against the shape's coefficient on
    # its reference area. The tolerance is four standard errors of the sampled mean.
    x, y, z = CUBESAT_FORM_FACTORS_M["3U"]
    rng = np.random.default_rng(11)
    directions = rng.normal(size=(200_000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    normals = np.vstack([np.eye(3), -np.eye(3)])
    areas = np.array([y * z, x * z, x * y] * 2)
    s, wall_to_gas = 7.0, 300.0 / 1000.0
    drag = panel_drag_area_m2(areas, directions @ normals.T, s, wall_to_gas)
    shape = cubesat("3U")
    expected = float(shape.drag_coefficient(np.array(s), np.array(wall_to_gas))) * shape.reference_area_m2
    assert abs(drag.mean() - expected) <= 4 * drag.std() / math.sqrt(drag.size)


@pytest.mark.parametrize(
    ("sizes", "problem"),
    [
        ((0.1, 0.0, 0.3), "size_m"),
        ((0.1, 0.2), "three edges"),
        ((999.0, 999.0, 999.0), "the box's area"),
    ],
)
def test_a_box_out_of_any_satellites_range_is_refused(sizes, problem):
    with pytest.raises(ValueError, match=problem):
        box(sizes)


def test_an_unknown_form_factor_names_the_known_ones():
    with pytest.raises(ValueError, match=r"unknown CubeSat form factor '5U'; known: 0\.5U, 1U"):
        cubesat("5U")


def lifetime_json(capsys, *flags: str) -> dict:
    argv = ["lifetime", "--perigee", "400", "--apogee", "420", "--inclination", "51.6", "--mass", "4", *flags]
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_the_command_flies_a_cubesat_as_the_box_of_its_envelope(capsys):
    pytest.importorskip("pymsis")
    as_cubesat = lifetime_json(capsys, "--shape", "cubesat", "--form-factor", "3U")
    as_box = lifetime_json(capsys, "--shape", "box", "--size-m", "0.1", "0.1", "0.3405")
    assert as_cubesat["drag_parameter_source"] == "shape"
    assert as_cubesat["shape"] == "3U CubeSat (0.1 x 0.1 x 0.3405 m), tumbling"
    assert as_cubesat["reference_area_m2"] == pytest.approx(0.1562 / 4, rel=1e-12)
    cd = as_cubesat["drag_coefficient"]
    assert 2.0 < cd < 2.3  # Sentman's sphere coefficient in low orbit (hypersonic cold-wall limit 2)
    assert as_cubesat["drag_parameter_m2_kg"] == pytest.approx(cd * 0.1562 / 4 / 4.0, rel=1e-12)
    assert as_box["days"] == as_cubesat["days"]
    # --cx keeps the shape's area and replaces its coefficient.
    fixed = lifetime_json(capsys, "--shape", "cubesat", "--form-factor", "3U", "--cx", "2.2")
    assert fixed["drag_parameter_m2_kg"] == pytest.approx(2.2 * 0.1562 / 4 / 4.0, rel=1e-12)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--shape", "box"], "--shape box needs --size-m"),
        (["--shape", "cylinder", "--diameter-m", "1"], "--shape cylinder needs --length-m"),
        (["--shape", "cubesat"], "--shape cubesat needs --form-factor"),
        (["--diameter-m", "1"], "--diameter-m goes with --shape sphere or cylinder"),
        (["--shape", "sphere", "--diameter-m", "1", "--length-m", "2"], "--length-m goes with --shape cylinder"),
        (["--form-factor", "3U"], "--form-factor goes with --shape cubesat"),
        (["--shape", "cubesat", "--form-factor", "3U", "--area", "0.1"], "--shape sets the area"),
        (["--shape", "box", "--size-m", "0.1", "-1", "0.3"], "--size-m -1 is out of range"),
    ],
)
def test_a_shape_without_its_dimensions_or_with_anothers_is_refused(capsys, flags, message):
    argv = ["lifetime", "--perigee", "400", "--apogee", "420", "--mass", "4", *flags]
    assert main(argv) == 2
    assert capsys.readouterr().err.startswith(f"orbit-env: error: {message}")


@pytest.mark.parametrize("norad", [38855, 43137, 41478])
def test_documented_cubesats_from_their_mass_and_form_factor_meet_their_reentries(norad, tmp_path):
    # F-1, Fox-1D and NODES 1 (benchmarks/data/reentry_tles/shapes.csv: launch mass and form factor from
    # public pages), flown from their latest set with that mass and body tumbling at random: each lands
    # within +-25% of the observed remaining life (the threshold; measured on 2026-12-07: -2.9%,
    # +1.3% and +5.9%).
    import benchmark_scripts

    script = benchmark_scripts.load("validate_element_sets")
    (obj,) = [o for o in script.load_objects() if o.norad == norad]
    last = len(obj.sets) - 1
    case = script.predict(obj, last, "known shape", [last], None, tmp_path, satellite=script.load_shapes()[norad])
    assert case.status == "ok" and abs(case.error) <= 0.25, case


@pytest.mark.slow
def test_documented_cubesats_from_mass_and_shape_beat_their_element_sets():
    # The whole "known shape" table (10 CubeSats, 18 cases, about a minute): measured on 2026-12-07 a median
    # |error| of 7.8% and 94.4% of cases within +-25% with the documented satellite, against 14.7% and
    # 83.3% from the same sets' B* alone. Held to the history's goals of issue 27 (median <= 10%, 90% within
    # +-25%, the 90% band holding >= 85%): the satellite known does as well as a history of sets.
    import benchmark_scripts

    script = benchmark_scripts.load("validate_element_sets")
    shapes = script.load_shapes()
    objects = [o for o in script.load_objects() if o.norad in shapes]
    cases = script.run_cases(objects, history=False, samples=200, limit=None, shapes=shapes)
    known = script.summarize(cases)["known shape"]["all"]
    assert known["cases"] == 18
    assert known["median_abs_error"] <= 0.10
    assert known["within_25"] >= 0.90
    assert known["band_coverage"] >= 0.85


def test_a_batch_takes_a_shapes_area_with_a_given_cx_and_says_it_computes_no_coefficient(capsys, tmp_path):
    # A batch has no one orbit whose gas gives the free-molecular coefficient: it had flown the shape's area at
    # the paper's c_x 2 without a word. It now asks for --cx, and with it flies the shape's area.
    import csv

    catalogue = tmp_path / "orbits.csv"
    catalogue.write_text("name,perigee_km,apogee_km\na,400,420\n")
    out = tmp_path / "out.csv"
    argv = ["lifetime", "--batch", str(catalogue), "--out", str(out), "--no-progress", "--mass", "4"]
    argv += ["--shape", "cubesat", "--form-factor", "3U"]
    assert main(argv) == 2
    assert "--shape in a batch gives the satellite's area only: give --cx too" in capsys.readouterr().err
    assert main([*argv, "--cx", "2.2"]) == 0
    (row,) = csv.DictReader(out.open())
    assert float(row["drag_parameter_m2_kg"]) == pytest.approx(2.2 * 0.1562 / 4 / 4.0, rel=1e-5)  # six digits


def test_a_catalogue_row_gives_a_cubesat_by_its_mass_and_form_factor(capsys, tmp_path):
    # A constellation's CSV names its CubeSats' form factor: the area is the tumbling envelope's (a quarter of
    # its surface), the coefficient the row's cx or --cx, as with mass_kg and area_m2.
    import csv

    catalogue = tmp_path / "orbits.csv"
    rows = ["name,perigee_km,apogee_km,mass_kg,form_factor,area_m2,cx", "a,400,420,4,3U,,2.4", "b,400,420,4,3U,,"]
    rows += ["no mass,400,420,,3U,,", "twice,400,420,4,3U,0.03,", "unknown,400,420,4,5U,,"]
    catalogue.write_text("\n".join(rows) + "\n")
    out = tmp_path / "out.csv"
    assert main(["lifetime", "--batch", str(catalogue), "--out", str(out), "--no-progress", "--cx", "2.2"]) == 1
    capsys.readouterr()
    got = {row["name"]: row for row in csv.DictReader(out.open())}
    area = 0.1562 / 4  # 2 (0.01 + 2 x 0.03405) / 4
    assert float(got["a"]["drag_parameter_m2_kg"]) == pytest.approx(2.4 * area / 4.0, rel=1e-5)  # six digits
    assert float(got["b"]["drag_parameter_m2_kg"]) == pytest.approx(2.2 * area / 4.0, rel=1e-5)
    assert got["no mass"]["status"] == "line 4: form_factor gives the area: give mass_kg with it"
    assert got["twice"]["status"] == "line 5: the area is given twice (area_m2; form_factor): give one of them"
    assert got["unknown"]["status"].startswith("line 6: unknown CubeSat form factor '5U'; known: 0.5U, 1U")
