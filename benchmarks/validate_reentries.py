"""Documented re-entries predicted with NRLMSIS 2.1, no per-case tuning (docs/validation-modern.md).

Run: python benchmarks/validate_reentries.py [--plot docs/validation-modern.png]   (needs pymsis)

Solar activity: docs/data/solar_quarterly_1992_2018.csv, the 13-month smoothed
sunspot number and smoothed F10.7 of NOAA SWPC's "observed solar cycle indices"
(every third month). Before April 2005 that table has no F10.7: it is filled from
the sunspot number by a straight line fitted where both exist. F10.7 = its 81-day
mean = the smoothed value; Ap = 12 throughout (no Ap record was at hand). Every case
uses c_x = 2.2 on the published frontal area (the primary prediction) and, as a
second column, the same plus free-molecular skin friction on the flow-parallel
surfaces (shear coefficient 1 / (S sqrt(pi)) per unit wetted area, speed ratio
S = 7.6); the table in the docs says which numbers come from where.
"""

from __future__ import annotations

import argparse
import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from orbit_env.api import Satellite, lifetime
from orbit_env.solar import TableActivity, unix_days

DATA = Path(__file__).resolve().parent.parent / "docs" / "data" / "solar_quarterly_1992_2018.csv"
#: Heights published above the equatorial radius (6378.137 km) are 7.137 km higher above our 6371 km sphere.
EQUATORIAL_OFFSET_KM = 7.137
#: A mean geodetic altitude along a polar orbit is 3.6 km lower above the sphere (mean WGS84 radius 6367.4 km).
POLAR_MEAN_OFFSET_KM = -3.6
SHEAR_PER_AREA = 1.0 / (7.6 * math.sqrt(math.pi))
AP = 12.0


@dataclass(frozen=True)
class Case:
    name: str
    epoch: str
    reentry: str
    height_km: float  # as published
    inclination_deg: float
    mass_kg: float
    frontal_area_m2: float
    wetted_area_m2: float  # flow-parallel surfaces, for the skin-friction variant
    node_local_time_h: float | None = None


CASES = [
    Case("GOCE", "2013-10-21", "2013-11-11", 224.0, 96.7, 1040.0, 1.1, 33.0, 18.0),
    Case("GRACE-2", "2002-03-17", "2017-12-24", 500.0, 89.0, 480.0, 1.0, 13.5),
    Case("GRACE-1", "2002-03-17", "2018-03-10", 500.0, 89.0, 480.0, 1.0, 13.5),
]


def solar_activity() -> TableActivity:
    with open(DATA) as handle:
        rows = list(csv.DictReader(handle))
    days = np.array([unix_days(r["date"]) for r in rows])
    ssn = np.array([float(r["ssn_smoothed"]) for r in rows])
    f107 = np.array([float(r["f107_smoothed"]) if r["f107_smoothed"] else np.nan for r in rows])
    both = np.isfinite(f107)
    slope, intercept = np.polyfit(ssn[both], f107[both], 1)
    filled = np.where(both, f107, intercept + slope * ssn)
    print(f"F10.7 = {intercept:.1f} + {slope:.3f} SSN on {both.sum()} quarters "
          f"(rms {np.std(f107[both] - intercept - slope * ssn[both]):.1f} sfu)")  # fmt: skip
    return TableActivity(days, filled, filled, np.full(days.size, AP), source=DATA.name)


def predict(case: Case, activity: TableActivity, offset_km: float, skin_friction: bool) -> float:
    area = case.frontal_area_m2
    cx = 2.2 + (SHEAR_PER_AREA * case.wetted_area_m2 / area if skin_friction else 0.0)
    height = case.height_km + offset_km
    result = lifetime(
        height,
        height,
        satellite=Satellite(cx, case.mass_kg, area),
        method="curves",
        inclination_deg=case.inclination_deg,
        rotating_atmosphere=True,
        activity=activity,
        epoch=case.epoch,
        ascending_node_local_time_h=case.node_local_time_h,
    )
    return result.days


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--plot", help="write predicted against observed to this PNG")
    args = parser.parse_args()
    activity = solar_activity()
    columns = ("observed d", "c_x 2.2", "err", "band (h convention)", "+skin fr.", "err")
    widths = (10, 9, 7, 22, 9, 7)
    print(f"{'case':8} " + " ".join(f"{name:>{width}}" for name, width in zip(columns, widths, strict=True)))
    rows = []
    for case in CASES:
        observed = unix_days(case.reentry) - unix_days(case.epoch)
        central = predict(case, activity, EQUATORIAL_OFFSET_KM, False)
        low = predict(case, activity, POLAR_MEAN_OFFSET_KM, False)
        skin = predict(case, activity, EQUATORIAL_OFFSET_KM, True)
        rows.append((case.name, observed, central, low, skin))
        print(
            f"{case.name:8} {observed:10.1f} {central:9.1f} {central / observed - 1:+7.1%} "
            f"{f'{low:.1f} to {central:.1f}':>22} {skin:9.1f} {skin / observed - 1:+7.1%}"
        )
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 5))
        lim = (5, 2e4)
        ax.fill_between(lim, [lim[0] * 0.7, lim[1] * 0.7], [lim[0] * 1.3, lim[1] * 1.3], color="0.9", label="+-30%")
        ax.plot(lim, lim, "k-", lw=0.8)
        for name, observed, central, low, skin in rows:
            ax.errorbar(observed, central, yerr=[[central - low], [0]], fmt="o", capsize=3, label=f"{name}, c_x 2.2")
            ax.plot(observed, skin, "x", color="0.3")
        ax.plot([], [], "x", color="0.3", label="with skin friction")
        ax.set(xscale="log", yscale="log", xlim=lim, ylim=lim, xlabel="observed lifetime [days]",
               ylabel="predicted lifetime [days]", title="Re-entries predicted with NRLMSIS 2.1")  # fmt: skip
        ax.legend(fontsize=8, loc="upper left")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
