"""Documented re-entries predicted with NRLMSIS 2.1, no per-case tuning (docs/validation-modern.md, section 5).

Run: python benchmarks/validate_reentries.py [--plot docs/validation-modern.png]   (needs pymsis; ~1 min)

Every case uses the same rules:

* solar activity: ``docs/data/solar_daily_1995_2018.csv``, CelesTrak's daily record
  (observed F10.7 of the previous day, its 81-day centred mean, daily Ap), through
  the time-stepped decay of :mod:`orbit_env.decay.chunked`;
* co-rotating air, the orbit's inclination (and the node's local time for the
  Sun-synchronous GOCE), published heights taken as above the equatorial radius;
* the drag coefficient of the primary prediction from ONE physical model,
  :mod:`orbit_env.physics.drag` (Sentman 1961, diffuse re-emission with full energy
  accommodation, wall 300 K), applied to each satellite's documented shape and
  attitude: spheres by the closed form, GOCE and GRACE as flat panels flown
  nose-first. The gas's temperature and mean molecular mass are NRLMSIS's at the
  start (initial height, start date's indices, density-weighted over the orbit's
  latitudes and local times), so nothing in it is fitted to a re-entry;
* the column chosen first, before any run (c_x = 2.2 on the frontal area), is kept
  beside it.

The sources of every number are in the docs; :data:`CASES` names them briefly.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, replace
from pathlib import Path

from orbit_env.analysis.lifetime import Satellite, lifetime
from orbit_env.analysis.shapes import Shape, drag_at_start, flown_nose_first, sphere
from orbit_env.decay.solar import TableActivity, read_solar_csv, unix_days

SOLAR_CSV = Path(__file__).resolve().parent.parent / "docs" / "data" / "solar_daily_1995_2018.csv"
#: Heights published above the equatorial radius (6378.137 km) are 7.137 km higher above our 6371 km sphere.
EQUATORIAL_OFFSET_KM = 7.137
#: The drag coefficient chosen first, on the frontal (cross-section) area.
FIRST_CHOICE_CX = 2.2
# GRACE panels (area m^2, normal) of the GRACE-FO Level-1 handbook's Table 5 (GRACE-FO kept the GRACE body),
# x along-track: front + boom face the flow, rear + boom in the wake, the rest (normals in the y-z plane) parallel.
GRACE_FRONT_M2 = 0.9551567 + 0.0461901
GRACE_PARALLEL_M2 = 2 * 3.1554792 + 2 * 0.2282913 + 6.071112 + 2.167362 + 2 * 0.0461901
# GOCE: ESA's 1.1 m^2 minimum cross-section; flow-parallel: the 0.8 m^2 octagonal body (side 0.407 m) over its
# 5.3 m length (17.3 m^2), plus the wings, both faces (ESA's ~9 m^2 array less ~3 m^2 body-mounted: 2 x 6 m^2),
# plus ~0.7 m^2 of tail fins: 30 m^2, an estimate (+-3 m^2).
GOCE_PARALLEL_M2 = 30.0


@dataclass(frozen=True)
class Case:
    """One documented decay: start, orbit, build, observed re-entry (UTC)."""

    name: str
    start: str
    reentry: str
    perigee_km: float  # as published
    apogee_km: float
    inclination_deg: float
    mass_kg: float
    shape: Shape
    node_local_time_h: float | None = None


CASES = [
    # GFZ-1: released from Mir; 382 x 395 km, 51.6 deg, 20 kg, 21.5 cm sphere; decayed 1999-06-23.
    Case("GFZ-1", "1995-04-19T19:12", "1999-06-23T12:00", 382.0, 395.0, 51.6, 20.0, sphere(0.215)),
    # Starshine 1: deployed from STS-96 at 07:21 UT, 387 km, 51.6 deg; 48 cm sphere, 38 kg; decayed 2000-02-18.
    Case("Starshine 1", "1999-06-05T07:21", "2000-02-18T15:08", 387.0, 387.0, 51.6, 38.0, sphere(0.48)),
    # Starshine 2: deployed from STS-108 at 15:02 UT, 240 mi (386 km), 51.6 deg; 19 in sphere, 85 lb; 2002-04-26.
    Case("Starshine 2", "2001-12-16T15:02", "2002-04-26T11:00", 386.0, 386.0, 51.6, 38.6, sphere(0.4826)),
    # Starshine 3: Athena 1 from Kodiak 02:40 UT, 470 km, 67 deg; 37 in (0.94 m) sphere, 91 kg; 2003-01-21 ~05:10.
    Case("Starshine 3", "2001-09-30T02:40", "2003-01-21T05:10", 470.0, 470.0, 67.0, 91.0, sphere(0.94)),
    # GOCE: xenon out 2013-10-21 at 224 km, 96.7 deg, node 18 h; 1100 kg; re-entered 2013-11-11 00:16.
    Case(
        "GOCE",
        "2013-10-21T12:00",
        "2013-11-11T00:16",
        224.0,
        224.0,
        96.7,
        1100.0,
        flown_nose_first(1.1, GOCE_PARALLEL_M2),
        18.0,
    ),
    # GRACE: launched 2002-03-17 09:21 into 483 x 508 km, 89.0 deg; 487 kg; re-entered 2017-12-24 / 2018-03-10.
    Case(
        "GRACE-2",
        "2002-03-17T09:21",
        "2017-12-24T00:16",
        483.0,
        508.0,
        89.0,
        487.0,
        flown_nose_first(GRACE_FRONT_M2, GRACE_PARALLEL_M2),
    ),
    Case(
        "GRACE-1",
        "2002-03-17T09:21",
        "2018-03-10T06:09",
        483.0,
        508.0,
        89.0,
        487.0,
        flown_nose_first(GRACE_FRONT_M2, GRACE_PARALLEL_M2),
    ),
]


def observed_days(case: Case) -> float:
    """Days from the start to the re-entry."""
    return unix_days(case.reentry) - unix_days(case.start)


def drag_coefficient(case: Case, activity: TableActivity) -> tuple[float, float, float]:
    """The model's drag coefficient on the reference area, density-weighted over the orbit; also mean S and T [K].

    NRLMSIS at the start (the orbit's latitudes and local times at the mean initial height, on the
    start date with its indices), against the co-rotating air: ``orbit_env.analysis.shapes.drag_at_start``.
    """
    height_m = (0.5 * (case.perigee_km + case.apogee_km) + EQUATORIAL_OFFSET_KM) * 1e3
    gas = drag_at_start(
        case.shape,
        height_m,
        case.inclination_deg,
        tuple(float(x) for x in activity.indices(unix_days(case.start))),
        case.start,
        ascending_node_local_time_h=case.node_local_time_h,
    )
    return gas.drag_coefficient, gas.speed_ratio, gas.temperature_k


def predict(case: Case, activity: TableActivity, cx: float, height_shift_km: float = 0.0) -> float:
    """Predicted lifetime [days] with drag coefficient ``cx`` on the reference area (heights shifted if asked)."""
    result = lifetime(
        case.perigee_km + EQUATORIAL_OFFSET_KM + height_shift_km,
        case.apogee_km + EQUATORIAL_OFFSET_KM + height_shift_km,
        satellite=Satellite(cx, case.mass_kg, case.shape.reference_area_m2),
        method="curves",
        inclination_deg=case.inclination_deg,
        rotating_atmosphere=True,
        activity=activity,
        epoch=case.start,
        ascending_node_local_time_h=case.node_local_time_h,
    )
    return result.days


@dataclass(frozen=True)
class Row:
    """One case's result."""

    name: str
    observed_days: float
    first_choice_days: float
    drag_coefficient: float
    mean_speed_ratio: float
    mean_temperature_k: float
    model_days: float


def run(cases: list[Case] = CASES, first_choice: bool = True) -> list[Row]:
    """Predict every case (``first_choice=False`` skips the c_x 2.2 column, which is then NaN)."""
    activity = read_solar_csv(SOLAR_CSV)
    rows = []
    for case in cases:
        cd, s, temperature = drag_coefficient(case, activity)
        first = predict(case, activity, FIRST_CHOICE_CX) if first_choice else math.nan
        rows.append(Row(case.name, observed_days(case), first, cd, s, temperature, predict(case, activity, cd)))
    return rows


def main() -> None:
    """Print the table and optionally plot predicted against observed."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--plot", help="write predicted against observed to this PNG")
    parser.add_argument("--sensitivity", action="store_true", help="also: C_D +5%%, heights -5/+5 km, masses")
    args = parser.parse_args()
    rows = run()
    header = f"{'case':12} {'observed d':>10} {'c_x 2.2 d':>10} {'err':>7} {'model C_D':>9} {'S':>5} {'T K':>5}"
    print(header + f" {'model d':>9} {'err':>7}")
    for r in rows:
        print(
            f"{r.name:12} {r.observed_days:10.1f} {r.first_choice_days:10.1f} "
            f"{r.first_choice_days / r.observed_days - 1:+7.1%} {r.drag_coefficient:9.2f} "
            f"{r.mean_speed_ratio:5.2f} {r.mean_temperature_k:5.0f} {r.model_days:9.1f} "
            f"{r.model_days / r.observed_days - 1:+7.1%}"
        )
    if args.plot:
        plot(rows, args.plot)
    if args.sensitivity:
        sensitivity(rows)


def sensitivity(rows: list[Row]) -> None:
    """How far each prediction moves with its most uncertain inputs (the model's C_D, the heights, the masses)."""
    activity = read_solar_csv(SOLAR_CSV)
    print(f"{'case':12} {'C_D +5%':>8} {'h -5 km':>8} {'h +5 km':>8}   (predicted / observed - 1 with that change)")
    for case, row in zip(CASES, rows, strict=True):
        changes = [
            predict(case, activity, row.drag_coefficient * 1.05),
            predict(case, activity, row.drag_coefficient, -5.0),
            predict(case, activity, row.drag_coefficient, 5.0),
        ]
        print(f"{case.name:12} " + " ".join(f"{d / row.observed_days - 1:+8.1%}" for d in changes))
    for name, mass in (("GOCE", 1040.0), ("GRACE-2", 432.0)):
        case = next(c for c in CASES if c.name == name)
        lighter = replace(case, mass_kg=mass)
        cd = drag_coefficient(lighter, activity)[0]
        print(f"{name} at {mass:g} kg: {predict(lighter, activity, cd) / observed_days(case) - 1:+.1%}")
    grace = next(c for c in CASES if c.name == "GRACE-2")
    print("GRACE model C_D later in life (date, height as published; the prediction keeps the start's):")
    for date, height_km in (("2008-07-01", 470.0), ("2014-06-01", 420.0), ("2016-06-01", 370.0), ("2017-10-01", 300.0)):
        later = replace(grace, start=date, perigee_km=height_km, apogee_km=height_km)
        cd, s, temperature = drag_coefficient(later, activity)
        print(f"  {date} {height_km:g} km: C_D {cd:.2f} (S {s:.2f}, T {temperature:.0f} K)")
    goce = next(c for c in CASES if c.name == "GOCE")
    for parallel in (27.0, 33.0):
        shaped = replace(goce, shape=flown_nose_first(1.1, parallel))
        cd = drag_coefficient(shaped, activity)[0]
        error = predict(shaped, activity, cd) / observed_days(goce) - 1
        print(f"GOCE with {parallel:g} m^2 parallel: C_D {cd:.2f}, {error:+.1%}")


def plot(rows: list[Row], path: str) -> None:
    """Predicted against observed lifetime, both drag columns, with the +-30% band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    lim = (8.0, 4e4)
    ax.fill_between(lim, [lim[0] * 0.7, lim[1] * 0.7], [lim[0] * 1.3, lim[1] * 1.3], color="0.9", label="+-30%")
    ax.plot(lim, lim, "k-", lw=0.8)
    for r in rows:
        (point,) = ax.plot(r.observed_days, r.model_days, "o", label=f"{r.name}")
        ax.plot(r.observed_days, r.first_choice_days, "x", color=point.get_color())
        ax.plot([r.observed_days] * 2, [r.first_choice_days, r.model_days], "-", color=point.get_color(), lw=0.6)
    ax.plot([], [], "ko", label="Sentman drag model (primary)")
    ax.plot([], [], "kx", label="c_x 2.2 on frontal area (first choice)")
    title = "Re-entries predicted with NRLMSIS 2.1, daily F10.7 and Ap"
    ax.set(xscale="log", yscale="log", xlim=lim, ylim=lim, xlabel="observed lifetime [days]",
           ylabel="predicted lifetime [days]", title=title)  # fmt: skip
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
