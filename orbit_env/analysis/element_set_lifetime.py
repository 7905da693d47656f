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
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.drag_source import DragSource, SatelliteInputs, drag_source
from orbit_env.analysis.elements import ElementSet, parse_tle_text, read_tle
from orbit_env.analysis.heights import offset_km
from orbit_env.analysis.lifetime import LifetimeResult, iso_datetime, lifetime
from orbit_env.analysis.scenario import Scenario
from orbit_env.decay.solar import unix_days
from orbit_env.physics.atmosphere.msis import DEFAULT_MSIS_VERSION

#: Element sets give heights above the equatorial radius (WGS84's 6378.137 km).
REFERENCE = "equatorial"


@dataclass(frozen=True)
class ElementSetLifetime:
    """The lifetime of an element set's object, and what it rests on.

    Attributes:
        result: The decay (its heights above the 6371 km sphere, as `lifetime` takes them).
        elements: The latest set: the start.
        drag: The satellite flown, ``drag_parameter_source`` and its report (the calibration, the fit).
        history: How many sets the object's history holds (1: one set).
    """

    result: LifetimeResult
    elements: ElementSet
    drag: DragSource
    history: int

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
        scenario: The air, dated or not (default: NRLMSIS ``msis_version`` under the shipped
            record from the latest set's epoch, co-rotating); its heights are the sphere's
            and are moved to the sets' (`Scenario.in_sphere_heights`).
        msis_version: NRLMSIS 2.1, 2.0 or 0.0 (NRLMSISE-00) for the default scenario.

    Raises:
        ValueError: no sets, sets of several objects, or what `drag_source` and `lifetime` refuse.
    """
    if isinstance(sets, str) and "\n" in sets:
        parsed = parse_tle_text(sets)
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
    history = sorted(parsed, key=lambda s: s.epoch_days)
    latest = history[-1]
    inclination = latest.inclination_deg
    if scenario is None:
        from orbit_env.decay.solar_record import load_record

        # The epoch as the command line reads the set's (to the second).
        scenario = Scenario(MsisAir(load_record(), unix_days(latest.epoch_iso.rstrip("Z")), version=msis_version))
    air = scenario.in_sphere_heights(REFERENCE, inclination)
    shift = offset_km(REFERENCE)
    sphere = (latest.flown_perigee_km + shift, latest.flown_apogee_km + shift)
    drag = drag_source(
        satellite or SatelliteInputs(),
        air,
        inclination,
        sphere_heights_km=sphere,
        elements=latest,
        history=history if len(history) > 1 else None,
    )
    result = lifetime(*sphere, satellite=drag.satellite, scenario=air, inclination_deg=inclination)
    return ElementSetLifetime(result, latest, drag, len(history))
