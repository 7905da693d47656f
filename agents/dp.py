"""The exact optimum of the known-density task by backward induction on a grid.

SI units inside (m, kg, s, m/s); values and rewards in days, as the env's reward.

State. The env's state is a point on the universal curves (label mu, tau), the
mass and the steps left. The grid uses three coordinates of it:

* mu, the curve's label, uniform on [``MU_LOW``, the domain's largest label].
  Below ``MU_LOW`` (e < 1e-7 at re-entry) the orbits are circular to within
  metres; there the curves are translates of each other (see
  :mod:`orbit_env.curves`) and carry the same lifetime, so the value is clamped.
* n = nu / (K g c s), the lifetime left in steps at the current mass: a coast of
  one step moves it from n to n - 1 exactly, so with ``life_per_step`` levels per
  unit of n up to the horizon (and a geometric tail above it, where every orbit
  outlives the mission) coasting needs no interpolation and the value's kink at
  n = steps left sits on the grid.
* the delta-v left, anchored at the full tank and spaced by the greatest common
  divisor of the burn sizes over ``dv_per_quantum``, plus 0: every burn from a
  grid level lands on a grid level unless the 4000 km apogee cap cuts it.

Only a burn's landing point in (mu, n) is interpolated (multilinearly). The
transitions are the env's own functions on whole arrays of grid states:
``perigee_burn`` at the heights of ``curves.at``, ``curves.locate`` of the new
orbit (with the mean period from ``at``, as the env's ``_set_point``), and
``coast``; reward = days - cost * dv, re-entered states are worth 0.
For every action the successor and reward are computed once, stored as a
scipy.sparse interpolation matrix P_a and a vector r_a, and then
V_k = max_a (r_a + P_a V_{k-1}) for k = 1..horizon, V_0 = 0. The policy acts by
the same one-step look-ahead from the state recovered from the observation:
argmax_a r_a(s) + V_{k-1}(successor) interpolated.

Grid refinement (default config, density scale 1, mean optimum over 200 seeded
start states of ``OrbitRaising-v0`` (seeds 0..199), one core of a 2-core machine
shared with a training run):

=========  ==========  =========  ==========  ===========  ===========
labels     states      solve [s]  optimum     DP in env    change of
                                  (value)     (200 eps)    optimum
=========  ==========  =========  ==========  ===========  ===========
24         300 288     12.7*      301.42      297.02       --
32         400 384     13.7*      301.00      297.45       -0.14%
48         600 576     10.8       300.76      299.30       -0.08%
64         800 768     14.9       300.66      299.86       -0.03%
=========  ==========  =========  ==========  ===========  ===========

(returns in days; life and delta-v levels 1 per step and per 10 m/s: refining
them, (48, 2, 1) and (48, 1, 2), changed nothing measurable on the test task, as
their transitions are exact; * measured with a second solve running.) The
optimum moves by less than 0.5% from 24 labels on; the policy acting on the
interpolated values needs more: with 24 labels it earns 1.5% less than its
value, with 48 labels 0.5%, with 64 labels 0.3%. On the same 200 episodes never
burning returns 261.6 days and the whole tank at once 244.0: the optimum beats
them by 15% and 23% (value at 48 labels), its policy in the env by 14% and 23%.
The default grid is (64, 1, 1): about 20 s and 0.6 GB of values stored as uint16
in steps of 0.01 day. On the evaluation episodes of `orbit-env evaluate` (seed 12345)
the DP policy earns 262.8, 263.6 and 263.9 days at 48, 64 and 96 labels.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from functools import lru_cache, reduce
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from agents.policies import observation_batch
from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.curves import (
    CURVES_MAX_APOGEE_M,
    CURVES_MAX_PERIGEE_M,
    NU_REF,
    CurvePoint,
    UniversalCurves,
    nu_per_revolution,
    universal_curves,
)
from orbit_env.envs.orbit_raising import (
    DV_SCALE_M_S,
    HEIGHT_SCALE_M,
    OrbitRaisingConfig,
    coast,
    delta_v_left_m_s,
    perigee_burn,
)

FloatArray = NDArray[np.float64]

#: Default grid: (labels, life levels per step, delta-v levels per burn quantum).
DEFAULT_GRID = (64, 1, 1)
#: Resolution of the stored values [days].
VALUE_QUANTUM_DAYS = 0.01
#: Lowest label on the grid; below it orbits are circular to within metres.
MU_LOW = -14.0
#: Labels where 98% of the start orbits of the default config and of their burns
#: lie (measured on 50000 starts); the grid puts 3/4 of its labels there.
CORE_LABELS = (-12.5, -7.0)
#: Labels above the most elongated reachable orbit's that the grid still covers.
LABEL_MARGIN = 0.2
#: Levels of the geometric tail of the life axis, above the horizon.
LIFE_TAIL_LEVELS = 24


@dataclass(frozen=True)
class _Axes:
    """The grid's axes and the satellite they were built for."""

    label: FloatArray
    life: FloatArray
    dv_m_s: FloatArray

    @property
    def shape(self) -> tuple[int, int, int]:
        return (self.label.size, self.life.size, self.dv_m_s.size)


def _axis_weights(axis: FloatArray, x: FloatArray) -> tuple[NDArray[np.intp], FloatArray]:
    """Lower cell index and upper weight of x on a sorted axis, clamped to its ends."""
    if axis.size == 1:
        return np.zeros(x.shape, np.intp), np.zeros(x.shape)
    x = np.clip(x, axis[0], axis[-1])
    i = np.clip(np.searchsorted(axis, x, side="right") - 1, 0, axis.size - 2)
    t = (x - axis[i]) / (axis[i + 1] - axis[i])
    # Transitions that land on a level (coasts, burns of whole quanta) stay exact.
    t = np.where(t < 1e-9, 0.0, np.where(t > 1.0 - 1e-9, 1.0, t))
    return i, t


def _interpolation(axes: _Axes, label: FloatArray, life: FloatArray, dv_m_s: FloatArray) -> tuple[Any, Any]:
    """Flat grid indices (m, 8) and trilinear weights (m, 8) of query states."""
    n1, n2, n3 = axes.shape
    (i, ti), (j, tj), (k, tk) = (
        _axis_weights(axes.label, label),
        _axis_weights(axes.life, life),
        _axis_weights(axes.dv_m_s, dv_m_s),
    )
    index, weight = [], []
    for di, wi in ((0, 1.0 - ti), (1, ti)):
        for dj, wj in ((0, 1.0 - tj), (1, tj)):
            for dk, wk in ((0, 1.0 - tk), (1, tk)):
                index.append(
                    ((np.minimum(i + di, n1 - 1) * n2 + np.minimum(j + dj, n2 - 1)) * n3) + (np.minimum(k + dk, n3 - 1))
                )
                weight.append(wi * wj * wk)
    return np.stack(index, axis=-1), np.stack(weight, axis=-1)


class _Model:
    """The env's step on arrays of states, for one config and density scale."""

    def __init__(self, config: OrbitRaisingConfig, density_scale: float) -> None:
        self.config = config
        self.curves: UniversalCurves = universal_curves()
        self.density_scale = density_scale
        self.drag_area_m2 = config.drag_coefficient * config.area_m2

    def step_nu(self, mass_kg: FloatArray) -> FloatArray:
        """The nu one step (K revolutions) is worth at this mass: K g c s (Eq. 4.1)."""
        nu_per_rev = nu_per_revolution(self.drag_area_m2 / mass_kg, self.density_scale)
        return self.config.revolutions_per_step * nu_per_rev

    def mass_kg(self, dv_left_m_s: FloatArray) -> FloatArray:
        """Mass from the delta-v left, by the rocket equation."""
        return self.config.dry_mass_kg * np.exp(dv_left_m_s / self.config.exhaust_velocity_m_s)

    def point(self, label: FloatArray, tau: FloatArray) -> CurvePoint:
        """A point with its mean period from ``at``, as the env's ``_set_point``."""
        return CurvePoint(label, tau, self.curves.at(label, tau)[2])

    def step(
        self, point: CurvePoint, mass_kg: FloatArray, requested_dv_m_s: float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The env's step from ``point``: successor (label, life in steps, delta-v left) and reward."""
        config = self.config
        perigee_m, apogee_m, _ = self.curves.at(point.label, point.tau)
        dv, apogee_after, mass_after = perigee_burn(
            perigee_m, apogee_m, mass_kg, config.dry_mass_kg, config.exhaust_velocity_m_s, requested_dv_m_s
        )
        burned = dv > 0.0
        if np.any(burned):
            moved = self.curves.locate(perigee_m, apogee_after)
            label = np.where(burned, moved.label, point.label)
            tau = np.where(burned, moved.tau, point.tau)
            point = self.point(label, tau)
            mass_after = np.where(burned, mass_after, mass_kg)
        else:
            mass_after = np.asarray(mass_kg, dtype=np.float64) + np.zeros_like(point.tau)
            dv = np.zeros_like(point.tau)
        nu_per_rev = self.step_nu(mass_after) / config.revolutions_per_step
        after, _, _, days, _ = coast(self.curves, point, config.revolutions_per_step, nu_per_rev)
        life = np.where(after.tau > 0.0, after.nu / self.step_nu(mass_after), 0.0)
        dv_left = np.maximum(delta_v_left_m_s(mass_after, config.dry_mass_kg, config.exhaust_velocity_m_s), 0.0)
        return after.label, life, dv_left, days - config.propellant_cost_per_m_s * dv


@dataclass
class DPSolution:
    """Values V_k of the grid for k = 0..horizon steps left, and the model that made them.

    Attributes:
        config: The task solved.
        density_scale: The known density scale.
        grid: (labels, life levels per step, delta-v levels per burn quantum).
        solve_s: Wall time of the solve [s].
    """

    config: OrbitRaisingConfig
    density_scale: float
    grid: tuple[int, int, int]
    solve_s: float
    _model: _Model
    _axes: _Axes
    _values: NDArray[np.uint16]  # (horizon + 1, states), in units of VALUE_QUANTUM_DAYS

    @property
    def num_states(self) -> int:
        """Grid states per stage."""
        return int(self._values.shape[1])

    def _state(
        self, perigee_m: FloatArray, apogee_m: FloatArray, dv_left_m_s: FloatArray
    ) -> tuple[CurvePoint, FloatArray]:
        """The env's point and mass for observed heights and delta-v left."""
        model = self._model
        located = model.curves.locate(perigee_m, apogee_m)
        return model.point(located.label, located.tau), model.mass_kg(dv_left_m_s)

    def q_values(
        self, perigee_m: FloatArray, apogee_m: FloatArray, dv_left_m_s: FloatArray, steps_left: NDArray[np.intp]
    ) -> FloatArray:
        """r_a + V_{k-1}(successor_a) for each state (rows) and action (columns) [days]; 0 at k = 0."""
        point, mass = self._state(perigee_m, apogee_m, dv_left_m_s)
        stage = np.clip(steps_left - 1, 0, self.config.horizon_steps - 1)
        q = np.empty((np.size(point.tau), len(self.config.burn_sizes_m_s)))
        for a, burn in enumerate(self.config.burn_sizes_m_s):
            label, life, dv_left, reward = self._model.step(point, mass, burn)
            index, weight = _interpolation(self._axes, label, life, dv_left)
            future = (self._values[stage[:, None], index] * weight).sum(axis=1) * VALUE_QUANTUM_DAYS
            q[:, a] = reward + future
        # A re-entered satellite or an ended mission earns nothing more.
        q[(steps_left <= 0) | (point.tau <= 0.0)] = 0.0
        return q

    def value(self, perigee_km: Any, apogee_km: Any, dv_left_m_s: Any, steps_left: Any) -> FloatArray:
        """The optimum's expected return from a state [days] (arrays broadcast).

        The one-step look-ahead of the policy, max_a r_a + V_{k-1}(successor), so
        it is what :class:`DPPolicy` expects to earn from there.

        Raises:
            ValueError: heights outside the curves, negative delta-v, or steps
                left outside 0..horizon.
        """
        hp, ha, dv, k = np.broadcast_arrays(
            np.asarray(perigee_km, np.float64) * 1e3,
            np.asarray(apogee_km, np.float64) * 1e3,
            np.asarray(dv_left_m_s, np.float64),
            np.asarray(steps_left),
        )
        UniversalCurves.check_domain(hp, ha)
        if not (np.all(np.isfinite(dv)) and np.all(dv >= 0.0)):
            raise ValueError(f"dv_left_m_s={dv_left_m_s!r} is invalid; allowed: finite values >= 0")
        horizon = self.config.horizon_steps
        if not (np.all(k == np.round(k)) and np.all((k >= 0) & (k <= horizon))):
            raise ValueError(f"steps_left={steps_left!r} is invalid; allowed: integers 0 to {horizon}")
        shape = hp.shape
        q = self.q_values(hp.ravel(), ha.ravel(), dv.ravel(), k.ravel().astype(np.intp))
        return q.max(axis=1).reshape(shape)


def _gcd(values: tuple[float, ...]) -> float:
    """Greatest common divisor of the positive burn sizes (to 1e-6 m/s); 0 if none."""
    micro = [round(v * 1e6) for v in values if v > 0.0]
    return reduce(math.gcd, micro, 0) / 1e6


def _axes(model: _Model, grid: tuple[int, int, int]) -> _Axes:
    config = model.config
    n_label, life_per_step, dv_per_quantum = grid
    curves = model.curves
    # The most elongated orbit reachable: the most elongated start (lowest perigee,
    # highest apogee), decayed to any point of its curve and raised with the whole tank.
    start = curves.locate(np.array([config.start_perigee_km[0] * 1e3]), np.array([config.start_apogee_max_km * 1e3]))
    along = np.linspace(0.0, 1.0, 201) * start.tau[0]
    perigee_m, apogee_m, _ = curves.at(np.full(along.size, start.label[0]), along)
    _, raised_m, _ = perigee_burn(
        perigee_m, apogee_m, config.wet_mass_kg, config.dry_mass_kg, config.exhaust_velocity_m_s, np.inf
    )
    top = float(curves.locate(perigee_m, raised_m).label.max()) + LABEL_MARGIN
    top = max(top, CORE_LABELS[1] + 0.5)
    # Most of the levels where the start orbits and their burns lie, the rest outside.
    outer = max(1, n_label // 8) if n_label >= 6 else 0
    if outer:
        core = np.linspace(*CORE_LABELS, n_label - 2 * outer)
        below = np.linspace(MU_LOW, CORE_LABELS[0], outer + 1)[:-1]
        above = np.linspace(CORE_LABELS[1], top, outer + 1)[1:]
        label = np.concatenate([below, core, above])
    else:
        label = np.linspace(MU_LOW, top, n_label)
    horizon = config.horizon_steps
    # The longest life in the domain, in steps of the heaviest satellite.
    highest = curves.locate(np.array([CURVES_MAX_PERIGEE_M]), np.array([CURVES_MAX_APOGEE_M]))
    life_max = max(float(highest.nu[0] / model.step_nu(config.wet_mass_kg)), 2.0 * (horizon + 1))
    unit = np.arange(0, (horizon + 1) * life_per_step + 1) / life_per_step
    tail = np.geomspace(horizon + 1, life_max, LIFE_TAIL_LEVELS + 1)[1:]
    capacity = config.delta_v_capacity_m_s
    quantum = _gcd(config.burn_sizes_m_s)
    if capacity > 0.0 and quantum > 0.0:
        spacing = quantum / dv_per_quantum
        levels = capacity - spacing * np.arange(int(capacity / spacing) + 1)
        dv_m_s = np.unique(np.concatenate([[0.0], levels[levels > 1e-9]]))
    else:
        dv_m_s = np.array([0.0, capacity]) if capacity > 0.0 else np.array([0.0])
    return _Axes(label, np.concatenate([unit, tail]), dv_m_s)


def _check_grid(grid: Any) -> tuple[int, int, int]:
    ok = (
        isinstance(grid, tuple)
        and len(grid) == 3
        and all(isinstance(g, (int, np.integer)) and not isinstance(g, bool) for g in grid)
        and grid[0] >= 2
        and grid[1] >= 1
        and grid[2] >= 1
    )
    if not ok:
        raise ValueError(
            f"grid={grid!r} is invalid; allowed: (labels >= 2, life levels per step >= 1, "
            "delta-v levels per burn quantum >= 1), integers"
        )
    return (int(grid[0]), int(grid[1]), int(grid[2]))


def solve(
    config: OrbitRaisingConfig | None = None,
    *,
    grid: tuple[int, int, int] = DEFAULT_GRID,
    density_scale: float = 1.0,
    progress: bool = False,
) -> DPSolution:
    """The optimum of the known-density task by backward induction (cached per arguments).

    Args:
        config: The task (default: ``OrbitRaisingConfig()``, that of ``OrbitRaising-v0``).
        grid: (labels, life levels per step, delta-v levels per burn quantum); see the module.
        density_scale: The density scale s, known to the planner.
        progress: Print the stages' progress to stderr.

    Raises:
        ValueError: an invalid config, grid or density scale.
    """
    config = OrbitRaisingConfig() if config is None else config
    if not isinstance(config, OrbitRaisingConfig):
        raise ValueError(f"config={config!r} is invalid; allowed: an OrbitRaisingConfig or None")
    grid = _check_grid(grid)
    if not (isinstance(density_scale, (int, float)) and math.isfinite(density_scale) and density_scale > 0):
        raise ValueError(f"density_scale={density_scale!r} is invalid; allowed: a finite number > 0")
    return _solve(config, grid, float(density_scale), bool(progress))


@lru_cache(maxsize=4)
def _solve(config: OrbitRaisingConfig, grid: tuple[int, int, int], density_scale: float, progress: bool) -> DPSolution:
    start = time.perf_counter()
    model = _Model(config, density_scale)
    axes = _axes(model, grid)
    label, life, dv_left = (a.ravel() for a in np.meshgrid(axes.label, axes.life, axes.dv_m_s, indexing="ij"))
    mass = model.mass_kg(dv_left)
    tau = np.log1p(life * model.step_nu(mass) / NU_REF)
    point = model.point(label, tau)
    n = label.size
    alive = life > 0.0
    rewards, matrices = [], []
    for burn in config.burn_sizes_m_s:
        next_label, next_life, next_dv, reward = model.step(point, mass, burn)
        index, weight = _interpolation(axes, next_label, next_life, next_dv)
        keep = (weight > 0.0) & alive[:, None]
        rows = np.broadcast_to(np.arange(n)[:, None], index.shape)[keep]
        matrices.append(sp.csr_matrix((weight[keep], (rows, index[keep])), shape=(n, n)))
        rewards.append(np.where(alive, reward, 0.0))
    if progress:
        print(f"dp: {n} states x {len(rewards)} actions built in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    horizon = config.horizon_steps
    # Values are stored as uint16 in steps of VALUE_QUANTUM_DAYS: half of float32's memory
    # (366 stages of up to a million states), far below the grid's own error.
    values = np.zeros((horizon + 1, n), dtype=np.uint16)
    v = np.zeros(n)
    for k in range(1, horizon + 1):
        v = reduce(np.maximum, [r + p @ v for r, p in zip(rewards, matrices, strict=True)])
        if v.max() > np.iinfo(np.uint16).max * VALUE_QUANTUM_DAYS:
            raise ValueError(f"values above {np.iinfo(np.uint16).max * VALUE_QUANTUM_DAYS:g} days: horizon too long")
        values[k] = np.rint(np.maximum(v, 0.0) / VALUE_QUANTUM_DAYS)
        if progress and k % 73 == 0:
            print(f"dp: stage {k}/{horizon}, {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return DPSolution(config, density_scale, grid, time.perf_counter() - start, model, axes, values)


class DPPolicy:
    """The optimum's policy, in Stable-Baselines3's ``predict`` protocol.

    It recovers the state from the observation (heights, delta-v left -> mass by
    the rocket equation, steps left from the mission clock) and takes
    argmax_a r_a + V_{k-1}(successor_a) with the env's own step.

    Args:
        config: The env's config (default: ``OrbitRaisingConfig()``).
        grid: The DP grid (see :func:`solve`).
        density_scale: The density scale the planner knows.
        solution: A solution to act on, instead of solving (its config wins).
    """

    name = "dp"

    def __init__(
        self,
        config: OrbitRaisingConfig | None = None,
        *,
        grid: tuple[int, int, int] = DEFAULT_GRID,
        density_scale: float = 1.0,
        solution: DPSolution | None = None,
    ) -> None:
        self.solution = solution if solution is not None else solve(config, grid=grid, density_scale=density_scale)
        self.config = self.solution.config

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[Any, Any]:
        """Actions for one observation (7,) or a batch (n, 7); SB3's signature."""
        batch = observation_batch(observation)
        perigee = np.clip(batch[:, 0] * HEIGHT_SCALE_M, REENTRY_ALTITUDE_M, CURVES_MAX_PERIGEE_M)
        apogee = np.clip(batch[:, 1] * HEIGHT_SCALE_M, perigee, CURVES_MAX_APOGEE_M)
        dv_left = np.maximum(batch[:, 2] * DV_SCALE_M_S, 0.0)
        horizon = self.config.horizon_steps
        steps_left = horizon - np.rint(np.clip(batch[:, 3], 0.0, 1.0) * horizon).astype(np.intp)
        actions = np.argmax(self.solution.q_values(perigee, apogee, dv_left, steps_left), axis=1).astype(np.int64)
        return (actions[0] if np.ndim(observation) == 1 else actions), state
