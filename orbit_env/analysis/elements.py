"""Element sets: two- and three-line element sets (TLE), OMM records and mean elements, read into orbits and drag.

An analyst's orbit is an element set from CelesTrak or Space-Track, as a TLE or as an
Orbit Mean-Elements Message (OMM, CCSDS 502.0-B-3: the same SGP4 elements by name, in JSON,
CSV or XML, the form CelesTrak recommends since catalogue numbers outgrow the TLE's five
columns), or a mean semi-major axis and eccentricity. This module reads both through the
``sgp4`` package (Brandon Rhodes, MIT licence; Vallado et al. 2006, "Revisiting Spacetrack
Report #3"), after checking each line's layout and checksum, or each record's fields,
itself so that a malformed set is a one-line error naming the file's line or record.

Units: km for heights and the semi-major axis (the user's units), unix days for the
epoch, m^2/kg for the drag parameter. Heights from elements are above the WGS84
equatorial radius, as catalogues quote them: ``a (1 - e) - 6378.137 km`` and
``a (1 + e) - 6378.137 km``. Mean elements are not the orbit flown: J2's short-period
terms put the flown orbit's mean radius `ElementSet.flown_offset_km` away (-9.7 km at
0 deg, +4.6 km at 97.5 deg for a 400 km orbit); the decay starts from the flown heights.

The drag parameter from B*: SGP4's B* = (C_D A / m) rho0 / 2 with the reference
density rho0 = 0.15696615 kg/(m^2 ER) (Vallado, *Fundamentals of Astrodynamics and
Applications*, 4th ed., section 9.7.2), so ``C_D A / m = 2 B* / rho0``. B* is a
fitted parameter: it absorbs density-model errors too, and can be zero or negative,
in which case no drag parameter follows from it (give the satellite instead).
"""

from __future__ import annotations

import calendar
import json
import math
import re
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any, NamedTuple

from orbit_env.checks import DATE_RANGE, check_number
from orbit_env.constants import EARTH_EQUATORIAL_RADIUS_M

#: SGP4's reference density of B* [kg/(m^2 ER)]: C_D A / m = 2 B* / rho0.
BSTAR_REFERENCE_DENSITY = 0.15696615
#: WGS84 equatorial radius [km], the surface element-set heights are quoted above.
EQUATORIAL_RADIUS_KM = EARTH_EQUATORIAL_RADIUS_M / 1e3
#: Length of a TLE line (69 columns, the last one the checksum).
TLE_LINE_LENGTH = 69


def _iso(epoch_days: float) -> str:
    """Unix days as ISO 8601 UTC to the second."""
    import numpy as np

    return str(np.datetime64(round(epoch_days * 86400.0), "s")) + "Z"


def tle_checksum(line: str) -> int:
    """The checksum of a TLE line's first 68 columns: the sum of its digits, each '-' counting 1, mod 10."""
    return sum(int(ch) if ch.isdigit() else 1 if ch == "-" else 0 for ch in line[:68]) % 10


@dataclass(frozen=True)
class ElementSet:
    """One satellite's mean elements at an epoch.

    Attributes:
        name: The satellite's name (a three-line set's line 0), or the catalogue number.
        epoch_days: Epoch, unix days (UTC).
        semi_major_axis_km: Mean semi-major axis (for a TLE: SGP4's Brouwer mean, from the mean motion).
        eccentricity: Mean eccentricity.
        inclination_deg: Inclination.
        bstar_per_earth_radius: SGP4's drag term B* [1/ER] (None: not from a TLE).
        line: The file's line number of the set's first line (0: not from a file).
        ndot_rev_day2: The first derivative of the mean motion [rev/day^2], twice line 1's
            ndot / 2 (None: not from a TLE).
        catalogue_number: The satellite's catalogue number (line 1, columns 3-7; an OMM's NORAD_CAT_ID;
            "" if none).
        record: The set's record in an OMM JSON or XML file, from 1 (0: a TLE's or CSV's, placed by ``line``).
    """

    name: str
    epoch_days: float | None
    semi_major_axis_km: float
    eccentricity: float
    inclination_deg: float
    bstar_per_earth_radius: float | None = None
    line: int = 0
    ndot_rev_day2: float | None = None
    catalogue_number: str = ""
    record: int = 0

    @property
    def where(self) -> str:
        """Where the set is in its file, for messages: ``line 12`` or ``record 3``."""
        return f"record {self.record}" if self.record else f"line {self.line}"

    @property
    def perigee_km(self) -> float:
        """Perigee height above the equatorial radius, a (1 - e) - 6378.137 km."""
        return self.semi_major_axis_km * (1.0 - self.eccentricity) - EQUATORIAL_RADIUS_KM

    @property
    def apogee_km(self) -> float:
        """Apogee height above the equatorial radius, a (1 + e) - 6378.137 km."""
        return self.semi_major_axis_km * (1.0 + self.eccentricity) - EQUATORIAL_RADIUS_KM

    @property
    def flown_offset_km(self) -> float:
        """The orbit flown's mean radius above the mean elements' (J2's short-period terms averaged), km.

        See `orbit_env.physics.oblateness.mean_to_flown_radius_offset_m`.
        """
        from orbit_env.physics.oblateness import mean_to_flown_radius_offset_m

        return float(mean_to_flown_radius_offset_m(self.semi_major_axis_km * 1e3, self.inclination_deg)) / 1e3

    @property
    def flown_perigee_km(self) -> float:
        """Perigee height of the orbit flown above the equatorial radius: the mean one plus `flown_offset_km`."""
        return self.perigee_km + self.flown_offset_km

    @property
    def flown_apogee_km(self) -> float:
        """Apogee height of the orbit flown above the equatorial radius: the mean one plus `flown_offset_km`."""
        return self.apogee_km + self.flown_offset_km

    @property
    def drag_parameter_m2_kg(self) -> float | None:
        """C_D A / m = 2 B* / rho0 [m^2/kg]; None when there is no positive B*."""
        if self.bstar_per_earth_radius is None or self.bstar_per_earth_radius <= 0.0:
            return None
        return 2.0 * self.bstar_per_earth_radius / BSTAR_REFERENCE_DENSITY

    @property
    def epoch_iso(self) -> str | None:
        """The epoch as ISO 8601 UTC to the second (None without an epoch)."""
        return None if self.epoch_days is None else _iso(self.epoch_days)

    def measured_at(self, days: float) -> bool:
        """Whether ``days`` [unix days] is the set's epoch (the same second, any form): where a decay of it starts."""
        return self.epoch_days is not None and abs(days - self.epoch_days) <= 1.0 / 86400.0


def mean_elements(semi_major_axis_km: float, eccentricity: float, inclination_deg: float = 0.0) -> ElementSet:
    """An element set from a mean semi-major axis and eccentricity (heights above the equatorial radius).

    Raises:
        InputError: a value out of range (eccentricity in [0, 1), perigee above the surface).
    """
    e = check_number(eccentricity, "eccentricity", low=0.0, high=1.0, high_inclusive=False)
    a = check_number(
        semi_major_axis_km,
        "semi_major_axis_km",
        unit="km",
        low=EQUATORIAL_RADIUS_KM / (1.0 - e),
        why="the perigee a (1 - e) must be above the equatorial radius 6378.137 km",
        low_inclusive=False,
    )
    inc = check_number(inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
    return ElementSet("mean elements", None, a, e, inc)


def _check_line(text: str, number: str, where: str) -> None:
    """Raise ValueError naming ``where`` if ``text`` is not a well-formed TLE line ``number``."""
    if len(text) != TLE_LINE_LENGTH:
        raise ValueError(f"{where}: a TLE line has {TLE_LINE_LENGTH} columns, this one {len(text)}")
    if not text.startswith(number + " "):
        raise ValueError(f"{where}: expected TLE line {number}, found {text[:10]!r}")
    if not text[68].isdigit():
        raise ValueError(f"{where}: the last column must be the checksum digit, found {text[68]!r}")
    expected = tle_checksum(text)
    if int(text[68]) != expected:
        raise ValueError(f"{where}: bad checksum {text[68]} (the line sums to {expected})")


#: A number of the fields the layout gives (columns of Spacetrack Report #3; CelesTrak's "NORAD Two-Line
#: Element Set Format"), as a regular expression on the field's text.
_DECIMAL = re.compile(r"^ *[+-]?\d*\.\d+$|^ *[+-]?\d+\.?\d*$")
#: Line 1's "assumed decimal point" fields (B*, the second derivative): a sign, five digits, an exponent.
_ASSUMED_DECIMAL = re.compile(r"^[ +-]\d{5}[ +-]\d$")
#: (line, first column, last column (1-based, inclusive), field, pattern, lowest, highest): what each field may hold.
_FIELDS = (
    (1, 19, 20, "epoch year", re.compile(r"^\d\d$"), -math.inf, math.inf),
    (1, 21, 32, "epoch day of the year", re.compile(r"^ *\d{1,3}\.\d+$"), 1.0, 366.99999999),
    (1, 34, 43, "first derivative of the mean motion", _DECIMAL, -math.inf, math.inf),
    (1, 45, 52, "second derivative of the mean motion", _ASSUMED_DECIMAL, -math.inf, math.inf),
    (1, 54, 61, "B*", _ASSUMED_DECIMAL, -math.inf, math.inf),
    (2, 9, 16, "inclination [deg]", _DECIMAL, 0.0, 180.0),
    (2, 18, 25, "right ascension of the ascending node [deg]", _DECIMAL, 0.0, 360.0),
    (2, 27, 33, "eccentricity (seven digits, decimal point assumed)", re.compile(r"^\d{7}$"), -math.inf, math.inf),
    (2, 35, 42, "argument of perigee [deg]", _DECIMAL, 0.0, 360.0),
    (2, 44, 51, "mean anomaly [deg]", _DECIMAL, 0.0, 360.0),
    (2, 53, 63, "mean motion [rev/day]", _DECIMAL, 0.0, 20.0),
)


def _check_fields(line1: str, line2: str, where1: str, where2: str) -> None:
    """Raise ValueError naming the line, the columns and the field if a number of the set is not one it may hold.

    SGP4's reader takes what it can from a damaged field (a blank epoch year, letters in B*, day 400 of a
    year), which would fly a wrong orbit or date with no word; its own errors name no field.
    """
    for line_number, first, last, field, pattern, lowest, highest in _FIELDS:
        line, where = (line1, where1) if line_number == 1 else (line2, where2)
        text = line[first - 1 : last]
        if field == "epoch day of the year" and line1[18:20].isdigit():  # 365 days in a common year
            year = int(line1[18:20]) + (1900 if int(line1[18:20]) >= 57 else 2000)
            highest = 366.99999999 if calendar.isleap(year) else 365.99999999
        if not pattern.match(text):
            raise ValueError(f"{where}, columns {first}-{last}: the {field} reads {text!r}, not a number of its form")
        if (math.isfinite(lowest) or math.isfinite(highest)) and not lowest <= float(text) <= highest:
            allowed = f"{lowest:.12g} to {highest:.12g}"
            raise ValueError(f"{where}, columns {first}-{last}: the {field} is {text.strip()}; allowed: {allowed}")


def parse_tle(
    line1: str, line2: str, name: str | None = None, *, source: str = "TLE", first_line: int = 1
) -> ElementSet:
    """One element set from its two lines (through ``sgp4``).

    Args:
        line1: TLE line 1.
        line2: TLE line 2.
        name: The satellite's name (line 0 of a three-line set).
        source: The file's name, for messages.
        first_line: The file's line number of ``line1``, for messages.

    Raises:
        ValueError: a line's layout or checksum is wrong, the two lines name different
            satellites, or SGP4 refuses the elements; the message names the line.
    """
    from sgp4.api import WGS72, Satrec

    line1, line2 = line1.rstrip(), line2.rstrip()
    where1, where2 = f"{source}, line {first_line}", f"{source}, line {first_line + 1}"
    _check_line(line1, "1", where1)
    _check_line(line2, "2", where2)
    _check_fields(line1, line2, where1, where2)
    if line1[2:7] != line2[2:7]:
        raise ValueError(f"{where2}: catalogue number {line2[2:7].strip()} differs from line 1's {line1[2:7].strip()}")
    try:
        satrec = Satrec.twoline2rv(line1, line2, WGS72)
    except ValueError as error:
        raise ValueError(f"{where1}: cannot read the element set ({error})") from None
    return _from_satrec(
        satrec,
        where1,
        "columns 19-32",
        name=(name or line1[2:7]).strip(),
        line=first_line,
        ndot_rev_day2=2.0 * float(line1[33:43]),
        catalogue_number=line1[2:7].strip(),
    )


def _from_satrec(satrec: Any, where: str, epoch_field: str, **identity: Any) -> ElementSet:
    """The element set of an initialised ``sgp4`` Satrec (``identity``: `ElementSet`'s other fields).

    Raises:
        ValueError: SGP4 refuses the elements, or the epoch (``epoch_field`` of ``where``) is before Sputnik 1.
    """
    if satrec.error != 0:
        raise ValueError(f"{where}: SGP4 refuses the elements (error {satrec.error}: {_SGP4_ERRORS.get(satrec.error)})")
    epoch_days = (satrec.jdsatepoch - 2440587.5) + satrec.jdsatepochF
    (first_day, first_date), _ = DATE_RANGE  # a TLE's two-digit years reach 2056 at most
    if epoch_days < first_day:
        two_digits = " (a two-digit year 57-99 is 1957-1999)" if epoch_field.startswith("columns") else ""
        raise ValueError(
            f"{where}, {epoch_field}: the epoch is {_iso(epoch_days)}{two_digits}; "
            f"allowed: from {first_date} (no satellite flew before Sputnik 1)"
        )
    # satrec.a is the Brouwer mean semi-major axis in Earth radii (of the WGS72 constants SGP4 uses).
    return ElementSet(
        epoch_days=epoch_days,
        semi_major_axis_km=satrec.a * satrec.radiusearthkm,
        eccentricity=satrec.ecco,
        inclination_deg=math.degrees(satrec.inclo),
        bstar_per_earth_radius=satrec.bstar,
        **identity,
    )


_SGP4_ERRORS = {
    1: "mean eccentricity out of range",
    2: "mean motion below zero",
    3: "perturbed eccentricity out of range",
    4: "semi-latus rectum below zero",
    6: "the orbit has decayed",
}


class BadSet(NamedTuple):
    """An element set that could not be read (`parse_tle_text` with ``bad``): where, whose, and why."""

    line: int  # the file's line of its TLE line 1 (an OMM's line or record)
    catalogue_number: str  # as line 1 gives it (columns 3-7), or the OMM's NORAD_CAT_ID
    name: str | None  # its name line, if any
    message: str  # what is wrong, naming the line (without the file's name)


def parse_tle_text(
    lines: str | Iterable[str], source: str = "TLE", bad: list[BadSet] | None = None
) -> list[ElementSet]:
    """Every element set of a text in CelesTrak's format: two-line sets, or three-line sets with a name line.

    ``lines``: the text's lines, or the text itself (one string).

    Text as people paste it is read: lines may be indented, end in spaces, tabs or CRLF,
    and a set may have no name line. Blank lines are skipped; a name line is any line that
    does not start with ``1 `` or ``2 `` (a leading ``0 `` is dropped, as Space-Track writes it).
    With ``bad`` (a list), a set whose lines are in place but do not read (a bad checksum, columns,
    or elements SGP4 refuses) is appended to it and skipped, as a batch reads its file.

    Raises:
        ValueError: a malformed set (the message names the file's line and what is wrong), or no set at all.
    """
    if isinstance(lines, str):
        lines = lines.splitlines()
    numbered = [(i + 1, text.strip()) for i, text in enumerate(lines)]
    numbered = [(i, text) for i, text in numbered if text.strip()]
    sets: list[ElementSet] = []
    k = 0
    while k < len(numbered):
        number, text = numbered[k]
        name = None
        if not text.startswith(("1 ", "2 ")):
            name = text[2:] if text.startswith("0 ") else text
            k += 1
            if k >= len(numbered):
                raise ValueError(f"{source}, line {number}: a name line without its two element lines")
            number, text = numbered[k]
        if k + 1 >= len(numbered):
            raise ValueError(f"{source}, line {number}: TLE line 1 without its line 2")
        next_number, next_text = numbered[k + 1]
        if next_number != number + 1:
            raise ValueError(f"{source}, line {number + 1}: expected TLE line 2, found a blank line")
        try:
            sets.append(parse_tle(text, next_text, name, source=source, first_line=number))
        except ValueError as error:
            if bad is None:
                raise
            bad.append(BadSet(number, text[2:7].strip(), name, str(error).removeprefix(f"{source}, ")))
        k += 2
    if not sets and not bad:
        raise ValueError(f"{source}: no element set found")
    return sets


def read_tle(path: str | Path, bad: list[BadSet] | None = None) -> list[ElementSet]:
    """The element sets of a file (``-``: standard input): TLEs or OMM records (`parse_element_sets`).

    Raises:
        ValueError: a malformed set, naming the line (or the record).
        OSError: the file cannot be read.
    """
    if str(path) == "-":
        data = sys.stdin.buffer.read() if hasattr(sys.stdin, "buffer") else sys.stdin.read().encode()
        return parse_element_sets(_text(data), "<stdin>", bad)
    with open(path, "rb") as handle:
        return parse_element_sets(_text(handle.read()), str(path), bad)


def parse_element_sets(text: str, source: str = "TLE", bad: list[BadSet] | None = None) -> list[ElementSet]:
    """Every element set of a text: TLEs (`parse_tle_text`) or OMM records in JSON, CSV or XML (`parse_omm_text`).

    The form is told by the text itself (`omm_format`); ``bad`` as `parse_tle_text`'s.
    """
    if omm_format(text) is not None:
        return parse_omm_text(text, source, bad)
    return parse_tle_text(_lines(text), source, bad)


#: The OMM fields an SGP4 element set needs (CCSDS 502.0-B-3's keywords, as CelesTrak and Space-Track name them).
OMM_FIELDS = (
    "EPOCH",
    "MEAN_MOTION",
    "ECCENTRICITY",
    "INCLINATION",
    "RA_OF_ASC_NODE",
    "ARG_OF_PERICENTER",
    "MEAN_ANOMALY",
    "NORAD_CAT_ID",
    "BSTAR",
    "MEAN_MOTION_DOT",
    "MEAN_MOTION_DDOT",
)
#: The OMM keywords of the TLE's fields that `_FIELDS` bounds.
_OMM_OF_TLE_FIELD = {
    "inclination [deg]": "INCLINATION",
    "right ascension of the ascending node [deg]": "RA_OF_ASC_NODE",
    "argument of perigee [deg]": "ARG_OF_PERICENTER",
    "mean anomaly [deg]": "MEAN_ANOMALY",
    "mean motion [rev/day]": "MEAN_MOTION",
}
#: The bounds of an OMM's numbers: those of the same fields of a TLE (`_FIELDS`, whose seven eccentricity digits
#: bound it by their form), and the eccentricity's, its top excluded.
_OMM_BOUNDS = {
    **{_OMM_OF_TLE_FIELD[field]: (low, high) for *_, field, _, low, high in _FIELDS if field in _OMM_OF_TLE_FIELD},
    "ECCENTRICITY": (0.0, 1.0),
}


def omm_format(text: str) -> str | None:
    """``"json"``, ``"xml"`` or ``"csv"`` for an OMM text, else None (a TLE's text, or none's).

    Told by the first characters, or for CSV by a header naming the elements (NORAD_CAT_ID, EPOCH,
    MEAN_MOTION, ECCENTRICITY) and no ``perigee_km``: a catalogue of orbits may carry a catalogue
    number and an epoch among its columns.
    """
    start = text.lstrip()
    if start.startswith(("[", "{")):
        return "json"
    if start.startswith("<"):
        return "xml"
    header = {name.strip().strip('"').upper() for name in start.split("\n", 1)[0].split(",")}
    if {"NORAD_CAT_ID", "EPOCH", "MEAN_MOTION", "ECCENTRICITY"} <= header and "PERIGEE_KM" not in header:
        return "csv"
    return None


def parse_omm_text(text: str, source: str = "OMM", bad: list[BadSet] | None = None) -> list[ElementSet]:
    """Every element set of an OMM text: JSON (an array of records, or one), CSV (a header row), or XML (CCSDS).

    The keywords are CCSDS's (`OMM_FIELDS`, in any case); numbers may be JSON numbers or text,
    and other fields (SEMIMAJOR_AXIS, DECAY_DATE, ... as Space-Track adds) are ignored. A JSON
    or XML record is named by its place (``record 3``), a CSV one by its line. With ``bad``, a
    record that does not read is appended to it and skipped (as `parse_tle_text`'s).

    Raises:
        ValueError: text that is not JSON, CSV or XML of records, a record without a field or with
            a field out of its bounds (the message names the record and the field), or no record.
    """
    form = omm_format(text)
    records: list[tuple[int, int, dict[str, Any]]] = []  # (line, record, fields)
    if form == "json":
        try:
            data = json.loads(text)
        except ValueError as error:
            raise ValueError(f"{source}: not a JSON text ({error})") from None
        for k, record in enumerate(data if isinstance(data, list) else [data], start=1):
            if not isinstance(record, dict):
                raise ValueError(f"{source}, record {k}: an OMM record is an object of named fields")
            records.append((0, k, record))
    elif form == "xml":
        from xml.etree import ElementTree

        try:
            root = ElementTree.fromstring(text)
        except ElementTree.ParseError as error:
            raise ValueError(f"{source}: not an XML text ({error})") from None
        segments = [e for e in root.iter() if e.tag.rsplit("}", 1)[-1] == "segment"]
        for k, segment in enumerate(segments, start=1):
            leaves = (e for e in segment.iter() if len(e) == 0)
            records.append((0, k, {e.tag.rsplit("}", 1)[-1]: (e.text or "").strip() for e in leaves}))
    elif form == "csv":
        import csv

        reader = csv.DictReader(_lines(text))
        for row in reader:
            if any((value or "").strip() for value in row.values() if isinstance(value, str)):
                records.append((reader.line_num, 0, row))
    sets: list[ElementSet] = []
    for line, record, fields in records:
        where = f"{source}, record {record}" if record else f"{source}, line {line}"
        named = {str(key).strip().upper(): value for key, value in fields.items() if key is not None}
        try:
            sets.append(_omm_set(named, where, line, record))
        except ValueError as error:
            if bad is None:
                raise
            number = str(named.get("NORAD_CAT_ID", "")).strip()
            name = str(named.get("OBJECT_NAME", "")).strip() or None
            bad.append(BadSet(record or line, number, name, str(error).removeprefix(f"{source}, ")))
    if not sets and not bad:
        raise ValueError(f"{source}: no element set found")
    return sets


def _omm_set(fields: dict[str, Any], where: str, line: int, record: int) -> ElementSet:
    """One OMM record's element set (through ``sgp4.omm.initialize``), or a ValueError naming ``where``."""
    from sgp4.api import WGS72, Satrec
    from sgp4.omm import initialize

    text = {key: ("" if value is None else str(value).strip()) for key, value in fields.items()}
    missing = [key for key in OMM_FIELDS if not text.get(key)]
    if missing:
        needs = ", ".join(OMM_FIELDS)
        raise ValueError(f"{where}: the record has no {', '.join(missing)} (an OMM element set needs {needs})")
    numbers = {}
    for key in OMM_FIELDS[1:]:
        try:
            numbers[key] = value = float(text[key])
        except ValueError:
            raise ValueError(f"{where}: {key} reads {text[key]!r}, not a number") from None
        lowest, highest = _OMM_BOUNDS.get(key, (-math.inf, math.inf))
        inside = lowest <= value < highest if key == "ECCENTRICITY" else lowest <= value <= highest
        if not (math.isfinite(value) and inside):
            bounds = f"{lowest:g} to {highest:g}" if math.isfinite(highest) else "a finite number"
            excluded = f" ({highest:g} excluded)" if key == "ECCENTRICITY" else ""
            raise ValueError(f"{where}: {key} is {text[key]}; allowed: {bounds}{excluded}")
    number = numbers["NORAD_CAT_ID"]
    if number < 0 or number != int(number):
        raise ValueError(f"{where}: NORAD_CAT_ID is {text['NORAD_CAT_ID']}; allowed: a whole number from 0")
    try:
        epoch = datetime.fromisoformat(text["EPOCH"].removesuffix("Z"))
    except ValueError:
        raise ValueError(
            f"{where}: EPOCH reads {text['EPOCH']!r}, not a UTC date and time (YYYY-MM-DDThh:mm:ss.ffffff)"
        ) from None
    if epoch.tzinfo is not None:
        raise ValueError(f"{where}: EPOCH {text['EPOCH']!r} has a time zone; an OMM's epoch is UTC, without one")
    # sgp4's own reader of the record. The catalogue number is ours: SGP4 keeps five Alpha-5 characters (at
    # most 339999) and never uses it; nor does it use the set's designator, class, type and counts (neutral).
    given = {
        **text,
        "EPOCH": epoch.strftime("%Y-%m-%dT%H:%M:%S.%f"),
        "NORAD_CAT_ID": "0",
        "OBJECT_ID": "",
        "CLASSIFICATION_TYPE": "U",
        "EPHEMERIS_TYPE": "0",
        "ELEMENT_SET_NO": "0",
        "REV_AT_EPOCH": "0",
    }
    satrec = Satrec()
    initialize(satrec, given, WGS72)
    catalogue_number = str(int(number))
    return _from_satrec(
        satrec,
        where,
        "EPOCH",
        name=text.get("OBJECT_NAME") or catalogue_number,
        line=line,
        record=record,
        ndot_rev_day2=2.0 * numbers["MEAN_MOTION_DOT"],  # MEAN_MOTION_DOT is the TLE's field: ndot / 2
        catalogue_number=catalogue_number,
    )


def _lines(text: str) -> list[str]:
    """A file's lines, ended by LF, CRLF or CR only (`str.splitlines` also ends one at U+0085, a Latin-1 byte)."""
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def _text(data: bytes) -> str:
    """A file's text: UTF-8 (a byte-order mark, from Windows' editors, is no part of a name), else Latin-1.

    The sets' lines are ASCII; a name line in another encoding is read as Latin-1 (every byte is a
    character), so bytes that are no text give a message naming a line, not a decoding error naming none.
    """
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def holds_element_sets(path: str | Path) -> bool:
    """Whether a file holds element sets, TLEs or OMM records (rather than a CSV catalogue of orbits).

    A look at its start only: bytes that are not text make no element set, and the CSV reader names the file.
    """
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        start = handle.read(4096)
    if omm_format(start) is not None:
        return True
    lines = [line.strip() for line in _lines(start)[:6] if line.strip()]  # indented as pasted: as read_tle
    return any(line.startswith("1 ") and len(line) == TLE_LINE_LENGTH for line in lines[:2])
