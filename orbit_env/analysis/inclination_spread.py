"""Lifetimes of orbits of many inclinations on one curve family: each row's inclination a density multiplier.

With NRLMSIS the profile depends on the inclination (and in co-rotating air the drag
does). A catalogue spread over many inclinations takes one family, that of the most
common inclination, and each row's own inclination as a density multiplier along its
decay (`orbit_env.decay.density_multiplier`): NRLMSIS at the row's inclination against
the family's, computed every ``ANCHOR_STEP_DEG`` in one NRLMSIS call and interpolated in
inclination. Near-circular rows (apogee at most ``SPREAD_MAX_SPAN_M`` above perigee) take
the ratio of the two densities weighted over the orbit as drag weights it
(`orbit_env.decay.density_multiplier.orbit_ratio`), times that of the co-rotating air's
drag; wider rows the ratio of the rates at which the life left falls
(`orbit_env.decay.density_multiplier.life_rate_ratio`), which a profile of another shape
moves through the eccentricity as well as the perigee. The time is Int dW / (g c s)
along the family's curve. On 10^4 rows over 0-98 deg this stays within the 0.5% the
curves hold of a family per 1-degree group, at the cost measured by
``benchmarks/bench_catalogue.py`` (docs/validation-modern.md section 7). SI units.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from orbit_env.analysis.scenario import Scenario
from orbit_env.decay.curves import NU_REF, UniversalCurves, days_from_weighted_s
from orbit_env.decay.density_multiplier import (
    FINE_RATIO_GRID_M,
    RATIO_NODES,
    SPREAD_MAX_SPAN_M,
    SPREAD_QUADRATURE_POINTS,
    corotation_factor,
    inclination_anchors,
    inclination_basis,
    interpolate_rows_with_slope,
    life_rate_ratio,
    orbit_ratio,
)

FloatArray = NDArray[np.float64]


#: Points along each decay (equal steps of the curves' tau) where the multiplier is taken.
PATH_NODES = 48

#: Points along each decay of a wide row (on the rows of SPREAD_QUADRATURE_POINTS in co-rotating air:
#: 24 leave up to 0.59%, 32 0.45%).
WIDE_PATH_NODES = 32


def inclination_log_ratio(scenario: Scenario, reference_deg: float, inclination_deg: FloatArray) -> FloatArray:
    """ln(the air's density at each inclination / at ``reference_deg``) on ``FINE_RATIO_GRID_M``, shape (n, heights).

    Zero for an air that does not depend on the inclination. NRLMSIS is averaged over the
    year at every ``ANCHOR_STEP_DEG`` spanning the inclinations, in one call, and its
    logarithm interpolated in inclination by a cubic spline.
    """
    inclination = np.asarray(inclination_deg, dtype=np.float64)
    zero = np.zeros((inclination.size, FINE_RATIO_GRID_M.size))
    if not scenario.air.depends_on_inclination:
        return zero
    anchors = inclination_anchors(inclination, reference_deg)
    if anchors.size < 2:
        return zero
    # The chunks' nodes (6 x 6): against 12 x 6, ln ratio within 2e-4 at 150-1200 km.
    rho = scenario.air.mean_density_over_inclinations_kg_m3(FINE_RATIO_GRID_M, anchors, **RATIO_NODES)
    return np.asarray(inclination_basis(anchors, inclination, reference_deg) @ np.log(rho), dtype=np.float64)


def spread_lifetime_days(
    curves: UniversalCurves,
    scenario: Scenario,
    reference_deg: float,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    drag_parameter_m2_kg: FloatArray,
) -> FloatArray:
    """Days to re-entry on the curves of ``reference_deg`` with each row's density multiplier along its decay.

    Row k's multiplier at an orbit is its profile's (the reference's times
    exp(``log_ratio[k]``) at each height) over the reference's: for near-circular
    rows (apogee at most `SPREAD_MAX_SPAN_M` above perigee) the ratio weighted over
    the orbit (`orbit_ratio`), for wider rows the ratio of the rates at which the life
    left falls (``_life_rate_ratio``); in co-rotating air times the drag of the air's
    speed at the perigee, ((v_p - Omega r_p cos i) / (v_p - Omega r_p cos i_ref))^2.
    The time is Int dW / (g c s) along the reference curve, by the trapezoidal rule at
    `PATH_NODES` (`WIDE_PATH_NODES`) equal steps of tau; with s = 1 it is the curves'
    own lifetime exactly.
    """
    perigee_m, apogee_m = np.asarray(perigee_m, dtype=np.float64), np.asarray(apogee_m, dtype=np.float64)
    days = np.empty(perigee_m.size)
    wide = apogee_m - perigee_m > SPREAD_MAX_SPAN_M
    for rows, nodes in ((np.flatnonzero(~wide), PATH_NODES), (np.flatnonzero(wide), WIDE_PATH_NODES)):
        if rows.size:
            days[rows] = _spread_days(
                curves,
                scenario,
                reference_deg,
                log_ratio[rows],
                np.asarray(inclination_deg, dtype=np.float64)[rows],
                perigee_m[rows],
                apogee_m[rows],
                np.asarray(drag_parameter_m2_kg, dtype=np.float64)[rows],
                nodes,
                wide=nodes == WIDE_PATH_NODES,
            )
    return days


def _spread_days(
    curves: UniversalCurves,
    scenario: Scenario,
    reference_deg: float,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    drag_parameter_m2_kg: FloatArray,
    nodes: int,
    *,
    wide: bool,
) -> FloatArray:
    """`spread_lifetime_days` of rows all near-circular or all wide (``wide``), at ``nodes`` steps."""
    point = curves.locate(perigee_m, apogee_m)
    steps = np.linspace(0.0, 1.0, nodes + 1)
    tau = point.tau[:, None] * steps[None, :]
    label = np.broadcast_to(point.label[:, None], tau.shape)
    hp, ha, q = curves.at(label, tau)
    weighted = q * (NU_REF * np.expm1(tau))
    if wide:
        ratio = _life_rate_ratio(curves, log_ratio, inclination_deg, hp, ha, weighted)
    else:
        log_value, log_slope = interpolate_rows_with_slope(log_ratio, FINE_RATIO_GRID_M, hp)
        ratio = np.exp(log_value)
        if scenario.air.depends_on_inclination:
            from orbit_env.decay.density_multiplier import log_density_slope_per_m
            from orbit_env.physics.atmosphere.msis import ALTITUDE_GRID_M, MsisAtmosphere

            atmosphere = curves.model.atmosphere
            assert isinstance(atmosphere, MsisAtmosphere)
            density_slope = np.interp(hp, ALTITUDE_GRID_M, log_density_slope_per_m(atmosphere))
            ratio = orbit_ratio(ratio, log_slope, density_slope, hp, ha)
    if scenario.rotating_atmosphere and not wide:  # the wide rows' rates carry their air's speed
        ratio = ratio * corotation_factor(hp, ha, np.asarray(inclination_deg, dtype=np.float64)[:, None], reference_deg)
    inverse = 1.0 / ratio
    time_gcs = np.sum(np.diff(weighted, axis=1) * 0.5 * (inverse[:, 1:] + inverse[:, :-1]), axis=1)
    return days_from_weighted_s(time_gcs, drag_parameter_m2_kg, scenario.density_scale)


def _life_rate_ratio(
    curves: UniversalCurves,
    log_ratio: FloatArray,
    inclination_deg: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    weighted: FloatArray,
) -> FloatArray:
    """dW/dnu of each row's air over the reference's, at orbits (rows, nodes) on the reference curves.

    `orbit_env.decay.density_multiplier.life_rate_ratio` with `SPREAD_QUADRATURE_POINTS` anomalies,
    in co-rotating air at the row's inclination. One multiplier of the density at the
    perigee (`orbit_ratio`) moves p and e alike, where a profile of another shape moves
    the eccentricity otherwise: on orbits up to 1500 km wide it came out up to 2.3% off
    a family per inclination, this within 0.46% (docs/validation-modern.md, section 7).
    At re-entry (the first node) the next node's ratio.
    """
    ratio = life_rate_ratio(
        curves,
        log_ratio,
        FINE_RATIO_GRID_M,
        perigee_m,
        apogee_m,
        quadrature_points=SPREAD_QUADRATURE_POINTS,
        inclination_deg=inclination_deg,
        weighted=weighted,
    )
    ratio[:, 0] = ratio[:, 1]
    return ratio
