"""The paper's universal curves: every decay on one precomputed family, SI units.

Section 3 of the paper: the averaged equations, written per unit of
nu = N g c s (Eq. 4.1), contain no satellite parameter, so all decays follow one
one-parameter family of curves in the (perigee, apogee) plane with nu along them
(the paper's Fig. 2). This module integrates that family once per decay model and
turns it into two regular tables, so that for any number of satellites

* the remaining lifetime of an orbit (``locate``), and
* the orbit after K more revolutions (``advance``)

are O(1) bilinear interpolations, vectorized over arrays.

Coordinates. A curve is labelled by mu = ln(e) at re-entry (perigee 100 km): the
label of the orbit whose decay it is. Along a curve the coordinate is
tau = ln(1 + nu / NU_REF), with nu the universal lifetime left: linear in nu
close to re-entry, logarithmic above. For nearly circular orbits the averaged
equations are linear in e, so there the curves are translates of each other in
ln(e) and carry the same nu: the tables store ln(e) - mu, which is exact for
any e below the lowest tabulated curve (circular orbits included).

* Table A, over (perigee height, ln e): mu - ln e and tau.
* Table B, over (mu, tau): perigee height, ln e - mu, and the mean period q = W/nu.

W = Int P dnu (P the Keplerian period) gives time: t = W / (g c s). Every method
takes q from table B: a simulator that locates an orbit, coasts it and locates it
again after a burn then sees one function W along each curve, so a step's time
(a drop of W) never carries the difference of two tables' interpolation errors.

Accuracy: against the averaged ODE solved with DOP853 at rtol 1e-9 the lifetime
from the curves differs by at most 0.5% for lifetimes nu >= 0.1 (Table II's
smallest cell) over the domain (``tests/decay/test_curves.py`` measures it on random
orbits; measured maximum 0.06% on 300 random orbits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env import cache
from orbit_env.checks import check_array
from orbit_env.constants import EARTH_RADIUS_M, G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.averaged import DecayModel
from orbit_env.physics.orbit import elements_from_heights, period_s, validate_heights, validate_heights_km
from orbit_env.workers import in_two_processes

FloatArray = NDArray[np.float64]

#: Newton steps of `UniversalCurves.locate_exactly` (bilinear cells: 2-3 from table A's point).
LOCATE_NEWTON_STEPS = 4
#: Lookups of W in `UniversalCurves.move_to_weight` at most (its first iterate, then three Newton steps).
WEIGHT_LOOKUPS = 4

#: Highest perigee height the curves cover [m].
CURVES_MAX_PERIGEE_M = 1100e3
#: Highest apogee height the curves cover [m].
CURVES_MAX_APOGEE_M = 4000e3
#: nu at which tau = ln(1 + nu / NU_REF) turns from linear to logarithmic.
NU_REF = 1e-3
#: Smallest eccentricity resolved; below it an orbit is treated as circular
#: (the difference in lifetime is below 1e-9 relative).
E_FLOOR = 1e-14

# The curves run past the domain so that the cells at its edges are valid.
_HP_TOP_M = CURVES_MAX_PERIGEE_M + 40e3
# Table A's rows stop at _HP_TOP_M, the curves run on to here: a row's last crossing is where the last curve
# that reaches its eccentricity meets it, and near the top adjacent curves meet a row some 40 km apart, so
# curves stopped at _HP_TOP_M left rows without a crossing above 1095 km (their values held from below, and
# lifetimes at 1095-1100 km perigee half what they are).
_HP_INTEGRATE_TOP_M = _HP_TOP_M + 150e3
_HA_TOP_M = 1.25 * CURVES_MAX_APOGEE_M
_DH_M = 2e3  # perigee-height step of table A
_TAU_TOP = 27.0  # nu up to 5e8, beyond any orbit in the domain
# The lowest curve stays nearly circular (e < 2e-4) up to the top of the domain,
# where the averaged equations are linear in e and lower curves are its translates.
_LOWEST_LABEL = float(np.log(1e-9))
_LABEL_SPACING = 0.1
_DY = 0.05  # ln(e) spacing of table A
_DTAU = 0.1  # tau step of the RK4 integration and of table B


def _eccentricity(perigee_m: FloatArray, apogee_m: FloatArray) -> FloatArray:
    """The eccentricity from perigee and apogee heights: plain arithmetic, for floats or arrays."""
    rp, ra = EARTH_RADIUS_M + perigee_m, EARTH_RADIUS_M + apogee_m
    return (ra - rp) / (ra + rp)


class GridScales(NamedTuple):
    """Where a point (x, y) falls on a `BilinearGrid`: the cell coordinates fx = x x_scale - x_offset and fy.

    ``ny`` is the grid's size in y (a cell's row in ``cells`` is i ny + j), ``x_top`` and ``y_top``
    the largest cell coordinates, where the clamps stop. Floats, so that the compiled loops of
    `orbit_env.envs.kernel` read them as one float64 array (``np.array(scales)``).
    """

    ny: float
    x_scale: float
    x_offset: float
    y_scale: float
    y_offset: float
    x_top: float
    y_top: float


def grid_cell(
    x: float,
    y: float,
    ny: float,
    x_scale: float,
    x_offset: float,
    y_scale: float,
    y_offset: float,
    x_top: float,
    y_top: float,
) -> tuple[int, float, int, float]:
    """One point's cell of a grid (clamped to it): its row in the cells, tx, the y index j, ty.

    The arguments after (x, y) are a `GridScales`, in its order (``grid_cell(x, y, *scales)``).
    Plain floats and no numpy, so that it is both the single environment's lookup
    (`BilinearGrid.values_scalar`, `BilinearGrid.segment_scalar`) and, compiled by numba,
    the vector environment's (`orbit_env.envs.kernel`): one definition of where a point
    falls. The same operations in the same order as `BilinearGrid`'s array path.
    """
    fx = min(max(x * x_scale - x_offset, 0.0), x_top)
    fy = y * y_scale
    if y_offset != 0.0:
        fy -= y_offset
    fy = min(max(fy, 0.0), y_top)
    i = int(fx)
    j = int(fy)
    return i * int(ny) + j, fx - i, j, fy - j


def _coefficients(f00: FloatArray, f10: FloatArray, f01: FloatArray, f11: FloatArray, out: FloatArray) -> None:
    """A bilinear cell's coefficients from its corners into ``out[..., 0:4]`` (`BilinearGrid.cells`)."""
    out[..., 0] = f00
    np.subtract(f10, f00, out=out[..., 1])
    np.subtract(f01, f00, out=out[..., 2])
    np.subtract(f11, f10, out=out[..., 3])
    out[..., 3] -= f01
    out[..., 3] += f00


#: Lookups of a `BilinearGrid` from its corners before it builds its cells: a lookup from the cells saves about
#: 9 us (12-15 us against 20-23 us, on 1-30 points), building them costs 2.2 ms (the curves' table B) to 7.5 ms
#: (table A), measured 2026-12-05. A threshold per grid at its break-even (about 280 and 720 lookups) was tried
#: and made repeated eccentric decays in one process slower (15.5 ms a life against 13.7 ms with the cells built).
CORNER_LOOKUPS = 200
#: Points up to which `BilinearGrid.values` looks each up in plain floats: 3.5 us for one against 13 us by the
#: array path, 10 against 11.5 for four, 14 against 12 for six (measured 2026-12-05).
SCALAR_POINTS = 4


def padded_corners(tables: FloatArray) -> FloatArray:
    """Tables (k, nx, ny) at every grid point, edges repeated once, as `BilinearGrid` reads them: (nx+1, ny+1, k)."""
    return np.ascontiguousarray(np.pad(tables, ((0, 0), (0, 1), (0, 1)), mode="edge").transpose(1, 2, 0))


class BilinearGrid:
    """Bilinear interpolation of a stack of tables (k, nx, ny) on a regular grid, clamped at its edges.

    Each cell stores the four coefficients of its bilinear form,
    f = c0 + c1 tx + c2 ty + c3 tx ty, for every table, side by side: one gather
    (``take`` of a row of 4k numbers) finds everything a query needs. On a batch of
    orbits that is ten numpy calls fewer per table than gathering the four
    corners table by table, which is what counts on the small batches of a
    vector environment's burning satellites (their cost is numpy's per-call
    overhead, not arithmetic). ``values`` and ``values_scalar`` do the same
    operations in the same order, so they give the same results, bit for bit.

    The cells (four times the tables' size) are built the first time something asks for
    them, or after `CORNER_LOOKUPS` lookups; until then ``values`` (and the scalar lookups)
    takes each point's four corners from the tables and forms the same coefficients by the
    same operations, so the results are the same bit for bit either way. A decay under the
    real Sun visits tens of bins' curves for a few lookups each, where building the cells
    would be most of its time; the uncertainty's samples look a bin up thousands of times,
    where the cells pay.
    """

    def __init__(
        self,
        tables: FloatArray | None,
        x0: float,
        dx: float,
        y0: float,
        dy: float,
        *,
        corners: FloatArray | None = None,
    ) -> None:
        """``corners``: the tables' `padded_corners` made before (the disk cache keeps them), ``tables`` then None."""
        if corners is None:
            assert tables is not None, "a grid needs its tables or their corners"
            corners = padded_corners(tables)
        #: The tables at every grid point, edges repeated once, shape (nx + 1, ny + 1, k).
        self.corners = np.ascontiguousarray(corners)
        nx, ny, k = corners.shape[0] - 1, corners.shape[1] - 1, corners.shape[2]
        self.k, self.nx, self.ny = k, nx, ny
        self._corner_lookups = 0
        self.x_scale, self.x_offset = 1.0 / dx, x0 / dx
        self.y_scale, self.y_offset = 1.0 / dy, y0 / dy
        self.x_top, self.y_top = nx - 1.000001, ny - 1.000001
        #: Where a point falls (`grid_cell`), as one tuple.
        self.scales = GridScales(
            ny=float(ny),
            x_scale=self.x_scale,
            x_offset=self.x_offset,
            y_scale=self.y_scale,
            y_offset=self.y_offset,
            x_top=self.x_top,
            y_top=self.y_top,
        )

    @cached_property
    def cells(self) -> FloatArray:
        """Each cell's bilinear coefficients of every table, shape (nx ny, k, 4); built on first use.

        c0 = f00, c1 = f10 - f00, c2 = f01 - f00, c3 = f11 - f10 - f01 + f00 (corners f_ij).
        """
        padded = self.corners
        f00, f10 = padded[:-1, :-1], padded[1:, :-1]
        f01, f11 = padded[:-1, 1:], padded[1:, 1:]
        cells = np.empty((self.nx, self.ny, self.k, 4))
        _coefficients(f00, f10, f01, f11, cells)
        return cells.reshape(self.nx * self.ny, self.k, 4)

    def _cells(self, x: ArrayLike, y: ArrayLike) -> tuple[FloatArray, FloatArray, NDArray[np.intp], FloatArray]:
        """Each point's cell (clamped to the grid): its coefficients (..., k, 4), tx, the y index j, ty."""
        fx = np.asarray(np.multiply(x, self.x_scale))  # an array even for 0-d input (the in-place clamps)
        fx -= self.x_offset
        np.maximum(fx, 0.0, out=fx)
        np.minimum(fx, self.x_top, out=fx)
        fy = np.asarray(np.multiply(y, self.y_scale))
        if self.y_offset:
            fy -= self.y_offset
        np.maximum(fy, 0.0, out=fy)
        np.minimum(fy, self.y_top, out=fy)
        i = fx.astype(np.intp)
        tx = fx - i
        j = fy.astype(np.intp)
        ty = fy - j
        self._corner_lookups += 1
        if "cells" in self.__dict__ or self._corner_lookups > CORNER_LOOKUPS:
            i *= self.ny
            cell = self.cells.take(i + j, axis=0)
            return cell, tx, j, ty
        # The cells not built: the four corners (the same coefficients, by the same operations).
        corners = self.corners.reshape(-1, self.k)
        row = i * (self.ny + 1) + j  # x and y broadcast against each other
        f00, f01 = corners.take(row, axis=0), corners.take(row + 1, axis=0)
        row += self.ny + 1
        f10, f11 = corners.take(row, axis=0), corners.take(row + 1, axis=0)
        cell = np.empty((*f00.shape, 4))
        _coefficients(f00, f10, f01, f11, cell)
        return cell, tx, j, ty

    def values(self, x: ArrayLike, y: ArrayLike) -> list[FloatArray]:
        """The k tables at the points (x, y) (arrays that broadcast against each other).

        Up to `SCALAR_POINTS` points of float64 arrays of one shape go through `values_scalar`
        one by one (the same floats): a decay's last days look up one to three orbits at a time,
        where the array path's fixed cost is four times the scalar lookup's.
        """
        x_array, y_array = np.asarray(x), np.asarray(y)
        if (
            0 < x_array.size <= SCALAR_POINTS
            and x_array.shape == y_array.shape
            and x_array.dtype == y_array.dtype == np.float64
        ):
            points = zip(x_array.ravel().tolist(), y_array.ravel().tolist(), strict=True)
            rows = [self.values_scalar(u, v) for u, v in points]
            table = np.array(rows).T
            return [table[m].reshape(x_array.shape) for m in range(self.k)]
        cell, tx, _, ty = self._cells(x, y)
        txy = tx * ty
        # Every table in each operation (the last axis): the calls of one table, not of k.
        tx, ty, txy = tx[..., None], ty[..., None], txy[..., None]
        value = cell[..., 1] * tx
        value += cell[..., 0]
        term = cell[..., 2] * ty
        value += term
        term = cell[..., 3] * txy
        value += term
        return [value[..., m] for m in range(self.k)]

    def segments(self, x: FloatArray, y: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Per point, the y cell it lies in and, per table, the line the interpolant follows across it at x.

        At a fixed x the bilinear form is linear in y within a cell:
        f = (c0 + c1 tx) + (c2 + c3 tx) ty. Returns a (1 + 2k, n) array: the cell
        index j (as a float), then the k bases c0 + c1 tx, then the k slopes
        c2 + c3 tx; and ty, where y is in its cell. `along` evaluates them.
        """
        cell, tx, j, ty = self._cells(x, y)
        assert tx.ndim == 1, "segments of a 1-d array of points"
        k = self.k
        out = np.empty((1 + 2 * k, tx.size))
        out[0] = j
        bases, slopes = out[1 : 1 + k], out[1 + k :]
        cell = cell.transpose(1, 2, 0)  # (k, 4, n): every table in each operation
        np.multiply(cell[:, 1], tx, out=bases)
        bases += cell[:, 0]
        np.multiply(cell[:, 3], tx, out=slopes)
        slopes += cell[:, 2]
        return out, ty

    def along(self, segments: FloatArray, ty: FloatArray) -> list[FloatArray]:
        """The k tables at ``ty`` of the way across each point's cell (see `segments`)."""
        values = segments[1 + self.k :] * ty  # every table in one operation: (k, n)
        values += segments[1 : 1 + self.k]
        return list(values)

    def on_segments(self, segments: FloatArray, x: FloatArray, y: FloatArray) -> list[FloatArray]:
        """`values` at (x, y) for points whose x has not changed since ``segments`` was made.

        Points whose y has left its cell get a fresh segment, written into
        ``segments`` in place. Equal to `values` up to round-off (the same
        bilinear form, its terms grouped differently).
        """
        fy = np.asarray(np.multiply(y, self.y_scale))
        if self.y_offset:
            fy -= self.y_offset
        # No clamps: a y beyond the grid is outside its cell, and `segments` clamps it.
        ty = fy - segments[0]
        moved = np.flatnonzero((ty < 0.0) | (ty > 1.0))
        if moved.size:
            segments[:, moved], ty[moved] = self.segments(x[moved], y[moved])
        return self.along(segments, ty)

    def values_scalar(self, x: float, y: float) -> list[float]:
        """`values` for one point, in plain floats.

        The single environment steps one orbit at a time, where numpy's per-call
        cost on 0-d arrays is ten times the arithmetic.
        """
        row, tx, _, ty = grid_cell(x, y, *self.scales)
        txy = tx * ty
        return [c1 * tx + c0 + c2 * ty + c3 * txy for c0, c1, c2, c3 in self._cell_scalar(row)]

    def _cell_scalar(self, row: int) -> list[list[float]]:
        """The coefficients of cell ``row``, per table, as Python floats (`cells`' row, or formed from its corners).

        From the corners while the cells are not built (`CORNER_LOOKUPS`), by `_coefficients`' operations in its
        order: the same floats. A lifetime on one set of curves looks them up a few times, where building the
        cells took 14 ms of a 0.23 s command.
        """
        self._corner_lookups += 1
        if "cells" in self.__dict__ or self._corner_lookups > CORNER_LOOKUPS:
            # As Python floats in one call (item() per number costs four times more).
            return self.cells[row].tolist()
        i, j = divmod(row, self.ny)
        f00, f01 = self.corners[i, j : j + 2].tolist()
        f10, f11 = self.corners[i + 1, j : j + 2].tolist()
        return [[a, b - a, c - a, d - b - c + a] for a, b, c, d in zip(f00, f10, f01, f11, strict=True)]

    def segment_scalar(self, x: float, y: float) -> tuple[list[float], float]:
        """`segments` for one point, in plain floats: the list [j, bases..., slopes...], and ty.

        The same operations in the same order as `segments`, so the single
        environment's orbit follows the same lines as a vector environment's, bit for bit.
        """
        row, tx, j, ty = grid_cell(x, y, *self.scales)
        cell = self._cell_scalar(row)
        bases = [c1 * tx + c0 for c0, c1, _, _ in cell]
        slopes = [c3 * tx + c2 for _, _, c2, c3 in cell]
        return [float(j), *bases, *slopes], ty

    def on_segment_scalar(self, segment: list[float], x: float, y: float) -> float:
        """`on_segments` for one point: how far across its cell ``y`` is, ty.

        ``segment`` (from `segment_scalar`) is renewed in place if ``y`` has left
        its cell; the values are then ``slope * ty + base`` (`_heights_along`).
        """
        fy = y * self.y_scale
        if self.y_offset:
            fy -= self.y_offset
        ty = fy - segment[0]
        if not 0.0 <= ty <= 1.0:  # left its cell (or a stale segment, j = -inf)
            segment[:], ty = self.segment_scalar(x, y)
        return ty


def _spline_rows(x: FloatArray, y: FloatArray, counts: NDArray[np.intp], query: FloatArray) -> FloatArray:
    """Cubic splines through the knots of each row, at the query points: scipy's ``CubicSpline`` in numpy.

    The spline of each row is scipy's default, not-a-knot at both ends, built the
    same way (first derivatives at the knots from one tridiagonal system, then the
    Hermite cubic of each interval), so it agrees with ``CubicSpline`` to round-off
    (``tests/decay/test_curves.py`` compares them). The rows' systems are solved together
    by the Thomas algorithm, a sweep over the knots vectorized over the rows: its
    pivots stay nonzero for not-a-knot ends on increasing knots, where scipy's
    banded solver pivots. Importing scipy.interpolate alone costs longer than the
    whole table.

    Args:
        x: Knots (rows, n): each row's first ``counts`` entries, increasing (the rest ignored).
        y: Values at the knots (k, rows, n): k functions per row.
        counts: Knots per row, each at least 4.
        query: Points (m,), clamped to each row's first and last knot.

    Returns:
        The splines at the query points (k, rows, m).
    """
    rows, size = x.shape
    assert np.all(counts >= 4) and np.all(counts <= size), "a not-a-knot cubic needs four knots"
    r = np.arange(rows)
    last = np.asarray(counts) - 1
    beyond = np.arange(size)[None, :] > last[:, None]
    # Past a row's last knot: knots 1 m apart and the last value repeated, finite and ignored.
    x = np.where(beyond, x[r, last][:, None] + (np.arange(size)[None, :] - last[:, None]), x)
    y = np.where(beyond[None], y[:, r, last][..., None], y)
    dx = np.diff(x, axis=-1)
    slope = np.diff(y, axis=-1) / dx
    lower, diag, upper = np.zeros((rows, size)), np.ones((rows, size)), np.zeros((rows, size))
    rhs = np.zeros(y.shape)
    # Inside: continuity of the second derivative (scipy's rows i = 1 .. n-2).
    lower[:, 1:-1], diag[:, 1:-1], upper[:, 1:-1] = dx[:, 1:], 2.0 * (dx[:, :-1] + dx[:, 1:]), dx[:, :-1]
    rhs[..., 1:-1] = 3.0 * (dx[:, 1:] * slope[..., :-1] + dx[:, :-1] * slope[..., 1:])
    # Not-a-knot at the first knot ...
    d = x[:, 2] - x[:, 0]
    diag[:, 0], upper[:, 0] = dx[:, 1], d
    rhs[..., 0] = ((dx[:, 0] + 2.0 * d) * dx[:, 1] * slope[..., 0] + dx[:, 0] ** 2 * slope[..., 1]) / d
    # ... and at the last, with the rows past it an identity that the sweep leaves at zero.
    d = x[r, last] - x[r, last - 2]
    lower[r, last], diag[r, last], upper[r, last] = d, dx[r, last - 2], 0.0
    dx_end, dx_before = dx[r, last - 1], dx[r, last - 2]
    rhs[:, r, last] = (dx_end**2 * slope[:, r, last - 2] + (2.0 * d + dx_end) * dx_before * slope[:, r, last - 1]) / d
    lower[beyond], diag[beyond], upper[beyond] = 0.0, 1.0, 0.0
    rhs[:, beyond] = 0.0
    # Thomas algorithm, knot after knot (columns made rows: contiguous slices).
    lower, diag, upper, rhs = lower.T.copy(), diag.T.copy(), upper.T.copy(), rhs.transpose(2, 0, 1).copy()
    for i in range(1, size):
        w = lower[i] / diag[i - 1]
        diag[i] -= w * upper[i - 1]
        rhs[i] -= w * rhs[i - 1]
    s = np.empty_like(rhs)
    s[-1] = rhs[-1] / diag[-1]
    for i in range(size - 2, -1, -1):
        s[i] = (rhs[i] - upper[i] * s[i + 1]) / diag[i]
    s = s.transpose(1, 2, 0)  # (k, rows, n): the first derivative at each knot
    # The Hermite cubic on each interval, in powers of the distance from its left knot (scipy's PPoly).
    t = (s[..., :-1] + s[..., 1:] - 2.0 * slope) / dx
    c3, c2, c1, c0 = t / dx, (slope - s[..., :-1]) / dx - t, s[..., :-1], y[..., :-1]
    interval = np.empty((rows, query.size), dtype=np.intp)
    for row in range(rows):
        interval[row] = np.searchsorted(x[row, : last[row] + 1], query, side="right")
    interval -= 1
    np.clip(interval, 0, (last - 1)[:, None], out=interval)  # the first and last interval extrapolate
    z = np.clip(query[None, :], x[:, :1], x[r, last][:, None]) - np.take_along_axis(x, interval, axis=1)
    out = np.empty((y.shape[0], rows, query.size))
    for m in range(y.shape[0]):
        value = np.take_along_axis(c0[m], interval, axis=1)
        power = z.copy()
        for c in (c1, c2, c3):
            value += np.take_along_axis(c[m], interval, axis=1) * power
            power *= z
        out[m] = value
    return out


def _heights(mu: FloatArray, b0: FloatArray, b1: FloatArray, q: FloatArray) -> tuple[FloatArray, ...]:
    """Table B's values (perigee height, ln e - mu, q) at labels mu into perigee and apogee heights [m] and q."""
    hp = np.maximum(b0, REENTRY_ALTITUDE_M)
    one_minus_e = np.asarray(b1 + mu)  # an array even for 0-d input (in-place below)
    np.exp(one_minus_e, out=one_minus_e)
    np.subtract(1.0, one_minus_e, out=one_minus_e)
    rp = hp + EARTH_RADIUS_M
    # ra = rp (1 + e) / (1 - e) = 2 rp / (1 - e) - rp, in place (a batch costs numpy calls and allocations)
    apogee = rp + rp
    apogee /= one_minus_e
    apogee -= rp
    apogee -= EARTH_RADIUS_M
    return hp, apogee, q


def _heights_scalar(mu: float, b0: float, b1: float, q: float) -> tuple[float, float, float]:
    """`_heights` for one orbit, in plain floats: the same operations in the same order."""
    hp = max(b0, REENTRY_ALTITUDE_M)
    one_minus_e = 1.0 - math.exp(b1 + mu)
    rp = hp + EARTH_RADIUS_M
    return hp, (rp + rp) / one_minus_e - rp - EARTH_RADIUS_M, q


def _heights_along(mu: float, segment: list[float], ty: float) -> tuple[float, float, float]:
    """`_heights` of table B's values at ``ty`` across one orbit's kept cell (`BilinearGrid.segment_scalar`).

    The arithmetic of ``_heights(mu, *BilinearGrid.along(...))``, unrolled for table B's three values.
    """
    _, hp_base, y_base, q_base, hp_slope, y_slope, q_slope = segment
    hp = max(hp_slope * ty + hp_base, REENTRY_ALTITUDE_M)
    one_minus_e = 1.0 - math.exp(y_slope * ty + y_base + mu)
    rp = hp + EARTH_RADIUS_M
    return hp, (rp + rp) / one_minus_e - rp - EARTH_RADIUS_M, q_slope * ty + q_base


@dataclass(frozen=True)
class CurvePoint:
    """Orbits located on the universal curves (arrays of the query's shape).

    Attributes:
        label: mu = ln(e) at re-entry, the curve the orbit decays along.
        tau: ln(1 + nu / NU_REF), position along the curve.
        mean_period_s: W / nu, the mean period over the rest of the decay [s].
    """

    label: FloatArray
    tau: FloatArray
    mean_period_s: FloatArray

    @cached_property
    def nu(self) -> FloatArray:
        """Universal lifetime left, nu [m^3/(kg s^2)]."""
        if isinstance(self.tau, float):
            return NU_REF * math.expm1(self.tau)
        return NU_REF * np.expm1(self.tau)

    @cached_property
    def weighted_s(self) -> FloatArray:
        """W = Int P dnu left [s m^3/(kg s^2)]; the time left is W / (g c s)."""
        return self.mean_period_s * self.nu

    @classmethod
    def with_nu(cls, label: FloatArray, tau: FloatArray, mean_period_s: FloatArray, nu: FloatArray) -> CurvePoint:
        """A point whose nu is known (tau was computed from it): nu is not recomputed from tau.

        Made without the frozen dataclass's checked ``__init__``: the environments' hot path.
        """
        point = object.__new__(cls)
        point.__dict__.update(label=label, tau=tau, mean_period_s=mean_period_s, nu=nu)
        return point


def _check_curve_limits(hp: FloatArray, ha: FloatArray, names: tuple[str, str], unit: str, unit_m: float) -> None:
    for name, values, limit in ((names[0], hp, CURVES_MAX_PERIGEE_M), (names[1], ha, CURVES_MAX_APOGEE_M)):
        check_array(
            values,
            name,
            unit=unit,
            high=limit / unit_m,
            why="the universal curves end there; the averaged ODE goes higher",
        )


class UniversalCurves:
    """The family of decay curves of one `DecayModel`, as lookup tables.

    Build it with `universal_curves` (cached per model). All methods take and
    return SI arrays and broadcast.

    The curves are integrated backward from re-entry, one every 0.1 in the label
    mu = ln(e at re-entry), from e = 1e-9 (circular to the top of the domain) to
    the orbit with a 5000 km apogee at re-entry.

    Python floats in, Python floats out: for ``float`` arguments ``locate``, ``at``
    and ``advance`` take a scalar path with the same arithmetic as the array path
    (results equal to 1e-12 relative; only ``math`` versus numpy ``exp``/``log``
    may differ in the last bit). It exists for the single environment, which
    steps one orbit at a time.

    Attributes:
        model: The decay model the curves are of.
        labels: The curves' labels mu, one every 0.1.
        table_a: Over (perigee height [m], ln e): mu - ln e and tau (`BilinearGrid`).
        table_b: Over (mu, tau): perigee height [m], ln e - mu and the mean period q [s]; the
            compiled loops of `orbit_env.envs.kernel` read its cells and those of table A.
    """

    def __init__(self, model: DecayModel) -> None:
        self.model = model
        self.labels = np.arange(_LOWEST_LABEL, np.log(_eccentricity(REENTRY_ALTITUDE_M, _HA_TOP_M)), _LABEL_SPACING)
        # Half a second to integrate: kept on disk per model (orbit_env.cache).
        description = cache.describe(model)
        corners = cache.load("curves", description, mapped=True)
        if corners is None or sorted(corners) != ["a", "b", "q"]:
            tables = self._build()
            corners = {"a": tables["a"], "b": tables["b"], "q": tables["b"][2:]}  # q: the mean period alone
            corners = {name: padded_corners(table) for name, table in corners.items()}
            # The grids' corners as they are read (no padding on loading), uncompressed (5 MB instead of 3), mapped
            # rather than read: a dated decay visits tens of bins' curves for a few lookups each.
            cache.store("curves", description, corners, mapped=True)
        label0 = float(self.labels[0])
        self.table_a = BilinearGrid(None, REENTRY_ALTITUDE_M, _DH_M, label0, _DY, corners=corners["a"])
        self.table_b = BilinearGrid(None, label0, _LABEL_SPACING, 0.0, _DTAU, corners=corners["b"])
        self._table_q = BilinearGrid(None, label0, _LABEL_SPACING, 0.0, _DTAU, corners=corners["q"])

    def _build(self) -> dict[str, FloatArray]:
        """Integrate the family and make its two tables: A (orbit -> curve, place) and B (curve, place -> orbit)."""
        tau = np.arange(0.0, _TAU_TOP + _DTAU, _DTAU)
        hp, y, weighted = self._integrate(tau, self.labels)
        nu = NU_REF * np.expm1(tau)
        with np.errstate(invalid="ignore", divide="ignore"):
            q = weighted / nu
        # At re-entry W/nu is the period itself.
        e_end = np.exp(self.labels)
        q[:, 0] = period_s((REENTRY_ALTITUDE_M + EARTH_RADIUS_M) * (1 + e_end), e_end)
        # Table B (and every height it gives) keeps to the domain and its margin; only table A's rows
        # need the curves beyond (`_HP_INTEGRATE_TOP_M`).
        inside = hp <= _HP_TOP_M
        hp_b, y_b, q_b = (np.where(inside, values, np.nan) for values in (hp, y, q))
        return {"a": self._build_table_a(hp, y, tau, np.nanmax(y_b)), "b": self._build_table_b(hp_b, y_b, q_b)}

    def _slope(self, hp: FloatArray, y: FloatArray, dnu_dtau: float | FloatArray) -> FloatArray:
        """d/dtau of perigee height, ln(e) and W, backward from re-entry, one curve each."""
        e = np.exp(y)
        p = (EARTH_RADIUS_M + hp) * (1.0 + e)
        dp_dnu, de_dnu = self.model.rates_per_nu(p, e)
        dhp_dnu = (dp_dnu * (1.0 + e) - p * de_dnu) / (1.0 + e) ** 2
        assert np.all(dhp_dnu < 0.0), "perigee height must fall monotonically under drag"
        return np.stack([-dhp_dnu, -de_dnu / e, period_s(p, e)]) * dnu_dtau

    def _integrate(self, tau: FloatArray, labels: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """RK4 in tau, backward from re-entry, all curves at once (half of them in a forked process, if it may).

        tau, not the perigee height, is the variable: elongated orbits lose apogee
        at an almost constant perigee, where the curves stand nearly vertical.
        Returns perigee height, ln(e) and W on the tau grid, NaN once a curve has
        left the domain. Each curve's steps are its own (numpy's element-wise operations
        and a sum over each orbit's anomalies), so the curves integrated in two groups
        are the curves integrated together, bit for bit; every other curve goes to each
        group, as the eccentric ones leave the domain sooner (each half takes 0.6 of the whole's time).
        """
        # The model's air tables built here, once, before the fork (else each process would build them).
        self.model.rates_per_nu(np.array([EARTH_RADIUS_M + REENTRY_ALTITUDE_M]), np.array([0.0]))
        order = np.concatenate([np.arange(0, labels.size, 2), np.arange(1, labels.size, 2)])

        def part(curves: slice) -> FloatArray:
            return np.stack(self._integrate_curves(tau, labels[order[curves]]), axis=1)

        together = in_two_processes(part, labels.size, row_shape=(3, tau.size), min_size=2)
        out = np.empty_like(together)
        out[order] = together
        return out[:, 0], out[:, 1], out[:, 2]

    def _integrate_curves(self, tau: FloatArray, labels: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """`_integrate` of the curves ``labels``, in this process."""
        n_curves = labels.size
        out = np.full((3, n_curves, tau.size), np.nan)
        state = np.stack([np.full(n_curves, REENTRY_ALTITUDE_M), labels, np.zeros(n_curves)])
        out[:, :, 0] = state
        active = np.arange(n_curves)
        h = _DTAU
        for index in range(1, tau.size):
            t = tau[index - 1]
            s = state[:, active]
            # nu = NU_REF (e^tau - 1), so dnu/dtau = NU_REF e^tau.
            d0, d1, d2 = (NU_REF * np.exp(t + x) for x in (0.0, h / 2, h))
            k1 = self._slope(s[0], s[1], d0)
            k2 = self._slope(s[0] + h / 2 * k1[0], s[1] + h / 2 * k1[1], d1)
            k3 = self._slope(s[0] + h / 2 * k2[0], s[1] + h / 2 * k2[1], d1)
            k4 = self._slope(s[0] + h * k3[0], s[1] + h * k3[1], d2)
            s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            e = np.exp(s[1])
            apogee = (EARTH_RADIUS_M + s[0]) * (1 + e) / (1 - e) - EARTH_RADIUS_M
            keep = np.isfinite(s).all(axis=0) & (e < 0.5) & (apogee <= _HA_TOP_M) & (s[0] <= _HP_INTEGRATE_TOP_M)
            active = active[keep]
            state[:, active] = s[:, keep]
            out[:, active, index] = s[:, keep]
            if active.size == 0:
                break
        return out[0], out[1], out[2]

    def _build_table_a(self, hp: FloatArray, y: FloatArray, tau: FloatArray, y_top: float) -> FloatArray:
        """Rows of constant ln(e) up to ``y_top``, inverted from the curves to perigee height.

        Under drag e falls monotonically, so every curve crosses a row once, and
        a row meets the curves in order of their labels (they never cross). Rows,
        not columns: elongated orbits decay at an almost constant perigee, so the
        curves stand nearly vertical in (perigee, ln e) and cross rows cleanly.
        Along a row the values are smooth in perigee height: a cubic spline
        through the crossings (`_spline_rows`, all rows at once). Beyond the lowest
        curve (more nearly circular orbits) the curves are translates of it: its
        values at the same height.
        """
        labels = self.labels
        y_grid = np.arange(labels[0], y_top, _DY)
        hp_grid = np.arange(REENTRY_ALTITUDE_M, _HP_TOP_M, _DH_M)
        crossing = np.full((2, labels.size, y_grid.size), np.nan)
        for j in range(labels.size):
            valid = np.isfinite(hp[j])
            for row, values in enumerate((hp[j], tau)):
                crossing[row, j] = np.interp(y_grid, y[j, valid], values[valid], left=np.nan, right=np.nan)
        lowest = np.isfinite(hp[0])
        beyond = np.stack([np.interp(hp_grid, hp[0, lowest], v[lowest]) for v in (labels[0] - y[0], tau)])
        # Per row, the crossings in order of falling label (rising perigee), packed to the left.
        valid = np.isfinite(crossing[0]).T[:, ::-1]
        order = np.argsort(~valid, axis=1, kind="stable")
        counts = valid.sum(axis=1)
        knots = np.take_along_axis(crossing[0].T[:, ::-1], order, axis=1)
        values = np.stack([labels[None, ::-1] - y_grid[:, None], crossing[1].T[:, ::-1]])
        values = np.take_along_axis(values, order[None], axis=2)
        packed = np.arange(labels.size) < counts[:, None]
        assert np.all(np.diff(knots, axis=1)[packed[:, 1:]] > 0), "decay curves must not cross"
        table = np.empty((2, y_grid.size, hp_grid.size))
        splined = counts >= 4
        table[:, splined] = _spline_rows(knots[splined], values[:, splined], counts[splined], hp_grid)
        for m in np.flatnonzero(~splined):  # too few crossings for a cubic: straight lines
            n = counts[m]
            table[:, m] = [np.interp(hp_grid, knots[m, :n], v[m, :n]) for v in values]
        top = knots[np.arange(y_grid.size), counts - 1]
        inside = hp_grid[None, :] <= top[:, None]
        table = np.where(inside, table, beyond[:, None, :])
        return np.ascontiguousarray(table.transpose(0, 2, 1))

    def _build_table_b(self, hp: FloatArray, y: FloatArray, q: FloatArray) -> FloatArray:
        """Each curve at equal steps of tau, held at its last value past its end."""
        table = np.stack([hp, y - self.labels[:, None], q])
        last = np.maximum.accumulate(np.where(np.isfinite(hp), np.arange(hp.shape[1]), 0), axis=1)
        return np.take_along_axis(table, np.broadcast_to(last, table.shape), axis=2)

    @staticmethod
    def check_domain(perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Validate heights and check that they lie where the curves are tabulated.

        Raises:
            ValueError: invalid heights, or perigee above ``CURVES_MAX_PERIGEE_M``
                or apogee above ``CURVES_MAX_APOGEE_M``.
        """
        hp, ha = validate_heights(perigee_m, apogee_m)
        _check_curve_limits(hp, ha, ("perigee_m", "apogee_m"), "m", 1.0)
        return hp, ha

    @staticmethod
    def check_domain_km(perigee_km: ArrayLike, apogee_km: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """`check_domain` for heights in km (checked, and named, in km); returns metres."""
        hp, ha = validate_heights_km(perigee_km, apogee_km)
        typed = np.broadcast_arrays(np.asarray(perigee_km, dtype=np.float64), np.asarray(apogee_km, dtype=np.float64))
        _check_curve_limits(*typed, ("perigee_km", "apogee_km"), "km", 1e3)
        return hp, ha

    def locate(self, perigee_m: ArrayLike, apogee_m: ArrayLike) -> CurvePoint:
        """Place orbits on the curves (heights must be valid and in the domain)."""
        return self._with_period(*self._label_tau(perigee_m, apogee_m))

    def locate_heights(self, perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[CurvePoint, FloatArray, FloatArray]:
        """`locate`, and the perigee and apogee heights [m] the curves give the located point.

        The counterpart of `advance_heights` for a simulator that observes
        heights: reading them from the same table before and after a coast makes
        the decay it sees one table's difference, free of the locate-and-read-back
        round trip's interpolation error (up to 0.1 km in perigee, 1.3 km in apogee).
        """
        label, tau = self._label_tau(perigee_m, apogee_m)
        perigee, apogee, q = self.at(label, tau)
        return CurvePoint(label=label, tau=tau, mean_period_s=q), perigee, apogee

    def locate_segments(
        self, perigee_m: ArrayLike, apogee_m: ArrayLike
    ) -> tuple[CurvePoint, FloatArray, FloatArray, FloatArray]:
        """`locate_heights` for arrays, and where the located orbits are on table B.

        The last value (a (7, n) array) is for `advance_heights` to keep
        between steps. An orbit coasts along one curve (fixed label) and its tau
        falls by a small part of a table cell per step (in the env's defaults 4-7%
        of satellites change cell in a step), so keeping each orbit's cell and the
        lines the three values follow across it replaces a gather per orbit and
        step by two operations per value. Locate anew the orbits whose label
        changed (a burn: `relocate_segments`); cell changes are handled by ``advance_heights``.

        For two floats (one orbit): floats, and the cell as a list (`BilinearGrid.segment_scalar`).
        """
        return self.segments_at(*self._label_tau(perigee_m, apogee_m))

    def relocate_segments(
        self, label: ArrayLike, tau: ArrayLike, perigee_m: ArrayLike, apogee_m: ArrayLike, apogee_after_m: ArrayLike
    ) -> tuple[CurvePoint, FloatArray, FloatArray, FloatArray]:
        """`locate_segments` of an orbit at (label, tau) whose apogee a perigee burn raised to ``apogee_after_m``.

        ``perigee_m`` and ``apogee_m`` are the heights the curves give (label, tau).
        Table A's point of the new heights is not used as it is: table A and table
        B are two interpolations of the same curves and disagree by up to some
        0.1 km in perigee and 1.3 km in apogee, so locating the unburnt heights
        would not give back (label, tau), and a burn of 1e-9 m/s would move the
        orbit to another curve, worth up to 0.14 day of life more (or less) than
        coasting. An optimiser harvests such steps with many small burns: in the
        continuous variant a search over burn plans found 0.57 day per start on
        average that way. Instead the orbit moves by table A's difference between
        the new heights and the old: (label, tau) + A(hp, ha') - A(hp, ha), so
        the point, and every value after it, is continuous in the burn and no
        burn is exactly no burn.
        """
        before_label, before_tau = self._label_tau(perigee_m, apogee_m)
        after_label, after_tau = self._label_tau(perigee_m, apogee_after_m)
        if isinstance(before_tau, float) and isinstance(label, float):
            return self.segments_at(
                label + (after_label - before_label), max(float(tau) + (after_tau - before_tau), 0.0)
            )
        return self.segments_at(
            np.asarray(label, dtype=np.float64) + (after_label - before_label),
            np.maximum(np.asarray(tau, dtype=np.float64) + (after_tau - before_tau), 0.0),
        )

    def segments_at(self, label: Any, tau: Any) -> tuple[CurvePoint, Any, Any, Any]:
        """The point (label, tau), its heights and its cell of table B (see `locate_segments`).

        What `locate_segments` gives for the heights table A puts at (label, tau): a start
        replayed from its curve coordinates is the start, bit for bit.
        """
        if isinstance(label, float) and isinstance(tau, float):
            segment, ty_s = self.table_b.segment_scalar(label, tau)
            hp_s, ha_s, q_s = _heights_along(label, segment, ty_s)
            return CurvePoint(label=label, tau=tau, mean_period_s=q_s), hp_s, ha_s, segment
        segments, ty = self.table_b.segments(label, tau)
        perigee, apogee, q = _heights(label, *self.table_b.along(segments, ty))
        return CurvePoint(label=label, tau=tau, mean_period_s=q), perigee, apogee, segments

    def locate_exactly(self, perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(label, tau) of orbits whose heights are table B's there: table A's point, refined on table B.

        `locate` reads table A, which disagrees with table B (what `at` and every
        coast read) by up to some 0.1 km in perigee and 1.3 km in apogee, so the point
        it gives for heights that table B gave is not the point they came from: an
        observer recovering a simulated orbit from its heights would plan on an orbit
        up to 0.1% off in nu (0.3 day of life left in a measured case). Here Newton's
        method on table B's interpolant (bilinear, derivatives by differences of 1e-7
        in label and tau) refines table A's point, `LOCATE_NEWTON_STEPS` steps; the
        orbits it does not bring within 1 mm in perigee and 1e-9 in ln e keep table A's.
        """
        hp = np.atleast_1d(np.asarray(perigee_m, dtype=np.float64))
        ha = np.atleast_1d(np.asarray(apogee_m, dtype=np.float64))
        start_label, start_tau = self._label_tau(hp, ha)
        label, tau = start_label, start_tau  # replaced, not changed, by each Newton step
        y = np.log(np.maximum(_eccentricity(hp, ha), E_FLOOR))
        step = 1e-7

        def residuals(mu: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray]:
            b0, b1, _ = self.table_b.values(mu, t)
            return b0 - hp, b1 + mu - y

        for _ in range(LOCATE_NEWTON_STEPS):
            f0, f1 = residuals(label, tau)
            l0, l1 = residuals(label + step, tau)
            t0, t1 = residuals(label, tau + step)
            j00, j01 = (l0 - f0) / step, (t0 - f0) / step
            j10, j11 = (l1 - f1) / step, (t1 - f1) / step
            det = j00 * j11 - j01 * j10
            ok = np.abs(det) > 0.0
            safe = np.where(ok, det, 1.0)
            label = label - np.where(ok, (f0 * j11 - f1 * j01) / safe, 0.0)
            tau = np.maximum(tau - np.where(ok, (f1 * j00 - f0 * j10) / safe, 0.0), 0.0)
        f0, f1 = residuals(label, tau)
        good = (np.abs(f0) < 1e-3) & (np.abs(f1) < 1e-9) & (tau > 0.0)
        return np.where(good, label, start_label), np.where(good, tau, start_tau)

    def _label_tau(self, perigee_m: ArrayLike, apogee_m: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(label, tau) of orbits, from table A."""
        if isinstance(perigee_m, float) and isinstance(apogee_m, float):
            hp_m = float(perigee_m)
            y_s = math.log(max(_eccentricity(hp_m, float(apogee_m)), E_FLOOR))
            a0, a1 = self.table_a.values_scalar(hp_m, y_s)
            return y_s + a0, max(a1, 0.0)
        hp = np.asarray(perigee_m, dtype=np.float64)
        y = np.log(np.maximum(_eccentricity(hp, np.asarray(apogee_m, dtype=np.float64)), E_FLOOR))
        # Table A holds mu - ln(e), exact for orbits below its lowest row (translates).
        a0, a1 = self.table_a.values(hp, y)
        return y + a0, np.maximum(a1, 0.0)

    def _with_period(self, label: FloatArray, tau: FloatArray) -> CurvePoint:
        """The point at (label, tau) with its mean period from table B."""
        if isinstance(label, float) and isinstance(tau, float):
            (q_s,) = self._table_q.values_scalar(label, tau)
            return CurvePoint(label=label, tau=tau, mean_period_s=q_s)
        (q,) = self._table_q.values(label, tau)
        return CurvePoint(label=label, tau=tau, mean_period_s=q)

    def at(self, label: ArrayLike, tau: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Perigee height [m], apogee height [m] and mean period left [s] at (label, tau)."""
        if isinstance(label, float) and isinstance(tau, float):
            return self._at_scalar(float(label), float(tau))
        mu = np.asarray(label, dtype=np.float64)
        return _heights(mu, *self.table_b.values(mu, tau))

    def weighted_at(self, label: ArrayLike, nu: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Perigee height [m], apogee height [m] and W = Int P dnu left at (label, nu)."""
        nu = np.asarray(nu, dtype=np.float64)
        hp, ha, q = self.at(label, np.log1p(nu / NU_REF))
        return hp, ha, q * nu

    def move_to_weight(
        self,
        label: ArrayLike,
        nu: ArrayLike,
        weighted: ArrayLike,
        target: ArrayLike,
        perigee_m: ArrayLike,
        apogee_m: ArrayLike,
        tolerance: float = 0.0,
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The nu at which W falls to ``target`` along each curve, from nu (where W is ``weighted``, at those heights).

        Returns nu (never below 0: re-entry), and the perigee [m], apogee [m] and W at it (its
        last lookup). Newton's method on W(nu) = target with dW/dnu = P, the period at each iterate: the
        first iterate from the period at the heights given, then up to `WEIGHT_LOOKUPS` lookups
        of W. An orbit stops at the first iterate whose W is within ``tolerance`` times the
        step (|W - target| <= tolerance |weighted - target|); each orbit's iterates are its
        own, whatever the others in the arrays do. With ``tolerance`` 0, every lookup (the
        table's own precision).
        """
        p_now, e_now = elements_from_heights(perigee_m, apogee_m)
        nu = np.maximum(np.asarray(nu, dtype=np.float64) - (weighted - target) / period_s(p_now, e_now), 0.0)
        close = np.abs(np.subtract(weighted, target)) * tolerance
        hp, ha, w = self.weighted_at(label, nu)
        for _ in range(WEIGHT_LOOKUPS - 1):
            going = np.abs(w - target) > close
            if not going.any():
                break
            p_k, e_k = elements_from_heights(hp, ha)
            nu = np.where(going, np.maximum(nu - (w - target) / period_s(p_k, e_k), 0.0), nu)
            hp, ha, w = self.weighted_at(label, nu)
        return nu, hp, ha, w

    def _at_scalar(self, mu: float, tau: float) -> tuple[float, float, float]:
        """`at` for one orbit, in plain floats (the arithmetic of `_heights`)."""
        return _heights_scalar(mu, *self.table_b.values_scalar(mu, tau))

    def _after(self, point: CurvePoint, dnu: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The (nu, tau) reached once nu has fallen by ``dnu``, clamped at re-entry (nu = tau = 0)."""
        if isinstance(point.tau, float) and isinstance(dnu, float):
            nu_s = max(point.nu - dnu, 0.0)
            return nu_s, math.log1p(nu_s * (1.0 / NU_REF))
        nu = np.maximum(point.nu - np.asarray(dnu, dtype=np.float64), 0.0)
        return nu, np.log1p(nu * (1.0 / NU_REF))

    def advance(self, point: CurvePoint, dnu: ArrayLike) -> CurvePoint:
        """Move along the curves by ``dnu`` of the universal variable (clamped at re-entry)."""
        nu, tau = self._after(point, dnu)
        label = float(point.label) if isinstance(tau, float) else np.asarray(point.label, dtype=np.float64)
        return CurvePoint.with_nu(label, tau, self._with_period(label, tau).mean_period_s, nu)

    def advance_heights(
        self, point: CurvePoint, dnu: ArrayLike, segments: FloatArray | None = None
    ) -> tuple[CurvePoint, FloatArray, FloatArray]:
        """`advance`, and the perigee and apogee heights [m] of the new point.

        The same as ``advance`` followed by ``at``, in one interpolation: what a
        simulator stepping many orbits and observing their heights needs. With
        ``segments`` (from `locate_segments`, for these orbits' labels) the
        interpolation uses and updates them in place.
        """
        if isinstance(dnu, float) and isinstance(point.tau, float):
            # One orbit (the single environment, every step): _after and at in plain floats, on its
            # kept cell if it has one (a list from locate_segments).
            nu_s = max(point.nu - dnu, 0.0)
            tau_s = math.log1p(nu_s * (1.0 / NU_REF))
            label_s = point.label
            if segments is None:
                hp_s, ha_s, q_s = self._at_scalar(label_s, tau_s)
            else:
                ty_s = self.table_b.on_segment_scalar(segments, label_s, tau_s)
                hp_s, ha_s, q_s = _heights_along(label_s, segments, ty_s)
            return CurvePoint.with_nu(label_s, tau_s, q_s, nu_s), hp_s, ha_s
        nu, tau = self._after(point, dnu)
        label = float(point.label) if isinstance(tau, float) else np.asarray(point.label, dtype=np.float64)
        if segments is None:
            perigee_m, apogee_m, q = self.at(label, tau)
        else:
            perigee_m, apogee_m, q = _heights(label, *self.table_b.on_segments(segments, label, tau))
        return CurvePoint.with_nu(label, tau, q, nu), perigee_m, apogee_m


def nu_per_revolution(drag_parameter_m2_kg: ArrayLike, density_scale: ArrayLike = 1.0) -> FloatArray:
    """Universal variable one revolution is worth: dnu/dN = g c s (Eq. 4.1)."""
    if isinstance(drag_parameter_m2_kg, float) and isinstance(density_scale, float):
        return G0_M_S2 * drag_parameter_m2_kg * density_scale
    return G0_M_S2 * np.multiply(drag_parameter_m2_kg, density_scale, dtype=np.float64)


def days_from_weighted_s(
    weighted_s: ArrayLike, drag_parameter_m2_kg: ArrayLike, density_scale: ArrayLike = 1.0
) -> FloatArray:
    """Days of a decay from its weighted time W = Int P dnu [s m^3/(kg s^2)]: W / (g c s) / 86400 (Eq. 4.1).

    The one conversion of the universal variable's time into days; W comes from the
    curves (``weighted_s``) or the averaged equations.
    """
    return np.asarray(
        np.asarray(weighted_s, dtype=np.float64)
        / (G0_M_S2 * np.multiply(drag_parameter_m2_kg, density_scale, dtype=np.float64))
        / SECONDS_PER_DAY
    )


def universal_curves(model: DecayModel | None = None) -> UniversalCurves:
    """The universal curves of ``model`` (default: the paper's), built once per process and kept on disk."""
    if model is None:
        return _default_curves()  # the envs ask for it every step: no DecayModel() built per call
    return _curves_of(model)


@lru_cache(maxsize=1)
def _default_curves() -> UniversalCurves:
    return _curves_of(DecayModel())


@lru_cache(maxsize=8)
def _curves_of(model: DecayModel) -> UniversalCurves:
    # Keyed by the model itself: universal_curves() and universal_curves(DecayModel()) share one table.
    return UniversalCurves(model)
