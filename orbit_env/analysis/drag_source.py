"""Where a satellite's drag parameter comes from: its mass and area, its shape, one element set, or a history.

The analyst's satellite wins: a mass and an area (or a load, a drag coefficient), or a
mass and a shape whose free-molecular C_D is computed at the start orbit. Without one,
an element set's decay gives the drag parameter: a history of sets (one object's) by
the fit of their mean motion's decay (`orbit_env.analysis.drag_calibration.fit_history`),
one set by its B* (or ndot) calibrated to the chosen air at its epoch
(`orbit_env.analysis.drag_calibration.calibrate`), or B* read raw against SGP4's own
density (to compare). Without either, the paper's sphere. `drag_sigma` says how uncertain
each source leaves the drag parameter, for the uncertainty run.

The command line (`orbit_env.cli.orbit_inputs`) only reads the flags into
`SatelliteInputs` and prints what comes back.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from orbit_env.analysis.catalogue_io import DRAG_SOURCE_KEY, BatchOrbits
from orbit_env.analysis.drag_calibration import (
    SOURCE_BSTAR_CALIBRATED,
    SOURCE_HISTORY_FIT,
    SOURCE_NDOT_CALIBRATED,
    NoHistoryToFit,
    calibrate,
    fit_history,
)
from orbit_env.analysis.lifetime import PAPER_DRAG_COEFFICIENT, Satellite, make_satellite
from orbit_env.analysis.uncertainty import ONE_SET_DRAG_SIGMA
from orbit_env.constants import REENTRY_ALTITUDE_M

#: What ``drag_parameter_source`` says in JSON.
SOURCE_BSTAR = "bstar"
SOURCE_SATELLITE = "satellite"
SOURCE_SHAPE = "shape"
SOURCE_DEFAULT = "default"
#: ``--drag-from``: what of an element set gives the drag parameter.
DRAG_FROM_SOURCES = {"bstar": SOURCE_BSTAR_CALIBRATED, "ndot": SOURCE_NDOT_CALIBRATED}
DRAG_FROM_DEFAULT = "bstar"
#: How each source of one set reads the drag, for messages.
READ_AS = {
    SOURCE_BSTAR_CALIBRATED: "its B* calibrated to this air at its epoch",
    SOURCE_NDOT_CALIBRATED: "its ndot calibrated to this air at its epoch",
    SOURCE_BSTAR: "2 B*/rho0",
}
DRAG_FROM_CHOICES = (*DRAG_FROM_SOURCES, "bstar-raw")


@dataclass(frozen=True)
class SatelliteInputs:
    """What the analyst said about the satellite (None: not said).

    Attributes:
        mass_kg: Mass.
        area_m2: Reference area.
        mass_per_area_kg_m2: Transverse load G/F (instead of mass and area).
        drag_coefficient: c_x.
        shape: One of `orbit_env.analysis.shapes.SHAPES`: the free-molecular C_D of this shape at the
            start (needs the mass); a box, a cylinder and a CubeSat tumbling at random.
        diameter_m: The sphere's or the cylinder's diameter.
        length_m: The cylinder's length.
        size_m: The box's three edges.
        form_factor: The CubeSat's (``"3U"``, `orbit_env.analysis.shapes.CUBESAT_FORM_FACTORS_M`).
        drag_from: What of one element set gives the drag parameter (`DRAG_FROM_CHOICES`).
    """

    mass_kg: float | None = None
    area_m2: float | None = None
    mass_per_area_kg_m2: float | None = None
    drag_coefficient: float | None = None
    shape: str | None = None
    diameter_m: float | None = None
    length_m: float | None = None
    size_m: tuple[float, float, float] | None = None
    form_factor: str | None = None
    drag_from: str | None = None

    @property
    def given(self) -> bool:
        """Whether the satellite itself was described (it then wins over any element set)."""
        described = (self.mass_kg, self.area_m2, self.mass_per_area_kg_m2, self.drag_coefficient, self.shape)
        return any(value is not None for value in described)

    @property
    def drag_absorbs_scale(self) -> bool:
        """Whether element sets' drag, calibrated or fitted to the air, flies: it absorbs any density scale.

        So unless the satellite is described or the drag is one set's 2 B* / rho0 as read (``bstar-raw``).
        """
        return not self.given and self.drag_from != "bstar-raw"


@dataclass(frozen=True)
class DragSource:
    """The satellite the decay flies, where its drag parameter came from, and what to report about it.

    Attributes:
        satellite: The satellite (from an element set: c_x 1 on c m^2 per kg).
        source: ``drag_parameter_source`` (`SOURCE_SATELLITE`, `SOURCE_SHAPE`, `SOURCE_DEFAULT`,
            `SOURCE_BSTAR`, or the calibrations' and the history fit's names).
        report: What JSON says about it (the calibration, the fit, the shape's gas).
    """

    satellite: Satellite
    source: str
    report: dict[str, Any] = field(default_factory=dict)


def drag_source(
    inputs: SatelliteInputs,
    scenario: Any,
    inclination_deg: float,
    *,
    sphere_heights_km: tuple[float, float] | None = None,
    elements: Any = None,
    history: list[Any] | None = None,
    ascending_node_local_time_h: float | None = None,
) -> DragSource:
    """The satellite and its drag parameter's source (see the module docstring).

    Args:
        inputs: What the analyst said about the satellite.
        scenario: The scenario in the 6371 km sphere's heights (`Scenario.in_sphere_heights`).
        inclination_deg: The orbit's inclination.
        sphere_heights_km: Start perigee and apogee above the sphere (for a shape's C_D).
        elements: The element set the orbit came from (its latest, for a history).
        history: Several element sets of one object, oldest first.
        ascending_node_local_time_h: For a shape's gas in a Sun-synchronous orbit.

    Raises:
        ValueError: inputs that do not go together, or an element set without decay.
    """
    if inputs.given and inputs.drag_from is not None:
        flags = {"--mass": inputs.mass_kg, "--area": inputs.area_m2, "--mass-per-area": inputs.mass_per_area_kg_m2}
        flags.update({"--cx": inputs.drag_coefficient, "--shape": inputs.shape})
        named = ", ".join(name for name, value in flags.items() if value is not None)
        raise ValueError(
            f"--drag-from chooses what an element set's drag is read from; the satellite given ({named}) flies "
            "its own drag instead: drop one of them"
        )
    cx = PAPER_DRAG_COEFFICIENT if inputs.drag_coefficient is None else inputs.drag_coefficient
    body = shape_of(inputs)
    if body is not None:
        if inputs.mass_kg is None:
            raise ValueError("--shape needs --mass (the drag parameter is C_D A / m)")
        if inputs.area_m2 is not None or inputs.mass_per_area_kg_m2 is not None:
            raise ValueError("--shape sets the area; do not give --area or --mass-per-area")
        report: dict[str, Any] = {"shape": body.description, "reference_area_m2": body.reference_area_m2}
        if inputs.drag_coefficient is None and sphere_heights_km is None:  # a batch: no one orbit's gas
            raise ValueError(
                "--shape in a batch gives the satellite's area only: give --cx too (the free-molecular coefficient "
                "is computed at one orbit, by orbit-env lifetime --shape without --batch)"
            )
        if inputs.drag_coefficient is None:
            cx, gas = shape_drag_coefficient(
                body, sphere_heights_km, inclination_deg, scenario, ascending_node_local_time_h
            )
            report.update(gas)
        return DragSource(make_satellite(cx, inputs.mass_kg, body.reference_area_m2), SOURCE_SHAPE, report)
    no_fit = None
    if not inputs.given and history is not None:
        if inputs.drag_from is not None:
            raise ValueError("--drag-from chooses what one element set gives; a history's drag is fitted to its decay")
        try:
            fit = fit_history(history, scenario)
        except NoHistoryToFit as why:  # the latest set alone, as for a file of one set, and the report says why
            no_fit = f"no history fit: {why}; from the latest set alone"
        else:
            report = {"drag_fit": fit.report()}
            satellite = _drag_satellite(fit.drag_parameter_m2_kg, "the decay between the sets")
            return DragSource(satellite, SOURCE_HISTORY_FIT, report)
    if not inputs.given and elements is not None and elements.bstar_per_earth_radius is not None:
        c, source, calibration_report = drag_from_elements(elements, scenario, inputs.drag_from or DRAG_FROM_DEFAULT)
        report = {"bstar_per_earth_radius": elements.bstar_per_earth_radius, "ndot_rev_day2": elements.ndot_rev_day2}
        report.update(calibration_report)
        if no_fit is not None:
            report["drag_note"] = no_fit
        # c_x 1 on an area of c m^2 per kg: the drag parameter is what the decay uses.
        return DragSource(_drag_satellite(c, f"the element set ({READ_AS[source]})"), source, report)
    satellite = make_satellite(cx, inputs.mass_kg, inputs.area_m2, inputs.mass_per_area_kg_m2)
    return DragSource(satellite, SOURCE_SATELLITE if inputs.given else SOURCE_DEFAULT)


def shape_of(inputs: SatelliteInputs) -> Any:
    """The `orbit_env.analysis.shapes.Shape` the inputs describe, or None without ``shape``.

    Raises:
        ValueError: a shape without its dimensions, or a dimension that is not its shape's (named by flag).
    """
    from orbit_env.analysis.shapes import SHAPE_DIMENSIONS, SHAPES, make_shape

    def flag(name: str) -> str:
        return "--" + name.replace("_", "-")

    names = dict.fromkeys(name for takes in SHAPE_DIMENSIONS.values() for name in takes)  # each once, in order
    dimensions = {name: getattr(inputs, name) for name in names}
    needs = SHAPE_DIMENSIONS.get(inputs.shape or "", ())
    for name, value in dimensions.items():
        if value is not None and name not in needs:
            owners = " or ".join(shape for shape, takes in SHAPE_DIMENSIONS.items() if name in takes)
            raise ValueError(f"{flag(name)} goes with --shape {owners}")
    if inputs.shape is None:
        return None
    if inputs.shape not in SHAPES:
        raise ValueError(f"unknown shape {inputs.shape!r}; known: {', '.join(SHAPES)}")
    missing = [flag(name) for name in needs if dimensions[name] is None]
    if missing:
        raise ValueError(f"--shape {inputs.shape} needs {' and '.join(missing)}")
    return make_shape(inputs.shape, **dimensions)


def _drag_satellite(c: float, where: str) -> Satellite:
    """The satellite of a drag parameter read from element sets (c_x 1 on c m^2 per kg), or an error saying so.

    The satellite's own check names its mass per area and area, which the user never gave.
    """
    try:
        return Satellite(1.0, 1.0, c)
    except ValueError:
        raise ValueError(
            f"{where} gives a drag parameter c_x A/m = {c:.4g} m^2/kg (G/F = {1.0 / c:.4g} kg/m^2 at c_x 1), "
            "outside any satellite's; give the satellite: --mass and --area (or --shape)"
        ) from None


class NoDragInSet(ValueError):
    """An element set whose decay term (B* or ndot, ``value`` as the set gives it) is not above zero."""

    def __init__(self, value: str) -> None:
        self.value = value
        super().__init__(
            f"the element set's {value} gives no drag parameter (it must be above 0); give the satellite: "
            "--mass and --area (or --shape)"
        )


def drag_from_elements(elements: Any, scenario: Any, how: str = DRAG_FROM_DEFAULT) -> tuple[float, str, dict[str, Any]]:
    """The drag parameter one element set carries: (c [m^2/kg], its source's name, the calibration's report).

    ``how``: one of `DRAG_FROM_CHOICES` (``bstar``, ``ndot``: calibrated to ``scenario``'s air at
    the set's epoch; ``bstar-raw``: 2 B*/rho0 against SGP4's own density).

    Raises:
        NoDragInSet: the set carries no decay (B* or ndot not above zero): give the satellite.
    """
    if how == "bstar-raw":
        c = elements.drag_parameter_m2_kg
        if c is None:
            raise NoDragInSet(f"B* = {elements.bstar_per_earth_radius:g} /ER")
        return c, SOURCE_BSTAR, {}
    source = DRAG_FROM_SOURCES[how]
    calibration = calibrate(elements, scenario, source=source)
    if calibration is None:
        raise NoDragInSet(
            f"ndot = {elements.ndot_rev_day2:g} rev/day^2"
            if source == SOURCE_NDOT_CALIBRATED
            else f"B* = {elements.bstar_per_earth_radius:g} /ER"
        )
    return calibration.drag_parameter_m2_kg, calibration.source, calibration.report()


def shape_drag_coefficient(
    body: Any,
    sphere_heights_km: tuple[float, float],
    inclination_deg: float,
    scenario: Any,
    ascending_node_local_time_h: float | None = None,
) -> tuple[float, dict[str, Any]]:
    """The shape's C_D at the start orbit's mean height in the scenario's gas (NRLMSIS), and what to report."""
    from orbit_env.analysis.shapes import drag_at_start

    hp, ha = sphere_heights_km
    # An air without a temperature of its own gives NRLMSIS's gas at moderate activity (Air.gas_activity).
    activity, start = scenario.air.gas_activity()
    if start is not None:
        indices = activity.indices(start)
    else:
        indices = (activity.f107_sfu, activity.f107a_sfu, activity.ap)
    date = None if start is None else str(np.datetime64(round(start * 86400.0), "s"))
    result = drag_at_start(
        body,
        0.5 * (hp + ha) * 1e3,
        inclination_deg,
        tuple(float(x) for x in indices),
        date,
        ascending_node_local_time_h=ascending_node_local_time_h,
        rotating_atmosphere=True,
    )
    return result.drag_coefficient, {
        "drag_coefficient": result.drag_coefficient,
        "speed_ratio": result.speed_ratio,
        "gas_temperature_k": result.temperature_k,
    }


def drag_sigma(source: DragSource) -> float | None:
    """The drag parameter's log-normal sigma: a history's from its fit, one set's measured, else None.

    None: the uncertainty's default, a known satellite's drag coefficient.
    """
    if "drag_fit" in source.report:
        return float(source.report["drag_fit"]["sigma_ln"])
    one_set = (SOURCE_BSTAR_CALIBRATED, SOURCE_NDOT_CALIBRATED, SOURCE_BSTAR)
    return ONE_SET_DRAG_SIGMA if source.source in one_set else None


def _beyond_the_curves(elements: Any, offset_m: float) -> str:
    """Why a batch cannot decay an element set's orbit, in the row's own heights (km flown, as its columns)."""
    from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M

    limits_m = (REENTRY_ALTITUDE_M, CURVES_MAX_PERIGEE_M, CURVES_MAX_APOGEE_M)
    low, top, apogee_top = ((h - offset_m) / 1e3 for h in limits_m)
    flown = f"the orbit flown, {elements.flown_perigee_km:.1f} x {elements.flown_apogee_km:.1f} km"
    if elements.flown_perigee_km < low:
        return f"{flown}, has its perigee below the re-entry height ({low:.1f} km here): it is re-entering"
    return (
        f"{flown}, is outside the universal curves, on which a batch decays (perigee {low:.1f} to {top:.1f} km, "
        f"apogee up to {apogee_top:.1f} km here); orbit-env lifetime --tle follows it by the averaged equations"
    )


def element_set_orbits(
    sets: list[Any],
    satellite: Satellite,
    scenario: Any,
    *,
    satellite_given: bool,
    offset_m: float = 0.0,
    drag_from: str | None = None,
    bad_sets: Sequence[Any] = (),
    progress: bool = False,
) -> BatchOrbits:
    """A batch of element sets as orbits in the sphere's heights [m] (``offset_m`` added), one row an object.

    Each object's sets are its history: its row starts from its latest set, the heights of
    the orbit flown, its inclination and, unless ``satellite`` is given, the drag fitted to
    the decay between its sets; an object with one set has its drag read from it as ``drag_from``
    says (`drag_from_elements`: by default its B* calibrated to ``scenario``'s air, in the sphere's
    heights). With ``satellite_given`` every row flies ``satellite``. A row that cannot be decayed
    says why in its status, naming the set's line (or record); so does an object with a set that could not be
    read (``bad_sets``, `orbit_env.analysis.elements.BadSet`): the batch goes on without it.
    Each row says where its drag came from (``drag_parameter_source``, as JSON's for one lifetime).
    ``progress``: a bar of the objects whose drag is read or fitted (a history's fit, cold, takes NRLMSIS
    over each day of its span: 13 s of nothing for 34 objects before the lifetimes' bar).
    """
    from tqdm import tqdm  # here, not at the top: a command that reads no batch does not import it

    from orbit_env.decay.curves import UniversalCurves

    histories: dict[str, list[Any]] = {}
    for s in sets:
        histories.setdefault(s.catalogue_number, []).append(s)
    objects = [sorted(history, key=lambda s: s.epoch_days) for history in histories.values()]
    latest = [history[-1] for history in objects]
    unread = {}  # catalogue number -> the first set of it that could not be read
    for bad in bad_sets:
        unread.setdefault(bad.catalogue_number, bad)
    only_unread = [(number, bad) for number, bad in unread.items() if number not in histories]
    # The catalogue number is the row's id (a name line would otherwise hide it).
    rows = [{"name": s.name, "id": s.catalogue_number} for s in latest]
    rows += [{"name": bad.name or number, "id": number} for number, bad in only_unread]
    n = len(rows)
    hp = np.full(n, np.nan)
    ha = np.full(n, np.nan)
    inc = np.full(n, np.nan)
    epochs = np.full(n, np.nan)
    hp[: len(latest)] = np.array([s.flown_perigee_km for s in latest]) * 1e3 + offset_m
    ha[: len(latest)] = np.array([s.flown_apogee_km for s in latest]) * 1e3 + offset_m
    inc[: len(latest)] = [s.inclination_deg for s in latest]
    epochs[: len(latest)] = [s.epoch_days for s in latest]
    c = np.full(n, satellite.drag_parameter_m2_kg)
    sigma = np.full(n, np.nan)
    status = ["ok"] * len(latest) + [bad.message for _, bad in only_unread]
    source = [SOURCE_SATELLITE] * n
    shown = progress and not satellite_given
    pairs = tqdm(zip(latest, objects, strict=True), total=len(latest), disable=not shown, unit="obj", desc="drag")
    for i, (s, history) in enumerate(pairs):
        if s.catalogue_number in unread:
            status[i] = f"{unread[s.catalogue_number].message}; the object's other sets are not used"
            continue
        if satellite_given:
            continue
        try:
            fit = None
            if len(history) > 1:
                with contextlib.suppress(NoHistoryToFit):  # else the latest set alone, as for an object of one set
                    fit = fit_history(history, scenario)
            if fit is not None:
                c[i], sigma[i], source[i] = fit.drag_parameter_m2_kg, fit.sigma_ln, SOURCE_HISTORY_FIT
            else:
                c[i], source[i], _ = drag_from_elements(s, scenario, drag_from or DRAG_FROM_DEFAULT)
                sigma[i] = ONE_SET_DRAG_SIGMA
        except NoDragInSet as error:  # the satellite of the command line would fly every row: not offered
            status[i] = f"{s.where}: {error.value} gives no drag parameter"
        except ValueError as error:
            status[i] = f"{s.where}: {error}"
    for i in range(n):
        if status[i] == "ok":
            try:
                UniversalCurves.check_domain(hp[i], ha[i])
            except ValueError:  # its message names metres above the sphere; the row shows km flown
                status[i] = f"{latest[i].where}: {_beyond_the_curves(latest[i], offset_m)}"
        if status[i] != "ok" or satellite_given:
            source[i] = SOURCE_SATELLITE if satellite_given else ""
        if status[i] != "ok" and not satellite_given:
            c[i] = np.nan  # no drag was read: the row shows none
        rows[i][DRAG_SOURCE_KEY] = source[i]
    return BatchOrbits(rows, hp, ha, c, inc, status, sigma, epochs)
