"""Side by side: orbit_env's dated lifetimes against satkit's numerical propagator (issue 27, item 4).

    pip install -e ".[bench]"       # satkit and satkit-data (benchmark only)
    python benchmarks/bench_satkit.py [--cases NAME ...] [--same-indices] [--daily-ap]

Both sides start from the same element set and run the same density model:

* **The element set.** Each case is a synthetic two-line set (written here, marked so,
  B* 0) whose mean elements put the mean perigee and apogee above the WGS84 equatorial
  radius (6378.137 km) at the case's values, as orbit_env reads them.
* **satkit** (`satkit.propagate`, Verner 9(8), tolerances 1e-8): SGP4's osculating state
  at the set's epoch (TEME, rotated to GCRF), then EGM2008 to degree and order 4, the Sun
  and the Moon (JPL DE440), solid tides and relativity (satkit's defaults), drag with
  NRLMSISE-00 under CelesTrak's space weather shipped in satkit-data, air co-rotating
  with the Earth; c_x A/m = 2.2 x 0.03 m^2 / 4 kg (`satproperties(cdaoverm=0.0165)`), no
  radiation pressure. Re-entry: the first 60-second step ending below 100 km geodetic
  altitude (steps of 1 day while the osculating perigee is above 220 km, 0.05 day above
  140 km); its time includes that stepping. Nothing is downloaded: offline mode,
  satkit-data's folder searched, its Earth orientation (CelesTrak's file) written in the
  columns satkit 0.24 reads (`use_shipped_data`).
* **orbit_env**: ``orbit-env lifetime --tle FILE --mass 4 --area 0.03 --cx 2.2
  --msis-version 00`` (the set's epoch, the shipped record, co-rotating air, the orbit
  flown: the mean elements plus J2's offset; ``--node-local-time`` for the Sun-synchronous
  case; on storm days NRLMSIS's storm-time mode with the record's 3-hourly ap, the default),
  timed as a whole command (a new process, disk cache warm) and in process
  (`orbit_env.lifetime` called as the command calls it, the median of five calls after a first in
  the same process).

The table also gives satkit's radius averaged over its first revolutions beside
orbit_env's flown mean radius a (1 + e^2/2): the two start on the same orbit.
``--same-indices`` (a diagnostic) runs both on the same indices: satkit on the daily Ap for
the 3-hourly ap and no radio bursts, orbit_env with ``--daily-ap`` (the daily Ap on storm
days too). ``--daily-ap`` alone runs orbit_env so against satkit's 3-hourly ap (orbit_env
before the storm-time mode). Times are wall-clock on a shared machine: read the
speed as the ratio within one run.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import numpy as np
import satkit as sk
import satkit_data

from orbit_env import Satellite, lifetime
from orbit_env.analysis.air import MsisAir
from orbit_env.analysis.elements import ElementSet, parse_tle_text, tle_checksum
from orbit_env.analysis.heights import offset_km
from orbit_env.analysis.scenario import Scenario

#: The 3U cubesat of the docs' dated examples.
CX, MASS_KG, AREA_M2 = 2.2, 4.0, 0.03
#: satkit's drag parameter, c_x A / m [m^2/kg].
CDA_OVER_M = CX * AREA_M2 / MASS_KG
#: WGS84 equatorial radius [m] (the element sets' heights are above it).
EQUATORIAL_RADIUS_M = 6378137.0
#: Earth's gravitational parameter [m^3/s^2] (EGM2008).
MU_M3_S2 = 3.986004418e14
#: Re-entry: the satellite's geodetic altitude below this [m].
REENTRY_ALTITUDE_M = 100e3
#: satkit's step [days] while the osculating perigee is above the first height [m], then the second.
COARSE_STEP = ((220e3, 1.0), (140e3, 0.05))
#: The last phase's step [s]: the re-entry time is known to it.
FINE_STEP_S = 60.0
#: Observed F10.7 above this [sfu] is a radio burst; orbit_env's record takes the 81-day mean instead.
BURST_SFU = 400.0
#: Revolutions over which the start orbit's mean radius is taken.
START_REVOLUTIONS = 4
#: orbit_env's in-process time: the median of this many calls after a first.
IN_PROCESS_CALLS = 5


@dataclass(frozen=True)
class Case:
    """One dated orbit: mean perigee and apogee [km] above the equatorial radius, angles [deg]."""

    name: str
    epoch: str
    perigee_km: float
    apogee_km: float
    inclination_deg: float
    raan_deg: float = 40.0
    argp_deg: float = 90.0
    #: Sun-synchronous: the ascending node's local solar time [h] (the set's node is placed there).
    node_local_time_h: float | None = None


CASES = (
    Case("storm-2003", "2003-10-20", 300, 320, 28.5),
    Case("iss-2024", "2024-01-01", 300, 350, 51.6),
    Case("equator-2001", "2001-11-01", 380, 400, 0.0),
    Case("sso-2009", "2009-06-01", 340, 360, 96.85, node_local_time_h=10.5),
    Case("iss-2015", "2015-03-01", 400, 420, 51.6),
    Case("ecc-65-2012", "2012-09-01", 220, 600, 65.0),
    Case("ecc-gto-2022", "2022-03-01", 200, 1000, 28.5),
    Case("ecc-polar-2019", "2019-05-01", 250, 800, 98.0),
)


def _tle_lines(case: Case, mean_motion_rev_day: float, raan_deg: float) -> list[str]:
    """Two lines of a synthetic set (catalogue number 99999, B* 0), checksums included."""
    epoch = datetime.fromisoformat(case.epoch)
    day = epoch.timetuple().tm_yday + (epoch.hour * 3600 + epoch.minute * 60 + epoch.second) / 86400.0
    e = (case.apogee_km - case.perigee_km) / (case.apogee_km + case.perigee_km + 2.0 * EQUATORIAL_RADIUS_M / 1e3)
    line1 = f"1 99999U 99999A   {epoch.year % 100:02d}{day:012.8f}  .00000000  00000-0  00000-0 0  999"
    line2 = (
        f"2 99999 {case.inclination_deg:8.4f} {raan_deg % 360.0:8.4f} {round(e * 1e7):07d} "
        f"{case.argp_deg:8.4f} {(360.0 - case.argp_deg) % 360.0:8.4f} {mean_motion_rev_day:11.8f}    1"
    )
    return [line + str(tle_checksum(line)) for line in (line1, line2)]


def _node_raan_deg(case: Case) -> float:
    """The case's right ascension of the node: its own, or the one that puts the node at its local time."""
    if case.node_local_time_h is None:
        return case.raan_deg
    sun = sk.sun.pos_gcrf(sk.time.from_datetime(datetime.fromisoformat(case.epoch + "T00:00:00+00:00")))
    return math.degrees(math.atan2(sun[1], sun[0])) + (case.node_local_time_h - 12.0) * 15.0


def element_set(case: Case) -> tuple[list[str], ElementSet]:
    """The case's set; its mean motion solved so that orbit_env reads the case's mean semi-major axis."""
    a_m = EQUATORIAL_RADIUS_M + 0.5e3 * (case.perigee_km + case.apogee_km)
    n = math.sqrt(MU_M3_S2 / a_m**3) * 86400.0 / (2.0 * math.pi)
    raan = _node_raan_deg(case)
    for _ in range(4):
        lines = _tle_lines(case, n, raan)
        (elements,) = parse_tle_text(["SYNTHETIC " + case.name, *lines], case.name)
        n *= (elements.semi_major_axis_km * 1e3 / a_m) ** 1.5
    return ["SYNTHETIC " + case.name, *lines], elements


def _finals_line(row: dict[str, str]) -> str:
    """One line of IERS's ``finals2000A.all`` (fixed columns) from a row of CelesTrak's ``EOP-All.csv``."""
    year, month, day = (int(x) for x in row["DATE"].split("-"))
    flag = "I" if row["DATA_TYPE"] == "O" else "P"
    fields = (  # (first column, 1-based, as IERS's format description numbers them; text)
        (1, f"{year % 100:02d}{month:2d}{day:2d}"),
        (8, f"{float(row['MJD']):8.2f}"),
        (17, flag),
        (19, f"{float(row['X']):9.6f}"),
        (38, f"{float(row['Y']):9.6f}"),
        (58, flag),
        (59, f"{float(row['UT1-UTC']):10.7f}"),
        (80, f"{1e3 * float(row['LOD']):7.4f}"),
        (96, flag),
        (98, f"{1e3 * float(row['DX']):9.3f}"),
        (117, f"{1e3 * float(row['DY']):9.3f}"),
    )
    line = [" "] * 134
    for column, text in fields:
        line[column - 1 : column - 1 + len(text)] = text
    return "".join(line)


def use_shipped_data(folder: str, same_indices: bool = False) -> None:
    """satkit reads satkit-data's files and downloads nothing.

    satkit 0.24 reads Earth orientation from IERS's ``finals2000A.all`` only, which
    satkit-data 0.9 does not ship; it ships CelesTrak's ``EOP-All.csv`` (the same IERS
    values), written here into ``folder`` in IERS's columns. ``same_indices``: satkit
    runs on the indices orbit_env takes (`_daily_indices`).
    """
    data = Path(satkit_data.__file__).parent / "data"
    with open(data / "EOP-All.csv") as handle:
        rows = list(csv.DictReader(handle))
    Path(folder, "finals2000A.all").write_text("\n".join(_finals_line(row) for row in rows) + "\n")
    sk.utils.set_offline(True)
    sk.utils.add_search_dir(folder)
    sk.utils.add_search_dir(str(data))
    if same_indices:
        sk.spaceweather.init_from_path(_daily_indices(data / "SW-All.csv", folder))


def _daily_indices(record: Path, folder: str) -> str:
    """A copy of CelesTrak's record holding the indices orbit_env takes (a diagnostic).

    Each day's eight 3-hourly ap become its daily Ap, and an observed F10.7 above
    400 sfu (a radio burst) its 81-day centred mean, as orbit_env's shipped record does.
    """
    with open(record) as handle:
        reader = csv.DictReader(handle)
        fields, rows = list(reader.fieldnames or ()), list(reader)
    for row in rows:
        for k in range(1, 9):
            row[f"AP{k}"] = row["AP_AVG"]
        if row["F10.7_OBS"] and float(row["F10.7_OBS"]) > BURST_SFU:
            row["F10.7_OBS"] = row["F10.7_OBS_CENTER81"]
    path = os.path.join(folder, "SW-All-daily.csv")
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fields)
        writer.writeheader()
        writer.writerows(rows)
    return path


def _perigee_height_m(state: np.ndarray) -> float:
    """Osculating perigee radius minus the equatorial radius [m]."""
    r, v = state[:3], state[3:]
    rn = float(np.linalg.norm(r))
    a = 1.0 / (2.0 / rn - float(v @ v) / MU_M3_S2)
    e = float(np.linalg.norm(np.cross(v, np.cross(r, v)) / MU_M3_S2 - r / rn))
    return a * (1.0 - e) - EQUATORIAL_RADIUS_M


def _altitude_m(state: np.ndarray, when: sk.time) -> float:
    return float(sk.itrfcoord(sk.frametransform.qgcrf2itrf(when) * state[:3]).altitude)


def start_state(lines: list[str]) -> tuple[np.ndarray, sk.time]:
    """SGP4's osculating state at the set's epoch, in GCRF [m, m/s]."""
    (tle,) = sk.TLE.from_lines(lines[1:])
    pos, vel = sk.sgp4(tle, tle.epoch)
    q = sk.frametransform.qteme2gcrf(tle.epoch)
    return np.concatenate([q * np.ravel(pos), q * np.ravel(vel)]), tle.epoch


def satkit_settings(interp: bool = False) -> sk.propsettings:
    """EGM2008 4 x 4, Sun, Moon, NRLMSISE-00 with space weather (satkit's defaults, said explicitly)."""
    return sk.propsettings(
        gravity_degree=4,
        gravity_model=sk.gravmodel.egm2008,
        use_spaceweather=True,
        use_sun_gravity=True,
        use_moon_gravity=True,
        enable_interp=interp,
    )


def satkit_lifetime(lines: list[str]) -> tuple[float, float]:
    """Days from the set's epoch until the altitude is below 100 km, and the wall time [s]."""
    state, epoch = start_state(lines)
    settings, props = satkit_settings(), sk.satproperties(cdaoverm=CDA_OVER_M)
    now = epoch
    start = time.perf_counter()
    while True:
        perigee = _perigee_height_m(state)
        step = next((days * 86400.0 for height, days in COARSE_STEP if perigee > height), FINE_STEP_S)
        result = sk.propagate(state, now, duration_secs=step, propsettings=settings, satproperties=props)
        settings.initial_step_secs = min(result.next_step_secs, step)
        state, now = result.state, result.time
        if step == FINE_STEP_S and _altitude_m(state, now) < REENTRY_ALTITUDE_M:
            return (now - epoch).days, time.perf_counter() - start


def satkit_start_height_km(lines: list[str]) -> float:
    """satkit's radius averaged over its first `START_REVOLUTIONS` (in time), minus the equatorial radius [km]."""
    state, epoch = start_state(lines)
    r = float(np.linalg.norm(state[:3]))
    a = 1.0 / (2.0 / r - float(state[3:] @ state[3:]) / MU_M3_S2)
    span_s = START_REVOLUTIONS * 2.0 * math.pi * math.sqrt(a**3 / MU_M3_S2)
    result = sk.propagate(
        state,
        epoch,
        duration_secs=span_s,
        propsettings=satkit_settings(interp=True),
        satproperties=sk.satproperties(cdaoverm=CDA_OVER_M),
    )
    times = np.linspace(0.0, span_s, 4001)[:-1]
    radii = [np.linalg.norm(result.interp(epoch + sk.duration.from_seconds(float(t)))[:3]) for t in times]
    return (float(np.mean(radii)) - EQUATORIAL_RADIUS_M) / 1e3


def orbit_env_options(case: Case, path: str, daily_ap: bool = False) -> list[str]:
    """The command's options (the set's epoch and inclination are read from it)."""
    options = ["--tle", path, "--mass", str(MASS_KG), "--area", str(AREA_M2), "--cx", str(CX), "--msis-version", "00"]
    if case.node_local_time_h is not None:
        options += ["--node-local-time", str(case.node_local_time_h)]
    return [*options, "--daily-ap"] if daily_ap else options


def orbit_env_in_process(case: Case, elements: ElementSet, daily_ap: bool = False) -> tuple[float, float]:
    """`orbit_env.lifetime` as the command calls it: its days, and the median time of `IN_PROCESS_CALLS` calls [s].

    The calls follow a first. One takes milliseconds, where a single timing moves by tens of
    percent with the machine (satkit's seconds-long run is timed once).
    """
    assert elements.epoch_iso is not None
    options = {
        "epoch": elements.epoch_iso.rstrip("Z"),
        "msis_version": "00",
        "node_local_time": case.node_local_time_h,
        "daily_ap": daily_ap,
    }
    air = Scenario(MsisAir.from_options(options)).in_sphere_heights("equatorial", elements.inclination_deg)
    offset = offset_km("equatorial")
    satellite = Satellite(drag_coefficient=CX, mass_kg=MASS_KG, area_m2=AREA_M2)

    def run() -> float:
        return lifetime(
            elements.flown_perigee_km + offset,
            elements.flown_apogee_km + offset,
            satellite=satellite,
            scenario=air,
            inclination_deg=elements.inclination_deg,
        ).days

    days = run()
    times = []
    for _ in range(IN_PROCESS_CALLS):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return days, statistics.median(times)


def orbit_env_command(case: Case, path: str, daily_ap: bool = False) -> tuple[float, float]:
    """The whole command in a new process (run once before, so the disk cache is warm): days and wall time [s]."""
    exe = shutil.which("orbit-env")
    command = [exe] if exe else [sys.executable, "-m", "orbit_env.cli"]
    command += ["lifetime", *orbit_env_options(case, path, daily_ap), "--json"]
    subprocess.run(command, check=True, capture_output=True)
    start = time.perf_counter()
    out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return float(json.loads(out)["days"]), time.perf_counter() - start


@dataclass(frozen=True)
class Row:
    case: Case
    elements: ElementSet
    satkit_days: float
    satkit_s: float
    orbit_env_days: float
    in_process_s: float
    command_s: float
    satkit_start_km: float

    @property
    def ratio(self) -> float:
        return self.orbit_env_days / self.satkit_days


def run_case(case: Case, folder: str, daily_ap: bool = False) -> Row:
    """Both sides on one case, one after the other (never in parallel); ``daily_ap``: orbit_env with ``--daily-ap``."""
    lines, elements = element_set(case)
    path = os.path.join(folder, case.name + ".tle")
    Path(path).write_text("\n".join(lines) + "\n")
    command_days, command_s = orbit_env_command(case, path, daily_ap)
    days, in_process_s = orbit_env_in_process(case, elements, daily_ap)
    if abs(days - command_days) > 1e-6 * days:
        raise RuntimeError(f"{case.name}: the in-process call gives {days} days, the command {command_days}")
    satkit_days, satkit_s = satkit_lifetime(lines)
    return Row(case, elements, satkit_days, satkit_s, days, in_process_s, command_s, satkit_start_height_km(lines))


def table(rows: Sequence[Row]) -> str:
    """The markdown table, then the medians."""
    out = [
        "| case | epoch | incl. | orbit flown (orbit_env) | mean r - Re, 4 revs: satkit / orbit_env "
        "| satkit | orbit_env | ratio | satkit time | orbit_env in process | whole command "
        "| speed: in process | speed: command |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        e = r.elements
        flown_mean_km = (e.flown_perigee_km + e.flown_apogee_km) / 2 + e.semi_major_axis_km * e.eccentricity**2 / 2
        out.append(
            f"| {r.case.name} | {r.case.epoch} | {e.inclination_deg:g} deg "
            f"| {e.flown_perigee_km:.1f} x {e.flown_apogee_km:.1f} km "
            f"| {r.satkit_start_km:.1f} / {flown_mean_km:.1f} km "
            f"| {r.satkit_days:.2f} d | {r.orbit_env_days:.2f} d | {r.ratio:.3f} | {r.satkit_s:.2f} s "
            f"| {r.in_process_s:.4f} s | {r.command_s:.2f} s | {r.satkit_s / r.in_process_s:,.0f} x "
            f"| {r.satkit_s / r.command_s:.1f} x |"
        )
    diff = statistics.median(abs(r.ratio - 1.0) for r in rows)
    out.append("")
    out.append(
        f"median |difference| {100 * diff:.2f}% (worst {100 * max(abs(r.ratio - 1.0) for r in rows):.2f}%); "
        f"median speed ratio {statistics.median(r.satkit_s / r.in_process_s for r in rows):,.0f} x in process, "
        f"{statistics.median(r.satkit_s / r.command_s for r in rows):.1f} x against the whole command"
    )
    return "\n".join(out)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="*", metavar="NAME", help="run only these cases (default: all)")
    parser.add_argument(
        "--same-indices",
        action="store_true",
        help="diagnostic: both on the same indices (satkit on the daily Ap, no radio bursts; orbit_env --daily-ap)",
    )
    parser.add_argument("--daily-ap", action="store_true", help="orbit_env with --daily-ap (the daily Ap every day)")
    args = parser.parse_args(argv)
    chosen = [c for c in CASES if not args.cases or c.name in args.cases]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        use_shipped_data(folder, args.same_indices)
        for case in chosen:
            row = run_case(case, folder, args.daily_ap or args.same_indices)
            rows.append(row)
            print(f"{case.name}: satkit {row.satkit_days:.2f} d, orbit_env {row.orbit_env_days:.2f} d", flush=True)
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
