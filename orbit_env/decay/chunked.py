"""Decay under solar activity that changes over the lifetime, on the universal curves. SI units.

The universal curves (`orbit_env.decay.curves`) belong to one fixed density profile.
NRLMSIS's profile changes with F10.7, Ap and the season, over days to years, so a
decay that spans a solar cycle cannot follow one family of curves. We step the
satellites through time in chunks (``chunk_days``, default 20 days); in each chunk

1. the curves are those of a *binned* profile: NRLMSIS at the chunk's mean 81-day
   F10.7 rounded to a step of ``bin_step`` in ln F10.7 (default 0.1, i.e. 10%),
   the chunk's mean Ap rounded to a coarse logarithmic grid, averaged over the
   year. A decade-long lifetime visits a handful of bins, each built once
   (~0.9 s) and cached;
2. what the bin leaves out (the exact indices of every day, the season) is a
   density multiplier s: the chunk's mean over its days of the orbit-averaged
   NRLMSIS density, each day with its own F10.7, 81-day mean, Ap and day of the
   year, divided by the bin's density. Densities are averaged, not indices:
   NRLMSIS responds to Ap concavely, and a chunk's mean Ap overstates the density
   after storms (by 1.5% in lifetime, measured). The ratio r(h) is tabulated every
   50 km with 6 x 6 latitude and local-time nodes (numerator and denominator
   alike, so the coarser sampling cancels);
3. the ratio is taken over the orbit as drag weights it, not at the perigee alone
   (`orbit_ratio`): with the bin's density and r locally exponential about the
   perigee (log-slopes -1/H and beta), King-Hele's orbit average of drag gives
   s = r(h_p) B((1/H - beta) a e) / B(a e / H), B(x) = e^-x (I0(x) + 2 e I1(x)).
   A circular orbit takes r(h_p) itself; an eccentric one feels the air above
   its perigee, where a storm heats the thermosphere more and the season changes
   the profile's shape. Near re-entry (step 5), where short lives are decided,
   orbits wider than a e / H = `AVERAGED_MIN_X` take s from the averaged equations
   themselves: dp/dnu under the chunk's profile over dp/dnu under the bin's. With
   the ratio at the perigee alone, lives of 10-40 days on orbits 120 km wide came
   out up to 3.2% off the daily reference, with the orbit's ratio within 0.65%
   (docs/validation-modern.md). The decay rate is linear in density, so what is
   left is the difference in the profile's shape that one multiplier cannot carry
   (second order in the bin step);
4. the satellite moves along its curve by the chunk's time: W = Int P dnu falls by
   dt g c s (``orbit_env.decay.averaged``), solved for nu by Newton's method with
   dW/dnu = P (the Keplerian period). If W left is smaller, it re-enters within
   the chunk;
5. near re-entry (less than `FINE_CHUNKS` chunks of decay left at the chunk's
   rate) a chunk goes one day at a time (`FINISH_STEP_DAYS`), each day with its
   own density multiplier at that day's orbit, so the last weeks, where the perigee
   falls fastest, are resolved (and recorded) day by day. With one multiplier per
   chunk, taken at the chunk's start height, lives of a few weeks came out 0.5-3.4%
   off the daily reference (measured in docs/validation-modern.md).

Satellites are re-located on the curves only when the bin changes. Everything is
vectorized over satellites. The measured effect of the chunk length and the bin
step against a day-by-day integration of the averaged equations
(`integrate_reference`) is in ``docs/validation-modern.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number
from orbit_env.constants import EARTH_RADIUS_M, G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import NU_REF, UniversalCurves
from orbit_env.decay.solar import SolarActivity, day_of_year
from orbit_env.physics.atmosphere import FunctionAtmosphere
from orbit_env.physics.atmosphere.msis import (
    ALTITUDE_GRID_M,
    SEASON_NODES,
    MsisAtmosphere,
    interpolate_log_density,
    mean_density_kg_m3,
    mean_density_over_days_kg_m3,
)
from orbit_env.physics.orbit import elements_from_heights, heights_from_elements, period_s

FloatArray = NDArray[np.float64]

#: Default chunk length [days] (see the module docstring and docs/validation-modern.md).
DEFAULT_CHUNK_DAYS = 20.0
#: Default bin step in ln(81-day mean F10.7).
DEFAULT_BIN_STEP = 0.1
#: Default cap on the time propagated [years]; a satellite still up then is reported as such.
#: Sub-step [days] of the chunks near re-entry.
FINISH_STEP_DAYS = 1.0
#: A chunk goes in daily sub-steps when less than this many chunks of decay (at the chunk's rate) are left.
FINE_CHUNKS = 3.0
DEFAULT_MAX_YEARS = 200.0
#: Near re-entry, orbits with a e / H above this take the multiplier from the averaged equations.
AVERAGED_MIN_X = 0.5
#: Anomalies of that average (a ratio of two averages on the same nodes: 8 agree with 64 to 2e-5 in lifetime,
#: measured on three 120 km wide orbits in their last month).
RATIO_QUADRATURE_POINTS = 8
#: Ap values of the bins (nearest in log).
AP_BINS = (3.0, 6.0, 12.0, 24.0, 48.0, 96.0, 192.0, 384.0)
#: Heights at which the exact/bin density ratio is tabulated [m].
RATIO_GRID_M = np.arange(100e3, 1200e3 + 1.0, 50e3)
#: Latitude and local-time nodes of the ratio (both profiles sampled alike).
RATIO_NODES = {"latitude_nodes": 6, "local_time_nodes": 6}

DailyIndices = tuple[tuple[float, float, float, float], ...]


@lru_cache(maxsize=64)
def cached_curves(model: DecayModel) -> UniversalCurves:
    """Universal curves per decay model; a larger cache than ``universal_curves`` (bins cycle)."""
    return UniversalCurves(model)


def bin_indices(f107a_sfu: float, ap: float, bin_step: float) -> tuple[float, float]:
    """The binned (F10.7 = 81-day mean, Ap) whose profile's curves a chunk uses."""
    f_bin = math.exp(bin_step * round(math.log(f107a_sfu) / bin_step))
    f_bin = min(max(f_bin, 40.0), 400.0)
    logs = np.log(np.array(AP_BINS))
    ap_bin = AP_BINS[int(np.argmin(np.abs(logs - math.log(max(ap, 1.0)))))]
    return round(f_bin, 6), ap_bin


@lru_cache(maxsize=4096)
def _log_ratio(
    daily: DailyIndices,
    binned: tuple[float, float],
    inclination_deg: float,
    ascending_node_local_time_h: float | None,
) -> FloatArray:
    f107, f107a, ap, doy = (np.array(column) for column in zip(*daily, strict=True))
    rho_exact = mean_density_over_days_kg_m3(
        RATIO_GRID_M, f107, f107a, ap, doy, inclination_deg, ascending_node_local_time_h, **RATIO_NODES
    )
    return np.log(rho_exact) - _log_bin_density(binned, inclination_deg, ascending_node_local_time_h)


@lru_cache(maxsize=256)
def _log_bin_density(
    binned: tuple[float, float], inclination_deg: float, ascending_node_local_time_h: float | None
) -> FloatArray:
    rho = mean_density_kg_m3(
        RATIO_GRID_M, binned[0], binned[0], binned[1], inclination_deg, None, ascending_node_local_time_h, **RATIO_NODES
    )
    return np.log(rho)


@lru_cache(maxsize=256)
def log_density_slope_per_m(atmosphere: MsisAtmosphere) -> FloatArray:
    """The log-slope d ln(density)/dh [1/m] of a bin's profile on ``ALTITUDE_GRID_M`` (the table its curves use)."""
    return np.gradient(atmosphere.log_density_table(), ALTITUDE_GRID_M)


def orbit_ratio(
    ratio_at_perigee: ArrayLike,
    log_ratio_slope_per_m: ArrayLike,
    log_density_slope_per_m: ArrayLike,
    perigee_m: ArrayLike,
    apogee_m: ArrayLike,
) -> FloatArray:
    """The density multiplier of an orbit: a ratio of densities r(h), averaged as drag weights the orbit.

    With the density locally exponential about the perigee (log-slope
    ``log_density_slope_per_m`` = -1/H) and r likewise (log-slope beta), the
    orbit average of drag to first order in e is King-Hele's
    rho_p e^-x (I0(x) + 2 e I1(x)), x = a e / H (D. G. King-Hele, *Theory of
    Satellite Orbits in an Atmosphere*, 1964, ch. 4). The multiplier is that
    average under rho r over that under rho: r(h_p) B(x (1 - beta H)) / B(x).
    Circular orbits (x = 0) take r(h_p). Arrays broadcast.
    """
    from scipy.special import i0e, i1e  # on use: a third of a second of start-up

    hp, ha = np.asarray(perigee_m, dtype=np.float64), np.asarray(apogee_m, dtype=np.float64)
    ae_m = 0.5 * (ha - hp)
    e = ae_m / (2.0 * EARTH_RADIUS_M + hp + ha)
    inverse_h = np.maximum(-np.asarray(log_density_slope_per_m, dtype=np.float64), 0.0)
    x0 = ae_m * inverse_h
    x1 = ae_m * (inverse_h - np.asarray(log_ratio_slope_per_m, dtype=np.float64))

    def weight(x: FloatArray) -> FloatArray:
        # e^-x (I0(x) + 2 e I1(x)) from the scaled Bessel functions (e^-|x| I(|x|)); x < 0 only for a
        # ratio steeper than the density (not seen in NRLMSIS, kept finite all the same).
        ax = np.abs(x)
        return np.exp(ax - x) * (i0e(ax) + 2.0 * e * np.sign(x) * i1e(ax))

    return np.asarray(ratio_at_perigee, dtype=np.float64) * weight(x1) / weight(x0)


@dataclass(frozen=True, eq=False)
class SolarDecayModel:
    """What a decay under changing solar activity depends on, apart from the satellite.

    Args:
        activity: Indices against time (`orbit_env.decay.solar`).
        start_days: Unix days of the start (the epoch of the orbit).
        inclination_deg: Orbit inclination (latitudes of the NRLMSIS average,
            and the co-rotating air if ``rotating_atmosphere``).
        follow_season: Use each chunk's day of the year (else the year's average).
        rotating_atmosphere: Let the air co-rotate with the Earth.
        ascending_node_local_time_h: For Sun-synchronous orbits (see
            `orbit_env.physics.atmosphere.msis.MsisAtmosphere`).
        chunk_days: Length of a time step.
        bin_step: Bin width in ln(81-day mean F10.7).
        max_years: Stop propagating after this long.
    """

    activity: SolarActivity
    start_days: float
    inclination_deg: float
    follow_season: bool = True
    rotating_atmosphere: bool = False
    ascending_node_local_time_h: float | None = None
    chunk_days: float = DEFAULT_CHUNK_DAYS
    bin_step: float = DEFAULT_BIN_STEP
    max_years: float = DEFAULT_MAX_YEARS
    _bins: dict[tuple[float, float], DecayModel] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        check_number(self.chunk_days, "chunk_days", unit="days", low=0.1, high=365.0)
        check_number(self.bin_step, "bin_step", low=0.0, high=1.0, low_inclusive=False)
        check_number(self.max_years, "max_years", unit="years", low=0.0, high=1000.0, low_inclusive=False)
        check_number(self.inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)

    def chunk_condition(self, t_days: float) -> tuple[DailyIndices, tuple[float, float]]:
        """Daily indices (and days of the year) of the chunk starting ``t_days`` after the start, and its bin."""
        samples = max(1, math.ceil(self.chunk_days))
        # One sample at the start of each day: a daily table's rows are then taken as they are
        # (midpoints would interpolate between two days and smooth the storms away).
        days = self.start_days + t_days + np.arange(samples) * (self.chunk_days / samples)
        f107, f107a, ap = self.activity.indices(days)
        if self.follow_season:
            # Rounded to 2 days: the season moves the density by < 0.3% in 2 days.
            doy = np.clip(2.0 * np.round(day_of_year(days) / 2.0), 1.0, 366.0)
        else:
            doy = np.zeros(samples)  # replaced by the year's nodes below
        # Rounded so that repeated runs (bisections, batches) hit the cache: 0.1 sfu and 0.1 Ap
        # move the density by less than 0.1%.
        columns = (np.round(f107, 1), np.round(f107a, 1), np.round(ap, 1), doy)
        if not self.follow_season:
            nodes = (np.arange(SEASON_NODES) + 0.5) * 365.0 / SEASON_NODES + 1.0
            columns = (*(np.repeat(c, SEASON_NODES) for c in columns[:3]), np.tile(nodes, samples))
        daily = tuple(zip(*(c.tolist() for c in columns), strict=True))
        return daily, bin_indices(float(np.mean(f107a)), float(np.mean(ap)), self.bin_step)

    def bin_model(self, binned: tuple[float, float]) -> DecayModel:
        """The decay model of a bin (its atmosphere: NRLMSIS at the binned indices, year-averaged)."""
        model = self._bins.get(binned)
        if model is None:
            atmosphere = MsisAtmosphere(
                binned[0], binned[0], binned[1], self.inclination_deg, None, self.ascending_node_local_time_h
            )
            model = DecayModel(atmosphere, self.rotating_atmosphere, self.inclination_deg)
            self._bins[binned] = model
        return model

    def density_ratio(
        self,
        daily: DailyIndices,
        binned: tuple[float, float],
        perigee_m: FloatArray,
        apogee_m: FloatArray,
        *,
        averaged: bool = False,
    ) -> FloatArray:
        """The chunk's mean density over the bin's, over each orbit (the multiplier s).

        King-Hele's local form (`orbit_ratio`); with ``averaged``, for orbits wider than
        `AVERAGED_MIN_X`, the ratio of the averaged equations' dp/dnu under the chunk's
        profile (the bin's times the tabulated ratio) and under the bin's, with
        `RATIO_QUADRATURE_POINTS` anomalies.
        """
        log_ratio = _log_ratio(daily, binned, float(self.inclination_deg), self.ascending_node_local_time_h)
        at_perigee = np.exp(np.interp(perigee_m, RATIO_GRID_M, log_ratio))
        ratio_slope = np.interp(perigee_m, RATIO_GRID_M, np.gradient(log_ratio, RATIO_GRID_M))
        atmosphere = self.bin_model(binned).atmosphere
        assert isinstance(atmosphere, MsisAtmosphere)
        density_slope = np.interp(perigee_m, ALTITUDE_GRID_M, log_density_slope_per_m(atmosphere))
        ratio = orbit_ratio(at_perigee, ratio_slope, density_slope, perigee_m, apogee_m)
        if not averaged:
            return ratio
        wide = np.flatnonzero(0.5 * (apogee_m - perigee_m) * -density_slope > AVERAGED_MIN_X)
        if wide.size:
            chunk = FunctionAtmosphere(
                lambda h: atmosphere.density_kg_m3(h) * np.exp(np.interp(h, RATIO_GRID_M, log_ratio))
            )
            p, e = elements_from_heights(perigee_m[wide], apogee_m[wide])
            rates = [
                DecayModel(air, self.rotating_atmosphere, self.inclination_deg, RATIO_QUADRATURE_POINTS).rates_per_nu(
                    p, e
                )[0]
                for air in (chunk, atmosphere)
            ]
            ratio[wide] = rates[0] / rates[1]
        return ratio


@dataclass(frozen=True)
class SolarLifetime:
    """Result of `propagate`, arrays over satellites.

    Attributes:
        days: Time from the start to re-entry [days]; ``max_years`` in days where not re-entered.
        reentered: False where the satellite was still up after ``max_years``.
        history_days: Chunk boundaries [days] (when recorded), shape (chunks,).
        history_perigee_m: Perigee heights at the boundaries, shape (chunks, satellites);
            re-entered satellites are held at their re-entry orbit (perigee 100 km).
        history_apogee_m: Apogee heights likewise.
        bins_used: Number of distinct bins (curve families) visited.
    """

    days: FloatArray
    reentered: NDArray[np.bool_]
    history_days: FloatArray
    history_perigee_m: FloatArray
    history_apogee_m: FloatArray
    bins_used: int


def _weight_at(curves: UniversalCurves, label: FloatArray, nu: FloatArray) -> tuple[FloatArray, ...]:
    hp, ha, q = curves.at(label, np.log1p(nu / NU_REF))
    return hp, ha, q * nu


def _solve_nu(
    curves: UniversalCurves,
    label: FloatArray,
    nu: FloatArray,
    w0: FloatArray,
    target: FloatArray,
    hp: FloatArray,
    ha: FloatArray,
) -> FloatArray:
    """Newton on W(nu) = target from nu (where W = w0, heights hp, ha), dW/dnu = P."""
    p_now, e_now = elements_from_heights(hp, ha)
    nu = np.maximum(nu - (w0 - target) / period_s(p_now, e_now), 0.0)
    for _ in range(3):
        hp_k, ha_k, w = _weight_at(curves, label, nu)
        p_k, e_k = elements_from_heights(hp_k, ha_k)
        nu = np.maximum(nu - (w - target) / period_s(p_k, e_k), 0.0)
    return nu


def _daily_steps(
    model: SolarDecayModel,
    curves: UniversalCurves,
    binned: tuple[float, float],
    daily: DailyIndices,
    label: FloatArray,
    nu: FloatArray,
    gcs: FloatArray,
    hp: FloatArray,
    ha: FloatArray,
    t0: float,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, tuple[list[float], list[FloatArray], list[FloatArray]]]:
    """The chunk from ``t0`` one day (`FINISH_STEP_DAYS`) at a time, for satellites near re-entry.

    Each day takes its own indices' density multiplier at that day's perigee. Returns the
    re-entry day (NaN for a satellite still up at the chunk's end), nu and the heights at
    the chunk's end (or at re-entry), and the sub-steps' times and heights (for the history).
    """
    samples = max(1, math.ceil(model.chunk_days))
    per_sample = len(daily) // samples
    steps = max(1, math.ceil(model.chunk_days / FINISH_STEP_DAYS))
    step_days = model.chunk_days / steps
    n = label.size
    days = np.full(n, np.nan)
    nu, hp, ha = nu.copy(), hp.copy(), ha.copy()
    alive = np.arange(n)
    times: list[float] = []
    heights_p: list[FloatArray] = []
    heights_a: list[FloatArray] = []
    for j in range(steps):
        first = min(samples - 1, int(j * step_days * samples / model.chunk_days))
        day = daily[first * per_sample : (first + 1) * per_sample]
        ratio = model.density_ratio(day, binned, hp[alive], ha[alive], averaged=True)
        _, _, w0 = _weight_at(curves, label[alive], nu[alive])
        rate = gcs[alive] * ratio
        target = w0 - rate * step_days * SECONDS_PER_DAY
        ended = target <= 0.0
        days[alive[ended]] = t0 + j * step_days + w0[ended] / rate[ended] / SECONDS_PER_DAY
        going = alive[~ended]
        if going.size:
            nu[going] = _solve_nu(curves, label[going], nu[going], w0[~ended], target[~ended], hp[going], ha[going])
            hp[going], ha[going], _ = _weight_at(curves, label[going], nu[going])
        if ended.any():
            nu[alive[ended]] = 0.0
            hp[alive[ended]], ha[alive[ended]], _ = curves.at(label[alive[ended]], np.zeros(int(ended.sum())))
        alive = going
        times.append(t0 + (j + 1) * step_days if alive.size else float(np.nanmax(days)))
        heights_p.append(hp.copy())
        heights_a.append(ha.copy())
        if alive.size == 0:
            break
    return days, nu, hp, ha, (times, heights_p, heights_a)


def propagate(
    perigee_m: ArrayLike,
    apogee_m: ArrayLike,
    drag_parameter_m2_kg: ArrayLike,
    model: SolarDecayModel,
    *,
    density_scale: ArrayLike = 1.0,
    record: bool = False,
    progress: Callable[[float], None] | None = None,
) -> SolarLifetime:
    """Propagate satellites to re-entry under the activity of ``model`` (see the module docstring).

    Args:
        perigee_m: Initial perigee heights [m] (in the curves' domain: the caller checks).
        apogee_m: Initial apogee heights [m].
        drag_parameter_m2_kg: c = c_x A / m of each satellite [m^2/kg].
        model: Activity, epoch, inclination, chunking.
        density_scale: Multiplier on the density (e.g. a fitted scale factor).
        record: Keep the heights at every chunk boundary.
        progress: Called with the fraction of satellites re-entered after each chunk.
    """
    hp, ha, c, scale = (
        np.array(x, dtype=np.float64).ravel()
        for x in np.broadcast_arrays(
            np.asarray(perigee_m, dtype=np.float64),
            np.asarray(apogee_m, dtype=np.float64),
            np.asarray(drag_parameter_m2_kg, dtype=np.float64),
            np.asarray(density_scale, dtype=np.float64),
        )
    )
    n = hp.size
    gcs = G0_M_S2 * c * scale
    days = np.full(n, model.max_years * 365.25)
    reentered = hp <= REENTRY_ALTITUDE_M
    days[reentered] = 0.0
    active = np.flatnonzero(~reentered)
    label = tau = np.empty(0)
    key_prev: tuple[float, float] | None = None
    curves: UniversalCurves | None = None
    history_t, history_hp, history_ha = [0.0], [hp.copy()], [ha.copy()]
    bins: set[tuple[float, float]] = set()
    dt_s = model.chunk_days * SECONDS_PER_DAY
    n_chunks = math.ceil(model.max_years * 365.25 / model.chunk_days)
    for k in range(n_chunks):
        if active.size == 0:
            break
        t0 = k * model.chunk_days
        daily, binned = model.chunk_condition(t0)
        bins.add(binned)
        if binned != key_prev:
            curves = cached_curves(model.bin_model(binned))
            point = curves.locate(hp[active], ha[active])
            label, tau = point.label, point.tau
            key_prev = binned
        assert curves is not None
        s = model.density_ratio(daily, binned, hp[active], ha[active])
        rate = gcs[active] * s  # dW/dt: W falls by this per second
        nu0 = NU_REF * np.expm1(tau)
        _, _, w0 = _weight_at(curves, label, nu0)
        # Near re-entry (less than FINE_CHUNKS chunks of decay left at this rate) the chunk goes day by day;
        # the others cannot re-enter within it.
        fine = w0 < rate * dt_s * FINE_CHUNKS
        coarse = ~fine
        nu_new = nu0.copy()
        hp_new, ha_new = hp[active].copy(), ha[active].copy()
        done = np.zeros(active.size, dtype=bool)
        if fine.any():
            which = np.flatnonzero(fine)
            f_days, f_nu, f_hp, f_ha, sub = _daily_steps(
                model,
                curves,
                binned,
                daily,
                label[which],
                nu0[which],
                gcs[active[which]],
                hp_new[which],
                ha_new[which],
                t0,
            )
            ended = np.isfinite(f_days)
            days[active[which[ended]]] = f_days[ended]
            done[which[ended]] = True
            nu_new[which], hp_new[which], ha_new[which] = f_nu, f_hp, f_ha
            if record:
                for t_sub, hp_sub, ha_sub in zip(*sub, strict=True):
                    history_t.append(t_sub)
                    history_hp.append(hp.copy())
                    history_ha.append(ha.copy())
                    history_hp[-1][active[which]], history_ha[-1][active[which]] = hp_sub, ha_sub
        if coarse.any():
            # Newton on W(nu) = target, dW/dnu = P; W is convex-ish and smooth, three steps reach 1e-10.
            target = w0[coarse] - rate[coarse] * dt_s
            nu_new[coarse] = _solve_nu(
                curves, label[coarse], nu0[coarse], w0[coarse], target, hp_new[coarse], ha_new[coarse]
            )
            hp_new[coarse], ha_new[coarse], _ = _weight_at(curves, label[coarse], nu_new[coarse])
        hp[active], ha[active] = hp_new, ha_new
        keep = ~done
        label, tau = label[keep], np.log1p(nu_new[keep] / NU_REF)
        active = active[keep]
        if record:
            history_t.append(t0 + model.chunk_days)
            history_hp.append(hp.copy())
            history_ha.append(ha.copy())
        if progress is not None:
            progress(1.0 - active.size / n)
    reentered = np.ones(n, dtype=bool)
    reentered[active] = False
    return SolarLifetime(
        days=days,
        reentered=reentered,
        history_days=np.array(history_t),
        history_perigee_m=np.array(history_hp),
        history_apogee_m=np.array(history_ha),
        bins_used=len(bins),
    )


def integrate_reference(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    *,
    profile_step_days: float = 1.0,
    rtol: float = 1e-8,
) -> float:
    """Days to re-entry from the averaged equations in time, with a fresh NRLMSIS profile every step.

    The reference for the chunked curves: no bins, no chunks, no curves. The
    profile (orbit-averaged NRLMSIS at the day's indices and day of year) is
    recomputed every ``profile_step_days`` and its logarithm interpolated
    linearly in time; dp/dt and de/dt are the averaged rates of
    `orbit_env.decay.averaged` times dnu/dt = g c / P. Slow: ~25 ms per profile.
    """
    solution = _solve_reference(perigee_m, apogee_m, drag_parameter_m2_kg, model, profile_step_days, rtol)
    if solution.status != 1:
        return model.max_years * 365.25
    return float(solution.t_events[0][0]) / SECONDS_PER_DAY


def _solve_reference(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    profile_step_days: float,
    rtol: float,
) -> Any:
    """The ``solve_ivp`` solution behind `integrate_reference` and `reference_path`."""
    profiles: dict[int, FloatArray] = {}

    def log_profile(index: int) -> FloatArray:
        if index not in profiles:
            t_days = index * profile_step_days
            f107, f107a, ap = (float(x) for x in model.activity.indices(model.start_days + t_days))
            doy = float(day_of_year(model.start_days + t_days)) if model.follow_season else None
            rho = mean_density_kg_m3(
                ALTITUDE_GRID_M, f107, f107a, ap, model.inclination_deg, doy, model.ascending_node_local_time_h
            )
            profiles[index] = np.log(rho)
        return profiles[index]

    def rhs(t_s: float, state: FloatArray) -> list[float]:
        p, e = state[0], max(state[1], 0.0)
        x = t_s / SECONDS_PER_DAY / profile_step_days
        i = math.floor(x)
        w = x - i
        log_rho = (1.0 - w) * log_profile(i) + w * log_profile(i + 1)
        atmosphere = FunctionAtmosphere(lambda h, table=log_rho: interpolate_log_density(h, table))
        decay = DecayModel(atmosphere, model.rotating_atmosphere, model.inclination_deg)
        with np.errstate(invalid="ignore"):  # trial steps past re-entry; the event stops before them
            dp_dnu, de_dnu = decay.rates_per_nu(p, e)
            dnu_dt = G0_M_S2 * drag_parameter_m2_kg / float(period_s(p, e))
        return [float(dp_dnu) * dnu_dt, float(de_dnu) * dnu_dt]

    def reentry(t_s: float, state: FloatArray) -> float:
        return float(heights_from_elements(state[0], max(state[1], 0.0))[0]) - REENTRY_ALTITUDE_M

    reentry.terminal = True  # type: ignore[attr-defined]
    p0, e0 = (float(x) for x in elements_from_heights(perigee_m, apogee_m))
    t_max = model.max_years * 365.25 * SECONDS_PER_DAY
    from scipy.integrate import solve_ivp  # on use: half a second of start-up

    solution = solve_ivp(
        rhs,
        (0.0, t_max),
        [p0, e0],
        method="DOP853",
        events=reentry,
        rtol=rtol,
        atol=[1e-3, 1e-12],
        max_step=profile_step_days * SECONDS_PER_DAY,
    )
    return solution


def reference_path(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    *,
    profile_step_days: float = 1.0,
    rtol: float = 1e-8,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The decay of `integrate_reference` as it goes: days, perigee [m] and apogee [m] at its steps.

    The last point is the re-entry (perigee 100 km), or the state at ``max_years``.
    """
    solution = _solve_reference(perigee_m, apogee_m, drag_parameter_m2_kg, model, profile_step_days, rtol)
    t_s, states = solution.t, solution.y.T
    if solution.status == 1:
        t_s = np.append(t_s[t_s < solution.t_events[0][0]], solution.t_events[0][0])
        states = np.vstack([states[: t_s.size - 1], solution.y_events[0][:1]])
    perigee, apogee = heights_from_elements(states[:, 0], np.maximum(states[:, 1], 0.0))
    return t_s / SECONDS_PER_DAY, np.asarray(perigee, dtype=np.float64), np.asarray(apogee, dtype=np.float64)
