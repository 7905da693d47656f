"""A lifetime from element sets in one call: what ``orbit-env lifetime --tle FILE`` computes, for Python.

One object's element sets (a file, TLE lines, or `ElementSet` objects) are its history: the
decay starts from the latest set's flown orbit (its mean elements turned into the orbit-averaged
heights, `ElementSet.flown_perigee_km`) at its epoch, under NRLMSIS 2.1 and the shipped record's
Sun in co-rotating air by default; its drag parameter is fitted to the decay between the sets
(a history), or calibrated from the latest set's B* (one set), unless the satellite is described
(`SatelliteInputs`: its mass and area, or its shape, win), all as `orbit_env.analysis.drag_source`
says. The same inputs give the command line's numbers (``tests/analysis/test_element_set_lifetime.py``).

Examples:
    >>> from orbit_env.analysis.element_set_lifetime import element_set_lifetime
    >>> found = element_set_lifetime("benchmarks/data/reentry_tles/41619_beesat4.tle")  # doctest: +SKIP
    >>> found.result.reentry_date, found.drag.source  # doctest: +SKIP
    ('2023-09-24T03:43Z', 'history_fit')
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.drag_source import DragSource, SatelliteInputs, drag_sigma, drag_source
from orbit_env.analysis.elements import ElementSet, parse_element_sets, parse_tle_text, read_tle
from orbit_env.analysis.heights import offset_km
from orbit_env.analysis.lifetime import LifetimeResult, iso_datetime, lifetime
from orbit_env.analysis.scenario import Scenario
from orbit_env.analysis.uncertainty import LifetimeSpread, lifetime_spread
from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.decay.solar import unix_days
from orbit_env.physics.atmosphere.msis import DEFAULT_MSIS_VERSION
from orbit_env.physics.orbit import MAX_APOGEE_M

#: Element sets give heights above the equatorial radius (WGS84's 6378.137 km).
REFERENCE = "equatorial"


def _km(value: float, decimals: int) -> str:
    """A distance in km to ``decimals`` places, or in four digits beyond any orbit (not 300 digits of 1e300)."""
    return f"{value:.{decimals}f}" if abs(value) < 1e7 else f"{value:.4g}"


def check_flown(elements: ElementSet, given: str = "the element set") -> None:
    """An orbit from mean elements that the decay can start from, or an error in the elements' own terms.

    The decay's own check would name a perigee in the 6371 km sphere's heights, which nobody typed.

    Raises:
        ValueError: the flown perigee below the surface or the re-entry height, or the apogee above the
            highest the decay follows.
    """
    shift = offset_km(REFERENCE)
    perigee, apogee = elements.flown_perigee_km, elements.flown_apogee_km
    where = (
        f"{given} (a = {_km(elements.semi_major_axis_km, 3)} km, e = {elements.eccentricity:.7f}) is flown at "
        f"{_km(perigee, 1)} x {_km(apogee, 1)} km above the equatorial radius"
    )
    reentry_km = REENTRY_ALTITUDE_M / 1e3 - shift
    if not perigee >= 0.0:
        raise ValueError(f"{where}: its perigee is below the Earth's surface, not an orbit a satellite flies")
    if not perigee + shift >= REENTRY_ALTITUDE_M / 1e3:
        raise ValueError(
            f"{where}: its perigee is below the re-entry height ({REENTRY_ALTITUDE_M / 1e3:g} km above the 6371 km "
            f"sphere, {reentry_km:.1f} km here), so it is re-entering now; no decay to follow"
        )
    if not apogee + shift <= MAX_APOGEE_M / 1e3:
        raise ValueError(
            f"{where}: its apogee is above the highest the decay follows ({MAX_APOGEE_M / 1e3:g} km above the "
            "6371 km sphere)"
        )


@dataclass(frozen=True)
class ElementSetLifetime:
    """The lifetime of an element set's object, and what it rests on.

    Attributes:
        result: The decay (its heights above the 6371 km sphere, as `lifetime` takes them).
        elements: The latest set: the start.
        drag: The satellite flown, ``drag_parameter_source`` and its report (the calibration, the fit).
        history: How many sets the object's history holds (1: one set).
        air: The scenario the decay flew, in the 6371 km sphere's heights.
    """

    result: LifetimeResult
    elements: ElementSet
    drag: DragSource
    history: int
    air: Scenario = field(compare=False, repr=False)

    def spread(self, samples: int = 1000, seed: int = 0, workers: int = 1) -> LifetimeSpread:
        """The lifetime's uncertainty, as ``--uncertainty`` samples it (`orbit_env.analysis.uncertainty`).

        The drag parameter's spread by its source (one set's calibration: wide; a history: its fit's;
        a described satellite: its drag coefficient's), the density model's and, dated, the Sun's.
        ``orbit_env.analysis.uncertainty.spread_report(spread, result.epoch_days, rule_years)`` gives the
        command's JSON keys.
        """
        sigma = drag_sigma(self.drag)
        return lifetime_spread(
            self.result.perigee_km * 1e3,
            self.result.apogee_km * 1e3,
            self.drag.satellite.drag_parameter_m2_kg,
            self.air,
            self.elements.inclination_deg,
            samples=samples,
            seed=seed,
            workers=workers,
            **({} if sigma is None else {"drag_sigma": sigma}),
        )

    @property
    def perigee_km(self) -> float:
        """The flown perigee above the equatorial radius, as the command line reports it."""
        return self.elements.flown_perigee_km

    @property
    def apogee_km(self) -> float:
        """The flown apogee above the equatorial radius."""
        return self.elements.flown_apogee_km

    def to_dict(self) -> dict[str, Any]:
        """The command line's JSON for the same inputs (``orbit-env lifetime --tle FILE --json``) but its air's line."""
        return {
            **self.result.to_dict(),
            "perigee_km": self.perigee_km,
            "apogee_km": self.apogee_km,
            "height_reference": REFERENCE,
            "inclination_deg": self.elements.inclination_deg,
            "drag_parameter_m2_kg": self.drag.satellite.drag_parameter_m2_kg,
            "drag_parameter_source": self.drag.source,
            **self.drag.report,
            **elements_report(self.elements, self.result),
        }


def elements_report(elements: ElementSet, result: LifetimeResult | None = None) -> dict[str, Any]:
    """What JSON says about an element set (and the re-entry date from its epoch, if the decay had none)."""
    report: dict[str, Any] = {
        "semi_major_axis_km": elements.semi_major_axis_km,
        "eccentricity": elements.eccentricity,
        "mean_perigee_km": elements.perigee_km,
        "mean_apogee_km": elements.apogee_km,
        "flown_offset_km": elements.flown_offset_km,
    }
    if elements.epoch_days is not None:
        report.update(name=elements.name, epoch=elements.epoch_iso)
        if result is not None and result.epoch_days is None and result.reentered:
            # A fixed atmosphere (no date in the decay): the element set's epoch still dates the re-entry.
            report["reentry_date"] = iso_datetime(elements.epoch_days + result.days)
    return report


def element_set_lifetime(
    sets: str | Path | Iterable[str] | Sequence[ElementSet],
    satellite: SatelliteInputs | None = None,
    *,
    scenario: Scenario | None = None,
    msis_version: float = DEFAULT_MSIS_VERSION,
) -> ElementSetLifetime:
    """The lifetime of one object from its element sets (see the module docstring).

    Args:
        sets: A TLE file's path, its text or lines (a name line optional, as pasted), or parsed
            sets; one object's (one catalogue number).
        satellite: What is known of the satellite (mass and area, c_x, a shape; ``drag_from``:
            what one set's drag is read from). None: the drag from the sets.
        scenario: The air (default: NRLMSIS ``msis_version`` under the shipped record from the
            latest set's epoch, co-rotating); its heights are the sphere's and are moved to the
            sets' (`Scenario.in_sphere_heights`). A dated one starts at the latest set's epoch
            (where its orbit was measured); with the drag from the sets, its scale is 1 (a drag
            calibrated or fitted to the air absorbs any scale).
        msis_version: NRLMSIS 2.1, 2.0 or 0.0 (NRLMSISE-00) for the default scenario.

    Raises:
        ValueError: no sets, sets of several objects, an orbit the decay cannot start from
            (`check_flown`), a scenario as above, or what `drag_source` and `lifetime` refuse.
    """
    if isinstance(sets, str) and "\n" in sets:
        parsed = parse_element_sets(sets)
    elif isinstance(sets, (str, Path)):
        parsed = read_tle(sets)
    else:
        items = list(sets)
        parsed = items if all(isinstance(s, ElementSet) for s in items) else parse_tle_text(items)
    if not parsed:
        raise ValueError("no element sets given")
    numbers = sorted({s.catalogue_number for s in parsed})
    if len(numbers) > 1:
        raise ValueError(
            f"element sets of {len(numbers)} objects ({', '.join(numbers)}); one object's sets are its history "
            "(orbit_env.analysis.catalogue reads several objects)"
        )
    if any(s.epoch_days is None for s in parsed):
        raise ValueError("an element set without an epoch (mean elements): give its orbit to orbit_env.lifetime")
    history = sorted(parsed, key=lambda s: s.epoch_days)
    latest = history[-1]
    check_flown(latest)
    inclination = latest.inclination_deg
    start = unix_days(latest.epoch_iso.rstrip("Z"))  # the epoch as the command line reads the set's (to the second)
    if scenario is None:
        from orbit_env.decay.solar_record import load_record

        scenario = Scenario(MsisAir(load_record(), start, version=msis_version))
    elif scenario.epoch_days is not None and not latest.measured_at(scenario.epoch_days):
        raise ValueError(
            f"the scenario starts at {np.datetime64(round(scenario.epoch_days * 86400.0), 's')}Z: the decay starts "
            "at the element set's epoch "
            f"({latest.epoch_iso}), where its orbit was measured (Scenario.at_epoch moves a scenario there)"
        )
    inputs = satellite or SatelliteInputs()
    if inputs.drag_absorbs_scale and scenario.density_scale != 1.0:
        raise ValueError(
            f"a density scale of {scenario.density_scale:g} changes nothing when the drag is calibrated to the air "
            "from element sets (the calibration absorbs it); to fly a scale, describe the satellite"
        )
    air = scenario.in_sphere_heights(REFERENCE, inclination)
    shift = offset_km(REFERENCE)
    sphere = (latest.flown_perigee_km + shift, latest.flown_apogee_km + shift)
    drag = drag_source(
        inputs,
        air,
        inclination,
        sphere_heights_km=sphere,
        elements=latest,
        history=history if len(history) > 1 else None,
        ascending_node_local_time_h=getattr(scenario.air, "ascending_node_local_time_h", None),
    )
    result = lifetime(*sphere, satellite=drag.satellite, scenario=air, inclination_deg=inclination)
    return ElementSetLifetime(result, latest, drag, len(history), air)
