"""Is the orbit-averaged NRLMSIS profile the cause of the early hindcasts' misses? (validation-modern.md, 5)

Run: python benchmarks/validate_geometry.py [--cases "San Marco 2,Sputnik 1"] [--phases 8]
(about 20 s per phase of San Marco 2, 40 s of Sputnik 1, on a shared 2-core machine)

The decay core sees NRLMSIS as one density-against-height profile, averaged over the
latitudes and local times an orbit visits (`orbit_env.physics.atmosphere.msis`): right
for a circular orbit, and for an eccentric one only if its perigee visits them all evenly
over the life. This check drops that assumption. It is independent of the package's decay
code: it shares with the package only the solar record, the constants, the case list and
geometry that is not under test here (elements from heights, J2's secular rates, the height
above WGS84):

* the orbit is (a, e, i, node, argument of perigee) at a date; each step averages the drag
  acceleration -1/2 B rho |v_rel| v_rel over one revolution, at ``POINTS`` points evenly
  spaced in eccentric anomaly (weighted by dt), with NRLMSIS 2.1 evaluated at each point's
  real latitude, longitude (Greenwich sidereal time of the date), height above the WGS84
  ellipsoid and the date's indices, v_rel against air co-rotating with the Earth;
* a and e change by the Gauss equations of that mean acceleration (energy: da/dt =
  2 a^2 (v . f) / mu; eccentricity vector: de/dt = (f x h + v x (r x f)) / mu), by the
  midpoint rule; the node and the perigee turn at J2's secular rates;
* steps of at most a quarter day, and at most 1% of the perigee's height above 100 km;
  re-entry when the perigee is 100 km above the 6371 km sphere (the package's criterion).

The perigee's starting latitude and local time are not in the published records, so each
case runs n = ``--phases`` times, the k-th with the perigee at local time 24 k / n h and,
for orbits inclined by more than 10 deg, argument of perigee 360 k / n deg: the spread is
what the unknown phase can do, and the mean is what the averaged profile assumes.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from sgp4.propagation import gstime
from validate_reentries import CASES, EQUATORIAL_OFFSET_KM, Case, drag_coefficient, observed_days, predict

from orbit_env.constants import EARTH_RADIUS_M, EARTH_ROTATION_RAD_S, MU_EARTH_M3_S2, REENTRY_ALTITUDE_M
from orbit_env.decay.solar import SolarActivity, unix_days
from orbit_env.decay.solar_record import load_record
from orbit_env.physics.atmosphere.msis import geodetic_altitude_m, require_pymsis
from orbit_env.physics.oblateness import node_rate_rad_per_day, perigee_rate_rad_per_day
from orbit_env.physics.orbit import elements_from_heights, semi_major_axis_m

#: Points per revolution, evenly spaced in eccentric anomaly.
POINTS = 720
#: Largest step [days].
MAX_STEP_DAYS = 0.25
#: Largest step as a fraction of the perigee's height above the re-entry height.
MAX_STEP_FRACTION = 0.01
_EPOCH = np.datetime64("1970-01-01T00:00", "s")


def sidereal_angle_rad(days: float) -> float:
    """Greenwich mean sidereal angle at unix day ``days`` (IAU 1982, sgp4's ``gstime``; UT1 taken as UTC)."""
    return float(gstime(days + 2440587.5))


def sun_right_ascension_rad(days: float) -> float:
    """The Sun's right ascension (the Astronomical Almanac's low-precision formula, 0.01 deg)."""
    n = days - 10957.5
    mean_longitude = math.radians(280.460 + 0.9856474 * n)
    anomaly = math.radians(357.528 + 0.9856003 * n)
    longitude = mean_longitude + math.radians(1.915) * math.sin(anomaly) + math.radians(0.020) * math.sin(2 * anomaly)
    obliquity = math.radians(23.439 - 4e-7 * n)
    return math.atan2(math.cos(obliquity) * math.sin(longitude), math.cos(longitude))


def mean_rates(
    a_m: float, e: float, i: float, node: float, perigee: float, days: float, b_m2_kg: float, activity: SolarActivity
) -> tuple[float, float]:
    """Revolution-averaged da/dt [m/s] and de/dt [1/s] from drag in NRLMSIS at the points' real places."""
    anomaly = (np.arange(POINTS) + 0.5) * 2.0 * np.pi / POINTS
    cos_e, sin_e = np.cos(anomaly), np.sin(anomaly)
    root = math.sqrt(1.0 - e * e)
    n = math.sqrt(MU_EARTH_M3_S2 / a_m**3)
    ratio = 1.0 - e * cos_e
    perifocal_r = np.stack([a_m * (cos_e - e), a_m * root * sin_e, np.zeros(POINTS)])
    perifocal_v = np.stack([-a_m * n * sin_e / ratio, a_m * n * root * cos_e / ratio, np.zeros(POINTS)])
    co, so = math.cos(node), math.sin(node)
    ci, si = math.cos(i), math.sin(i)
    cw, sw = math.cos(perigee), math.sin(perigee)
    rotation = np.array(
        [
            [co * cw - so * sw * ci, -co * sw - so * cw * ci, so * si],
            [so * cw + co * sw * ci, -so * sw + co * cw * ci, -co * si],
            [sw * si, cw * si, ci],
        ]
    )
    r = rotation @ perifocal_r
    v = rotation @ perifocal_v
    radius = np.linalg.norm(r, axis=0)
    latitude = np.arcsin(r[2] / radius)
    height_km = geodetic_altitude_m(radius - EARTH_RADIUS_M, np.degrees(latitude)) / 1e3
    longitude = np.degrees(np.mod(np.arctan2(r[1], r[0]) - sidereal_angle_rad(days), 2.0 * np.pi))
    f107, f107a, ap = (float(x) for x in activity.indices(days))
    date = _EPOCH + np.timedelta64(round(days * 86400.0), "s")
    rho = require_pymsis().calculate(
        np.full(POINTS, date),
        longitude,
        np.degrees(latitude),
        height_km,
        f107s=np.full(POINTS, f107),
        f107as=np.full(POINTS, f107a),
        aps=np.full((POINTS, 7), ap),
        version=2.1,
    )[..., 0]
    air = np.stack([-EARTH_ROTATION_RAD_S * r[1], EARTH_ROTATION_RAD_S * r[0], np.zeros(POINTS)])
    relative = v - air
    force = -0.5 * b_m2_kg * rho * np.linalg.norm(relative, axis=0) * relative
    weights = ratio / ratio.sum()  # dt is proportional to (1 - e cos E) dE
    da = 2.0 * a_m * a_m / MU_EARTH_M3_S2 * np.sum(weights * np.sum(v * force, axis=0))
    h = np.cross(r, v, axis=0)
    de_vec = (np.cross(force, h, axis=0) + np.cross(v, np.cross(r, force, axis=0), axis=0)) / MU_EARTH_M3_S2
    e_hat = rotation @ np.array([1.0, 0.0, 0.0])
    de = float(e_hat @ (de_vec @ weights))
    return float(da), de


def j2_rates_rad_s(a_m: float, e: float, i: float) -> tuple[float, float]:
    """Secular d(node)/dt and d(argument of perigee)/dt by J2 [rad/s] (`orbit_env.physics.oblateness`)."""
    p = a_m * (1.0 - e * e)
    return float(node_rate_rad_per_day(p, e, i)) / 86400.0, float(perigee_rate_rad_per_day(p, e, i)) / 86400.0


def resolved_lifetime_days(
    case: Case, b_m2_kg: float, perigee_local_time_h: float, perigee_rad: float, activity: SolarActivity
) -> float:
    """Days to re-entry from the case's start with the perigee at that local time and argument."""
    p, ecc = elements_from_heights(
        (case.perigee_km + EQUATORIAL_OFFSET_KM) * 1e3, (case.apogee_km + EQUATORIAL_OFFSET_KM) * 1e3
    )
    a, e = float(semi_major_axis_m(p, ecc)), float(ecc)
    i = math.radians(case.inclination_deg)
    days = start = unix_days(case.start)
    # The node that puts the perigee's right ascension at that local time.
    perigee_ra = sun_right_ascension_rad(days) + math.radians(15.0 * (perigee_local_time_h - 12.0))
    node = perigee_ra - math.atan2(math.cos(i) * math.sin(perigee_rad), math.cos(perigee_rad))
    perigee = perigee_rad
    reentry_m = EARTH_RADIUS_M + REENTRY_ALTITUDE_M
    while a * (1.0 - e) > reentry_m:
        da, de = mean_rates(a, e, i, node, perigee, days, b_m2_kg, activity)
        margin = a * (1.0 - e) - reentry_m
        rp_rate = abs(da * (1.0 - e) - a * de)
        step = min(MAX_STEP_DAYS * 86400.0, MAX_STEP_FRACTION * margin / max(rp_rate, 1e-30) + 60.0)
        half = 0.5 * step
        dnode, dperigee = j2_rates_rad_s(a, e, i)
        da2, de2 = mean_rates(
            a + half * da, max(e + half * de, 0.0), i, node + half * dnode, perigee + half * dperigee,
            days + half / 86400.0, b_m2_kg, activity,
        )  # fmt: skip
        dnode, dperigee = j2_rates_rad_s(a + half * da, max(e + half * de, 0.0), i)
        a, e = a + step * da2, max(e + step * de2, 0.0)
        node, perigee, days = node + step * dnode, perigee + step * dperigee, days + step / 86400.0
    return days - start


def main() -> None:
    """Print, per case, the resolved lives over the starting phases against the package's averaged prediction."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--cases", default="San Marco 2", help="comma-separated names of benchmarks/reentry_cases.csv")
    parser.add_argument("--phases", type=int, default=8, help="starting local times of the perigee (and arguments)")
    args = parser.parse_args()
    activity = load_record()
    names = [name.strip() for name in args.cases.split(",")]
    for name in names:
        case = next(c for c in CASES if c.name == name)
        cd = drag_coefficient(case, activity)[0]
        b = cd * case.shape.reference_area_m2 / case.mass_kg
        begin = time.perf_counter()
        lives = []
        for k in range(args.phases):
            local_time = 24.0 * k / args.phases
            argument = 2.0 * math.pi * k / args.phases if case.inclination_deg > 10.0 else 0.0
            lives.append(resolved_lifetime_days(case, b, local_time, argument, activity))
            print(f"  {name}: perigee at {local_time:4.1f} h, argument {math.degrees(argument):5.1f} deg: "
                  f"{lives[-1]:8.1f} d", flush=True)  # fmt: skip
        seconds = time.perf_counter() - begin
        observed = observed_days(case)
        mean = float(np.mean(lives))
        line = (
            f"{name}: C_D {cd:.2f}, resolved mean {mean:.1f} d (min {min(lives):.1f}, max {max(lives):.1f}), "
            f"observed {observed:.1f} d ({mean / observed - 1:+.1%}), {seconds:.0f} s"
        )
        averaged = predict(case, activity, cd)
        print(line + f"; the package (averaged profile) {averaged:.1f} d, resolved / averaged {mean / averaged:.3f}")


if __name__ == "__main__":
    main()
