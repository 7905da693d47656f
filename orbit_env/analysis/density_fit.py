"""The density scale factor from an observed decay: the paper's proposal at the end of section 4.

SI units inside (m, s); observation files and results at the edge in km and days.

The paper notes that the lifetime is nearly inversely proportional to the density
near the initial perigee, so an observed decay measures the real density. Here the
measured quantity is a factor s on the chosen model's density (any atmosphere of a
`orbit_env.analysis.scenario.Scenario`). On a fixed profile s enters the decay only
through time: t = W / (g c s) (``orbit_env.decay.averaged``), so the decay follows the
universal curves and s sets how fast.

Two kinds of data:

* **Observed orbits** (three or more rows of time, perigee, apogee). Parameters: ln s
  and the first orbit's perigee and apogee (the first row is as noisy as the rest).
  The model orbit at time t_i is found on the curves: W falls by g c s (t_i - t_0)
  from the first orbit's W, solved for nu by Newton's method (dW/dnu = P).
  Nonlinear least squares on the height residuals, unweighted; the noise sigma is
  estimated from the residuals (RSS / (2n - 3)) and the covariance is
  sigma^2 (J^T J)^-1. Intervals use Student's t with 2n - 3 degrees of freedom.
  Needs a fixed profile (not a time-stepped NRLMSIS scenario).
* **A re-entry date** (the first row and ``reentry``): s = W_0 / (g c dt) on a
  fixed profile, or, under changing activity, the s whose time-stepped lifetime is
  dt (found by bracketing on a vectorized grid of s, then interpolation in ln s).
  The uncertainty is propagated linearly from the re-entry time's
  (``reentry_sigma_days``) and the first orbit's heights' (``height_sigma_km``,
  both heights, independent); the model's own error is not included.

Observation CSV: a header, then rows with ``date`` (``YYYY-MM-DD``, optionally with
``THH:MM``) or ``days`` (days from any origin), ``perigee_km`` and ``apogee_km``,
in time order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.analysis.scenario import DENSITY_SCALE_RANGE, Scenario
from orbit_env.checks import InputError, check_date, check_number
from orbit_env.constants import DAYS_PER_YEAR, G0_M_S2, SECONDS_PER_DAY
from orbit_env.csvfile import cell_value, read_csv
from orbit_env.decay.curves import NU_REF, UniversalCurves
from orbit_env.decay.solar import iso_date, unix_days
from orbit_env.physics.orbit import elements_from_heights, period_s

FloatArray = NDArray[np.float64]


#: A re-entry fit's uncertainties unless told: of the re-entry time [days] (a day-only date is +-0.5 day) and of
#: the first orbit's heights [km].
REENTRY_SIGMA_DAYS = 0.5
HEIGHT_SIGMA_KM = 1.0


@dataclass(frozen=True)
class Observations:
    """Observed orbits: time [days], perigee and apogee heights [km].

    Attributes:
        days: Times, strictly increasing: unix days (``axis="date"``) or days from any origin.
        perigee_km: Perigee heights.
        apogee_km: Apogee heights.
        source: Where they came from (for messages).
        axis: ``"date"`` (the file gave dates) or ``"days"`` (it gave days); a re-entry
            given as text must be on the same axis.
        lines: The file's line of each observation (for messages), if read from a file.
    """

    days: FloatArray
    perigee_km: FloatArray
    apogee_km: FloatArray
    source: str = "observations"
    axis: str = "days"
    lines: tuple[int, ...] | None = None

    def where(self, index: int) -> str:
        """``file, line N`` (or ``observations, observation N``) of one observation."""
        if self.lines is None:
            return f"{self.source}, observation {index + 1}"
        return f"{self.source}, line {self.lines[index]}"


def read_observations(path: str | Path) -> Observations:
    """Read observed orbits (format in the module docstring).

    Raises:
        ValueError: missing columns, both a ``date`` and a ``days`` column, unreadable
            values, dates outside 1957-2200, times not increasing; the message names the
            file and the line.
    """
    from orbit_env.analysis.elements import holds_element_sets

    table = read_csv(path)
    source = table.source
    if holds_element_sets(path):
        raise ValueError(
            f"{source} holds element sets, not observed orbits (date, perigee_km, apogee_km): an element set "
            "history's drag is fitted by orbit-env lifetime --tle FILE"
        )
    table.require("perigee_km", "apogee_km", what="the observations file")
    if "date" in table.header and "days" in table.header:
        raise ValueError(
            f"{source}: the times are in two columns, 'date' and 'days'; keep one (one time axis for every row)"
        )
    if "date" not in table.header and "days" not in table.header:
        raise ValueError(
            f"{source}: the observations need a 'date' or a 'days' column; its header has {', '.join(table.header)}"
        )
    axis = "date" if "date" in table.header else "days"
    if not table.rows:
        raise ValueError(f"{source}: the file has a header but no observations")
    n = len(table.rows)
    days, hp, ha = (np.empty(n) for _ in range(3))
    for i, row in enumerate(table.rows):
        where = row.where(source)
        if row.extra:
            raise ValueError(f"{where}: more cells than the header has columns (extra: {', '.join(row.extra)[:40]})")
        try:
            text = row.cells[axis]
            if axis == "date":
                days[i] = check_date(unix_days(text), "date", text=text)
            else:
                days[i] = check_number(cell_value(text), "days", unit="days")
            hp[i] = check_number(cell_value(row.cells["perigee_km"]), "perigee_km", unit="km")
            ha[i] = check_number(cell_value(row.cells["apogee_km"]), "apogee_km", unit="km")
        except ValueError as error:
            raise ValueError(f"{where}: {error}") from None
    for i in np.flatnonzero(np.diff(days) <= 0):
        raise ValueError(
            f"{table.rows[i + 1].where(source)}: the time is not after line {table.rows[i].line}'s; "
            "observations go in time order, one per time"
        )
    return Observations(days, hp, ha, source, axis, tuple(row.line for row in table.rows))


def reentry_days(reentry: str | float, observations: Observations, name: str = "reentry") -> float:
    """The re-entry on the observations' time axis [days].

    Args:
        reentry: A date (``YYYY-MM-DD``) for dated observations, a number of days for
            observations in days (as text or a number); a number is always read on the
            observations' axis (unix days for dated ones).
        observations: The observations it belongs to.
        name: The parameter or flag, for messages (``"--reentry"``).

    Raises:
        ValueError: a date for observations in days, a number typed as text for dated
            observations (the message names both), or an unreadable or out-of-range date.
    """
    if not isinstance(reentry, str):
        return check_number(reentry, name, unit="days")
    text = reentry.strip()
    label = f"{name} {text}" if name.startswith("-") else f"{name}={text!r}"
    try:
        number: float | None = float(text)
    except ValueError:
        number = None
    if observations.axis == "days":
        if number is None:
            try:
                unix_days(text)
                kind = "is a date"
            except ValueError:
                kind = "is not a number of days"
            raise ValueError(
                f"{label} {kind}, but {observations.source} gives its times in days (a 'days' column); "
                "give the re-entry in days on that axis"
            )
        return check_number(number, name, unit="days")
    if number is not None:
        raise ValueError(
            f"{label} is a number, but {observations.source} gives its times as dates (a 'date' column); "
            "give the re-entry as a date, YYYY-MM-DD"
        )
    return check_date(unix_days(text), name, text=text)


@dataclass(frozen=True)
class DensityFit:
    """A fitted density scale factor.

    Attributes:
        scale: Best estimate of s (multiplies the model's density).
        sigma_log: Standard error of ln s.
        dof: Degrees of freedom of the noise estimate (None: known sigmas, normal intervals).
        description: What was fitted.
        residual_rms_km: RMS height residual of an orbit fit.
    """

    scale: float
    sigma_log: float
    dof: int | None
    description: str
    residual_rms_km: float | None = None

    def interval(self, level: float = 0.68) -> tuple[float, float]:
        """Central interval of s at probability ``level`` (symmetric in ln s)."""
        tail = 0.5 + 0.5 * level
        from scipy import stats  # on use: start-up

        quantile = float(stats.norm.ppf(tail) if self.dof is None else stats.t.ppf(tail, self.dof))
        return self.scale * math.exp(-quantile * self.sigma_log), self.scale * math.exp(quantile * self.sigma_log)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        low68, high68 = self.interval(0.68)
        low95, high95 = self.interval(0.95)
        return {
            "scale": self.scale,
            "sigma_log": self.sigma_log,
            "interval68": [low68, high68],
            "interval95": [low95, high95],
            "residual_rms_km": self.residual_rms_km,
            "description": self.description,
        }


def orbits_after(
    curves: UniversalCurves, perigee_m: float, apogee_m: float, weight_drop: ArrayLike
) -> tuple[FloatArray, FloatArray]:
    """Perigee and apogee [m] after W has fallen by ``weight_drop`` [s m^3/(kg s^2)] from an orbit.

    W = Int P dnu along the orbit's curve; dW/dnu = P, so Newton's method in nu
    converges in a few steps. Past re-entry the re-entry orbit is returned.
    """
    point = curves.locate(np.array([perigee_m]), np.array([apogee_m]))
    label0, nu0 = point.label[0], float(point.nu[0])
    hp0, ha0, q0 = curves.at(point.label, point.tau)
    w0 = float(q0[0]) * nu0
    drop = np.asarray(weight_drop, dtype=np.float64)
    target = np.maximum(w0 - drop, 0.0)
    label = np.full(drop.shape, label0)
    nu = np.maximum(nu0 - drop / float(period_s(*elements_from_heights(hp0, ha0))[0]), 0.0)
    for _ in range(4):
        hp, ha, q = curves.at(label, np.log1p(nu / NU_REF))
        nu = np.maximum(nu - (q * nu - target) / period_s(*elements_from_heights(hp, ha)), 0.0)
    hp, ha, _ = curves.at(label, np.log1p(nu / NU_REF))
    return hp, ha


def fit_density_scale(
    observations: Observations,
    *,
    satellite: Any,
    scenario: Scenario,
    inclination_deg: float = 0.0,
    reentry: str | float | None = None,
    reentry_sigma_days: float = REENTRY_SIGMA_DAYS,
    height_sigma_km: float = HEIGHT_SIGMA_KM,
) -> DensityFit:
    """Estimate the density scale factor s of ``scenario`` from an observed decay.

    Args:
        observations: Observed orbits (the first is the start).
        satellite: A `orbit_env.analysis.lifetime.Satellite` (its drag parameter is used).
        scenario: Atmosphere and activity whose density is scaled.
        inclination_deg: Orbit inclination.
        reentry: Observed re-entry (date, or days on the observations' time axis):
            fit from the first orbit and the lifetime.
        reentry_sigma_days: Uncertainty of the re-entry time (reentry fits).
        height_sigma_km: Uncertainty of the first orbit's heights (reentry fits).

    Raises:
        ValueError: too few observations, a re-entry before the last orbit observed, heights
            outside the curves, an orbit that does not come down from the first observation to the last,
            or data that leave the scale undetermined (its 68% interval beyond `DENSITY_SCALE_RANGE`).
    """
    c = satellite.drag_parameter_m2_kg
    try:
        hp, ha = UniversalCurves.check_domain_km(observations.perigee_km, observations.apogee_km)
    except InputError as error:
        row = error.index[0] if error.index else 0
        raise ValueError(f"{observations.where(row)}: {error.message(show_index=False)}") from None
    if reentry is not None:
        dt_days = reentry_days(reentry, observations) - float(observations.days[0])
        # A date without a time is a day: the re-entry may fall anywhere in it (after a tracking that morning).
        day = isinstance(reentry, str) and observations.axis == "date" and "T" not in reentry.strip()
        if not isinstance(reentry, str):  # as the observations give times: a date or a number of days
            reentry = iso_date(float(reentry)) if observations.axis == "date" else f"{float(reentry):g}"
        if not dt_days > 0:
            raise ValueError(f"the re-entry ({reentry}) must come after the first observation")
        last = float(observations.days[-1] - observations.days[0])
        if not dt_days + (1.0 if day else 0.0) > last:
            raise ValueError(
                f"the re-entry ({reentry}) is not after the last observation "
                f"({observations.where(observations.days.size - 1)}): an orbit cannot be observed after it re-entered"
            )
        check_number(reentry_sigma_days, "reentry_sigma_days", unit="days", low=0.0)
        check_number(height_sigma_km, "height_sigma_km", unit="km", low=0.0)
        return _plausible(
            _fit_reentry(
                float(hp[0]), float(ha[0]), dt_days, c, scenario, inclination_deg, reentry_sigma_days, height_sigma_km
            )
        )
    n = hp.size
    if n < 3:
        raise ValueError(f"an orbit fit needs at least 3 observations, got {n} (or give --reentry)")
    rise_km = (hp[-1] + ha[-1] - hp[0] - ha[0]) / 2e3
    if not rise_km < 0.0:  # drag only lowers an orbit: these are not one decay
        raise ValueError(
            f"the orbit does not come down between the first and the last observation (its mean height "
            f"{rise_km:+.3f} km over {observations.days[-1] - observations.days[0]:.1f} days): a manoeuvre, or "
            "observations of more than one decay"
        )
    if scenario.time_varying:
        return _plausible(_fit_orbits_time_varying(observations, hp, ha, c, scenario, inclination_deg))
    curves = scenario.curves(inclination_deg)
    gc_dt = G0_M_S2 * c * scenario.density_scale * (observations.days - observations.days[0]) * SECONDS_PER_DAY
    observed = np.concatenate([hp, ha]) / 1e3

    def predicted_km(theta: FloatArray) -> FloatArray:
        log_s, hp0_km, ha0_km = theta
        hp0 = max(hp0_km, 100.0 + 1e-3) * 1e3
        ha0 = max(ha0_km, hp0_km) * 1e3
        p_hp, p_ha = orbits_after(curves, hp0, ha0, gc_dt * math.exp(log_s))
        return np.concatenate([p_hp, p_ha]) / 1e3

    start = _initial_log_scale(curves, hp, ha, gc_dt)
    from scipy import optimize  # on use: start-up

    solution = optimize.least_squares(
        lambda theta: predicted_km(theta) - observed,
        x0=np.array([start, hp[0] / 1e3, ha[0] / 1e3]),
        x_scale=np.array([0.1, 1.0, 1.0]),
        diff_step=1e-5,
    )
    dof = 2 * n - 3
    residuals = solution.fun
    sigma2 = float(residuals @ residuals) / dof
    jac = solution.jac
    covariance = sigma2 * np.linalg.pinv(jac.T @ jac)
    return _plausible(
        DensityFit(
            scale=float(math.exp(solution.x[0])),
            sigma_log=float(math.sqrt(max(covariance[0, 0], 0.0))),
            dof=dof,
            description=f"{n} orbits over {observations.days[-1] - observations.days[0]:.4g} days "
            f"({observations.source})",
            residual_rms_km=float(math.sqrt(float(residuals @ residuals) / residuals.size)),
        )
    )


#: ln s of the time-varying orbit fit's first grid (0.05 to 20, as the re-entry fit's bracket).
_LOG_SCALE_GRID = np.linspace(math.log(0.05), math.log(20.0), 41)


def _fit_orbits_time_varying(
    observations: Observations, hp: FloatArray, ha: FloatArray, c: float, scenario: Scenario, inclination_deg: float
) -> DensityFit:
    """The orbit fit under changing activity: s on a grid, every candidate propagated at once from the first orbit.

    The air follows the record from the first observation's date, which must be the
    scenario's epoch (one date convention). Each candidate s is a satellite of its own in
    one vectorized propagation, stepped a day at a time; its heights at the observed times
    give the sum of squared height residuals, whose minimum over a grid refined twice is
    the fit; sigma of ln s from the parabola through the minimum and its neighbours, with
    the noise estimated from the residuals (2n - 1 degrees of freedom). The first orbit's
    heights are held as observed (the fixed-profile fit also fits them).
    """
    from dataclasses import replace

    from orbit_env.decay.chunked import propagate

    if observations.axis != "date":
        raise ValueError(
            "under the real Sun the observations need dates (a 'date' column), so the air is that of their days"
        )
    start = float(observations.days[0])
    if scenario.epoch_days is None or abs(scenario.epoch_days - start) > 1e-6:
        from orbit_env.analysis.lifetime import iso_datetime

        air = "an undated air" if scenario.epoch_days is None else f"air from {iso_datetime(scenario.epoch_days)}"
        raise ValueError(
            f"the fit starts at the first observation ({iso_datetime(start)}), in the air of its days, not in {air}: "
            "give no --epoch (or the first observation's date)"
        )
    t = observations.days - start
    model = replace(scenario.solar_model(inclination_deg, max_years=float(t[-1]) / DAYS_PER_YEAR + 0.1), chunk_days=1.0)
    observed = np.concatenate([hp, ha])

    def rss(log_scales: FloatArray) -> FloatArray:
        k = log_scales.size
        result = propagate(
            np.full(k, hp[0]),
            np.full(k, ha[0]),
            c,
            model,
            density_scale=np.exp(log_scales) * scenario.density_scale,
            record=True,
        )
        # Heights at the observed times; a candidate re-entered before an observation sits at re-entry.
        days = result.history_days
        model_hp = np.stack([np.interp(t, days, result.history_perigee_m[:, j]) for j in range(k)])
        model_ha = np.stack([np.interp(t, days, result.history_apogee_m[:, j]) for j in range(k)])
        residual = np.concatenate([model_hp, model_ha], axis=1) - observed[None, :]
        return np.sum(residual**2, axis=1)

    grid = _LOG_SCALE_GRID
    for _ in range(3):
        values = rss(grid)
        best = int(np.argmin(values))
        low, high = grid[max(best - 1, 0)], grid[min(best + 1, grid.size - 1)]
        if best in (0, grid.size - 1):
            break
        grid = np.linspace(low, high, 9)
    values = rss(grid)
    best = int(np.clip(np.argmin(values), 1, grid.size - 2))
    x0, x1 = grid[best - 1 : best + 1]
    y0, y1, y2 = values[best - 1 : best + 2]
    h = x1 - x0
    curvature = (y0 - 2.0 * y1 + y2) / h**2
    shift = 0.5 * h * (y0 - y2) / (y0 - 2.0 * y1 + y2) if curvature > 0 else 0.0
    log_s = float(x1 + shift)
    dof = 2 * hp.size - 1
    rss_min = float(y1 - (y0 - y2) ** 2 / (8.0 * (y0 - 2.0 * y1 + y2)) if curvature > 0 else y1)
    sigma2 = max(rss_min, 0.0) / dof
    sigma_log = math.sqrt(2.0 * sigma2 / curvature) if curvature > 0 else math.inf
    return DensityFit(
        scale=math.exp(log_s),
        sigma_log=sigma_log,
        dof=dof,
        description=f"{hp.size} orbits over {t[-1]:.4g} days, in the air of their days ({observations.source})",
        residual_rms_km=math.sqrt(max(rss_min, 0.0) / (2 * hp.size)) / 1e3,
    )


def _plausible(fit: DensityFit) -> DensityFit:
    """The fit, if its scale is one an atmosphere can have; else an error saying what that means.

    A scale outside `DENSITY_SCALE_RANGE` (or not finite)
    says that the data do not fit this satellite in this atmosphere: a wrong mass or area,
    heights or times mistyped, or an orbit raised by a burn between two observations.
    """
    low, high, _ = DENSITY_SCALE_RANGE
    if not (math.isfinite(fit.scale) and math.isfinite(fit.sigma_log) and low <= fit.scale <= high):
        raise ValueError(
            f"the fitted density scale, {fit.scale:.3g}, is outside {low:g} to {high:g}: the data do not fit "
            "this satellite in this atmosphere (check its mass and area, the heights and the times)"
        )
    low68, high68 = fit.interval(0.68)
    if not low <= low68 <= high68 <= high:
        raise ValueError(
            f"the data do not determine the density scale: {fit.scale:.3g}, but anything from {low68:.3g} to "
            f"{high68:.3g} (68%) fits them, beyond {low:g} to {high:g}; the orbits do not follow one decay (a "
            "manoeuvre between two observations, or observations of more than one object) or hardly decay over the span"
        )
    return fit


def _initial_log_scale(curves: UniversalCurves, hp: FloatArray, ha: FloatArray, gc_dt: FloatArray) -> float:
    """Return ln s from the first and last orbits' W difference (a starting point for the fit)."""
    points = curves.locate(hp[[0, -1]], ha[[0, -1]])
    drop = float(points.weighted_s[0] - points.weighted_s[1])
    if drop <= 0 or gc_dt[-1] <= 0:
        return 0.0
    return math.log(drop / float(gc_dt[-1]))


def _fit_reentry(
    hp_m: float,
    ha_m: float,
    dt_days: float,
    c: float,
    scenario: Scenario,
    inclination_deg: float,
    sigma_t_days: float,
    sigma_h_km: float,
) -> DensityFit:
    def log_scale(hp: float, ha: float, dt: float) -> float:
        if not scenario.time_varying:
            w0 = float(scenario.curves(inclination_deg).locate(np.array([hp]), np.array([ha])).weighted_s[0])
            return math.log(w0 / (G0_M_S2 * c * scenario.density_scale * dt * SECONDS_PER_DAY))
        return _log_scale_time_varying(hp, ha, dt, c, scenario, inclination_deg)

    best = log_scale(hp_m, ha_m, dt_days)
    step_h = max(sigma_h_km, 0.5) * 1e3
    d_hp = (log_scale(hp_m + step_h, max(ha_m, hp_m + step_h), dt_days) - best) / step_h
    d_ha = (log_scale(hp_m, ha_m + step_h, dt_days) - best) / step_h
    sigma_h_m = sigma_h_km * 1e3
    return DensityFit(
        scale=math.exp(best),
        # sqrt((sigma_t / dt)^2 + (d_hp^2 + d_ha^2) sigma_h^2), without squaring a large slope
        # (a float's ** 2 raises OverflowError; the fuzz test found slopes near 1e160 per m).
        sigma_log=math.hypot(sigma_t_days / dt_days, d_hp * sigma_h_m, d_ha * sigma_h_m),
        dof=None,
        description=f"re-entry {dt_days:.4g} days after a {hp_m / 1e3:g} x {ha_m / 1e3:g} km orbit",
    )


def _log_scale_time_varying(
    hp: float, ha: float, dt_days: float, c: float, scenario: Scenario, inclination_deg: float
) -> float:
    """Return ln s whose time-stepped lifetime equals ``dt_days`` (lifetime falls monotonically with s)."""
    lo, hi = math.log(0.05), math.log(20.0)
    for _ in range(3):
        grid = np.linspace(lo, hi, 17)
        days, reentered = scenario.lifetime_days(
            np.full(grid.size, hp),
            np.full(grid.size, ha),
            np.full(grid.size, c),
            inclination_deg,
            density_scale=np.exp(grid),
            max_days=4.0 * dt_days + 60.0,
        )
        days = np.where(reentered, days, np.inf)
        short = days <= dt_days
        if not short.any() or short.all():
            raise ValueError(
                f"no density scale between 0.05 and 20 gives a lifetime of {dt_days:.4g} days for this orbit"
            )
        k = int(np.argmax(short))  # first (smallest s) with a lifetime <= dt
        lo, hi = grid[k - 1], grid[k]
        d_lo, d_hi = days[k - 1], days[k]
    # Lifetime ~ 1/s locally: interpolate ln(days) linearly in ln s.
    if np.isfinite(d_lo):
        w = (math.log(d_lo) - math.log(dt_days)) / (math.log(d_lo) - math.log(d_hi))
        return float(lo + w * (hi - lo))
    return float(hi)
