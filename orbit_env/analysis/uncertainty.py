"""Lifetime with its uncertainty: Monte Carlo over the solar forecast, the density model and the drag coefficient.

Units: SI inside (m, days); the public function takes heights in m above the package's
6371 km sphere, as `orbit_env.analysis.scenario.Scenario.lifetime_days` does.

Three sources, independent, each a log-normal factor (sigma in the natural log):

* **the solar forecast** (`SOLAR_FORECAST_SIGMA`): F10.7 and its 81-day mean after
  the last observed day are multiplied by exp(sigma z). The record's monthly forecast
  (NOAA SWPC's predicted cycle, as CelesTrak carries it) states no spread in the file; 0.15
  is our reading of the spread of published cycle predictions (the NASA/NOAA Solar Cycle
  25 Prediction Panel's and NASA MSFC's bands are about +-25-30% of the smoothed F10.7 at
  95%; figures from memory, not checked against a source here). Observed days are not
  varied. Without an epoch (a constant, user-given activity) this source is left out;
* **the density model** (`DENSITY_MODEL_SIGMA`): NRLMSIS's own error, a factor on
  the density held for the whole life. A lifetime integrates the density over months or
  years, so the spread that matters is that of the model's slowly varying bias: Bruinsma &
  Boniface (2021, "The operational and research DTM-2020 thermosphere models", J. Space
  Weather Space Clim. 11, 47, Table 3) give the standard deviation of the yearly mean density
  ratio between the data and NRLMSISE-00 as 4.9-21.5% over eleven data sets (CHAMP 12.9%, GRACE
  16.7%, GOCE 4.9%, orbit-derived densities at 250 km 10-11%, HASDM at 400 km 18.1%). 0.15
  sits in that range; for NRLMSIS 2.0 (Emmert et al. 2021, Earth and Space Science) we had
  no such table at hand. The hindcasts of ``docs/validation-modern.md`` (section 5) count
  how many observed lives fall in the resulting band;
* **the drag coefficient** (`DRAG_COEFFICIENT_SIGMA`): 0.10, for the accommodation
  and attitude a free-molecular coefficient assumes, or the fit error of a B*.

Everything goes through the fast paths: a fixed profile's lifetime is inversely
proportional to the density scale and the drag coefficient (Eq. 3.4: the decay rate is
linear in rho c), so the samples of a fixed profile are one lifetime divided by their
factors, exactly. With an epoch, the time-stepped decay (`orbit_env.decay.chunked`)
runs once per solar node (`SOLAR_NODES`, values of z) with the samples that use that
node at once, a vector of satellites each with its own density and drag factor; each
sample's lifetime is then interpolated in z between the two nodes around it (linearly
in log days). A node propagates only its own samples (the outer nodes about a sixth of
them), so it stops when they have re-entered, not the longest-lived of all. The
interpolation error is measured in ``tests/analysis/test_uncertainty.py`` against samples
propagated one by one. (A grid in the factor as well is cheaper but misses by up to 4%:
the lifetime is not smooth in the factor where the fall meets a turn of the solar cycle.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.analysis.scenario import check_scenario
from orbit_env.checks import check_int, check_number
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.curves import UniversalCurves
from orbit_env.physics.satellite_bounds import check_drag_parameter

FloatArray = NDArray[np.float64]

#: Log-normal sigma of F10.7 after the last observed day (see the module docstring).
SOLAR_FORECAST_SIGMA = 0.15
#: Log-normal sigma of NRLMSIS's density (see the module docstring).
DENSITY_MODEL_SIGMA = 0.15
#: Log-normal sigma of the drag coefficient.
DRAG_COEFFICIENT_SIGMA = 0.10
#: Log-normal sigma of a drag parameter calibrated from one element set (B* or ndot): the scatter
#: between sets of one object 1-15 days apart, 0.170 for B* and 0.174 for ndot over 91 pairs of 22
#: objects (benchmarks/measure_drag_scatter.py, which uses no re-entry outcome).
ONE_SET_DRAG_SIGMA = 0.17
#: Values of the solar z at which the time-stepped decay runs; samples outside are extrapolated linearly.
SOLAR_NODES = (-2.0, -1.0, 0.0, 1.0, 2.0)
#: Percentiles reported.
PERCENTILES = (5, 50, 95)
#: The confidence STELA asks of the disposal rule ("within 25 years with probability >= 0.9").
RULE_CONFIDENCE = 0.9
#: Allowed numbers of samples.
SAMPLES_RANGE = (10, 1_000_000)


@dataclass(frozen=True, eq=False)
class ScaledForecast:
    """An activity whose F10.7 and 81-day mean after ``after_days`` are multiplied by ``factor``.

    Attributes:
        activity: The activity it scales.
        factor: Multiplier on F10.7 and its 81-day mean.
        after_days: Unix days after which it applies (the last observed day).
    """

    activity: Any
    factor: float
    after_days: float

    def indices(self, days: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The scaled indices (F10.7 kept inside NRLMSIS's range)."""
        from orbit_env.physics.atmosphere.msis import F107_RANGE_SFU

        f107, f107a, ap = self.activity.indices(days)
        future = np.asarray(days, dtype=np.float64) > self.after_days
        k = np.where(future, self.factor, 1.0)
        low, high = F107_RANGE_SFU
        return np.clip(f107 * k, low, high), np.clip(f107a * k, low, high), ap

    def ap_history(self, days: ArrayLike) -> FloatArray:
        """The activity's 3-hourly ap, not scaled (NaN if it has none): its storm days stay storm days."""
        inner = getattr(self.activity, "ap_history", None)
        return np.full((np.size(days), 27), np.nan) if inner is None else inner(days)

    def describe(self) -> str:
        """One line."""
        inner = self.activity.describe() if hasattr(self.activity, "describe") else type(self.activity).__name__
        return f"{inner}, forecast x {self.factor:.3g}"


@dataclass(frozen=True)
class LifetimeSpread:
    """Lifetimes of the Monte Carlo samples.

    Attributes:
        days: Each sample's lifetime [days] (the propagation's cap where it did not re-enter).
        reentered: Per sample, whether it re-entered.
        seed: The seed the samples came from.
        sources: Which sources were sampled, with their sigmas.
    """

    days: FloatArray
    reentered: NDArray[np.bool_]
    seed: int
    sources: dict[str, float]

    def percentiles_days(self) -> dict[str, float | None]:
        """The 5th, 50th and 95th percentile lifetimes [days] (None where beyond the propagation)."""
        out: dict[str, float | None] = {}
        for p in PERCENTILES:
            value = float(np.percentile(np.where(self.reentered, self.days, np.inf), p))
            out[str(p)] = value if math.isfinite(value) else None
        return out

    def compliance_probability(self, rule_years: float) -> float:
        """Fraction of the samples that re-enter within ``rule_years``."""
        years = check_number(rule_years, "rule_years", unit="years", low=0.0, low_inclusive=False)
        return float(np.mean(self.reentered & (self.days <= years * DAYS_PER_YEAR)))


def sample_factors(
    samples: int, seed: int, drag_sigma: float = DRAG_COEFFICIENT_SIGMA
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The samples' solar z, density factor and drag factor (sigma ``drag_sigma``; seeded: the same twice)."""
    n = check_samples(samples)
    rng = np.random.default_rng(check_int(seed, "seed", low=0))
    z_sun = rng.standard_normal(n)
    density = np.exp(DENSITY_MODEL_SIGMA * rng.standard_normal(n))
    drag = np.exp(drag_sigma * rng.standard_normal(n))
    return z_sun, density, drag


def check_samples(samples: int) -> int:
    """The number of samples, checked against `SAMPLES_RANGE`.

    Raises:
        InputError: outside the range.
    """
    low, high = SAMPLES_RANGE
    return check_int(samples, "samples", low=low, high=high)


def lifetime_spread(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    scenario: Any,
    inclination_deg: float,
    *,
    samples: int = 1000,
    seed: int = 0,
    drag_sigma: float = DRAG_COEFFICIENT_SIGMA,
    workers: int = 1,
    progress: bool = False,
) -> LifetimeSpread:
    """Monte Carlo lifetimes of one satellite (see the module docstring).

    Args:
        perigee_m: Perigee height above the 6371 km sphere.
        apogee_m: Apogee height above the sphere.
        drag_parameter_m2_kg: c = c_x A / m.
        scenario: The `Scenario`.
        inclination_deg: The orbit's inclination.
        samples: Number of samples.
        seed: Seed of the random numbers.
        drag_sigma: Log-normal sigma of the drag parameter: `DRAG_COEFFICIENT_SIGMA` for a
            satellite of known mass and area, `ONE_SET_DRAG_SIGMA` for one element set's.
        workers: Processes for the solar nodes (`propagate_nodes`); the results do not depend on it.
        progress: A bar of the solar nodes done on standard error, if it is a terminal (a cold run of a long
            life computes decades of each node's air: tens of seconds).

    Raises:
        ValueError: heights outside the universal curves' domain (metres, not km), a drag parameter
            out of range, or not a `Scenario`.
    """
    check_scenario(scenario)
    UniversalCurves.check_domain(perigee_m, apogee_m)  # the samples decay on the curves, dated or not
    check_drag_parameter(drag_parameter_m2_kg)
    z_sun, density, drag = sample_factors(samples, seed, drag_sigma)
    scale = density * drag
    drag_key = "drag_coefficient" if drag_sigma == DRAG_COEFFICIENT_SIGMA else "drag_parameter"
    sources = {"density_model": DENSITY_MODEL_SIGMA, drag_key: drag_sigma}
    if not scenario.time_varying:
        days, reentered = scenario.lifetime_days(perigee_m, apogee_m, drag_parameter_m2_kg, inclination_deg)
        return LifetimeSpread(float(days) / scale, np.full(scale.size, bool(reentered)), seed, sources)
    sources["solar_forecast"] = SOLAR_FORECAST_SIGMA
    base = scenario.solar_model(inclination_deg)
    activity = base.activity
    after = getattr(activity, "observed_end_days", -math.inf)
    # Each sample's lifetime is interpolated in z between the two nodes around it, in log days.
    nodes = np.array(SOLAR_NODES)
    right = np.clip(np.searchsorted(nodes, z_sun), 1, nodes.size - 1)
    left = right - 1
    w = (z_sun - nodes[left]) / (nodes[right] - nodes[left])
    # At each node, the samples that use it at once (a vector of satellites, each with its own
    # density and drag factor): a node then runs only until its own samples have re-entered, and
    # the samples' lifetimes are those of propagating all of them at every node (each satellite
    # is propagated on its own arithmetic; the others in the vector do not change it).
    log_days = np.zeros((nodes.size, z_sun.size))
    up = np.zeros((nodes.size, z_sun.size), dtype=bool)
    # The nominal forecast's node first: it runs on the days the nominal lifetime ran just before
    # (the command line's), whose NRLMSIS ratios are still in chunked's in-memory cache.
    runs: list[NodeRun] = []
    for k in np.argsort(np.abs(nodes), kind="stable"):
        needed = np.flatnonzero((left == k) | (right == k))
        if needed.size:
            k_sun = math.exp(SOLAR_FORECAST_SIGMA * float(nodes[k]))
            model = replace(base, activity=ScaledForecast(activity, k_sun, after))
            runs.append((int(k), needed, model))
    orbit = (float(perigee_m), float(apogee_m), float(drag_parameter_m2_kg))
    for (k, needed, _), (days_k, reentered_k) in zip(
        runs, propagate_nodes(orbit, runs, scale * scenario.density_scale, workers, progress), strict=True
    ):
        log_days[k, needed] = np.log(np.maximum(days_k, 1e-6))
        up[k, needed] = reentered_k
    cols = np.arange(z_sun.size)
    days = np.exp(log_days[left, cols] * (1.0 - w) + log_days[right, cols] * w)
    reentered = up[left, cols] & up[right, cols]
    cap = base.max_years * DAYS_PER_YEAR
    days = np.where(reentered, np.minimum(days, cap), cap)
    return LifetimeSpread(days, reentered, seed, sources)


#: A solar node's run: its index, the samples that use it, and its decay model (the forecast scaled).
NodeRun = tuple[int, NDArray[np.intp], Any]


def propagate_nodes(
    orbit: tuple[float, float, float],
    runs: list[NodeRun],
    density_scale: FloatArray,
    workers: int,
    progress: bool = False,
) -> list[tuple[FloatArray, NDArray[np.bool_]]]:
    """Each node's samples propagated (`orbit_env.decay.chunked.propagate`): their days and whether they re-entered.

    ``orbit`` is (perigee [m], apogee [m], drag parameter [m^2/kg]), ``density_scale`` every
    sample's factor. With ``workers`` > 1 the nodes after the first run in as many worker
    processes (`orbit_env.workers.worker_pool`: forked where it may) while this one runs the
    first (the nominal forecast's, whose air is in memory); the workers' new rows of the real
    Sun's air come back with their results (`orbit_env.decay.daily_air.merge_rows`). Each node
    runs on its own arithmetic, so the results are the same bit for bit in any process. ``progress``:
    a bar of the nodes done on standard error, shown on a terminal only and cleared at the end.
    """
    from orbit_env.decay import daily_air

    bar = _nodes_bar(len(runs)) if progress else None
    try:
        if workers <= 1 or len(runs) <= 1:
            results = []
            for _, needed, model in runs:
                results.append(_propagate_node(orbit, model, density_scale[needed])[:2])
                _advance(bar)
            return results
        from orbit_env.workers import worker_pool

        with worker_pool(min(workers, len(runs) - 1)) as pool:  # Ctrl-C or a failed node stops the workers now
            futures = [
                pool.submit(_propagate_node, orbit, model, density_scale[needed], True) for _, needed, model in runs[1:]
            ]
            _, needed, model = runs[0]
            results = [_propagate_node(orbit, model, density_scale[needed])[:2]]
            _advance(bar)
            for future in futures:
                days, reentered, rows = future.result()
                daily_air.merge_rows(rows)
                results.append((days, reentered))
                _advance(bar)
        return results
    finally:
        if bar is not None:
            bar.close()


def _nodes_bar(total: int) -> Any:
    """A tqdm bar of the solar nodes, on a terminal only (tqdm's ``disable=None``), cleared when closed."""
    from tqdm import tqdm  # here: a command without --uncertainty does not import it

    return tqdm(total=total, unit="node", desc="samples' solar nodes", disable=None, leave=False)


def _advance(bar: Any) -> None:
    if bar is not None:
        bar.update(1)


def _propagate_node(
    orbit: tuple[float, float, float], model: Any, density_scale: FloatArray, worker: bool = False
) -> tuple[FloatArray, NDArray[np.bool_], Any]:
    """One node's samples (`propagate_nodes`); in a worker, also the air rows it computed."""
    from orbit_env.decay import daily_air
    from orbit_env.decay.chunked import propagate

    perigee_m, apogee_m, drag_parameter_m2_kg = orbit
    size = density_scale.size
    result = propagate(
        np.full(size, perigee_m), np.full(size, apogee_m), drag_parameter_m2_kg, model, density_scale=density_scale
    )
    return result.days, result.reentered, daily_air.new_rows() if worker else None


def spread_report(spread: LifetimeSpread, epoch_days: float | None, rule_years: float | None) -> dict[str, Any]:
    """The JSON keys of ``--uncertainty``: percentiles (days and dates), and the rule as a probability."""
    from orbit_env.analysis.lifetime import iso_datetime

    days = spread.percentiles_days()
    report: dict[str, Any] = {
        "days_percentiles": days,
        "uncertainty_samples": int(spread.days.size),
        "uncertainty_seed": spread.seed,
        "uncertainty_sigmas": spread.sources,
    }
    if epoch_days is not None:
        report["reentry_date_percentiles"] = {
            key: None if value is None else iso_datetime(epoch_days + value) for key, value in days.items()
        }
    if rule_years is not None:
        probability = spread.compliance_probability(rule_years)
        report["compliance_probability"] = probability
        report["complies_with_confidence"] = probability >= RULE_CONFIDENCE
        report["rule_verdict"] = verdict(rule_years, probability)
    return report


def verdict(rule_years: float, probability: float) -> str:
    """The rule at 90% confidence, in STELA's words ("re-enters within 25 years with probability >= 0.9")."""
    holds = probability >= RULE_CONFIDENCE
    sign = ">=" if holds else "<"
    return (
        f"{'complies' if holds else 'does not comply'}: re-enters within {rule_years:g} years with probability "
        f"{probability:.3f} ({sign} {RULE_CONFIDENCE:g})"
    )
