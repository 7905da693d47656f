"""The drag parameter an element set carries, calibrated to the air the prediction uses.

An element set's B* is SGP4's fitting parameter against SGP4's own static density, the
power law rho0 ((q0 - s) / (r - s))^4 (Hoots & Roehrich, *Spacetrack Report #3*, 1980;
Vallado et al. 2006): read as C_D A / m = 2 B* / rho0 it carries the ratio of that
density to the real air's, a factor of 1.3 at 300 km and of 10 to 30 at 500-600 km in a
quiet Sun. What the set measures is the product, the decay: C_D A / m x rho_SGP4. The
drag parameter the prediction needs is the one that makes the chosen air, at the set's
epoch, give the same decay:

    c = (2 B* / rho0) <rho_SGP4 v^3> / (<rho_air v^3> F_rot),

with <.> the time average over the orbit (drag takes energy at the rate c rho v^3 / 2)
and F_rot = ((v - Omega r cos i) / v)^2 the weaker drag of co-rotating air, which SGP4
does not model. The air is averaged over the days before the epoch that an orbit
determination spans (`FIT_SPAN_DAYS`), with the record's indices of each day.

The same calibration reads the set's first derivative of the mean motion (ndot / 2 of
line 1) when asked: da/dt = -(2/3) (a / n) ndot, against the model's
da/dt = -(a^2 / mu) c <rho_air v^3> F_rot. Which of the two predicts better, measured on
real re-entries, is in docs/validation-modern.md.

Units: SI (m, kg, s), km only where named.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env import cache
from orbit_env.analysis.uncertainty import ONE_SET_DRAG_SIGMA
from orbit_env.constants import EARTH_RADIUS_M, MU_EARTH_M3_S2
from orbit_env.decay.solar import calendar_day, day_of_year
from orbit_env.physics.orbit import corotation_drag_factor
from orbit_env.workers import in_two_processes

FloatArray = NDArray[np.float64]

#: SGP4's B* reference density, 0.15696615 kg/(m^2 ER) per Earth radius of WGS72: rho at q0 = 120 km [kg/m^3].
SGP4_RHO0_KG_M3 = 0.15696615 / 6378.135e3
#: SGP4's Earth radius (WGS72) [m] and the heights of its power law [m]: q0 = 120 km, s = 78 km.
SGP4_EARTH_RADIUS_M = 6378.135e3
SGP4_Q0_M = 120e3
SGP4_S_M = 78e3
#: Days before the epoch whose air the calibration averages: an orbit determination spans a few days.
FIT_SPAN_DAYS = 5
#: Points in eccentric anomaly of the orbit average (the integrand is smooth and periodic).
ORBIT_POINTS = 64
#: The sources a drag parameter can come from (JSON ``drag_parameter_source``).
SOURCE_BSTAR_CALIBRATED = "bstar_calibrated"
SOURCE_NDOT_CALIBRATED = "ndot_calibrated"
SOURCE_HISTORY_FIT = "history_fit"


def sgp4_density_kg_m3(radius_m: Any, mean_perigee_radius_m: float) -> FloatArray:
    """SGP4's density at ``radius_m``: rho0 ((q0 - s) / (r - s))^4, s lowered for perigees under 156 km.

    As SGP4 does (sgp4init): s = 78 km above its Earth radius; for a perigee below 156 km,
    s = perigee - 78 km, and 20 km for a perigee below 98 km.
    """
    perigee_km = (mean_perigee_radius_m - SGP4_EARTH_RADIUS_M) / 1e3
    s_m = SGP4_S_M
    if perigee_km < 156.0:
        s_m = (perigee_km - 78.0) * 1e3 if perigee_km >= 98.0 else 20e3
    height_m = np.asarray(radius_m, dtype=np.float64) - SGP4_EARTH_RADIUS_M
    return SGP4_RHO0_KG_M3 * ((SGP4_Q0_M - s_m) / np.maximum(height_m - s_m, 1.0)) ** 4


def _orbit(semi_major_axis_m: float, eccentricity: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Radius [m], speed^3 [m^3/s^3] and time weight at ``ORBIT_POINTS`` eccentric anomalies."""
    anomaly = (np.arange(ORBIT_POINTS) + 0.5) * 2.0 * math.pi / ORBIT_POINTS
    cos_e = np.cos(anomaly)
    radius = semi_major_axis_m * (1.0 - eccentricity * cos_e)
    speed3 = (MU_EARTH_M3_S2 * (2.0 / radius - 1.0 / semi_major_axis_m)) ** 1.5
    weight = (1.0 - eccentricity * cos_e) / ORBIT_POINTS
    return radius, speed3, weight


def rotation_factor(perigee_radius_m: float, apogee_radius_m: float, inclination_deg: float) -> float:
    """F_rot of an orbit given by its radii (`orbit_env.physics.orbit.corotation_drag_factor`)."""
    return float(
        corotation_drag_factor(perigee_radius_m - EARTH_RADIUS_M, apogee_radius_m - EARTH_RADIUS_M, inclination_deg)
    )


@dataclass(frozen=True)
class DragCalibration:
    """A drag parameter calibrated to an air, and what it rests on.

    Attributes:
        drag_parameter_m2_kg: c = C_D A / m that gives the set's decay in the air.
        source: `SOURCE_BSTAR_CALIBRATED` or `SOURCE_NDOT_CALIBRATED`.
        uncalibrated_m2_kg: 2 B* / rho0, the set's drag parameter read against SGP4's density.
        density_ratio: <rho_SGP4 v^3> / <rho_air v^3> over the orbit at the epoch.
        rotation_factor: F_rot (1 in still air).
    """

    drag_parameter_m2_kg: float
    source: str
    uncalibrated_m2_kg: float
    density_ratio: float
    rotation_factor: float

    def report(self) -> dict[str, float | str]:
        """The JSON keys."""
        return {
            "drag_parameter_uncalibrated_m2_kg": self.uncalibrated_m2_kg,
            "sgp4_to_air_density_ratio": self.density_ratio,
            "rotation_factor": self.rotation_factor,
        }


def air_drag_rate(
    scenario: Any, semi_major_axis_m: float, eccentricity: float, inclination_deg: float, epoch_days: float | None
) -> float:
    """<rho_air v^3> F_rot over the flown orbit at the epoch [kg/s^3], the scenario's scale included.

    The air is the mean over the `FIT_SPAN_DAYS` before the epoch (an orbit determination's span).
    """
    return _air_rate(
        scenario,
        semi_major_axis_m,
        eccentricity,
        inclination_deg,
        lambda height_m: scenario.air.density_near_kg_m3(height_m, inclination_deg, epoch_days, FIT_SPAN_DAYS),
    )


def _air_rate(
    scenario: Any,
    semi_major_axis_m: float,
    eccentricity: float,
    inclination_deg: float,
    density_kg_m3: Callable[[FloatArray], Any],
) -> float:
    """<rho v^3> F_rot over the flown orbit [kg/s^3] of the density at heights ``density_kg_m3``, the scale included."""
    radius, speed3, weight = _orbit(semi_major_axis_m, eccentricity)
    rho = density_kg_m3(radius - EARTH_RADIUS_M)
    rate = float(np.sum(rho * speed3 * weight)) * scenario.density_scale
    if scenario.corotating:
        q = semi_major_axis_m * (1.0 - eccentricity)
        rate *= rotation_factor(q, semi_major_axis_m * (1.0 + eccentricity), inclination_deg)
    return rate


def calibrate(elements: Any, scenario: Any, *, source: str = SOURCE_BSTAR_CALIBRATED) -> DragCalibration | None:
    """The drag parameter of ``elements`` (an `orbit_env.analysis.elements.ElementSet`) in ``scenario``'s air.

    Returns None when the set carries no decay (B* or ndot not above zero).

    Raises:
        ValueError: an unknown source.
    """
    if source not in (SOURCE_BSTAR_CALIBRATED, SOURCE_NDOT_CALIBRATED):
        raise ValueError(f"source must be {SOURCE_BSTAR_CALIBRATED} or {SOURCE_NDOT_CALIBRATED}, got {source!r}")
    uncalibrated = elements.drag_parameter_m2_kg
    mean_a_m = elements.semi_major_axis_km * 1e3
    e = elements.eccentricity
    flown_a_m = mean_a_m + elements.flown_offset_km * 1e3
    air_rate = air_drag_rate(scenario, flown_a_m, e, elements.inclination_deg, elements.epoch_days)
    q_flown, q_mean = flown_a_m * (1.0 - e), mean_a_m * (1.0 - e)
    turning = rotation_factor(q_flown, flown_a_m * (1.0 + e), elements.inclination_deg) if scenario.corotating else 1.0
    radius, speed3, weight = _orbit(mean_a_m, e)
    sgp4_rate = float(np.sum(sgp4_density_kg_m3(radius, q_mean) * speed3 * weight))
    ratio = sgp4_rate * turning / air_rate
    if source == SOURCE_BSTAR_CALIBRATED:
        if uncalibrated is None:
            return None
        c = uncalibrated * sgp4_rate / air_rate
    else:
        ndot = elements.ndot_rev_day2
        if ndot is None or ndot <= 0.0:
            return None
        n_rad_s = math.sqrt(MU_EARTH_M3_S2 / flown_a_m**3)
        dadt = (2.0 / 3.0) * flown_a_m / n_rad_s * ndot * 2.0 * math.pi / 86400.0**2
        c = dadt * MU_EARTH_M3_S2 / (flown_a_m**2 * air_rate)
    return DragCalibration(c, source, float("nan") if uncalibrated is None else uncalibrated, ratio, turning)


#: Sets of a history further back than this before the latest are not fitted [days]: the satellite's
#: attitude and the air change over months, and the prediction starts from the latest set.
HISTORY_SPAN_DAYS = 90.0
#: Steps of a history fit from which a forked child computes half of them (`orbit_env.workers.in_two_processes`):
#: a step's air costs about 14 ms (NRLMSIS over the orbit on its day, eight times on a storm day; measured over 40
#: days of August 2023, 7 of them storm days), a fork 5-15 ms.
FIT_FORK_MIN_STEPS = 4
#: The integration step of a history fit [days].
HISTORY_STEP_DAYS = 1.0


@dataclass(frozen=True)
class DragFit:
    """A drag parameter fitted to the decay of the semi-major axis between element sets of one object.

    Attributes:
        drag_parameter_m2_kg: c that reproduces the decay in the air.
        sets: How many sets the fit used.
        span_days: From the first fitted set to the last.
        residual_km: RMS of the mean semi-major axes about the fitted decay; None for two sets (the
            fit goes through both).
        sigma_ln: Standard error of ln c from the residuals (a floor of the air's day-to-day
            error is not included; see `orbit_env.analysis.uncertainty`); for two sets, which leave
            no residual, one set's scatter (`orbit_env.analysis.uncertainty.ONE_SET_DRAG_SIGMA`).
    """

    drag_parameter_m2_kg: float
    sets: int
    span_days: float
    residual_km: float | None
    sigma_ln: float

    def report(self) -> dict[str, float | int]:
        """The JSON object ``drag_fit``."""
        return {
            "drag_parameter_m2_kg": self.drag_parameter_m2_kg,
            "sets": self.sets,
            "span_days": self.span_days,
            "residual_km": self.residual_km,
            "sigma_ln": self.sigma_ln,
        }


def _rates_description(
    air: str, scenario: Any, a_path: FloatArray, middle: FloatArray, eccentricity: float, inclination_deg: float
) -> str:
    """The cache description of a history fit's rates: the air's, the scale, the turning air and the orbit's path."""
    path = hashlib.sha256(np.concatenate([a_path, middle]).tobytes()).hexdigest()
    settings = (scenario.density_scale, bool(scenario.corotating), eccentricity, inclination_deg)
    return f"history rates {air} {cache.describe(tuple(float(v) for v in settings))} path={path}"


def _days_air_description(model: Any, days: FloatArray) -> str:
    """What `SolarDecayModel.density_on_day_kg_m3` reads on ``days``: the settings and a digest of the indices."""
    storm = model.storm_history(days)
    read = [*model.activity.indices(days), day_of_year(days), np.array([] if storm is None else storm.ravel())]
    digest = hashlib.sha256(np.concatenate([np.asarray(x, dtype=np.float64).ravel() for x in read]).tobytes())
    settings = (model.version, model.ascending_node_local_time_h, model.follow_season, model.storm_ap)
    return f"days' air {settings!r} days={digest.hexdigest()}"


class NoHistoryToFit(ValueError):
    """A history with fewer than two sets a day apart within `HISTORY_SPAN_DAYS` of its latest: nothing to fit.

    Its latest set alone still gives the drag (`calibrate`), which is what the callers fall back on.
    """


def fit_history(history: list[Any], scenario: Any) -> DragFit:
    """Fit c to the decay between the sets of one object (oldest first), in ``scenario``'s air.

    Each set's mean semi-major axis is a measurement; the model's decay from the first,
    da/dt = -(a^2 / mu) c <rho_air v^3> F_rot, is integrated day by day in the air of each
    day along the observed orbit (the semi-major axes interpolated between the sets; a dated
    air's each calendar day as the decay reads it, `SolarDecayModel.density_on_day_kg_m3`) and c
    is the least-squares fit of the measured drops to c times the integral. Sets older than
    `HISTORY_SPAN_DAYS` before the latest are left out, and sets of the same epoch count once.

    Raises:
        NoHistoryToFit: fewer than two sets a day apart in the span.
        ValueError: sets of different objects, or no decay between them (the semi-major
            axis does not fall: a manoeuvre, or too short a span).
    """
    numbers = sorted({s.catalogue_number for s in history})
    if len(numbers) > 1:
        raise ValueError(f"a history is one object's sets; these are of {', '.join(numbers)}")
    latest = max(s.epoch_days for s in history)
    # A set given twice (downloads joined into one file) is one measurement: one set per epoch, the last read.
    sets = list({s.epoch_days: s for s in history if latest - s.epoch_days <= HISTORY_SPAN_DAYS}.values())
    sets.sort(key=lambda s: s.epoch_days)
    if len(sets) < 2 or sets[-1].epoch_days - sets[0].epoch_days < HISTORY_STEP_DAYS:
        raise NoHistoryToFit(
            f"a drag fit needs sets at least a day apart within {HISTORY_SPAN_DAYS:g} days of the latest; "
            f"{len(sets)} set(s) there"
        )
    t = np.array([s.epoch_days for s in sets])
    a_m = np.array([(s.semi_major_axis_km + s.flown_offset_km) * 1e3 for s in sets])
    e = float(np.median([s.eccentricity for s in sets]))
    inclination = float(np.median([s.inclination_deg for s in sets]))
    steps = max(1, math.ceil((t[-1] - t[0]) / HISTORY_STEP_DAYS))
    grid = np.linspace(t[0], t[-1], steps + 1)
    middle = 0.5 * (grid[1:] + grid[:-1])
    a_path = np.interp(middle, t, a_m)

    # Each step in the air the decay flies on its day (a dated air: the calendar day's row, storm days in
    # NRLMSIS's storm-time mode); an undated air has one air.
    model = scenario.solar_model(inclination) if scenario.time_varying else None
    step_days = calendar_day(middle)

    def step_rate(a: float, day: float) -> float:
        if model is None:
            return air_drag_rate(scenario, a, e, inclination, day)
        return _air_rate(scenario, a, e, inclination, lambda height_m: model.density_on_day_kg_m3(day, height_m))

    def rates(days: slice) -> FloatArray:
        """da/dt per unit c on the steps ``days`` (each step's on its own: a forked child may take half)."""
        return np.array(
            [a * a / MU_EARTH_M3_S2 * step_rate(a, day) for a, day in zip(a_path[days], step_days[days], strict=True)],
            dtype=np.float64,
        )

    # The steps' air is most of a fit's cost: kept on disk, so that the same history (another command on
    # the same file, a batch run again) is fitted without NRLMSIS. The key holds all that the rates read.
    air = None if model is None else _days_air_description(model, step_days)
    key = None if air is None else _rates_description(air, scenario, a_path, middle, e, inclination)
    stored = cache.load("fit", key)
    if stored is not None:
        rate = stored["rate"]
    else:
        rate = in_two_processes(rates, middle.size, min_size=FIT_FORK_MIN_STEPS)
        cache.store("fit", key, {"rate": rate})
    # The model's drop of a from the first set to each set per unit c [m per m^2/kg].
    cumulative = np.concatenate([[0.0], np.cumsum(rate * np.diff(grid) * 86400.0)])
    unit_drop = np.interp(t, grid, cumulative)
    # Least squares of a_k = a_start - c unit_drop_k, the start fitted too: every set's semi-major axis is a
    # measurement with the same error, the first one's included (held as exact, its error would shift c for
    # every later set alike). For two sets the line goes through both, as before.
    centred, deviation = unit_drop - unit_drop.mean(), a_m - a_m.mean()
    c = float(-np.dot(centred, deviation) / np.dot(centred, centred))
    if not c > 0.0:
        raise ValueError(
            f"the semi-major axis does not fall between these {len(sets)} sets "
            f"({(a_m[-1] - a_m[0]) / 1e3:+.3f} km over {t[-1] - t[0]:.1f} days): a manoeuvre, "
            "or too short a span to fit"
        )
    if len(sets) == 2:  # the fit goes through both: no residual to judge it by, so one set's scatter
        return DragFit(c, 2, float(t[-1] - t[0]), None, ONE_SET_DRAG_SIGMA)
    residual = deviation + c * centred
    rms = float(np.sqrt(np.sum(residual**2) / (len(sets) - 2)))
    sigma_c = rms / math.sqrt(float(np.dot(centred, centred)))
    return DragFit(c, len(sets), float(t[-1] - t[0]), rms / 1e3, sigma_c / c)
