"""Decay under solar activity that changes over the lifetime, on the universal curves. SI units.

The universal curves (`orbit_env.decay.curves`) belong to one fixed density profile; NRLMSIS's
changes with F10.7, Ap and the season. The satellites step through time in chunks
(``chunk_days``, default 20 days). In each, the curves are those of a *binned* profile (the
chunk's 81-day F10.7 in steps of ``bin_step`` in ln F10.7, its Ap on a coarse logarithmic grid,
year-averaged; each bin built once and cached), and what the bin leaves out (every day's
indices, the season) is a density multiplier s: the chunk's mean of the daily densities over the
bin's, taken over the orbit as drag weights it (`orbit_ratio`; near re-entry from the averaged
equations' rates, `orbit_env.decay.density_multiplier.life_rate_ratio`). The satellite moves along its curve by the
chunk's time (W = Int P dnu falls by dt g c s); near re-entry a chunk goes a day at a time, in
the last days by the midpoint rule (`FINE_CHUNKS`, `FINISH_STEP_DAYS`, `LAST_DAYS`). Satellites are re-located on the
curves only when the bin changes, where their heights are (`UniversalCurves.locate_exactly`: table A's point
alone moved nu at each placement, and the moves added up over many); everything is vectorized over satellites.

Why each choice, and its measured effect against a day-by-day integration of the averaged
equations (`orbit_env.decay.reference_path.integrate_reference`): docs/validation-modern/solar-activity.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number
from orbit_env.constants import (
    DAYS_PER_YEAR,
    G0_M_S2,
    REENTRY_ALTITUDE_M,
    SECONDS_PER_DAY,
)
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import NU_REF, UniversalCurves
from orbit_env.decay.daily_air import DailyAirTable, daily_air_table
from orbit_env.decay.density_multiplier import (
    RATIO_GRID_M,
    RATIO_NODES,
    SPREAD_MAX_SPAN_M,
    SPREAD_QUADRATURE_POINTS,
    corotation_factor,
    inclination_anchors,
    inclination_basis,
    interpolate_rows,
    life_rate_ratio,
    log_density_slope_per_m,
    orbit_ratio,
    uniform_gradient,
)
from orbit_env.decay.solar import SolarActivity, calendar_day, day_of_year
from orbit_env.physics.atmosphere.msis import (
    ALTITUDE_GRID_M,
    DEFAULT_MSIS_VERSION,
    SEASON_NODES,
    MsisAtmosphere,
    check_msis_version,
    season_days,
)

FloatArray = NDArray[np.float64]

#: Default chunk length [days] (see the module docstring and docs/validation-modern.md).
DEFAULT_CHUNK_DAYS = 20.0
#: Default bin step in ln(81-day mean F10.7).
DEFAULT_BIN_STEP = 0.1
#: Sub-step [days] of the chunks near re-entry.
FINISH_STEP_DAYS = 1.0
#: A satellite with less than this many days left at the day's rate takes the day by the midpoint rule.
LAST_DAYS = 4.0
#: A chunk goes in daily sub-steps when less than this many chunks of decay (at the chunk's rate) are left.
FINE_CHUNKS = 3.0
#: A step along the curves stops its Newton iterations once W is within this fraction of the step's fall
#: (`UniversalCurves.move_to_weight`): a millionth of a day on a daily step, one or two lookups fewer.
NEWTON_TOLERANCE = 1e-6
#: Default cap on the time propagated [years]; a satellite still up then is reported as such.
DEFAULT_MAX_YEARS = 200.0
#: Near re-entry, orbits with a e / H above this take the multiplier from the averaged equations (W-weighted).
AVERAGED_MIN_X = 0.5
#: Anomalies of that average (a ratio of two averages on the same nodes: 8 agree with 64 to 2e-5 in lifetime,
#: measured on three 120 km wide orbits in their last month).
RATIO_QUADRATURE_POINTS = 8
#: Ap values of the bins (nearest in log).
AP_BINS = (3.0, 6.0, 12.0, 24.0, 48.0, 96.0, 192.0, 384.0)
#: Orbits no wider than this [m] (apogee - perigee height) take coarser bins, `NEAR_CIRCULAR_BIN_STEP` and
#: `NEAR_CIRCULAR_AP_BINS`: the multiplier makes a circular orbit's decay exact whatever the bin, and a
#: near-circular one's nearly so, while a life visits several times fewer bins (the cost of a dated decay is
#: its bins' curves). Measured against the fine bins on 35 lives of 2 months to 18 years:
#: docs/validation-modern/solar-activity.md.
NEAR_CIRCULAR_SPAN_M = 20e3
#: Bin width in ln(81-day mean F10.7) of near-circular orbits.
NEAR_CIRCULAR_BIN_STEP = 0.3
#: Ap values of near-circular orbits' bins.
NEAR_CIRCULAR_AP_BINS = (3.0, 12.0, 48.0, 192.0)
#: Those wider orbits' ratio of the life's rates is recomputed when the perigee has moved this far [m] (or the bin
#: changed), and held in between as a factor on the ratio over the orbit.
SPREAD_REFRESH_M = 5e3

#: Days [d] whose air is computed together when a chunk meets a day the air table does not hold yet
#: (`orbit_env.decay.daily_air`): one NRLMSIS call of half a year instead of one per chunk.
PREFETCH_DAYS = 180

#: A day counts as a storm day, and takes NRLMSIS's storm-time mode (3-hourly ap history), when the largest
#: of the 27 3-hourly ap that mode reads on it (57 h before its first slot to its last) reaches this; the
#: other days keep the daily Ap. Needs a record with the 3-hourly ap (`RecordActivity.ap_history`).
#: Measured: docs/validation-modern/solar-activity.md, section "Storm days".
STORM_AP = 48.0

#: Heights of `RATIO_GRID_M` above the highest one a decay's orbits reach whose air it still needs: the
#: interpolation's upper neighbour and its gradient's (`SolarDecayModel.air_columns`).
AIR_COLUMNS_ABOVE = 2

DailyIndices = tuple[tuple[float, ...], ...]


@lru_cache(maxsize=64)
def cached_curves(model: DecayModel) -> UniversalCurves:
    """Universal curves per decay model; a larger cache than ``universal_curves`` (bins cycle)."""
    return UniversalCurves(model)


def bin_indices(
    f107a_sfu: float, ap: float, bin_step: float, ap_bins: tuple[float, ...] = AP_BINS
) -> tuple[float, float]:
    """The binned (F10.7 = 81-day mean, Ap) whose profile's curves a chunk uses."""
    f_bin = math.exp(bin_step * round(math.log(f107a_sfu) / bin_step))
    f_bin = min(max(f_bin, 40.0), 400.0)
    logs = np.log(np.array(ap_bins))
    ap_bin = ap_bins[int(np.argmin(np.abs(logs - math.log(max(ap, 1.0)))))]
    return round(f_bin, 6), ap_bin


def air_table(inclination_deg: float, ascending_node_local_time_h: float | None, version: float) -> DailyAirTable:
    """The days' orbit-averaged NRLMSIS densities on `RATIO_GRID_M` at `RATIO_NODES` (`orbit_env.decay.daily_air`)."""
    return daily_air_table(
        tuple(RATIO_GRID_M.tolist()),
        float(inclination_deg),
        ascending_node_local_time_h,
        version,
        RATIO_NODES["latitude_nodes"],
        RATIO_NODES["local_time_nodes"],
    )


@lru_cache(maxsize=4096)
def _log_ratio(
    daily: DailyIndices,
    binned: tuple[float, float],
    inclination_deg: float,
    ascending_node_local_time_h: float | None,
    version: float,
    columns: int | None,
) -> FloatArray:
    log_rho = air_table(inclination_deg, ascending_node_local_time_h, version).log_density(daily, columns=columns)
    return np.log(np.exp(log_rho).mean(axis=0)) - _log_bin_density(
        binned, inclination_deg, ascending_node_local_time_h, version
    )


@lru_cache(maxsize=1024)
def _log_ratios_by_day(
    daily: DailyIndices,
    per_day: int,
    binned: tuple[float, float],
    inclination_deg: float,
    ascending_node_local_time_h: float | None,
    version: float,
    columns: int | None,
) -> FloatArray:
    """`_log_ratio` of each day of ``daily`` (``per_day`` rows each): shape (days, heights)."""
    log_rho = air_table(inclination_deg, ascending_node_local_time_h, version).log_density(daily, columns=columns)
    rho_days = np.exp(log_rho).reshape(-1, per_day, log_rho.shape[1]).mean(axis=1)
    bin_log_rho = _log_bin_density(binned, inclination_deg, ascending_node_local_time_h, version)
    return np.log(rho_days) - bin_log_rho[None, :]


@lru_cache(maxsize=256)
def _log_bin_density(
    binned: tuple[float, float], inclination_deg: float, ascending_node_local_time_h: float | None, version: float
) -> FloatArray:
    """Ln of a bin's density on `RATIO_GRID_M`: its indices on `SEASON_NODES` days spread over the year, averaged."""
    keys = [(binned[0], binned[0], binned[1], float(doy)) for doy in season_days()]
    log_rho = air_table(inclination_deg, ascending_node_local_time_h, version).log_density(keys)
    return np.log(np.exp(log_rho).mean(axis=0))


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
        ap_bins: Ap values of the bins (nearest in log).
        near_circular_bins: `propagate` takes `NEAR_CIRCULAR_BIN_STEP` and `NEAR_CIRCULAR_AP_BINS`
            instead (where wider) when every orbit is within `NEAR_CIRCULAR_SPAN_M` of circular.
        max_years: Stop propagating after this long.
        version: NRLMSIS version of every profile and ratio (see
            `orbit_env.physics.atmosphere.msis.MSIS_VERSIONS`; 0.0 is NRLMSISE-00).
        storm_ap: On storm days (`STORM_AP`) of an activity that has the 3-hourly ap
            (``activity.ap_history``, the CelesTrak record's), NRLMSIS in its storm-time mode
            (`daily_indices`); False: the daily Ap every day.
        air_top_m: The highest height [m] the orbits decayed on this model reach (`propagate`
            sets it from their apogees; None: any). The days' air is then computed up to it
            only (`air_columns`): the ratios hold NaN above, where no orbit reads them.
    """

    activity: SolarActivity
    start_days: float
    inclination_deg: float
    follow_season: bool = True
    rotating_atmosphere: bool = False
    ascending_node_local_time_h: float | None = None
    chunk_days: float = DEFAULT_CHUNK_DAYS
    bin_step: float = DEFAULT_BIN_STEP
    ap_bins: tuple[float, ...] = AP_BINS
    near_circular_bins: bool = True
    max_years: float = DEFAULT_MAX_YEARS
    version: float = DEFAULT_MSIS_VERSION
    storm_ap: bool = True
    air_top_m: float | None = None
    _bins: dict[tuple[float, float], DecayModel] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        check_number(self.chunk_days, "chunk_days", unit="days", low=0.1, high=365.0)
        check_number(self.bin_step, "bin_step", low=0.0, high=1.0, low_inclusive=False)
        check_number(self.max_years, "max_years", unit="years", low=0.0, high=1000.0, low_inclusive=False)
        check_number(self.inclination_deg, "inclination_deg", unit="deg", low=0.0, high=180.0)
        object.__setattr__(self, "version", check_msis_version(self.version))

    def air_columns(self) -> int | None:
        """How many heights of `RATIO_GRID_M` from the lowest the days' air needs (None: all of them).

        Those up to `air_top_m`, and `AIR_COLUMNS_ABOVE` more: an orbit's density ratio is
        interpolated between two heights, its slope from a central difference.
        """
        if self.air_top_m is None:
            return None
        below = int(np.searchsorted(RATIO_GRID_M, self.air_top_m, side="right"))
        return below + AIR_COLUMNS_ABOVE if below + AIR_COLUMNS_ABOVE < RATIO_GRID_M.size else None

    def chunk_condition(self, t_days: float) -> tuple[DailyIndices, tuple[float, float]]:
        """Daily indices (and days of the year) of the chunk starting ``t_days`` after the start, and its bin."""
        days = self.chunk_samples(t_days)
        daily = self.daily_indices(days)
        self.prefetch(daily, t_days)
        return daily, self._bin_of(days)

    def chunk_bin(self, t_days: float) -> tuple[float, float]:
        """The bin of the chunk starting ``t_days`` after the start: its mean 81-day F10.7 and Ap, binned.

        No day's air: what the lifetime's mean air (`orbit_env.decay.lifetime_mean`) reads.
        """
        return self._bin_of(self.chunk_samples(t_days))

    def _bin_of(self, days: FloatArray) -> tuple[float, float]:
        """The bin of the chunk sampled at ``days`` (`chunk_samples`)."""
        _, f107a, ap = self.activity.indices(days)
        return bin_indices(float(np.mean(f107a)), float(np.mean(ap)), self.bin_step, self.ap_bins)

    def near_circular(self) -> SolarDecayModel:
        """The same model on the near-circular bins (no finer than its own).

        `propagate` gives them to the orbits within `NEAR_CIRCULAR_SPAN_M` of circular when ``near_circular_bins``.
        """
        return replace(self, bin_step=max(self.bin_step, NEAR_CIRCULAR_BIN_STEP), ap_bins=NEAR_CIRCULAR_AP_BINS)

    def chunk_samples(self, t_days: float) -> FloatArray:
        """The Unix days at which the chunk starting ``t_days`` after the start is sampled.

        One sample a day, each a calendar day's start (`calendar_day`: the day that holds the
        middle of the sample's share of the chunk): a daily table's rows are then taken as they
        are, and a storm day's 3-hourly ap (`storm_history`) with its own daily indices
        (midpoints, or an epoch's fraction of a day, would interpolate between two days' rows:
        a lifetime then fell by 2.2% from 00:00 to 21:36 UT of one day of epoch, measured on a 457 km
        orbit from 2015-03-25, the storm days counted twice).
        """
        samples = max(1, math.ceil(self.chunk_days))
        return calendar_day(self.start_days + t_days + (np.arange(samples) + 0.5) * (self.chunk_days / samples))

    def daily_indices(self, days: FloatArray) -> DailyIndices:
        """(F10.7, 81-day mean, Ap, day of the year) at each of ``days`` (Unix days), rounded for the caches.

        Without ``follow_season`` each day is `SEASON_NODES` entries, one per node of the year.
        A storm day (``storm_ap``, `STORM_AP`) adds the 27 3-hourly ap of its storm-time history
        (`orbit_env.decay.daily_air`): its air is NRLMSIS's storm-time mode through the day.
        """
        f107, f107a, ap = self.activity.indices(days)
        if self.follow_season:
            # Rounded to 2 days: the season moves the density by < 0.3% in 2 days.
            doy = np.clip(2.0 * np.round(day_of_year(days) / 2.0), 1.0, 366.0)
        else:
            doy = np.zeros(days.size)  # replaced by the year's nodes below
        # Rounded so that repeated runs (bisections, batches) hit the cache: 0.1 sfu and 0.1 Ap
        # move the density by less than 0.1%.
        columns = (np.round(f107, 1), np.round(f107a, 1), np.round(ap, 1), doy)
        per_day = 1
        if not self.follow_season:
            columns = (*(np.repeat(c, SEASON_NODES) for c in columns[:3]), np.tile(season_days(), days.size))
            per_day = SEASON_NODES
        keys = tuple(zip(*(c.tolist() for c in columns), strict=True))
        history = self.storm_history(days)
        if history is None:
            return keys
        history = np.repeat(history, per_day, axis=0)
        return tuple(key if np.isnan(row[0]) else (*key, *row.tolist()) for key, row in zip(keys, history, strict=True))

    def storm_history(self, days: ArrayLike) -> FloatArray | None:
        """Each storm day's 27 3-hourly ap (``activity.ap_history``), NaN on the other days: shape (days, 27).

        A storm day: all 27 known and the largest at least `STORM_AP`. None: no storm day
        among ``days`` (or ``storm_ap`` off, or an activity without 3-hourly ap).
        """
        ap_history = getattr(self.activity, "ap_history", None) if self.storm_ap else None
        if ap_history is None:
            return None
        history = np.asarray(ap_history(np.atleast_1d(np.asarray(days, dtype=np.float64))), dtype=np.float64)
        storm = np.all(np.isfinite(history), axis=1) & (np.max(history, axis=1) >= STORM_AP)
        if not storm.any():
            return None
        history[~storm] = np.nan
        return history

    def density_on_day_kg_m3(self, day_days: float, heights_m: ArrayLike) -> FloatArray:
        """NRLMSIS averaged over the orbit at the indices of ``day_days`` (Unix) [kg/m^3], at ``heights_m``.

        The air the decay reads on that day, without its caches' rounding: a calendar day's start
        (`calendar_day`) reads the record's row; its day of the year (or the year's nodes without
        ``follow_season``); on a storm day (`storm_history`) NRLMSIS's storm-time mode through its
        eight 3-hour slots. The daily reference (`orbit_env.decay.reference_path`) and a history's drag
        fit (`orbit_env.analysis.drag_calibration.fit_history`) read it.
        """
        from orbit_env.physics.atmosphere.msis import ap_histories, mean_density_kg_m3, mean_density_over_days_kg_m3

        f107, f107a, ap = (float(x) for x in self.activity.indices(day_days))
        doy = float(day_of_year(day_days)) if self.follow_season else None
        storm = self.storm_history(day_days)
        if storm is None or np.isnan(storm[0, 0]):
            rho = mean_density_kg_m3(
                heights_m,
                f107,
                f107a,
                ap,
                self.inclination_deg,
                doy,
                self.ascending_node_local_time_h,
                version=self.version,
            )
        else:
            days = np.array([doy]) if doy is not None else season_days()
            rho = mean_density_over_days_kg_m3(
                heights_m,
                f107,
                f107a,
                ap,
                days,
                self.inclination_deg,
                self.ascending_node_local_time_h,
                version=self.version,
                ap_history=np.repeat(ap_histories([ap], storm), days.size, axis=0),
            )
        return np.asarray(rho, dtype=np.float64)

    def prefetch(self, daily: DailyIndices, t_days: float) -> None:
        """Make sure the air table holds ``daily``; if not, it also computes the `PREFETCH_DAYS` from ``t_days``.

        The `PREFETCH_DAYS` after those are then computed by a forked process while the decay goes
        on (`DailyAirTable.log_density`'s ``after``): on a cold run the next bin's curves and the
        next half year's air are computed side by side.
        """
        table = air_table(self.inclination_deg, self.ascending_node_local_time_h, self.version)

        def window(first: int) -> DailyIndices:  # the `PREFETCH_DAYS` from ``first`` days after ``t_days``
            return self.daily_indices(
                calendar_day(self.start_days + t_days + 0.5 + (first + np.arange(PREFETCH_DAYS, dtype=float)))
            )

        table.log_density(
            daily, ahead=lambda: window(0), after=lambda: window(PREFETCH_DAYS), columns=self.air_columns()
        )

    def log_ratios_by_day(self, first_day: int, count: int, binned: tuple[float, float]) -> FloatArray:
        """`log_ratio` of each of ``count`` calendar days, shape (days, heights).

        The first is the calendar day that holds ``first_day`` days after the start
        (`calendar_day`). One NRLMSIS call for all of them (cached).
        """
        days = calendar_day(self.start_days + first_day) + np.arange(count, dtype=np.float64)
        per_day = 1 if self.follow_season else SEASON_NODES
        daily = self.daily_indices(days)
        self.prefetch(daily, float(first_day))
        return _log_ratios_by_day(
            daily,
            per_day,
            binned,
            float(self.inclination_deg),
            self.ascending_node_local_time_h,
            self.version,
            self.air_columns(),
        )

    def log_ratio(self, daily: DailyIndices, binned: tuple[float, float]) -> FloatArray:
        """ln(the mean density over ``daily`` / the bin's) on `RATIO_GRID_M` (cached; NaN above `air_columns`)."""
        return _log_ratio(
            daily,
            binned,
            float(self.inclination_deg),
            self.ascending_node_local_time_h,
            self.version,
            self.air_columns(),
        )

    def bin_model(self, binned: tuple[float, float]) -> DecayModel:
        """The decay model of a bin (its atmosphere: NRLMSIS at the binned indices, year-averaged)."""
        model = self._bins.get(binned)
        if model is None:
            atmosphere = MsisAtmosphere(
                binned[0],
                binned[0],
                binned[1],
                self.inclination_deg,
                None,
                self.ascending_node_local_time_h,
                version=self.version,
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
        log_ratio: FloatArray | None = None,
        offsets: FloatArray | None = None,
        inclination_deg: FloatArray | None = None,
    ) -> FloatArray:
        """The chunk's mean density over the bin's, over each orbit (the multiplier s).

        King-Hele's local form (`orbit_ratio`); with ``averaged``, for orbits wider than
        `AVERAGED_MIN_X`, the ratio of dW/dnu (W the life left on the bin's curves) under
        the chunk's profile (the bin's times the tabulated ratio) and under the bin's
        (`life_rate_ratio` with `RATIO_QUADRATURE_POINTS` anomalies; the module docstring,
        step 3). ``log_ratio`` (on `RATIO_GRID_M`) replaces the one of ``daily``
        (`log_ratio`). ``offsets`` (satellites, `RATIO_GRID_M`) adds each satellite's
        ln(density at its inclination ``inclination_deg`` / at the model's), see
        `propagate`; in co-rotating air such a satellite's ratio carries its air's speed
        (`corotation_factor`, or the rates at its inclination).
        """
        if log_ratio is None:
            log_ratio = self.log_ratio(daily, binned)
        if offsets is not None and inclination_deg is not None:
            spread = np.any(offsets != 0.0, axis=1)
            if not spread.all():  # the model's own inclination exactly as without offsets
                ratio = np.empty(np.shape(perigee_m))
                for rows, extra in ((~spread, (None, None)), (spread, (offsets[spread], inclination_deg[spread]))):
                    if rows.any():
                        ratio[rows] = self.density_ratio(
                            daily,
                            binned,
                            perigee_m[rows],
                            apogee_m[rows],
                            averaged=averaged,
                            log_ratio=log_ratio,
                            offsets=extra[0],
                            inclination_deg=extra[1],
                        )
                return ratio
        table = log_ratio[None, :] if offsets is None else log_ratio[None, :] + offsets
        at_perigee = np.exp(interpolate_rows(table, RATIO_GRID_M, perigee_m))
        ratio_slope = interpolate_rows(uniform_gradient(table, RATIO_GRID_M), RATIO_GRID_M, perigee_m)
        atmosphere = self.bin_model(binned).atmosphere
        assert isinstance(atmosphere, MsisAtmosphere)
        density_slope = np.interp(perigee_m, ALTITUDE_GRID_M, log_density_slope_per_m(atmosphere))
        ratio = orbit_ratio(at_perigee, ratio_slope, density_slope, perigee_m, apogee_m)
        if self.rotating_atmosphere and inclination_deg is not None:
            ratio = ratio * corotation_factor(perigee_m, apogee_m, inclination_deg, self.inclination_deg)
        if not averaged:
            return ratio
        wide = np.flatnonzero(0.5 * (apogee_m - perigee_m) * -density_slope > AVERAGED_MIN_X)
        if wide.size:
            # dW/dt along the bin's curve is g c s: s weights the two rates by the gradient of W (the
            # remaining life on the bin's curves) in (p, e), so that the life left falls at the chunk's rate
            # although the orbit stays on the bin's curve.
            ratio[wide] = life_rate_ratio(
                cached_curves(self.bin_model(binned)),
                table if offsets is None else table[wide],
                RATIO_GRID_M,
                perigee_m[wide],
                apogee_m[wide],
                quadrature_points=RATIO_QUADRATURE_POINTS if offsets is None else SPREAD_QUADRATURE_POINTS,
                inclination_deg=None if inclination_deg is None else inclination_deg[wide],
            )
        return ratio

    def inclination_offsets(self, t_days: float, basis: FloatArray, anchors_deg: FloatArray) -> FloatArray:
        """ln(density at each satellite's inclination / at the model's) on `RATIO_GRID_M` in the chunk from ``t_days``.

        NRLMSIS at the chunk's mean indices (F10.7, its 81-day mean, Ap) and its middle
        day of the year, orbit-averaged at the inclinations ``anchors_deg`` in one call
        (cached), combined by ``basis`` (satellites, anchors: `inclination_basis`).
        """
        f107, f107a, ap = (round(float(np.mean(x)), 1) for x in self.activity.indices(self.chunk_samples(t_days)))
        middle = self.start_days + t_days + 0.5 * self.chunk_days
        doy = float(np.clip(2.0 * np.round(day_of_year(middle) / 2.0), 1.0, 366.0)) if self.follow_season else None
        log_rho = _anchor_log_density(
            (f107, f107a, ap, doy), tuple(anchors_deg.tolist()), self.ascending_node_local_time_h, self.version
        )
        return np.asarray(basis @ log_rho, dtype=np.float64)


@lru_cache(maxsize=4096)
def _anchor_log_density(
    indices: tuple[float, float, float, float | None],
    anchors_deg: tuple[float, ...],
    ascending_node_local_time_h: float | None,
    version: float,
) -> FloatArray:
    """ln(orbit-averaged density) on `RATIO_GRID_M` at each anchor inclination, shape (anchors, heights).

    With a day of the year, each anchor's row of its days' air table (`air_table`: the same NRLMSIS
    average, kept on disk with the days' rows), so a warm run computes none of them again (a snapshot
    of element sets over many inclinations had spent 90% of its warm run here).
    """
    from orbit_env.physics.atmosphere.msis import mean_density_over_inclinations_kg_m3

    f107, f107a, ap, doy = indices
    if doy is not None:
        key = (f107, f107a, ap, doy)
        return np.array(
            [air_table(anchor, ascending_node_local_time_h, version).log_density([key])[0] for anchor in anchors_deg]
        )
    rho = mean_density_over_inclinations_kg_m3(
        RATIO_GRID_M,
        f107,
        f107a,
        ap,
        anchors_deg,
        ascending_node_local_time_h,
        day_of_year=doy,
        **RATIO_NODES,
        version=version,
    )
    return np.log(rho)


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


def _daily_steps(
    model: SolarDecayModel,
    curves: UniversalCurves,
    binned: tuple[float, float],
    label: FloatArray,
    nu: FloatArray,
    gcs: FloatArray,
    hp: FloatArray,
    ha: FloatArray,
    t0: float,
    offsets: FloatArray | None = None,
    inclination_deg: FloatArray | None = None,
    begin_days: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, tuple[list[float], list[FloatArray], list[FloatArray]]]:
    """The chunk from ``t0`` a day (`FINISH_STEP_DAYS`) at a time, for satellites near re-entry.

    Each step takes the density multiplier at its orbit of the profile at its middle: the
    daily profiles' logarithms interpolated linearly in time, as `orbit_env.decay.reference_path.integrate_reference`
    does. A satellite with less than `LAST_DAYS` left at the day's rate takes the
    multiplier at the orbit of the day's middle (the midpoint rule). Returns the re-entry day (NaN for a satellite still
    up at the chunk's end), nu and the heights at the chunk's end (or at re-entry), and
    the days' ends and heights (for the history). ``offsets`` and ``inclination_deg``:
    the satellites' own inclinations (`SolarDecayModel.density_ratio`). ``begin_days``: the day each
    satellite starts from (at or after ``t0``; default ``t0``): one that starts within a step moves for the rest of
    it, at the step's multiplier.
    """
    first_day = math.floor(t0)
    # The rows are calendar days (`calendar_day`): the first starts this many days before ``first_day``.
    fraction = float(model.start_days + first_day - calendar_day(model.start_days + first_day))
    log_ratios = model.log_ratios_by_day(
        first_day, math.floor(t0 + model.chunk_days) + 2 - first_day + math.ceil(fraction), binned
    )
    steps = max(1, math.ceil(model.chunk_days / FINISH_STEP_DAYS))
    step_days = model.chunk_days / steps
    n = label.size
    days = np.full(n, np.nan)
    nu, hp, ha = nu.copy(), hp.copy(), ha.copy()
    # W left at each satellite's nu, kept from the lookup that gave its heights (the next step starts there).
    w_left = curves.weighted_at(label, nu)[2]

    def rates(which: NDArray[np.intp], start: float, length: float) -> tuple[FloatArray, FloatArray]:
        """W left and dW/dt of ``which`` in the step from ``start`` (days) of ``length`` days."""
        middle = start + 0.5 * length - first_day + fraction
        day = min(math.floor(middle), log_ratios.shape[0] - 2)
        weight = middle - day
        log_ratio = (1.0 - weight) * log_ratios[day] + weight * log_ratios[day + 1]
        ratio = model.density_ratio(
            (),
            binned,
            hp[which],
            ha[which],
            averaged=True,
            log_ratio=log_ratio,
            offsets=None if offsets is None else offsets[which],
            inclination_deg=None if inclination_deg is None else inclination_deg[which],
        )
        return w_left[which], gcs[which] * ratio

    def move(which: NDArray[np.intp], start: FloatArray, length: FloatArray, w0: FloatArray, rate: FloatArray) -> None:
        target = w0 - rate * length * SECONDS_PER_DAY
        ended = target <= 0.0
        if ended.any():
            gone = which[ended]
            days[gone] = start[ended] + w0[ended] / rate[ended] / SECONDS_PER_DAY
            nu[gone] = 0.0
            hp[gone], ha[gone], _ = curves.at(label[gone], np.zeros(gone.size))
            which, w0, target = which[~ended], w0[~ended], target[~ended]
        if which.size:
            nu[which], hp[which], ha[which], w_left[which] = curves.move_to_weight(
                label[which], nu[which], w0, target, hp[which], ha[which], NEWTON_TOLERANCE
            )

    alive = np.arange(n)
    times: list[float] = []
    heights_p: list[FloatArray] = []
    heights_a: list[FloatArray] = []
    for j in range(steps):
        start = t0 + j * step_days
        moving = alive if begin_days is None else alive[begin_days[alive] < start + step_days]
        # Each moving satellite's start and length in the step (the whole step but for one that starts within it).
        starts, lengths = np.full(moving.size, start), np.full(moving.size, step_days)
        if begin_days is not None:
            late = begin_days[moving] > start
            starts[late] = begin_days[moving[late]]
            lengths[late] = start + step_days - starts[late]
        w0, rate = rates(moving, start, step_days)
        # In its last days the perigee falls tens of km a day: the day takes the multiplier at the orbit of its
        # middle (reached by half the day at the start's), from the start again (the midpoint rule).
        last = w0 < rate * LAST_DAYS * SECONDS_PER_DAY
        if not last.any():
            move(moving, starts, lengths, w0, rate)
        else:
            move(moving[~last], starts[~last], lengths[~last], w0[~last], rate[~last])
            close = moving[last]
            at_start = (nu[close], hp[close], ha[close], w_left[close])
            move(close, starts[last], 0.5 * lengths[last], w0[last], rate[last])
            up = np.isnan(days[close])  # the others re-entered within the half day, at the start's rate
            if up.any():
                middle = close[up]
                _, rate_middle = rates(middle, start, step_days)
                nu[middle], hp[middle], ha[middle], w_left[middle] = (x[up] for x in at_start)
                move(middle, starts[last][up], lengths[last][up], w_left[middle], rate_middle)
        alive = alive[np.isnan(days[alive])]
        times.append(t0 + (j + 1) * step_days if alive.size else float(np.nanmax(days)))
        heights_p.append(hp.copy())
        heights_a.append(ha.copy())
        if alive.size == 0:
            break
    return days, nu, hp, ha, (times, heights_p, heights_a)


@dataclass
class _Spread:
    """What `propagate` keeps for satellites of other inclinations than the model's (see there)."""

    inclination_deg: FloatArray
    anchors_deg: FloatArray
    basis: FloatArray
    wide: NDArray[np.bool_]
    factor: FloatArray
    factor_perigee_m: FloatArray

    @classmethod
    def of(
        cls, model: SolarDecayModel, inclination_deg: ArrayLike | None, hp: FloatArray, ha: FloatArray
    ) -> _Spread | None:
        """None when every satellite has the model's inclination."""
        if inclination_deg is None:
            return None
        inclination = np.broadcast_to(np.asarray(inclination_deg, dtype=np.float64), hp.shape).copy()
        if np.all(inclination == model.inclination_deg):
            return None
        anchors = inclination_anchors(inclination, model.inclination_deg)
        basis = inclination_basis(anchors, inclination, model.inclination_deg)
        wide = np.any(basis != 0.0, axis=1) & (ha - hp > SPREAD_MAX_SPAN_M)
        return cls(inclination, anchors, basis, wide, np.ones(hp.size), np.full(hp.size, np.nan))

    def wide_factor(
        self,
        model: SolarDecayModel,
        curves: UniversalCurves,
        daily: DailyIndices,
        binned: tuple[float, float],
        active: NDArray[np.intp],
        offsets: FloatArray,
        hp: FloatArray,
        ha: FloatArray,
        ratio: FloatArray,
        new_bin: bool,
    ) -> FloatArray:
        """The wide satellites' `life_rate_ratio` over their ``ratio`` (`orbit_ratio`'s), refreshed as needed.

        1 for the others.
        """
        wide = self.wide[active]
        stale = wide & (new_bin | ~(np.abs(hp[active] - self.factor_perigee_m[active]) <= SPREAD_REFRESH_M))
        if stale.any():
            rows = active[stale]
            table = model.log_ratio(daily, binned)[None, :] + offsets[stale]
            rate = life_rate_ratio(
                curves,
                table,
                RATIO_GRID_M,
                hp[rows],
                ha[rows],
                quadrature_points=SPREAD_QUADRATURE_POINTS,
                inclination_deg=self.inclination_deg[rows],
            )
            self.factor[rows] = rate / ratio[stale]
            self.factor_perigee_m[rows] = hp[rows]
        return self.factor[active]


def propagate(
    perigee_m: ArrayLike,
    apogee_m: ArrayLike,
    drag_parameter_m2_kg: ArrayLike,
    model: SolarDecayModel,
    *,
    density_scale: ArrayLike = 1.0,
    record: bool = False,
    progress: Callable[[float], None] | None = None,
    inclination_deg: ArrayLike | None = None,
    start_days: ArrayLike | None = None,
    clock: Callable[[float], None] | None = None,
) -> SolarLifetime:
    """Propagate satellites to re-entry under the activity of ``model`` (see the module docstring).

    With ``inclination_deg`` (per satellite), satellites of other inclinations than the
    model's stay on the model's curves and take their own inclination as a density
    multiplier as well: in each chunk, NRLMSIS at the chunk's mean indices and middle
    day of the year, every `ANCHOR_STEP_DEG` in one call, gives ln(density at the
    satellite's inclination / at the model's) by a cubic spline in inclination
    (`SolarDecayModel.inclination_offsets`), added to the chunk's ratio. Orbits up to
    `SPREAD_MAX_SPAN_M` wide take it over the orbit (`orbit_ratio`), in co-rotating air
    times `corotation_factor`; wider ones the ratio of the rates at which the life left
    falls (`life_rate_ratio`), refreshed when the bin changes or the perigee has moved
    `SPREAD_REFRESH_M` since, and held in between as a factor on `orbit_ratio`'s. A
    catalogue spread over inclinations then costs one family, not one per inclination
    (docs/validation-modern.md, section 7).

    Orbits within `NEAR_CIRCULAR_SPAN_M` of circular are propagated on the near-circular
    bins (`SolarDecayModel.near_circular`), the others on the model's, each group on its own,
    so a satellite's lifetime does not depend on the others in the vector. With
    ``record``, a vector holding both kinds takes the model's bins for all (one history).

    With ``start_days`` (per satellite, days after the model's epoch), each satellite starts
    at its own date (a snapshot of element sets, each object at its epoch): it joins the
    others' chunks in the one that holds its start, moving for the rest of that chunk at the
    chunk's multiplier, and its lifetime (and ``max_years``) counts from its start. The
    chunks then begin at the model's epoch, not at each satellite's: its lifetime moves by
    the chunking's own error (within 0.26% on twelve orbits, docs/how-to/catalogue.md), and
    the satellites of different dates share their bins' curves and days' air.

    Args:
        perigee_m: Initial perigee heights [m] (in the curves' domain: the caller checks).
        apogee_m: Initial apogee heights [m].
        drag_parameter_m2_kg: c = c_x A / m of each satellite [m^2/kg].
        model: Activity, epoch, inclination, chunking.
        density_scale: Multiplier on the density (e.g. a fitted scale factor).
        record: Keep the heights at every chunk boundary.
        progress: Called with the fraction of satellites re-entered after each chunk.
        inclination_deg: Each satellite's inclination (default: the model's).
        start_days: Each satellite's start [days after the model's epoch, >= 0] (default 0).
        clock: Called with the days from the model's epoch reached after each chunk (one satellite's progress,
            which ``progress`` cannot show; orbits of both kinds, near-circular and wider, run it once each).

    Raises:
        ValueError: ``start_days`` negative or not finite, or given with ``record``.
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
    start = None
    if start_days is not None:
        start = np.broadcast_to(np.asarray(start_days, dtype=np.float64), hp.shape).copy()
        if not np.all(np.isfinite(start) & (start >= 0.0)):
            raise ValueError("start_days must be finite and >= 0 (days after the model's epoch)")
        if record:
            raise ValueError("record keeps one history for all satellites: it takes no start_days")
    near = (ha - hp <= NEAR_CIRCULAR_SPAN_M) if model.near_circular_bins else np.zeros(hp.size, dtype=bool)
    if near.all() or not near.any() or record:
        fixed = model.near_circular() if near.size and near.all() else model
        return _propagate(hp, ha, c, scale, fixed, record, progress, inclination_deg, start, clock)
    days, reentered, bins_used, done = np.empty(hp.size), np.empty(hp.size, dtype=bool), 0, 0
    for group, group_model in ((near, model.near_circular()), (~near, model)):
        count = int(group.sum())

        def group_progress(fraction: float, before: int = done, count: int = count) -> None:
            if progress is not None:
                progress((before + fraction * count) / hp.size)

        inclination = None if inclination_deg is None else np.broadcast_to(inclination_deg, hp.shape)[group]
        result = _propagate(
            hp[group],
            ha[group],
            c[group],
            scale[group],
            group_model,
            False,
            group_progress,
            inclination,
            None if start is None else start[group],
            clock,
        )
        days[group], reentered[group] = result.days, result.reentered
        bins_used, done = bins_used + result.bins_used, done + count
    return SolarLifetime(days, reentered, np.array([0.0]), hp[None, :], ha[None, :], bins_used)


def _propagate(
    hp: FloatArray,
    ha: FloatArray,
    c: FloatArray,
    scale: FloatArray,
    model: SolarDecayModel,
    record: bool,
    progress: Callable[[float], None] | None,
    inclination_deg: ArrayLike | None,
    start_days: FloatArray | None = None,
    clock: Callable[[float], None] | None = None,
) -> SolarLifetime:
    """`propagate` on the bins of ``model`` for every satellite."""
    hp, ha = hp.copy(), ha.copy()
    if ha.size:  # decaying orbits only come down: the days' air above their highest apogee is never read
        model = replace(model, air_top_m=float(np.max(ha)))
    n = hp.size
    gcs = G0_M_S2 * c * scale
    spread = _Spread.of(model, inclination_deg, hp, ha)
    start = np.zeros(n) if start_days is None else start_days
    # The re-entry day [days after the model's epoch]; NaN while up.
    reentry = np.where(hp <= REENTRY_ALTITUDE_M, start, np.nan)
    # Not yet started (by start), then started.
    waiting = np.flatnonzero(np.isnan(reentry))
    waiting = waiting[np.argsort(start[waiting], kind="stable")]
    active = np.empty(0, dtype=np.intp)
    label = tau = np.empty(0)
    key_prev: tuple[float, float] | None = None
    curves: UniversalCurves | None = None
    history_t, history_hp, history_ha = [0.0], [hp.copy()], [ha.copy()]
    bins: set[tuple[float, float]] = set()
    dt_s = model.chunk_days * SECONDS_PER_DAY
    # Each satellite's span: as many chunks as cover max_years from its start.
    span_days = math.ceil(model.max_years * DAYS_PER_YEAR / model.chunk_days) * model.chunk_days
    k = 0
    while active.size or waiting.size:
        if active.size == 0:  # the next to start: its chunk
            k = max(k, math.floor(start[waiting[0]] / model.chunk_days))
        t0 = k * model.chunk_days
        t1 = t0 + model.chunk_days
        joining = waiting[: np.searchsorted(start[waiting], t1, side="left")]
        if joining.size:
            waiting = waiting[joining.size :]
        over = t0 >= start[active] + span_days  # past its span: still up
        if over.any():
            active, label, tau = active[~over], label[~over], tau[~over]
        if active.size == 0 and joining.size == 0:
            k += 1
            continue
        daily, binned = model.chunk_condition(t0)
        bins.add(binned)
        new_bin = binned != key_prev
        active = np.concatenate([active, joining])
        if new_bin:
            curves = cached_curves(model.bin_model(binned))
            label, tau = curves.locate_exactly(hp[active], ha[active])
            key_prev = binned
        elif joining.size:
            assert curves is not None
            label_joining, tau_joining = curves.locate_exactly(hp[joining], ha[joining])
            label, tau = np.concatenate([label, label_joining]), np.concatenate([tau, tau_joining])
        assert curves is not None
        if spread is None:
            offsets = inclination = None
            s = model.density_ratio(daily, binned, hp[active], ha[active])
        else:
            offsets, inclination = (
                model.inclination_offsets(t0, spread.basis[active], spread.anchors_deg),
                spread.inclination_deg[active],
            )
            s = model.density_ratio(daily, binned, hp[active], ha[active], offsets=offsets, inclination_deg=inclination)
            s = s * spread.wide_factor(model, curves, daily, binned, active, offsets, hp, ha, s, new_bin)
        rate = gcs[active] * s  # dW/dt: W falls by this per second
        nu0 = NU_REF * np.expm1(tau)
        _, _, w0 = curves.weighted_at(label, nu0)
        # Near re-entry (less than FINE_CHUNKS chunks of decay left at this rate) the chunk goes day by day;
        # the others cannot re-enter within it.
        fine = w0 < rate * dt_s * FINE_CHUNKS
        coarse = ~fine
        # A satellite that starts within the chunk moves for the rest of it.
        begin = np.maximum(start[active], t0)
        late = begin > t0
        dt_row_s = np.where(late, (t1 - begin) * SECONDS_PER_DAY, dt_s)
        nu_new = nu0.copy()
        hp_new, ha_new = hp[active].copy(), ha[active].copy()
        done = np.zeros(active.size, dtype=bool)
        if fine.any():
            which = np.flatnonzero(fine)
            f_days, f_nu, f_hp, f_ha, sub = _daily_steps(
                model,
                curves,
                binned,
                label[which],
                nu0[which],
                gcs[active[which]],
                hp_new[which],
                ha_new[which],
                t0,
                None if offsets is None else offsets[which],
                None if inclination is None else inclination[which],
                begin[which] if late[which].any() else None,
            )
            ended = np.isfinite(f_days)
            reentry[active[which[ended]]] = f_days[ended]
            done[which[ended]] = True
            nu_new[which], hp_new[which], ha_new[which] = f_nu, f_hp, f_ha
            if record:
                for t_sub, hp_sub, ha_sub in zip(*sub, strict=True):
                    history_t.append(t_sub)
                    history_hp.append(hp.copy())
                    history_ha.append(ha.copy())
                    history_hp[-1][active[which]], history_ha[-1][active[which]] = hp_sub, ha_sub
        if coarse.any():
            # Newton on W(nu) = target, dW/dnu = P (W is convex-ish and smooth).
            target = w0[coarse] - rate[coarse] * dt_row_s[coarse]
            nu_new[coarse], hp_new[coarse], ha_new[coarse], _ = curves.move_to_weight(
                label[coarse], nu0[coarse], w0[coarse], target, hp_new[coarse], ha_new[coarse], NEWTON_TOLERANCE
            )
        hp[active], ha[active] = hp_new, ha_new
        keep = ~done
        label, tau = label[keep], np.log1p(nu_new[keep] / NU_REF)
        active = active[keep]
        if record:
            history_t.append(t0 + model.chunk_days)
            history_hp.append(hp.copy())
            history_ha.append(ha.copy())
        if progress is not None:
            progress(1.0 - (active.size + waiting.size) / n)
        if clock is not None:
            clock(t0 + model.chunk_days)
        k += 1
    reentered = np.isfinite(reentry)
    return SolarLifetime(
        days=np.where(reentered, reentry - start, model.max_years * DAYS_PER_YEAR),
        reentered=reentered,
        history_days=np.array(history_t),
        history_perigee_m=np.array(history_hp),
        history_apogee_m=np.array(history_ha),
        bins_used=len(bins),
    )
