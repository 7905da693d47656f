"""How much more (or less) drag an orbit meets in one air than on the curves of another: the density multiplier.

The universal curves (`orbit_env.decay.curves`) belong to one density profile. An orbit in
another air (another day's Sun, another inclination) stays on those curves and takes the
ratio of the two airs as a multiplier on its drag clock:

- near-circular orbits the ratio weighted over the orbit as drag weights it
  (`orbit_ratio`, King-Hele's first-order average), in co-rotating air times the ratio of
  the air's speed at the perigee (`corotation_factor`);
- wider orbits the ratio of the rates at which the life left on the curves falls
  (`life_rate_ratio`): one multiplier at the perigee would move the perigee and the
  eccentricity alike, where a profile of another shape moves the eccentricity otherwise.

Other inclinations' airs are NRLMSIS at anchor inclinations (`ANCHOR_STEP_DEG`) and a
cubic spline between them (`inclination_anchors`, `inclination_basis`). Both the dated
decay (`orbit_env.decay.chunked.propagate`) and the fixed-air catalogue
(`orbit_env.analysis.inclination_spread`) take every inclination's multiplier from here.
SI units.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.constants import EARTH_RADIUS_M, EARTH_ROTATION_RAD_S
from orbit_env.decay.averaged import DecayModel, kernel_rates
from orbit_env.decay.curves import UniversalCurves
from orbit_env.physics.atmosphere.msis import ALTITUDE_GRID_M, MsisAtmosphere
from orbit_env.physics.orbit import air_speed_at_perigee_m_s, elements_from_heights, heights_from_elements

FloatArray = NDArray[np.float64]


#: Steps of the forward differences of W (the life left on a bin's curves) in p [m] and in e: halved or
#: multiplied by 4, the 120 km wide short lives of docs/validation-modern.md move by at most 0.03%.
GRADIENT_STEP_P_M = 500.0
GRADIENT_STEP_E = 5e-5
#: Widest orbit [m] (apogee - perigee height) of another inclination than the family's that takes the density ratio
#: over the orbit; wider ones the ratio of the life's rates (one multiplier moves the perigee and the eccentricity
#: alike: docs/validation-modern.md, section 7).
SPREAD_MAX_SPAN_M = 100e3
#: Anomalies of those wider orbits' rates (a ratio of two averages on the same nodes; on 10^4 rows 100-1500 km wide,
#: 8 leave up to 0.96% against a family per inclination at 200 km perigees, 12 and 16 0.43%).
SPREAD_QUADRATURE_POINTS = 12
#: Heights [m] at which the ratio of two airs' densities is tabulated (uniform: the rows' tables are read by
#: index), by the dated decay's days and bins and by every inclination's multiplier.
RATIO_GRID_M = np.arange(100e3, 1200e3 + 1.0, 50e3)
#: The finer heights [m] of an inclination's multiplier in a fixed air (`orbit_env.analysis.inclination_spread`),
#: computed once per catalogue. Against a family per inclination group, on 2000 near-circular rows at
#: 250-1000 km over 0-98 deg, its worst lifetime is 0.14% off (0.17% in co-rotating air), on `RATIO_GRID_M` 0.43%;
#: the dated path keeps `RATIO_GRID_M`, where the table is per day and half the heights halve NRLMSIS's cost.
FINE_RATIO_GRID_M = np.arange(100e3, 1200e3 + 1.0, 25e3)
#: Latitude and local-time nodes of the ratio (both profiles sampled alike).
RATIO_NODES = {"latitude_nodes": 6, "local_time_nodes": 6}
#: Inclinations [deg] at which the NRLMSIS density of other inclinations is computed (a spline between).
ANCHOR_STEP_DEG = 10.0
#: Rows of `life_rate_ratio` computed together (its kernels, 3 air speeds x 33 steps x 7 anomalies a
#: row in a co-rotating spread catalogue, stay in the cache instead of fresh pages of 100 MB).
RATE_BLOCK_ROWS = 1000
#: `scaled_bessel_i0_i1`: the trapezoid rule's intervals over the half circle (64 points over the circle), and the
#: argument above which the asymptotic series takes over, with its number of terms.
BESSEL_INTERVALS = 32
BESSEL_SERIES_X = 30.0
BESSEL_SERIES_TERMS = 30


def _asymptotic_coefficients(order: int) -> FloatArray:
    """Coefficients of 1/x^k in sqrt(2 pi x) e^-x I_order(x) ~ sum (-1)^k prod_j (4 n^2 - (2j - 1)^2) / (k! 8^k x^k)."""
    coefficients = [1.0]
    for k in range(1, BESSEL_SERIES_TERMS):
        coefficients.append(-coefficients[-1] * (4.0 * order * order - (2 * k - 1) ** 2) / (8.0 * k))
    return np.array(coefficients)


_BESSEL_COS = np.cos(np.linspace(0.0, np.pi, BESSEL_INTERVALS + 1))
_BESSEL_COS_LESS_1 = _BESSEL_COS - 1.0
_BESSEL_WEIGHTS = np.full(BESSEL_INTERVALS + 1, 1.0 / BESSEL_INTERVALS)
_BESSEL_WEIGHTS[[0, -1]] = 0.5 / BESSEL_INTERVALS
_BESSEL_SERIES = np.stack([_asymptotic_coefficients(0), _asymptotic_coefficients(1)])


def scaled_bessel_i0_i1(x: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """e^-x I0(x) and e^-x I1(x) for x >= 0 (scipy's ``i0e``, ``i1e``), in numpy alone.

    Up to `BESSEL_SERIES_X`, e^-x I_n(x) = (1/pi) Int_0^pi e^(x (cos t - 1)) cos(n t) dt by
    the trapezoid rule, exact for this periodic integrand but for the aliased terms
    I_(64k)(x) / I_0(x) < e^-60 at x = 30; beyond, Hankel's asymptotic series, whose 30th
    term is below 1e-23 there. Both within 1e-15 of scipy's relative to e^-x I0 (the size of
    the orbit average they enter), measured in `tests/decay/test_density_multiplier.py`.
    Here so that a dated lifetime does not import ``scipy.special`` (0.27 s of a new
    process's 0.35 s of compute, measured).
    """
    x = np.asarray(x, dtype=np.float64)
    near = np.minimum(x, BESSEL_SERIES_X)
    integrand = np.exp(np.multiply.outer(near, _BESSEL_COS_LESS_1))
    integrand *= _BESSEL_WEIGHTS
    i0, i1 = integrand.sum(axis=-1), integrand @ _BESSEL_COS
    far = x > BESSEL_SERIES_X
    if np.any(far):
        big = np.maximum(x, BESSEL_SERIES_X)
        inverse = 1.0 / big
        series = [np.polynomial.polynomial.polyval(inverse, c) / np.sqrt(2.0 * np.pi * big) for c in _BESSEL_SERIES]
        i0, i1 = np.where(far, series[0], i0), np.where(far, series[1], i1)
    return np.asarray(i0, dtype=np.float64), np.asarray(i1, dtype=np.float64)


def weight_left_s(curves: UniversalCurves, p_m: FloatArray, e: FloatArray) -> FloatArray:
    """W left (`orbit_env.decay.curves.CurvePoint.weighted_s`) of the orbits (p, e) on ``curves``."""
    return np.asarray(curves.locate(*heights_from_elements(p_m, e)).weighted_s, dtype=np.float64)


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
    hp, ha = np.asarray(perigee_m, dtype=np.float64), np.asarray(apogee_m, dtype=np.float64)
    ae_m = 0.5 * (ha - hp)
    e = ae_m / (2.0 * EARTH_RADIUS_M + hp + ha)
    inverse_h = np.maximum(-np.asarray(log_density_slope_per_m, dtype=np.float64), 0.0)
    x0 = ae_m * inverse_h
    x1 = ae_m * (inverse_h - np.asarray(log_ratio_slope_per_m, dtype=np.float64))

    # e^-x (I0(x) + 2 e I1(x)) at x0 and x1 (one call: a decay's steps pass a few orbits at a time) from the scaled
    # Bessel functions (e^-|x| I(|x|)); x < 0 only for a ratio steeper than the density (not seen in NRLMSIS, kept
    # finite all the same).
    x = np.empty((2, *np.shape(x0 + x1)))  # x0 + x1: their broadcast shape, in one ufunc call
    x[0], x[1] = x0, x1
    ax = np.abs(x)
    i0, i1 = scaled_bessel_i0_i1(ax)
    weight = np.exp(ax - x) * (i0 + 2.0 * e * np.sign(x) * i1)
    return np.asarray(ratio_at_perigee, dtype=np.float64) * weight[1] / weight[0]


def uniform_gradient(table: FloatArray, grid_m: FloatArray) -> FloatArray:
    """The slope along the last axis on the uniform heights ``grid_m``: ``np.gradient``'s arithmetic, bit for bit.

    Central differences inside, one-sided at the ends; in a few numpy calls where ``np.gradient`` takes about
    40 us of checks, which a dated decay's daily steps pay thousands of times.
    """
    dh = float(grid_m[1] - grid_m[0])
    gradient = np.empty_like(table)
    np.subtract(table[..., 2:], table[..., :-2], out=gradient[..., 1:-1])
    gradient[..., 1:-1] /= 2.0 * dh
    gradient[..., 0] = (table[..., 1] - table[..., 0]) / dh
    gradient[..., -1] = (table[..., -1] - table[..., -2]) / dh
    return gradient


def interpolate_rows(table: FloatArray, grid_m: FloatArray, height_m: FloatArray) -> FloatArray:
    """Row k of ``height_m`` (any trailing shape) interpolated linearly in row k of ``table`` (rows, heights).

    ``grid_m`` is uniform (the rows' tables are read by index); heights beyond it take
    its end values, as ``np.interp``. A table of one row serves every row of ``height_m``
    (``np.interp`` itself: a tenth of the cost on the few heights of a decay's daily step).
    """
    if table.shape[0] == 1:
        return np.interp(height_m, grid_m, table[0])
    return interpolate_rows_with_slope(table, grid_m, height_m)[0]


def interpolate_rows_with_slope(
    table: FloatArray, grid_m: FloatArray, height_m: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """`interpolate_rows`, and the slope of the table's cell each height falls in [1/m]."""
    h = np.asarray(height_m, dtype=np.float64)
    dh = float(grid_m[1] - grid_m[0])
    x = np.clip((h - grid_m[0]) / dh, 0.0, grid_m.size - 1.000001)
    cell = x.astype(np.intp)
    rows = 0 if table.shape[0] == 1 else np.arange(table.shape[0]).reshape(-1, *([1] * (h.ndim - 1)))
    low, high = table[rows, cell], table[rows, cell + 1]
    return np.asarray(low + (x - cell) * (high - low), dtype=np.float64), np.asarray((high - low) / dh)


def corotation_factor(
    perigee_m: FloatArray, apogee_m: FloatArray, inclination_deg: ArrayLike, reference_deg: float
) -> FloatArray:
    """Drag in co-rotating air at each orbit's inclination over that at ``reference_deg``, at the perigee.

    ((v_p - Omega r_p cos i) / (v_p - Omega r_p cos i_ref))^2: the air's speed along
    the orbit at the perigee, where near-circular orbits meet most of their drag.
    ``inclination_deg`` broadcasts against the heights.
    """
    own = air_speed_at_perigee_m_s(perigee_m, apogee_m, inclination_deg)
    return np.asarray((own / air_speed_at_perigee_m_s(perigee_m, apogee_m, reference_deg)) ** 2)


def life_rate_ratio(
    curves: UniversalCurves,
    log_ratio: FloatArray,
    grid_m: FloatArray,
    perigee_m: FloatArray,
    apogee_m: FloatArray,
    *,
    quadrature_points: int,
    inclination_deg: FloatArray | None = None,
    weighted: FloatArray | None = None,
) -> FloatArray:
    """dW/dnu under each row's air over the same under the air of ``curves``, at orbits on those curves.

    W is the life left on ``curves`` (times g c; ``weighted``, if known, its value at the
    orbits). Row k's air is the curves' density times exp(``log_ratio[k]``) (on the uniform
    ``grid_m``; a table of one row serves all). The orbit stays on the curves, so what
    must be right is how fast W falls: W_p p' + W_e e' with the averaged equations'
    rates p', e' (``quadrature_points`` anomalies) under the row's air over the same
    under the curves' own; one density multiplier at the perigee (`orbit_ratio`) would
    move p and e alike, where a profile of another shape moves the eccentricity
    otherwise. The gradient of W by forward differences (`GRADIENT_STEP_P_M`,
    `GRADIENT_STEP_E`), towards higher perigees. In co-rotating air with
    ``inclination_deg`` (one per row), the air's speed (Omega r cos i) enters the rates
    nonlinearly but smoothly (Omega r / v < 0.07): rates at cos i = 0 and 1, and each
    row's cos i on the line through them; without, the curves' inclination. Heights
    have shape (rows, ...).
    """
    if np.ndim(perigee_m) and len(perigee_m) > RATE_BLOCK_ROWS:  # blocks of rows: arrays that stay in cache
        return np.concatenate(
            [
                life_rate_ratio(
                    curves,
                    log_ratio if log_ratio.shape[0] == 1 else log_ratio[rows],
                    grid_m,
                    perigee_m[rows],
                    apogee_m[rows],
                    quadrature_points=quadrature_points,
                    inclination_deg=None if inclination_deg is None else inclination_deg[rows],
                    weighted=None if weighted is None else weighted[rows],
                )
                for rows in (slice(k, k + RATE_BLOCK_ROWS) for k in range(0, len(perigee_m), RATE_BLOCK_ROWS))
            ]
        )
    model = curves.model
    reference = model.atmosphere
    p, e = elements_from_heights(perigee_m, apogee_m)
    e = np.maximum(e, 0.0)
    own = _with_quadrature(model, quadrature_points)
    rows_turn = model.rotating_atmosphere and inclination_deg is not None
    # The air's speeds: the curves' own, and for rows at their inclinations cos i = 0 and 1.
    air_rad_s = (own.corotation_rad_s, 0.0, EARTH_ROTATION_RAD_S) if rows_turn else (own.corotation_rad_s,)
    height_m, k_p, k_e = own.drag_kernels_in_air(p, e, air_rad_s)
    rho_ref = reference.density_kg_m3(height_m)
    # Heights (rows, ..., anomalies): each row reads its own table.
    rho_row = rho_ref * np.exp(interpolate_rows(log_ratio, grid_m, height_m))
    dp_ref, de_ref = kernel_rates(k_p[0], k_e[0], rho_ref)
    if rows_turn:  # each row's cos i on the line through the rates at cos i = 0 and 1
        cos_i = np.cos(np.radians(np.asarray(inclination_deg, dtype=np.float64)))
        cos_i = cos_i.reshape(-1, *((1,) * (np.ndim(perigee_m) - 1)))
        (dp_90, dp_0), (de_90, de_0) = kernel_rates(k_p[1:], k_e[1:], rho_row)
        dp_row, de_row = (1.0 - cos_i) * dp_90 + cos_i * dp_0, (1.0 - cos_i) * de_90 + cos_i * de_0
    else:  # the rows' air moves as the curves' (still, or at their inclination)
        dp_row, de_row = kernel_rates(k_p[0], k_e[0], rho_row)
    # W at the orbits (unless given) and at the two steps, in one lookup of all the points.
    points_p = [p + GRADIENT_STEP_P_M, p] + ([p] if weighted is None else [])
    points_e = [e, np.maximum(e - GRADIENT_STEP_E, 0.0)] + ([e] if weighted is None else [])
    w_up, w_down, *w_here = weight_left_s(curves, np.stack(points_p), np.stack(points_e))
    w0 = w_here[0] if w_here else weighted
    w_p = (w_up - w0) / GRADIENT_STEP_P_M
    w_e = (w0 - w_down) / GRADIENT_STEP_E
    return np.asarray((w_p * dp_row + w_e * de_row) / (w_p * dp_ref + w_e * de_ref), dtype=np.float64)


@lru_cache(maxsize=64)
def _with_quadrature(model: DecayModel, quadrature_points: int) -> DecayModel:
    """``model`` on ``quadrature_points`` anomalies, built once (its rule's nodes are kept with it)."""
    return replace(model, quadrature_points=quadrature_points)


def inclination_anchors(inclination_deg: FloatArray, reference_deg: float) -> FloatArray:
    """Every `ANCHOR_STEP_DEG` spanning ``inclination_deg`` and ``reference_deg`` [deg] (one, if they all agree)."""
    low = math.floor(min(float(np.min(inclination_deg)), reference_deg) / ANCHOR_STEP_DEG) * ANCHOR_STEP_DEG
    high = math.ceil(max(float(np.max(inclination_deg)), reference_deg) / ANCHOR_STEP_DEG) * ANCHOR_STEP_DEG
    return np.arange(low, high + 0.5 * ANCHOR_STEP_DEG, ANCHOR_STEP_DEG)


def inclination_basis(anchors_deg: FloatArray, inclination_deg: FloatArray, reference_deg: float) -> FloatArray:
    """B (satellites, anchors): B @ f(anchors) is f(i) - f(reference) of the cubic spline through them.

    The interpolating spline is linear in its data, so its basis, the splines of the
    unit vectors, turns a table at the anchors into values at the inclinations in one
    product. Zero rows at the reference.
    """
    from scipy.interpolate import make_interp_spline  # on use: half a second of start-up

    spline = make_interp_spline(anchors_deg, np.eye(anchors_deg.size), k=min(3, anchors_deg.size - 1), axis=0)
    at = np.asarray(spline(np.asarray(inclination_deg, dtype=np.float64)), dtype=np.float64)
    return at - np.asarray(spline(reference_deg), dtype=np.float64)[None, :]
