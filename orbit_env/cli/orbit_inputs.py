"""The orbit and the satellite as an analyst gives them: an element set, mean elements or heights; a shape.

Shared by ``orbit-env lifetime`` and ``fit-density``. The orbit comes from one of

* ``--perigee KM --apogee KM`` (heights above ``--height-reference``),
* ``--semi-major-axis-km KM --eccentricity E`` (mean elements; heights a (1 -+ e) - 6378.137 km),
* ``--tle FILE`` (a two- or three-line element set, ``-`` for stdin): epoch, mean elements,
  inclination and, unless the satellite is given, the drag parameter from B*.

Heights are converted to the decay core's 6371 km sphere here (`orbit_env.analysis.heights`)
and back for what is printed. Heavy imports (sgp4, pymsis) happen inside the functions.
"""

from __future__ import annotations

import argparse
import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from orbit_env.analysis.air import DATED_AIR, DEFAULT_AIR, air_model
from orbit_env.analysis.drag_calibration import SOURCE_BSTAR_CALIBRATED
from orbit_env.analysis.drag_source import (
    DRAG_FROM_CHOICES,
    SOURCE_BSTAR,
    DragSource,
    SatelliteInputs,
    drag_source,
    element_set_orbits,
)
from orbit_env.analysis.heights import HEIGHT_REFERENCES, offset_km
from orbit_env.analysis.lifetime import Satellite
from orbit_env.analysis.uncertainty import ONE_SET_DRAG_SIGMA
from orbit_env.cli.common import number
from orbit_env.constants import DAYS_PER_YEAR

if TYPE_CHECKING:
    from orbit_env.analysis.catalogue_io import BatchOrbits


@dataclass(frozen=True)
class OrbitInput:
    """The start orbit as given, and what it is measured from.

    Attributes:
        perigee_km: Perigee height above ``reference`` (None: not given).
        apogee_km: Apogee height above ``reference``.
        reference: ``equatorial`` or ``sphere``.
        elements: The element set, if the orbit came from one.
    """

    perigee_km: float | None
    apogee_km: float | None
    reference: str
    elements: Any = None

    @property
    def offset_km(self) -> float:
        """Height of the reference surface above the 6371 km sphere."""
        return offset_km(self.reference)

    @property
    def sphere_heights_km(self) -> tuple[float, float]:
        """Perigee and apogee above the 6371 km sphere (the decay core's heights)."""
        assert self.perigee_km is not None and self.apogee_km is not None
        return self.perigee_km + self.offset_km, self.apogee_km + self.offset_km


def add_orbit_options(parser: argparse.ArgumentParser) -> None:
    """``--tle``, ``--semi-major-axis-km``, ``--eccentricity``, ``--height-reference``."""
    group = parser.add_argument_group("orbit from elements")
    group.add_argument(
        "--tle",
        metavar="FILE",
        help="element sets ('-': stdin): two- or three-line sets (TLE) or OMM records (JSON, CSV or XML, as "
        "CelesTrak and Space-Track give them); several of one object are its history: epoch, mean elements "
        "(the decay starts from the orbit flown: J2's offset added), inclination, B*",
    )
    group.add_argument(
        "--drag-from",
        choices=DRAG_FROM_CHOICES,
        help="with --tle and no satellite: the drag parameter from B* (default) or from ndot, calibrated to the "
        "chosen air at the set's epoch; bstar-raw: 2 B*/rho0 against SGP4's own density (to compare)",
    )
    group.add_argument(
        "--semi-major-axis-km",
        type=number,
        metavar="KM",
        help="mean semi-major axis [km] (SGP4's, Brouwer's; the decay starts from the orbit flown: J2's offset added)",
    )
    group.add_argument("--eccentricity", type=number, metavar="E", help="mean eccentricity (with --semi-major-axis-km)")
    group.add_argument(
        "--height-reference",
        choices=HEIGHT_REFERENCES,
        help="heights above the WGS84 equatorial radius 6378.137 km or the 6371 km sphere "
        "(default: equatorial for msis and exponential, sphere for the paper's atmosphere)",
    )


def add_shape_options(group: Any) -> None:
    """``--shape`` and its dimensions in the satellite group."""
    from orbit_env.analysis.shapes import CUBESAT_FORM_FACTORS_M, SHAPES

    group.add_argument(
        "--shape",
        choices=SHAPES,
        help="free-molecular C_D of this shape at the orbit (needs --mass; with --cx, the shape gives the area "
        "only); a box, a cylinder or a CubeSat tumbles at random (its mean cross-section, a quarter of its surface)",
    )
    group.add_argument(
        "--diameter-m", type=number, metavar="M", help="with --shape sphere or cylinder: its diameter [m]"
    )
    group.add_argument("--length-m", type=number, metavar="M", help="with --shape cylinder: its length [m]")
    group.add_argument(
        "--size-m", type=number, nargs=3, metavar=("X", "Y", "Z"), help="with --shape box: its three edges [m]"
    )
    group.add_argument(
        "--form-factor",
        choices=tuple(CUBESAT_FORM_FACTORS_M),
        help="with --shape cubesat: its form factor (the CubeSat Design Specification's envelope, panels stowed)",
    )


def prepare(args: argparse.Namespace) -> OrbitInput:
    """Read the orbit options; fill in the epoch, inclination and atmosphere an element set implies.

    Sets ``args.atmosphere`` (msis when there is an epoch and no ``--atmosphere``, else
    paper), ``args.epoch`` (a TLE's, unless given), ``args.inclination`` (a TLE's, else 0)
    and ``args.height_reference``. With ``--batch``, ``args.batch_element_sets`` and the sets
    read (``args.batch_sets``, None for a CSV); a batch of element sets without ``--epoch`` sets
    ``args.rows_own_epochs``: each row's air starts at its object's latest set
    (`orbit_env.analysis.catalogue.batch_lifetimes`'s ``epoch_days``).
    """
    elements = None
    tle = getattr(args, "tle", None)
    mean_a = getattr(args, "semi_major_axis_km", None)
    ecc = getattr(args, "eccentricity", None)
    perigee, apogee = getattr(args, "perigee", None), getattr(args, "apogee", None)
    if tle is not None:
        from orbit_env.analysis.elements import read_tle

        if mean_a is not None or ecc is not None or perigee is not None or apogee is not None:
            raise ValueError("--tle gives the orbit; do not give --perigee/--apogee or --semi-major-axis-km too")
        if getattr(args, "batch", None):
            raise ValueError("give either --tle or --batch (a batch file may hold element sets)")
        sets = read_tle(tle)
        numbers = sorted({s.catalogue_number for s in sets})
        if len(numbers) > 1:
            raise ValueError(
                f"{tle} holds element sets of {len(numbers)} objects ({', '.join(numbers)}); one object's sets are "
                "its history, several objects need --batch"
            )
        # Several sets of one object: a history; the prediction starts from the latest.
        sets.sort(key=lambda s: s.epoch_days)
        args.tle_history = sets if len(sets) > 1 else None
        elements = sets[-1]
        if args.epoch is None and "epoch" in air_model(args.atmosphere or DATED_AIR).options:
            args.epoch = elements.epoch_iso.rstrip("Z")
        if args.inclination is not None:
            raise ValueError(
                f"--inclination: the element set gives the inclination ({elements.inclination_deg:g} deg); "
                "drop --inclination (to fly that orbit at another, give its heights with --perigee/--apogee)"
            )
        args.inclination = elements.inclination_deg
    elif mean_a is not None or ecc is not None:
        from orbit_env.analysis.elements import mean_elements

        if mean_a is None or ecc is None:
            raise ValueError("give --semi-major-axis-km and --eccentricity together")
        if perigee is not None or apogee is not None:
            raise ValueError("give either --perigee/--apogee or --semi-major-axis-km/--eccentricity, not both")
        elements = mean_elements(mean_a, ecc, 0.0 if args.inclination is None else args.inclination)
    if getattr(args, "batch", None):
        from orbit_env.analysis.elements import holds_element_sets, read_tle

        args.batch_element_sets = holds_element_sets(args.batch)
        # Read once (`read_orbits`); a set that does not read is its object's row's status, not the batch's end.
        args.batch_bad_sets = []
        args.batch_sets = read_tle(args.batch, bad=args.batch_bad_sets) if args.batch_element_sets else None
        if args.batch_element_sets and args.inclination is not None:
            raise ValueError("--inclination: each object's element set gives its inclination; drop --inclination")
        dated = "epoch" in air_model(args.atmosphere or DATED_AIR).options
        # A batch of element sets: each object from its own latest set's epoch, as --tle starts from its set's.
        if args.batch_sets and args.epoch is None and dated:
            first = min(args.batch_sets, key=lambda s: s.epoch_days)
            args.epoch = first.epoch_iso.rstrip("Z")  # dates the air; each row moves it to its own
            args.rows_own_epochs = True
    _check_element_set_options(args, tle is not None or getattr(args, "batch_sets", None) is not None, elements)
    if args.inclination is None:
        args.inclination = 0.0
    if args.atmosphere is None:
        args.atmosphere = DATED_AIR if args.epoch is not None else DEFAULT_AIR
    reference = getattr(args, "height_reference", None)
    args.height_reference_given = reference is not None
    if reference is None:
        reference = "equatorial" if elements is not None else air_model(args.atmosphere).height_reference
    args.height_reference = reference
    if elements is not None:
        if reference != "equatorial":
            raise ValueError("element sets give heights above the equatorial radius; drop --height-reference sphere")
        # Mean elements are not the orbit flown: the decay starts from the flown heights (J2's offset).
        orbit = OrbitInput(elements.flown_perigee_km, elements.flown_apogee_km, reference, elements)
        from orbit_env.analysis.element_set_lifetime import check_flown

        check_flown(elements, "the element set" if tle is not None else "--semi-major-axis-km/--eccentricity")
        return orbit
    return OrbitInput(perigee, apogee, reference)


def _check_element_set_options(args: argparse.Namespace, from_sets: bool, latest: Any) -> None:
    """Options that mean nothing, or something else than they say, with (or without) element sets: refused.

    ``--drag-from`` reads element sets; a drag calibrated or fitted to the air from them absorbs any
    ``--density-scale`` (the same lifetime whatever the scale); a ``--tle`` set's epoch is the decay's start.
    """
    drag_from = getattr(args, "drag_from", None)
    if drag_from is not None and not from_sets:
        raise ValueError(
            "--drag-from says what an element set's drag is read from: it goes with --tle (or --batch sets)"
        )
    if from_sets and satellite_inputs(args).drag_absorbs_scale and getattr(args, "density_scale", 1.0) != 1.0:
        raise ValueError(
            "--density-scale changes nothing when the drag is calibrated to the air from element sets (the "
            "calibration absorbs the scale); to fly a fitted scale, give the satellite: --mass and --area (or --shape)"
        )
    from orbit_env.decay.solar import unix_days

    from_tle = latest is not None and getattr(args, "tle", None) is not None and args.epoch is not None
    if from_tle and not latest.measured_at(unix_days(args.epoch)):
        raise ValueError(
            f"--epoch {args.epoch}: the decay starts at the element set's epoch ({latest.epoch_iso}), where its orbit "
            "was measured; drop --epoch (to fly that orbit from another date, give its heights with --perigee/--apogee)"
        )


def satellite_inputs(args: argparse.Namespace) -> SatelliteInputs:
    """What the command line says about the satellite."""
    return SatelliteInputs(
        mass_kg=getattr(args, "mass", None),
        area_m2=getattr(args, "area", None),
        mass_per_area_kg_m2=getattr(args, "mass_per_area", None),
        drag_coefficient=getattr(args, "cx", None),
        shape=getattr(args, "shape", None),
        diameter_m=getattr(args, "diameter_m", None),
        length_m=getattr(args, "length_m", None),
        size_m=None if getattr(args, "size_m", None) is None else tuple(args.size_m),
        form_factor=getattr(args, "form_factor", None),
        drag_from=getattr(args, "drag_from", None),
    )


def satellite_from_args(args: argparse.Namespace, orbit: OrbitInput, scenario: Any) -> DragSource:
    """The satellite and where its drag parameter came from (`orbit_env.analysis.drag_source.drag_source`)."""
    known = orbit.perigee_km is not None and orbit.apogee_km is not None
    return drag_source(
        satellite_inputs(args),
        scenario.in_sphere_heights(orbit.reference, args.inclination),
        args.inclination,
        sphere_heights_km=orbit.sphere_heights_km if known else None,
        elements=orbit.elements,
        history=getattr(args, "tle_history", None),
        ascending_node_local_time_h=getattr(args, "node_local_time", None),
    )


def orbit_lines(orbit: OrbitInput, inclination_deg: float) -> list[str]:
    """The text output's lines about the orbit."""
    from orbit_env.analysis.heights import describe

    lines = []
    elements = orbit.elements
    if elements is not None and elements.epoch_days is not None:
        lines.append(
            f"element set        {elements.name}, epoch {elements.epoch_iso}, inclination {inclination_deg:g} deg"
        )
    if elements is not None:
        lines.append(
            f"mean elements      a = {elements.semi_major_axis_km:.3f} km, e = {elements.eccentricity:.7f} "
            f"({elements.perigee_km:.6g} x {elements.apogee_km:.6g} km)"
        )
    assert orbit.perigee_km is not None and orbit.apogee_km is not None
    flown = (
        ""
        if elements is None
        else f" (flown: J2 moves the mean elements' radius by {elements.flown_offset_km:+.2f} km)"
    )
    lines.append(
        f"orbit              {orbit.perigee_km:.6g} x {orbit.apogee_km:.6g} km, {describe(orbit.reference)}{flown}"
    )
    return lines


def satellite_line(drag: DragSource) -> str:
    """The text output's line about the satellite."""
    satellite, source, report = drag.satellite, drag.source, drag.report
    c = satellite.drag_parameter_m2_kg
    if source == SOURCE_BSTAR:
        return (
            f"satellite          c_x A/m = {c:.4g} m^2/kg from the element set's B* = "
            f"{report['bstar_per_earth_radius']:.5g} /ER (2 B* / 0.15696615, against SGP4's own density)"
        )
    if "drag_fit" in report:
        fit = report["drag_fit"]
        residual = (
            "two sets, no residual" if fit["residual_km"] is None else f"residual {fit['residual_km'] * 1e3:.0f} m"
        )
        return (
            f"satellite          c_x A/m = {c:.4g} m^2/kg fitted to the decay between {fit['sets']} element sets over "
            f"{fit['span_days']:.1f} days ({residual}, c within {100 * fit['sigma_ln']:.1f}% at 1 sigma); "
            "from the latest set"
        )
    if "sgp4_to_air_density_ratio" in report:
        what = "B*" if source == SOURCE_BSTAR_CALIBRATED else "ndot"
        note = f" ({report['drag_note']})" if "drag_note" in report else ""
        return (
            f"satellite          c_x A/m = {c:.4g} m^2/kg from one element set's {what}, calibrated to this air at its "
            f"epoch (SGP4's density {report['sgp4_to_air_density_ratio']:.3g} x this air's; 2 B*/rho0 = "
            f"{report['drag_parameter_uncalibrated_m2_kg']:.4g}); one set: uncertain by a factor of "
            f"{math.exp(ONE_SET_DRAG_SIGMA):.2g} (1 sigma){note}"
        )
    text = (
        f"satellite          c_x {satellite.drag_coefficient:.4g}, {satellite.mass_kg:g} kg, "
        f"{satellite.area_m2:.4g} m^2 (G/F = {satellite.mass_per_area_kg_m2:.4g} kg/m^2, c_x A/m = {c:.4g} m^2/kg)"
    )
    if "shape" in report:
        text += f"; {report['shape']}"
    if "speed_ratio" in report:
        text += (
            f"; free-molecular c_x (Sentman) at S = {report['speed_ratio']:.2f}, "
            f"T = {report['gas_temperature_k']:.0f} K"
        )
    return text


def history_rows(history: Any, offset: float, epoch_days: float | None = None) -> list[dict[str, Any]]:
    """The decay history's rows with heights above the reference (and the UTC date, with an epoch)."""
    from orbit_env.analysis.lifetime import iso_datetime

    rows: list[dict[str, Any]] = history.rows()
    for row in rows:
        row["perigee_km"] -= offset
        row["apogee_km"] -= offset
    if epoch_days is not None:
        rows = [{"date": iso_datetime(epoch_days + row["days"]), **row} for row in rows]
    return rows


def history_points(args: argparse.Namespace, start_days: float | None) -> list[tuple[float, float, float]]:
    """A ``--tle`` history's sets for `plot_history`'s ``observed``: (days from the start, perigee, apogee [km]).

    The decay starts at ``start_days`` (None: undated, at the latest set). Each set's orbit flown, above the
    equatorial radius: the reference of every element set's heights (`prepare` refuses another), so drawn as
    the decay's are; none for one set (the decay's start).
    """
    sets = getattr(args, "tle_history", None) or []
    if not sets:
        return []
    start = sets[-1].epoch_days if start_days is None else start_days
    return [(s.epoch_days - start, s.flown_perigee_km, s.flown_apogee_km) for s in sets]


def read_orbits(args: argparse.Namespace, satellite: Satellite, scenario: Any) -> BatchOrbits:
    """A batch file's orbits in the sphere's heights [m]: a CSV (see ``catalogue``) or element sets.

    Element sets give the heights of the orbit flown above the equatorial radius, their
    inclination and, unless the satellite is given on the command line, the drag parameter:
    each object's sets are its history (one row, from its latest set, the drag fitted to the
    decay between its sets), an object with one set has its B* calibrated to the air.
    """
    import numpy as np

    from orbit_env.analysis.catalogue_io import BatchOrbits, read_batch

    sets = args.batch_sets  # read by `prepare`; None for a CSV
    if sets is not None and not getattr(args, "height_reference_given", False):
        args.height_reference = "equatorial"  # element sets give heights above the equatorial radius
    offset_m = offset_km(args.height_reference) * 1e3
    if sets is None:
        rows, hp, ha, c, inc, status = read_batch(
            args.batch, satellite.drag_coefficient, satellite.drag_parameter_m2_kg, args.inclination
        )
        none = np.full(len(rows), np.nan)
        return BatchOrbits(rows, hp + offset_m, ha + offset_m, c, inc, status, none, none)
    if args.height_reference != "equatorial":
        raise ValueError("element sets give heights above the equatorial radius; drop --height-reference sphere")
    return element_set_orbits(
        sets,
        satellite,
        scenario.in_sphere_heights("equatorial", float(args.inclination or 0.0)),
        satellite_given=satellite_inputs(args).given,
        offset_m=offset_m,
        drag_from=getattr(args, "drag_from", None),
        bad_sets=args.batch_bad_sets,
        progress=not getattr(args, "no_progress", False),
    )


def records_in_reference(records: list[dict[str, Any]], reference: str) -> list[dict[str, Any]]:
    """Batch records with heights above the reference (the records hold the sphere's)."""
    shift = offset_km(reference)
    if shift == 0.0:
        return records
    for record in records:
        for key in ("perigee_km", "apogee_km", "new_perigee_km"):
            if record.get(key, "") != "":
                record[key] = f"{float(record[key]) - shift:.6g}"
    return records


def add_uncertainty_options(parser: argparse.ArgumentParser) -> None:
    """``--uncertainty``, ``--samples``, ``--seed``."""
    group = parser.add_argument_group("uncertainty (orbit_env.analysis.uncertainty)")
    group.add_argument(
        "--uncertainty",
        action="store_true",
        help="Monte Carlo over the solar forecast, NRLMSIS's error and the drag coefficient: percentiles, "
        "and with --rule the probability of compliance; with --batch, every row's (seeded by the row), in "
        "chunks over --workers processes, resumed from OUT.parts/ by the same command",
    )
    group.add_argument("--samples", type=int, help=f"with --uncertainty: samples (default {DEFAULT_SAMPLES})")
    group.add_argument("--seed", type=int, help="with --uncertainty: random seed (default 0)")


#: ``--samples`` when not given.
DEFAULT_SAMPLES = 1000


def resolve_uncertainty_options(args: argparse.Namespace) -> None:
    """Refuse ``--samples``/``--seed`` without ``--uncertainty`` (they would do nothing); fill in their defaults."""
    for name in ("samples", "seed"):
        if getattr(args, name) is not None and not args.uncertainty:
            raise ValueError(f"--{name} goes with --uncertainty")
    args.samples = DEFAULT_SAMPLES if args.samples is None else args.samples
    args.seed = 0 if args.seed is None else args.seed


def uncertainty(
    args: argparse.Namespace,
    orbit: OrbitInput,
    scenario: Any,
    satellite: Satellite,
    result: Any,
    summary: dict,
    drag_sigma: float | None = None,
) -> tuple[float, float] | None:
    """Run ``--uncertainty``; add its keys to ``summary``; return the 5-95% band [days] for the plot."""
    from orbit_env.analysis.uncertainty import lifetime_spread, spread_report

    perigee_km, apogee_km = orbit.sphere_heights_km
    spread = lifetime_spread(
        perigee_km * 1e3,
        apogee_km * 1e3,
        satellite.drag_parameter_m2_kg,
        scenario.in_sphere_heights(orbit.reference, args.inclination),
        args.inclination,
        samples=args.samples,
        seed=args.seed,
        **({} if drag_sigma is None else {"drag_sigma": drag_sigma}),
        workers=args.workers or os.cpu_count() or 1,
        progress=True,
    )
    epoch = result.epoch_days
    if epoch is None and orbit.elements is not None:
        epoch = orbit.elements.epoch_days
    summary.update(spread_report(spread, epoch, args.rule))
    low, high = summary["days_percentiles"]["5"], summary["days_percentiles"]["95"]
    return None if low is None or high is None else (low, high)


#: A band whose 95th percentile is shorter than this [days] is printed in days, not years.
SHORT_BAND_DAYS = 730.0


def uncertainty_lines(summary: dict[str, Any]) -> list[str]:
    """The text output's lines of ``--uncertainty``."""
    values = [summary["days_percentiles"][k] for k in ("5", "50", "95")]
    known = [value for value in values if value is not None]  # the percentiles beyond the propagation are last
    if len(known) == 3 and known[2] < SHORT_BAND_DAYS:  # "0.08 / 0.09 / 0.12 years" would say little
        band = " / ".join(f"{value:.1f}" for value in known) + " days"
    else:
        parts = [" / ".join(f"{value / DAYS_PER_YEAR:.2f}" for value in known) + " years"] if known else []
        band = " / ".join(parts + ["beyond the propagation"] * (3 - len(known)))
    samples = f"{summary['uncertainty_samples']} samples, seed {summary['uncertainty_seed']}"
    lines = [f"lifetime 5/50/95%  {band} ({samples})"]
    dates = summary.get("reentry_date_percentiles")
    if dates:
        lines.append(f"re-entry 5-95%     {dates['5'] or '-'} to {dates['95'] or '-'}")
    if "rule_verdict" in summary:
        lines.append(f"rule, 90% conf.    {summary['rule_verdict']}")
    return lines
