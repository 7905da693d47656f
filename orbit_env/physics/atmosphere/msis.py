"""NRLMSIS (through ``pymsis``) as an orbit-averaged density profile, SI units.

The decay core needs density against altitude only (``density_kg_m3(altitude_m)``,
altitude above the package's spherical Earth of radius ``EARTH_RADIUS_M``). NRLMSIS
gives density at a point: latitude, local solar time, day of year, altitude and the
solar and geomagnetic indices. `MsisAtmosphere` averages it, once per solar
condition, into a table of log-density on an altitude grid, and interpolates that.

How the average is taken, and why:

* **Density, not log-density.** The decay rates are linear in density, so the
  time-average of density is what the orbit average needs.
* **Latitude: the arcsine law of the inclination.** On a circular orbit of
  inclination i the argument of latitude u advances uniformly and
  sin(latitude) = sin(i) sin(u), so the time spent at latitude phi has the density
  cos(phi) / (pi sqrt(sin^2 i - sin^2 phi)) for |phi| < i (peaks at +-i). For an
  eccentric orbit the same holds for the perigee region, because J2 turns the line
  of apsides (the argument of perigee) through all values over the lifetime. We
  take u at the midpoints of ``LATITUDE_NODES`` equal intervals of [-pi/2, pi/2]:
  the integrand is smooth and periodic in u, so this midpoint rule converges
  geometrically (by symmetry it is the 2n-point rule on the full circle).
* **Local time: uniform.** The orbit plane precesses against the Sun (J2 turns the
  node by degrees a day while the Sun moves 0.99 deg/day), so over a lifetime every
  point of the orbit sees every local time. ``LOCAL_TIME_NODES`` equally spaced
  local times integrate the diurnal, semidiurnal and terdiurnal tides exactly. The
  exception is a Sun-synchronous orbit: give ``ascending_node_local_time_h`` and
  the local time then follows the orbit (it is fixed by the node's local time and
  the argument of latitude).
* **Universal time: the day's.** At one local time a satellite passes every longitude in a
  day, and near the poles NRLMSIS depends on longitude (the geomagnetic pole is off the
  geographic one): a day's mean covers its universal times too. Where the local time is free
  the latitude x local time grid alternates between 6 h and 18 h UT like a chessboard
  (`CHECKERBOARD_UT_H`: no more samples); a Sun-synchronous orbit's points are each taken at
  4, 12 and 20 h (`SUN_SYNCHRONOUS_UT_H`). Against 48 universal times (40 days, 28.5-97.5 deg,
  250-1000 km) the worst error is 0.31% at 6 x 6 nodes, 0.12% at 12 x 12; every sample at
  12 h UT was up to 3.1% off (+1.2% at 500 km on a polar orbit at solar minimum), which
  shortened a 17-year polar life by 2% (docs/validation-modern/solar-activity.md). A day of
  the year with a fraction moves the universal times, never the samples' local times.
* **Season: the year, or one day.** ``day_of_year=None`` averages over
  ``SEASON_NODES`` days spread evenly over the year (the annual and semiannual
  variations, +-30% at 400 km, integrate exactly); a number takes that day.

With 12 x 12 x 6 nodes the average differs from one with 48 x 48 x 24 by at most
0.1% from 200 to 900 km at 51.6 and 97.5 deg (F10.7 70-220, Ap 4-30), far inside
the model's own uncertainty (~15%).
* **Geometry.** NRLMSIS wants geodetic altitude; the package's altitude is above a
  6371 km sphere. A point at radius R + h and latitude phi has a geodetic altitude
  R + h - a (1 - f sin^2 phi) with the WGS84 a and f: 7 km lower at the equator,
  14 km higher at the poles, which matters at scale heights of 30-60 km.

The indices are held fixed: F10.7 of the day before (``f107_sfu``), its 81-day
centred mean (``f107a_sfu``) and the daily Ap (``ap``), all seven Ap slots equal.
For activity that changes over a lifetime see `orbit_env.decay.solar`; on its storm
days a day's average can take NRLMSIS's storm-time mode instead, each 3-hour slot with
its own ap history (``ap_history``, `ap_histories`).

Table: ``ALTITUDE_GRID_M`` (40-6000 km, 2 km steps where the scale height is short;
below 40 km the 40 km value is held: no decay computed here reaches that low);
log-density is interpolated linearly (it is nearly linear between nodes: the
relative error is below 1e-3 from 150 to 1000 km and below 4e-3 elsewhere,
measured in ``tests/physics/test_msis.py``),
and extrapolated above the grid with its top slope. Building a table costs about
0.3 s (~600 000 NRLMSIS points) and is cached per condition, so the universal
curves of `orbit_env.decay.curves` can be built and cached per profile too.

Versions (``version``, `MSIS_VERSIONS`): 2.1 (the default, Emmert et al. 2022), 2.0 and 0.0
for NRLMSISE-00 (Picone et al. 2002), the version most numerical propagators (STK, Orekit)
run: 8-19% denser than 2.1 at the heights that decide a lifetime (docs/how-to/lifetime.md).
Every table is cached per version.

Nothing is downloaded: all indices are given explicitly to ``pymsis``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env import cache
from orbit_env.checks import check_number
from orbit_env.constants import EARTH_EQUATORIAL_RADIUS_M, EARTH_RADIUS_M
from orbit_env.workers import in_two_processes

FloatArray = NDArray[np.float64]

#: The message of the ImportError when pymsis is missing.
MSIS_INSTALL_HINT = "the NRLMSIS atmosphere needs pymsis: pip install 'orbit-env[msis]'"

#: Flattening of the WGS84 ellipsoid (NRLMSIS altitudes are geodetic).
WGS84_FLATTENING = 1.0 / 298.257223563
#: Arguments of latitude in the orbit average (midpoints of equal intervals).
LATITUDE_NODES = 12
#: Local solar times in the orbit average (uniform over the day).
LOCAL_TIME_NODES = 12
#: Days in the average over the year.
SEASON_NODES = 6
#: Allowed ranges of the indices (NRLMSIS is fitted to F10.7 of about 60-300 sfu).
F107_RANGE_SFU = (40.0, 400.0)
AP_RANGE = (0.0, 400.0)
#: NRLMSIS versions ``pymsis`` runs: 2.1, 2.0 and 0.0 (NRLMSISE-00).
MSIS_VERSIONS = (2.1, 2.0, 0.0)
#: The version used unless one is chosen.
DEFAULT_MSIS_VERSION = 2.1
#: Each version's name.
MSIS_VERSION_NAMES = {2.1: "NRLMSIS 2.1", 2.0: "NRLMSIS 2.0", 0.0: "NRLMSISE-00"}

#: Altitude grid of the tables [m]: fine where the scale height is short.
ALTITUDE_GRID_M = np.concatenate(
    [
        np.arange(40e3, 200e3, 2e3),
        np.arange(200e3, 1000e3, 5e3),
        np.arange(1000e3, 2000e3, 20e3),
        np.arange(2000e3, 6000e3 + 1.0, 100e3),
    ]
)

#: Universal times [h] of a day's samples where the local time is free: alternating over the latitude x local
#: time grid like a chessboard (the module docstring, "Universal time").
CHECKERBOARD_UT_H = (6.0, 18.0)
#: Universal times [h] at which each point of a Sun-synchronous orbit is taken (its local times are fixed).
SUN_SYNCHRONOUS_UT_H = (4.0, 12.0, 20.0)

# A reference non-leap year for days of the year; NRLMSIS has no secular trend.
_REFERENCE_YEAR_START = np.datetime64("2001-01-01T00:00", "s")


def require_pymsis() -> Any:
    """Import ``pymsis.msis`` or raise an ImportError that names the extra."""
    try:
        from pymsis import msis
    except ImportError as error:  # pragma: no cover - exercised only without pymsis
        raise ImportError(MSIS_INSTALL_HINT) from error
    return msis


def check_msis_version(version: float) -> float:
    """``version`` as a float, if it is one of `MSIS_VERSIONS`.

    Raises:
        ValueError: another value, naming the allowed ones.
    """
    if isinstance(version, bool) or not isinstance(version, (int, float)) or version not in MSIS_VERSIONS:
        allowed = ", ".join(f"{v:g}" for v in MSIS_VERSIONS)
        raise ValueError(f"NRLMSIS version must be one of {allowed} (0 = NRLMSISE-00), got {version!r}")
    return float(version)


def _pymsis_version(version: float) -> float | str:
    """``pymsis``'s name of a version: it reads ``str(version)``, and knows "0" but not "0.0"."""
    return "0" if version == 0.0 else version


def orbit_samples(
    inclination_deg: float,
    ascending_node_local_time_h: float | None = None,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
) -> tuple[FloatArray, FloatArray]:
    """Latitudes [deg] and local solar times [h] of equally weighted samples of an orbit.

    Uniform local time: the product of the arcsine-law latitudes and uniform local
    times. Sun-synchronous (node local time given): the points of the orbit itself,
    u uniform over the full circle, each with its own local time.
    """
    sin_i = math.sin(math.radians(inclination_deg))
    cos_i = math.cos(math.radians(inclination_deg))
    if ascending_node_local_time_h is None:
        u = -0.5 * np.pi + (np.arange(latitude_nodes) + 0.5) * np.pi / latitude_nodes
        lat = np.degrees(np.arcsin(sin_i * np.sin(u)))
        local_time = (np.arange(local_time_nodes) + 0.5) * 24.0 / local_time_nodes
        lat_grid, lt_grid = np.meshgrid(lat, local_time, indexing="ij")
        return lat_grid.ravel(), lt_grid.ravel()
    u = (np.arange(2 * latitude_nodes) + 0.5) * np.pi / latitude_nodes
    lat = np.degrees(np.arcsin(sin_i * np.sin(u)))
    # Right ascension from the node: the Sun's hour angle moves with it (15 deg/h).
    right_ascension = np.degrees(np.arctan2(cos_i * np.sin(u), np.cos(u)))
    local_time = np.mod(ascending_node_local_time_h + right_ascension / 15.0, 24.0)
    return lat, local_time


def orbit_samples_through_day(
    inclination_deg: float,
    ascending_node_local_time_h: float | None = None,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """`orbit_samples` with a universal time [h] each, so that a day's mean covers its longitudes too.

    Local time free: the (latitude, local time) grid alternates between the two `CHECKERBOARD_UT_H`
    like a chessboard (no more samples). Sun-synchronous: every point at each of `SUN_SYNCHRONOUS_UT_H`.
    """
    lat, local_time = orbit_samples(inclination_deg, ascending_node_local_time_h, latitude_nodes, local_time_nodes)
    if ascending_node_local_time_h is None:
        row, column = np.divmod(np.arange(lat.size), local_time_nodes)
        ut = np.asarray(CHECKERBOARD_UT_H, dtype=np.float64)[(row + column) % 2]
        return lat, local_time, ut
    slots = len(SUN_SYNCHRONOUS_UT_H)
    return np.tile(lat, slots), np.tile(local_time, slots), np.repeat(SUN_SYNCHRONOUS_UT_H, lat.size)


def geodetic_altitude_m(altitude_m: ArrayLike, latitude_deg: ArrayLike) -> FloatArray:
    """Height above WGS84 of the point at radius EARTH_RADIUS_M + altitude and that latitude."""
    sin_lat = np.sin(np.radians(np.asarray(latitude_deg, dtype=np.float64)))
    surface = EARTH_EQUATORIAL_RADIUS_M * (1.0 - WGS84_FLATTENING * sin_lat * sin_lat)
    return np.asarray(altitude_m, dtype=np.float64) + (EARTH_RADIUS_M - surface)


def season_days(nodes: int = SEASON_NODES) -> FloatArray:
    """The days of the year (1-366) at which a year's average takes NRLMSIS: ``nodes`` spread evenly, mid-interval."""
    return (np.arange(nodes) + 0.5) * 365.0 / nodes + 1.0


def mean_density_kg_m3(
    altitude_m: ArrayLike,
    f107_sfu: float,
    f107a_sfu: float,
    ap: float,
    inclination_deg: float,
    day_of_year: float | None = None,
    ascending_node_local_time_h: float | None = None,
    *,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
    season_nodes: int = SEASON_NODES,
    version: float = DEFAULT_MSIS_VERSION,
) -> FloatArray:
    """NRLMSIS density [kg/m^3] (``version``) averaged over an orbit's latitudes, local times and season.

    The averaging is described in the module docstring. ``altitude_m`` is a 1-D
    array of heights above the package's spherical Earth.
    """
    days = season_days(season_nodes) if day_of_year is None else np.array([float(day_of_year)])
    ones = np.ones(days.size)
    return mean_density_over_days_kg_m3(
        altitude_m,
        f107_sfu * ones,
        f107a_sfu * ones,
        ap * ones,
        days,
        inclination_deg,
        ascending_node_local_time_h,
        latitude_nodes=latitude_nodes,
        local_time_nodes=local_time_nodes,
        version=version,
    )


def _msis_density(
    altitude_m: FloatArray,
    lat: FloatArray,
    local_time: FloatArray,
    days: FloatArray,
    f107_sfu: ArrayLike,
    f107a_sfu: ArrayLike,
    ap: ArrayLike,
    version: float,
    ut_hours: ArrayLike,
) -> FloatArray:
    """NRLMSIS mass density [kg/m^3] on a grid, in one call: shape (groups, days, samples, altitudes).

    ``lat`` and ``local_time`` are (groups, samples) orbit samples; ``days`` are days of
    the year from 0; the indices are per day (or scalars); ``version`` one of `MSIS_VERSIONS`.
    ``ap`` per day is the daily Ap (all seven of NRLMSIS's slots equal, its daily mode), or,
    shape (days, 7), each day's ap history (`ap_histories`): NRLMSIS's storm-time mode.
    ``ut_hours``: universal time of each point, broadcast to (groups, days, samples): per sample
    (`orbit_samples_through_day`) or per day (the storm-time mode's slots). A day's fraction adds to
    it, and the longitude is the one where it is the sample's local time then.
    """
    msis = require_pymsis()
    shape = (lat.shape[0], days.size, lat.shape[1], altitude_m.size)
    hours = np.broadcast_to(days[None, :, None] * 24.0 + np.asarray(ut_hours, dtype=np.float64), shape[:3])
    lon = np.mod((local_time[:, None, :] - hours) * 15.0, 360.0)  # (groups, days, samples)
    seconds = np.round(hours * 3600.0).astype("timedelta64[s]")
    dates = np.broadcast_to((_REFERENCE_YEAR_START + seconds)[..., None], shape).ravel()
    lats = np.broadcast_to(lat[:, None, :, None], shape).ravel()
    lons = np.broadcast_to(lon[..., None], shape).ravel()
    alts_km = geodetic_altitude_m(altitude_m[None, None, None, :], lat[:, None, :, None]) / 1e3
    alts_km = np.broadcast_to(alts_km, shape).ravel()

    def per_point(values: ArrayLike) -> FloatArray:
        per_day = np.broadcast_to(np.asarray(values, dtype=np.float64), (days.size,))
        return np.broadcast_to(per_day[None, :, None, None], shape).ravel()

    ap_values = np.asarray(ap, dtype=np.float64)
    if ap_values.ndim == 2:  # each day's ap history: the storm-time mode
        histories = np.broadcast_to(ap_values[None, :, None, None, :], (*shape, 7)).reshape(-1, 7)
        storm = {"geomagnetic_activity": -1.0}
    else:
        histories, storm = np.repeat(per_point(ap_values)[:, None], 7, axis=1), {}
    f107s, f107as = per_point(f107_sfu), per_point(f107a_sfu)
    name = _pymsis_version(check_msis_version(version))

    def mass_density(part: slice) -> FloatArray:  # [kg/m^3] at the points of ``part``
        out = msis.calculate(
            dates[part],
            lons[part],
            lats[part],
            alts_km[part],
            f107s=f107s[part],
            f107as=f107as[part],
            aps=histories[part],
            version=name,
            **storm,
        )
        return np.asarray(out[..., 0], dtype=np.float64).ravel()

    # Pointwise, so a large call is split over two processes (the cold path's most costly part).
    return in_two_processes(mass_density, dates.size).reshape(shape)


def mean_density_over_days_kg_m3(
    altitude_m: ArrayLike,
    f107_sfu: ArrayLike,
    f107a_sfu: ArrayLike,
    ap: ArrayLike,
    day_of_year: ArrayLike,
    inclination_deg: float,
    ascending_node_local_time_h: float | None = None,
    *,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
    version: float = DEFAULT_MSIS_VERSION,
    ap_history: ArrayLike | None = None,
) -> FloatArray:
    """Orbit-averaged NRLMSIS density [kg/m^3] (``version``), averaged again over days with their own indices.

    The k-th day has indices ``f107_sfu[k]``, ``f107a_sfu[k]``, ``ap[k]`` and day of
    the year ``day_of_year[k]`` (1-366). One NRLMSIS call for all of them. The mean
    of densities, not the density of mean indices: NRLMSIS responds to Ap
    concavely, so averaging the indices would overstate the density after storms.
    ``ap_history``: NRLMSIS's storm-time mode through each day (`orbit_mean_density_by_day_kg_m3`).
    """
    rho = _orbit_samples_density(
        altitude_m,
        f107_sfu,
        f107a_sfu,
        ap,
        day_of_year,
        inclination_deg,
        ascending_node_local_time_h,
        latitude_nodes,
        local_time_nodes,
        version,
        ap_history,
    )
    return rho.mean(axis=(0, 1))


def orbit_mean_density_by_day_kg_m3(
    altitude_m: ArrayLike,
    f107_sfu: ArrayLike,
    f107a_sfu: ArrayLike,
    ap: ArrayLike,
    day_of_year: ArrayLike,
    inclination_deg: float,
    ascending_node_local_time_h: float | None = None,
    *,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
    version: float = DEFAULT_MSIS_VERSION,
    ap_history: ArrayLike | None = None,
) -> FloatArray:
    """Each day's orbit-averaged NRLMSIS density [kg/m^3], shape (days, altitudes), in one NRLMSIS call.

    The arguments are `mean_density_over_days_kg_m3`'s, which is the mean of these rows (up to
    the order of the sums). With ``ap_history`` (days, slots, 7: each slot's ap history,
    `ap_histories`), NRLMSIS runs in its storm-time mode at each of the day's slots (slot k at
    universal time (k + 1/2) 24 / slots h, the orbit's local times kept), and a day's row is the
    mean over its slots too; ``ap`` is then unused (the history's first element is the daily Ap).
    """
    rho = _orbit_samples_density(
        altitude_m,
        f107_sfu,
        f107a_sfu,
        ap,
        day_of_year,
        inclination_deg,
        ascending_node_local_time_h,
        latitude_nodes,
        local_time_nodes,
        version,
        ap_history,
    )
    return rho.mean(axis=1)


def ap_histories(daily_ap: ArrayLike, three_hourly_ap: ArrayLike) -> FloatArray:
    """NRLMSIS's storm-time ap input at each 3-hour slot of days: shape (days, 8, 7).

    Args:
        daily_ap: Each day's Ap (the history's first element).
        three_hourly_ap: Shape (days, 27): the 3-hourly ap from the slot 57 h before the day's
            first slot (the sixth slot of three days before) to the day's last, oldest first.

    Slot k's history (as `pymsis.calculate` documents it): the daily Ap; the ap of the slot,
    of 3, 6 and 9 h before; the mean of the eight from 12 to 33 h before; of the eight from 36
    to 57 h before.
    """
    ap3 = np.asarray(three_hourly_ap, dtype=np.float64)
    now = np.arange(8) + 19  # the day's slots' places in the 27
    back = now[:, None] - np.arange(20)[None, :]  # (slots, 20): the slot, then 1 to 19 slots before
    past = ap3[:, back]  # (days, slots, 20)
    daily = np.broadcast_to(np.asarray(daily_ap, dtype=np.float64)[:, None, None], (ap3.shape[0], 8, 1))
    return np.concatenate(
        [
            daily,
            past[..., :4],
            past[..., 4:12].mean(axis=-1, keepdims=True),
            past[..., 12:20].mean(axis=-1, keepdims=True),
        ],
        axis=-1,
    )


def _orbit_samples_density(
    altitude_m: ArrayLike,
    f107_sfu: ArrayLike,
    f107a_sfu: ArrayLike,
    ap: ArrayLike,
    day_of_year: ArrayLike,
    inclination_deg: float,
    ascending_node_local_time_h: float | None,
    latitude_nodes: int,
    local_time_nodes: int,
    version: float,
    ap_history: ArrayLike | None = None,
) -> FloatArray:
    """NRLMSIS at an orbit's samples on each day: shape (days, samples, altitudes).

    With ``ap_history`` (days, slots, 7), the storm-time mode at each of the day's slots: shape
    (days, slots x samples, altitudes).
    """
    alt = np.atleast_1d(np.asarray(altitude_m, dtype=np.float64))
    days = np.atleast_1d(np.asarray(day_of_year, dtype=np.float64)) - 1.0
    if ap_history is None:
        lat, local_time, ut = orbit_samples_through_day(
            inclination_deg, ascending_node_local_time_h, latitude_nodes, local_time_nodes
        )
        return _msis_density(
            alt, lat[None, :], local_time[None, :], days, f107_sfu, f107a_sfu, ap, version, ut[None, None, :]
        )[0]
    # The storm-time mode's slots span the day's universal times: each slot takes the orbit's samples at its own.
    lat, local_time = orbit_samples(inclination_deg, ascending_node_local_time_h, latitude_nodes, local_time_nodes)
    history = np.asarray(ap_history, dtype=np.float64)
    count, slots = history.shape[:2]

    def per_slot(values: ArrayLike) -> FloatArray:
        return np.repeat(np.broadcast_to(np.asarray(values, dtype=np.float64), (count,)), slots)

    ut = np.tile((np.arange(slots) + 0.5) * 24.0 / slots, count)
    rho = _msis_density(
        alt,
        lat[None, :],
        local_time[None, :],
        per_slot(days),
        per_slot(f107_sfu),
        per_slot(f107a_sfu),
        history.reshape(count * slots, 7),
        version,
        ut[None, :, None],
    )[0]
    return rho.reshape(count, slots * lat.size, alt.size)


def mean_density_over_inclinations_kg_m3(
    altitude_m: ArrayLike,
    f107_sfu: float,
    f107a_sfu: float,
    ap: float,
    inclinations_deg: ArrayLike,
    ascending_node_local_time_h: float | None = None,
    *,
    day_of_year: float | None = None,
    latitude_nodes: int = LATITUDE_NODES,
    local_time_nodes: int = LOCAL_TIME_NODES,
    season_nodes: int = SEASON_NODES,
    version: float = DEFAULT_MSIS_VERSION,
) -> FloatArray:
    """`mean_density_kg_m3` (averaged over the year, or on ``day_of_year``) at several inclinations, in one call.

    Returns an array (inclinations, altitudes): row k is `mean_density_kg_m3` at
    ``inclinations_deg[k]`` with the same nodes. One call for all rows: NRLMSIS's
    cost is per point, but a catalogue spread over inclinations should not pay
    ``pymsis``'s set-up once per inclination.
    """
    alt = np.atleast_1d(np.asarray(altitude_m, dtype=np.float64))
    inclinations = np.atleast_1d(np.asarray(inclinations_deg, dtype=np.float64))
    samples = [
        orbit_samples_through_day(float(i), ascending_node_local_time_h, latitude_nodes, local_time_nodes)
        for i in inclinations
    ]
    lat, local_time, ut = (np.stack(parts) for parts in zip(*samples, strict=True))  # each (inclinations, samples)
    if day_of_year is None:
        days = (np.arange(season_nodes) + 0.5) * 365.0 / season_nodes
    else:
        days = np.array([float(day_of_year) - 1.0])
    return _msis_density(alt, lat, local_time, days, f107_sfu, f107a_sfu, ap, version, ut[:, None, :]).mean(axis=(1, 2))


@lru_cache(maxsize=256)
def _cached_log_density_table(*conditions: float | None) -> FloatArray:
    """`_log_density_table`, kept on disk (orbit_env.cache): a profile costs NRLMSIS thousands of calls.

    ``conditions`` are `_log_density_table`'s arguments, the version last: every key, in memory
    and on disk, names the version.
    """
    description = cache.describe(conditions)
    table = cache.load("msis", description)
    if table is None:
        table = {"log_density": _log_density_table(*conditions)}
        cache.store("msis", description, table)
    return table["log_density"]


def _log_density_table(
    f107_sfu: float,
    f107a_sfu: float,
    ap: float,
    inclination_deg: float,
    day_of_year: float | None,
    ascending_node_local_time_h: float | None,
    version: float,
) -> FloatArray:
    rho = mean_density_kg_m3(
        ALTITUDE_GRID_M,
        f107_sfu,
        f107a_sfu,
        ap,
        inclination_deg,
        day_of_year,
        ascending_node_local_time_h,
        version=version,
    )
    assert np.all(np.isfinite(rho) & (rho > 0.0)), "NRLMSIS returned a non-positive density"
    return np.log(rho)


def interpolate_log_density(altitude_m: ArrayLike, log_rho: FloatArray) -> FloatArray:
    """Density from a log-density table, interpolated at ``altitude_m`` (extrapolated above the top)."""
    h = np.asarray(altitude_m, dtype=np.float64)
    grid = ALTITUDE_GRID_M
    value = np.interp(h, grid, log_rho)
    top_slope = (log_rho[-1] - log_rho[-2]) / (grid[-1] - grid[-2])
    return np.exp(np.where(h > grid[-1], log_rho[-1] + top_slope * (h - grid[-1]), value))


@dataclass(frozen=True)
class MsisAtmosphere:
    """NRLMSIS averaged over an orbit, at fixed solar and geomagnetic activity.

    Frozen and hashable: `orbit_env.decay.curves.universal_curves` caches the
    curves per instance, and the density table is cached per condition.

    Args:
        f107_sfu: Daily F10.7 of the previous day [sfu = 1e-22 W m^-2 Hz^-1].
        f107a_sfu: 81-day centred mean of F10.7 [sfu].
        ap: Daily geomagnetic Ap index.
        inclination_deg: Orbit inclination: sets the latitudes averaged over.
        day_of_year: 1-366, or None for the average over the year.
        ascending_node_local_time_h: Local solar time of the ascending node of a
            Sun-synchronous orbit [h]; None (default) averages over local time.
        scale: Multiplier on the whole profile.
        version: NRLMSIS version, one of `MSIS_VERSIONS`: 2.1 (default), 2.0, or 0.0
            for NRLMSISE-00 (what STK and Orekit users mostly run).

    Examples:
        >>> atmosphere = MsisAtmosphere(150.0, 150.0, 15.0, inclination_deg=51.6)
        >>> 1e-12 < float(atmosphere.density_kg_m3(400e3)) < 1e-11
        True
    """

    f107_sfu: float
    f107a_sfu: float
    ap: float
    inclination_deg: float
    day_of_year: float | None = None
    ascending_node_local_time_h: float | None = None
    scale: float = 1.0
    version: float = DEFAULT_MSIS_VERSION

    def __post_init__(self) -> None:
        low, high = F107_RANGE_SFU
        check_number(self.f107_sfu, "f107_sfu", unit="sfu", low=low, high=high)
        check_number(self.f107a_sfu, "f107a_sfu", unit="sfu", low=low, high=high)
        check_number(self.ap, "ap", low=AP_RANGE[0], high=AP_RANGE[1])
        check_number(self.inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
        if self.day_of_year is not None:
            check_number(self.day_of_year, "day_of_year", low=1.0, high=367.0)
        if self.ascending_node_local_time_h is not None:
            check_number(self.ascending_node_local_time_h, "ascending_node_local_time_h", unit="h", low=0.0, high=24.0)
        check_number(self.scale, "scale", low=0.0, low_inclusive=False)
        # A float always (0 and 0.0 are one version, and one cache key).
        object.__setattr__(self, "version", check_msis_version(self.version))

    def log_density_table(self) -> FloatArray:
        """ln(density [kg/m^3]) on ``ALTITUDE_GRID_M``, without ``scale`` (cached)."""
        return _cached_log_density_table(
            float(self.f107_sfu),
            float(self.f107a_sfu),
            float(self.ap),
            float(self.inclination_deg),
            None if self.day_of_year is None else float(self.day_of_year),
            None if self.ascending_node_local_time_h is None else float(self.ascending_node_local_time_h),
            self.version,
        )

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Orbit-averaged density [kg/m^3] at altitude [m] above the spherical Earth."""
        return self.scale * interpolate_log_density(altitude_m, self.log_density_table())
