"""Hindcasts of documented re-entries from launch or a documented epoch, one method for all (validation-modern.md).

Run: python benchmarks/validate_reentries.py [--plot docs/validation-modern.png] [--sensitivity] [--band] [--trend]
(needs pymsis; about 4.5 minutes for the 15 cases on a cold cache on a shared 2-core machine; ``--band``
adds the 90% band of ``--uncertainty``, two lifetimes a case; ``--trend`` the secular density trend)

The cases, their inputs and sources are in ``benchmarks/reentry_cases.csv`` (one row each;
its ``source`` column names where every number comes from, and says "from memory" where
no source was at hand). Every case uses the same rules, nothing fitted to a re-entry:

* solar activity: the shipped CelesTrak record (`orbit_env.decay.solar_record.load_record`,
  observed F10.7 of the previous day, its 81-day centred mean, daily Ap, from 1957-10-01;
  on storm days NRLMSIS's storm-time mode with the record's 3-hourly ap), through the
  time-stepped decay of :mod:`orbit_env.decay.chunked`;
* co-rotating air, the orbit's inclination (and the node's local time for the
  Sun-synchronous GOCE), published heights taken as above the equatorial radius;
* the drag coefficient from ONE physical model, :mod:`orbit_env.physics.drag` (Sentman
  1961, diffuse re-emission with full energy accommodation, wall 300 K), applied to each
  satellite's documented shape and attitude: spheres by the closed form; a body
  tumbling at random (Explorer 1's cylinder) as the sphere of the same surface (the
  orientation average of a convex body, ``tumbling_drag_area_m2``); GOCE and GRACE as
  flat panels flown nose-first. The gas's temperature and mean molecular mass are
  NRLMSIS's at the start, at the initial perigee (where the drag acts), density-weighted
  over the orbit's latitudes and local times; the coefficient is held for the whole life;
* the column chosen first, before any run (c_x = 2.2 on the frontal area), is kept
  beside it.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from orbit_env.analysis.lifetime import Satellite, lifetime
from orbit_env.analysis.shapes import ACCOMMODATION, Shape, cylinder, drag_at_start, flown_nose_first, sphere
from orbit_env.analysis.uncertainty import DENSITY_MODEL_SIGMA, DRAG_COEFFICIENT_SIGMA
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.solar import SolarActivity, unix_days
from orbit_env.decay.solar_record import load_record

CASES_CSV = Path(__file__).resolve().parent / "reentry_cases.csv"
#: Heights published above the equatorial radius (6378.137 km) are 7.137 km higher above our 6371 km sphere.
EQUATORIAL_OFFSET_KM = 7.137
#: The drag coefficient chosen first, on the frontal (cross-section) area.
FIRST_CHOICE_CX = 2.2
#: The goal of the hindcast (issue 13, item 9): median |error| and 90th percentile of |error|.
GOAL_MEDIAN = 0.10
GOAL_P90 = 0.25
#: The 95th percentile of a standard normal: the edges of the 90% band.
Z_95 = 1.6448536269514722
#: The sigma of ln(density x drag coefficient) that ``--uncertainty`` samples; the hindcasts lie
#: inside the observed record, so its third source, the solar forecast, does not enter.
BAND_SIGMA = math.hypot(DENSITY_MODEL_SIGMA, DRAG_COEFFICIENT_SIGMA)
#: The thermosphere's secular density trend at 400 km, 1967-2005, and the year taken as NRLMSIS's own
#: (Emmert 2015, JGR Space Physics: -2.0 +- 0.5% per decade; weaker below 400 km).
TREND_PER_DECADE = -0.020
TREND_REFERENCE_YEAR = 2005.0


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
    source: str = ""


def shape_of(row: dict[str, str]) -> Shape:
    """The shape of a row of the cases' CSV: ``sphere``, ``tumbling cylinder`` or ``nose-first``."""
    kind = row["shape"]
    if kind == "sphere":
        return sphere(float(row["diameter_m"]))
    if kind == "tumbling cylinder":
        return cylinder(float(row["diameter_m"]), float(row["length_m"]))
    if kind == "nose-first":
        return flown_nose_first(float(row["front_m2"]), float(row["parallel_m2"]))
    raise ValueError(f"{CASES_CSV.name}: unknown shape {kind!r} for {row['name']}")


def read_cases(path: Path = CASES_CSV) -> list[Case]:
    """The documented decays, one per row of the CSV."""
    with open(path, newline="") as handle:
        return [
            Case(
                row["name"],
                row["start_utc"],
                row["reentry_utc"],
                float(row["perigee_km"]),
                float(row["apogee_km"]),
                float(row["inclination_deg"]),
                float(row["mass_kg"]),
                shape_of(row),
                float(row["node_local_time_h"]) if row["node_local_time_h"] else None,
                row["source"],
            )
            for row in csv.DictReader(handle)
        ]


CASES = read_cases()


def observed_days(case: Case) -> float:
    """Days from the start to the re-entry."""
    return unix_days(case.reentry) - unix_days(case.start)


def drag_coefficient(
    case: Case, activity: SolarActivity, gas_height: str = "perigee", accommodation: float = ACCOMMODATION
) -> tuple[float, float, float]:
    """The model's drag coefficient on the reference area, density-weighted over the orbit; also mean S and T [K].

    NRLMSIS at the start (the orbit's latitudes and local times at the initial perigee, or at
    the mean of perigee and apogee with ``gas_height="mean"``, on the start date with its
    indices), against the co-rotating air: ``orbit_env.analysis.shapes.drag_at_start``.
    """
    published_km = case.perigee_km if gas_height == "perigee" else 0.5 * (case.perigee_km + case.apogee_km)
    gas = drag_at_start(
        case.shape,
        (published_km + EQUATORIAL_OFFSET_KM) * 1e3,
        case.inclination_deg,
        tuple(float(x) for x in activity.indices(unix_days(case.start))),
        case.start,
        ascending_node_local_time_h=case.node_local_time_h,
        accommodation=accommodation,
    )
    return gas.drag_coefficient, gas.speed_ratio, gas.temperature_k


def predict(
    case: Case, activity: SolarActivity, cx: float, height_shift_km: float = 0.0, density_scale: float = 1.0
) -> float:
    """Predicted lifetime [days] with drag coefficient ``cx`` on the reference area (heights shifted if asked)."""
    result = lifetime(
        case.perigee_km + EQUATORIAL_OFFSET_KM + height_shift_km,
        case.apogee_km + EQUATORIAL_OFFSET_KM + height_shift_km,
        satellite=Satellite(cx, case.mass_kg, case.shape.reference_area_m2),
        method="curves",
        density_scale=density_scale,
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
    seconds: float
    band_days: tuple[float, float] = (math.nan, math.nan)

    @property
    def error(self) -> float:
        """Predicted / observed - 1 with the drag model."""
        return self.model_days / self.observed_days - 1.0

    @property
    def inside_band(self) -> bool:
        """Whether the observed life lies in the 90% band."""
        return self.band_days[0] <= self.observed_days <= self.band_days[1]


def trend_scale(case: Case) -> float:
    """The density factor of the secular trend at the middle of the observed life, against 2005."""
    middle_year = 1970.0 + 0.5 * (unix_days(case.start) + unix_days(case.reentry)) / DAYS_PER_YEAR
    return (1.0 + TREND_PER_DECADE) ** ((middle_year - TREND_REFERENCE_YEAR) / 10.0)


def band(case: Case, activity: SolarActivity, cx: float) -> tuple[float, float]:
    """The 5th and 95th percentile lifetimes [days] of ``--uncertainty`` in the observed record.

    With the Sun observed, the samples differ only by their factor s on density x drag
    coefficient, log-normal with sigma `BAND_SIGMA`, and the lifetime falls as s grows
    (the decay rate is rho c at every instant), so the lifetime's percentiles are the
    lifetimes at s's opposite percentiles: exp(+-1.645 sigma), two propagations. This is
    the limit the Monte Carlo's percentiles approach as its samples grow.
    """
    factor = math.exp(Z_95 * BAND_SIGMA)
    return predict(case, activity, cx, density_scale=factor), predict(case, activity, cx, density_scale=1.0 / factor)


def run(
    cases: list[Case] = CASES, first_choice: bool = True, with_band: bool = False, accommodation: float = ACCOMMODATION
) -> list[Row]:
    """Predict every case (``first_choice=False`` skips the c_x 2.2 column, then NaN; ``with_band`` adds the band)."""
    activity = load_record()
    rows = []
    for case in cases:
        begin = time.perf_counter()
        cd, s, temperature = drag_coefficient(case, activity, accommodation=accommodation)
        model = predict(case, activity, cd)
        seconds = time.perf_counter() - begin
        first = predict(case, activity, FIRST_CHOICE_CX) if first_choice else math.nan
        spread = band(case, activity, cd) if with_band else (math.nan, math.nan)
        rows.append(Row(case.name, observed_days(case), first, cd, s, temperature, model, seconds, spread))
    return rows


def summary(errors: list[float]) -> tuple[float, float, int]:
    """Median |error|, its 90th percentile (numpy's linear interpolation) and how many are within +-25%."""
    absolute = np.abs(np.asarray(errors))
    return float(np.median(absolute)), float(np.percentile(absolute, 90)), int(np.sum(absolute <= GOAL_P90))


def main() -> None:
    """Print the table and optionally plot predicted against observed."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--plot", help="write predicted against observed to this PNG")
    parser.add_argument("--sensitivity", action="store_true", help="also: C_D +5%%, heights -5/+5 km, gas height")
    parser.add_argument("--trend", action="store_true", help="also: the secular density trend (TREND_PER_DECADE)")
    parser.add_argument(
        "--accommodation",
        type=float,
        default=ACCOMMODATION,
        help="the drag model's energy accommodation (default 1: full)",
    )
    parser.add_argument("--band", action="store_true", help="also the 90%% band of --uncertainty (2 lifetimes a case)")
    args = parser.parse_args()
    begin = time.perf_counter()
    if not 0.0 < args.accommodation <= 1.0:
        parser.error(f"--accommodation must be in (0, 1], got {args.accommodation}")
    print(f"drag model: energy accommodation {args.accommodation:g}")
    rows = run(with_band=args.band, accommodation=args.accommodation)
    total = time.perf_counter() - begin
    header = f"{'case':12} {'observed d':>10} {'c_x 2.2 d':>10} {'err':>7} {'model C_D':>9} {'S':>5} {'T K':>5}"
    print(header + f" {'model d':>9} {'err':>7} {'s':>5}" + ("   90% band d" if args.band else ""))
    for r in rows:
        print(
            f"{r.name:12} {r.observed_days:10.1f} {r.first_choice_days:10.1f} "
            f"{r.first_choice_days / r.observed_days - 1:+7.1%} {r.drag_coefficient:9.2f} "
            f"{r.mean_speed_ratio:5.2f} {r.mean_temperature_k:5.0f} {r.model_days:9.1f} {r.error:+7.1%} "
            f"{r.seconds:5.1f}" + (f"   {r.band_days[0]:.1f}-{r.band_days[1]:.1f}" if args.band else "")
        )
    median, p90, within = summary([r.error for r in rows])
    print(
        f"{len(rows)} cases: median |error| {median:.1%} (goal {GOAL_MEDIAN:.0%}), 90th percentile {p90:.1%} "
        f"(goal {GOAL_P90:.0%}), {within} within +-{GOAL_P90:.0%}"
    )
    first = summary([r.first_choice_days / r.observed_days - 1 for r in rows])
    print(f"c_x 2.2: median |error| {first[0]:.1%}, 90th percentile {first[1]:.1%}, {first[2]} within +-25%")
    if args.band:
        inside = sum(r.inside_band for r in rows)
        print(f"observed life inside the 90% band (sigma {BAND_SIGMA:.3f} on density x C_D): {inside} of {len(rows)}")
    model_seconds = sum(r.seconds for r in rows)
    print(f"cost: {model_seconds:.1f} s for the drag-model predictions, {total:.1f} s with the c_x 2.2 column")
    if args.plot:
        plot(rows, args.plot)
    if args.sensitivity:
        sensitivity(rows, args.accommodation)
    if args.trend:
        trend(rows)


def trend(rows: list[Row]) -> None:
    """Each case with NRLMSIS's density times the thermosphere's secular trend (`trend_scale`)."""
    activity = load_record()
    errors = []
    for case, row in zip(CASES, rows, strict=True):
        scale = trend_scale(case)
        errors.append(predict(case, activity, row.drag_coefficient, density_scale=scale) / row.observed_days - 1)
        print(f"{case.name:12} density x {scale:.3f}: {errors[-1]:+7.1%} (central {row.error:+.1%})")
    median, p90, within = summary(errors)
    print(f"with the trend: median |error| {median:.1%}, 90th percentile {p90:.1%}, {within} within +-25%")


def sensitivity(rows: list[Row], accommodation: float = ACCOMMODATION) -> None:
    """How far each prediction moves with its most uncertain inputs (C_D, the heights, the gas's height)."""
    activity = load_record()
    print(
        f"{'case':12} {'central':>8} {'C_D +5%':>8} {'h -5 km':>8} {'h +5 km':>8} {'h sphere':>8} {'gas mean':>8}"
        "   (predicted / observed - 1 with that change)"
    )
    for case, row in zip(CASES, rows, strict=True):
        mean_cd = drag_coefficient(case, activity, gas_height="mean", accommodation=accommodation)[0]
        changes = [
            predict(case, activity, row.drag_coefficient * 1.05),
            predict(case, activity, row.drag_coefficient, -5.0),
            predict(case, activity, row.drag_coefficient, 5.0),
            predict(case, activity, row.drag_coefficient, -EQUATORIAL_OFFSET_KM),
            predict(case, activity, mean_cd),
        ]
        print(f"{case.name:12} {row.error:+8.1%} " + " ".join(f"{d / row.observed_days - 1:+8.1%}" for d in changes))
    for name, mass in (("GOCE", 1040.0), ("GRACE-2", 432.0)):
        case = next(c for c in CASES if c.name == name)
        lighter = replace(case, mass_kg=mass)
        cd = drag_coefficient(lighter, activity, accommodation=accommodation)[0]
        print(f"{name} at {mass:g} kg: {predict(lighter, activity, cd) / observed_days(case) - 1:+.1%}")
    goce = next(c for c in CASES if c.name == "GOCE")
    for parallel in (27.0, 33.0):
        shaped = replace(goce, shape=flown_nose_first(1.1, parallel))
        cd = drag_coefficient(shaped, activity, accommodation=accommodation)[0]
        error = predict(shaped, activity, cd) / observed_days(goce) - 1
        print(f"GOCE with {parallel:g} m^2 parallel: C_D {cd:.2f}, {error:+.1%}")


def plot(rows: list[Row], path: str) -> None:
    """Predicted against observed lifetime (log axes, the +-25% band) and each case's error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bars) = plt.subplots(1, 2, figsize=(10.0, 5.0), gridspec_kw={"width_ratios": [1.15, 1.0]})
    lim = (8.0, 2e4)
    ax.fill_between(lim, [x * (1 - GOAL_P90) for x in lim], [x * (1 + GOAL_P90) for x in lim], color="0.88")
    ax.plot(lim, lim, "k-", lw=0.8)
    starts = {c.name: unix_days(c.start) for c in CASES}
    order = sorted(rows, key=lambda r: r.error)
    for number, r in enumerate(rows, start=1):
        color = "tab:red" if starts[r.name] < unix_days("1990-01-01") else "tab:blue"
        if not math.isnan(r.band_days[0]):  # the 90% band of --uncertainty
            below, above = r.model_days - r.band_days[0], r.band_days[1] - r.model_days
            ax.errorbar(r.observed_days, r.model_days, yerr=[[below], [above]], color=color, lw=0.8, capsize=2)
        ax.plot(r.observed_days, r.model_days, "o", color=color, ms=5)
        ax.annotate(
            str(number), (r.observed_days, r.model_days), fontsize=7, xytext=(4, -8), textcoords="offset points"
        )
    ax.plot([], [], "o", color="tab:red", label="launched 1957-1974")
    ax.plot([], [], "o", color="tab:blue", label="launched 1995-2013")
    ax.fill_between([], [], [], color="0.88", label="+-25%")
    if not any(math.isnan(r.band_days[0]) for r in rows):
        inside = sum(r.inside_band for r in rows)
        label = f"90% band of --uncertainty ({inside} of {len(rows)} hold the observed)"
        ax.errorbar([], [], yerr=[], color="0.3", lw=0.8, label=label)
    median, p90, within = summary([r.error for r in rows])
    ax.set(xscale="log", yscale="log", xlim=lim, ylim=lim, xlabel="observed lifetime [days]",
           ylabel="predicted lifetime [days]")  # fmt: skip
    ax.set_title(f"{len(rows)} re-entries from launch: median |error| {median:.1%}, 90th pct {p90:.0%}", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    numbers = {r.name: n for n, r in enumerate(rows, start=1)}
    y = range(len(order))
    colors = ["tab:red" if starts[r.name] < unix_days("1990-01-01") else "tab:blue" for r in order]
    bars.axvspan(-100 * GOAL_P90, 100 * GOAL_P90, color="0.88")
    bars.barh(list(y), [100 * r.error for r in order], color=colors)
    bars.axvline(0.0, color="k", lw=0.8)
    bars.set_yticks(list(y), [f"{numbers[r.name]}. {r.name}" for r in order], fontsize=7)
    bars.set_xlabel("predicted / observed - 1 [%]")
    bars.set_title(f"{within} of {len(rows)} within +-25%", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
