r"""The optimum of the known-density task by backward induction on a grid.

SI units inside (m, kg, s, m/s); values and rewards in days, as the env's reward.

The grid spans three coordinates of the env's state: the curve label mu (spaced in proportion to
the label change of the smallest burn), the lifetime left in steps $n = \nu / (K g c s)$ (a coast
moves $n$ to $n - 1$ exactly) and the delta-v left (burns land on its levels). A satellite that
outlives the $k$ steps left coasts, its value the exact sum of the coasts' days, so only the states
with $n \le k$ decide and are stored. The env's own task model gives each action's successor and
reward once, as a sparse interpolation matrix $P_a$ and a vector $r_a$; then
$V_k = \max_a (r_a + P_a V_{k-1})$, $V_0 = 0$, stored compressed (`orbit_env.agents.stage_values`) and
kept in the disk cache (`orbit_env.cache`). `DPPolicy` acts by the same one-step look-ahead from
the state recovered from the observation; ``DPPolicy(rollout=2)`` is the rollout policy on it
(`rollout_returns`).

The method, the grid refinement, the storage, the certificate and their measurements are in the
documentation's page on the DP (docs/dp.md).
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from functools import lru_cache, reduce
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.optimize import brentq

from orbit_env import cache
from orbit_env.agents.protocol import Predicts
from orbit_env.agents.stage_values import StageValues
from orbit_env.decay.curves import (
    CURVES_MAX_APOGEE_M,
    CURVES_MAX_PERIGEE_M,
    NU_REF,
    UniversalCurves,
    nu_per_revolution,
    universal_curves,
)
from orbit_env.envs import task as task_model
from orbit_env.envs.config import DensityConfig, OrbitRaisingConfig
from orbit_env.envs.rocket import mass_from_delta_v_left_kg, perigee_burn, period_gain_days_per_m_s_per_step
from orbit_env.envs.state import BatchState
from orbit_env.envs.task import Task

FloatArray = NDArray[np.float64]

#: Default grid: (labels, life levels per step, delta-v levels per burn quantum).
DEFAULT_GRID = (192, 1, 1)
#: Resolution of the stored values [days].
VALUE_QUANTUM_DAYS = 0.01
#: Lowest label on the grid; below it orbits are circular to within metres.
MU_LOW = -14.0
#: Label change above which the labels' spacing stops growing (nearly circular orbits,
#: where a burn moves mu most).
LABEL_MAX_SPACING = 0.3
#: Life (as a fraction of the horizon, at the wet mass) at which the label change of
#: the smallest burn sets the labels' spacing.
LABEL_REFERENCE_LIFE = 0.5
#: Fraction of the apogee cap above which the labels' spacing grows geometrically.
LABEL_FINE_APOGEE = 0.7
#: Labels above the most elongated reachable orbit's that the grid still covers.
LABEL_MARGIN = 0.2
#: Levels of the geometric tail of the life axis, above the horizon.
LIFE_TAIL_LEVELS = 24
#: States per chunk of the transitions' computation (the curves' tables stay in cache).
CHUNK_STATES = 16384


@dataclass(frozen=True)
class _Axes:
    """The grid's axes. States are stored life-major: (life level, label, delta-v level).

    So the decision states of a stage, n <= k, are a prefix of the state vector.
    """

    label: FloatArray
    life: FloatArray
    dv_m_s: FloatArray
    unit_levels: int  # life levels spaced 1 / life_per_step, from 0 to the horizon + 1
    life_per_step: int

    @property
    def shape(self) -> tuple[int, int, int]:
        return (self.life.size, self.label.size, self.dv_m_s.size)

    @property
    def plane(self) -> int:
        """States per life level."""
        return self.label.size * self.dv_m_s.size

    @property
    def size(self) -> int:
        return self.life.size * self.plane


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
    n_life, n_label, n_dv = axes.shape
    (j, tj), (i, ti), (k, tk) = (
        _axis_weights(axes.life, life),
        _axis_weights(axes.label, label),
        _axis_weights(axes.dv_m_s, dv_m_s),
    )
    index, weight = [], []
    for dj, wj in ((0, 1.0 - tj), (1, tj)):
        for di, wi in ((0, 1.0 - ti), (1, ti)):
            for dk, wk in ((0, 1.0 - tk), (1, tk)):
                flat = (np.minimum(j + dj, n_life - 1) * n_label + np.minimum(i + di, n_label - 1)) * n_dv
                index.append(flat + np.minimum(k + dk, n_dv - 1))
                weight.append(wj * wi * wk)
    return np.stack(index, axis=-1), np.stack(weight, axis=-1)


class DPStep(NamedTuple):
    """One step of the task from arrays of states."""

    state: BatchState  # after the burn and the coast
    life: FloatArray  # steps of life left at the new mass (0 once re-entered)
    reward: FloatArray


class DPModel:
    """The task with the density known, on arrays of grid states (the task model's functions)."""

    def __init__(self, config: OrbitRaisingConfig, density_scale: float) -> None:
        self.config = config
        self.task = Task(config, DensityConfig(scale_range=(density_scale, density_scale)))
        self.curves: UniversalCurves = universal_curves()
        self.density_scale = density_scale

    def step_nu(self, mass_kg: FloatArray) -> FloatArray:
        """The nu one step (K revolutions) is worth at this mass: K g c s (Eq. 4.1)."""
        drag_parameter = self.config.drag_coefficient * self.config.area_m2 / mass_kg
        return self.config.revolutions_per_step * nu_per_revolution(drag_parameter, self.density_scale)

    def mass_kg(self, dv_left_m_s: FloatArray) -> FloatArray:
        """Mass from the delta-v left, by the rocket equation."""
        config = self.config
        return mass_from_delta_v_left_kg(dv_left_m_s, config.dry_mass_kg, config.exhaust_velocity_m_s)

    def states(self, label: FloatArray, life: FloatArray, dv_left_m_s: FloatArray) -> BatchState:
        """Grid states: on curve ``label`` with ``life`` steps of life left at the mass ``dv_left_m_s`` gives."""
        tau = np.log1p(life * self.step_nu(self.mass_kg(dv_left_m_s)) / NU_REF)
        return task_model.states_on_curves(self.task, label, tau, dv_left_m_s, 0.0)

    def step(self, states: BatchState, requested_dv: float) -> DPStep:
        """The task's step from ``states`` (not changed): burn (maybe), then coast."""
        after = states.copy()
        result = task_model.step(self.task, after, requested_dv)
        life = np.where(after.tau > 0.0, after.nu / (self.config.revolutions_per_step * after.nu_per_rev), 0.0)
        return DPStep(after, life, result.reward)

    def coast_days(self, states: BatchState, steps: Any) -> FloatArray:
        """The days of ``steps`` coasts in one (the sum of the task's coasts' days)."""
        return task_model.lookahead(self.task, states, 0.0, steps)[0]


def _coast_certain_stages(model: DPModel) -> int:
    """The stages k (steps left) up to which a satellite that outlives them coasts in the optimum.

    With n >= k the satellite lives through the mission coasting; a burn of dv
    then changes the return by the days of longer periods, at most c0 * k * dv,
    minus cost * dv. c0 = K max dP/d(dv) / day, the largest rate over the curves'
    domain (P grows convexly with the perigee speed, so a finite burn gains
    less per m/s than the rate at its end, which lies in the domain; assumed:
    the difference of the periods does not grow as both orbits decay, checked by
    solving with every state deciding in tests/agents/test_dp.py). Returns the largest
    k with c0 * k < cost, at most the horizon.
    """
    config = model.config
    if config.delta_v_capacity_m_s <= 0.0 or max(config.burn_sizes_m_s) <= 0.0:
        return config.horizon_steps
    c0 = period_gain_days_per_m_s_per_step(config.revolutions_per_step)
    stages = math.ceil(config.propellant_cost_per_m_s / c0) - 1
    return int(min(max(stages, 0), config.horizon_steps))


def _gcd(values: tuple[float, ...]) -> float:
    """Greatest common divisor of the positive burn sizes (to 1e-6 m/s); 0 if none."""
    micro = [round(v * 1e6) for v in values if v > 0.0]
    return reduce(math.gcd, micro, 0) / 1e6


def _top_label(model: DPModel) -> float:
    """Label of the most elongated orbit reachable, plus ``LABEL_MARGIN``.

    The most elongated start (lowest perigee, highest apogee), decayed to any point
    of its curve and raised with the whole tank.
    """
    config = model.config
    curves = model.curves
    start = curves.locate(np.array([config.start_perigee_km[0] * 1e3]), np.array([config.start_apogee_max_km * 1e3]))
    along = np.linspace(0.0, 1.0, 201) * start.tau[0]
    perigee_m, apogee_m, _ = curves.at(np.full(along.size, start.label[0]), along)
    _, raised_m, _ = perigee_burn(
        perigee_m, apogee_m, config.wet_mass_kg, config.dry_mass_kg, config.exhaust_velocity_m_s, np.inf
    )
    return max(float(curves.locate(perigee_m, raised_m).label.max()) + LABEL_MARGIN, MU_LOW + 1.0)


def _labels(model: DPModel, n_label: int) -> FloatArray:
    """The label axis: spacing in proportion to the label change of the smallest burn (see the module)."""
    config = model.config
    top = _top_label(model)
    burns = [b for b in config.burn_sizes_m_s if b > 0.0]
    if n_label < 6 or not burns or config.delta_v_capacity_m_s <= 0.0:
        return np.linspace(MU_LOW, top, n_label)
    mu = np.arange(MU_LOW, top, 0.002)
    life = np.full(mu.size, LABEL_REFERENCE_LIFE * config.horizon_steps)
    states = model.states(mu, life, config.delta_v_capacity_m_s)
    apogee_m = states.apogee_m
    moved = model.step(states, min(burns)).state.label - mu
    fine = (apogee_m <= LABEL_FINE_APOGEE * CURVES_MAX_APOGEE_M) & (moved > 0.0)
    end = int(np.argmin(fine)) if not fine.all() else mu.size
    if end < 2:
        return np.linspace(MU_LOW, top, n_label)
    density = np.maximum(1.0 / np.maximum(moved[:end], 1e-9), 1.0 / LABEL_MAX_SPACING)
    u = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * np.diff(mu[:end]))])
    n_above = max(2, n_label // 12)
    fine_labels = np.interp(np.linspace(0.0, u[-1], n_label - n_above), u, mu[:end])
    # Above: spacings h q, h q^2, ... from the last fine spacing h, summing to the rest of the range.
    h, rest = fine_labels[-1] - fine_labels[-2], top - fine_labels[-1]
    powers = np.arange(1, n_above + 1)
    if h * n_above >= rest:
        ratio = 1.0
    else:
        ratio = brentq(lambda q: h * np.sum(q**powers) - rest, 1.0, 1e3)
    above = fine_labels[-1] + np.cumsum(h * ratio**powers)
    above[-1] = top
    return np.concatenate([fine_labels, above])


def _axes(model: DPModel, grid: tuple[int, int, int]) -> _Axes:
    config = model.config
    n_label, life_per_step, dv_per_quantum = grid
    curves = model.curves
    label = _labels(model, n_label)
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
    return _Axes(label, np.concatenate([unit, tail]), dv_m_s, unit.size, life_per_step)


def _grid_states(model: DPModel, axes: _Axes, rows: NDArray[np.intp]) -> BatchState:
    """The task's states at flat grid indices."""
    j, rest = np.divmod(rows, axes.plane)
    i, k = np.divmod(rest, axes.dv_m_s.size)
    return model.states(axes.label[i], axes.life[j], axes.dv_m_s[k])


@dataclass
class DPSolution:
    """Values V_k of the grid for k = 0..horizon steps left, and the model that made them.

    Attributes:
        config: The task solved.
        density_scale: The known density scale.
        grid: (labels, life levels per step, delta-v levels per burn quantum).
        solve_s: Wall time of the solve [s].
        model: The task the values are of, on arrays of grid states.
        coast_certain_stages: The stages (steps left) up to which a satellite that outlives them
            coasts in the optimum (see the module).
    """

    config: OrbitRaisingConfig
    density_scale: float
    grid: tuple[int, int, int]
    solve_s: float
    model: DPModel
    _axes: _Axes
    _stages: StageValues  # the decision states of every stage, in units of VALUE_QUANTUM_DAYS
    _rows: NDArray[np.int64]  # decision states of stage k (a prefix of the state vector)
    _cumulative: FloatArray  # sums of the coasts' days along the life levels [days]
    coast_certain_stages: int
    _tail: BatchState  # the states of the life axis' tail

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The solution as named arrays, for the disk cache (`from_arrays` reads them back)."""
        axes = self._axes
        return {
            **self._stages.to_arrays(),
            "label": axes.label,
            "life": axes.life,
            "dv_m_s": axes.dv_m_s,
            "levels": np.array([axes.unit_levels, axes.life_per_step, self.coast_certain_stages]),
            "rows": self._rows,
            "cumulative": self._cumulative,
            "solve_s": np.array(self.solve_s),
        }

    @classmethod
    def from_arrays(
        cls, config: OrbitRaisingConfig, grid: tuple[int, int, int], density_scale: float, arrays: dict[str, np.ndarray]
    ) -> DPSolution:
        """The solution of ``config``, ``grid`` and ``density_scale`` from the arrays of `to_arrays`."""
        model = DPModel(config, density_scale)
        unit_levels, life_per_step, certain = (int(x) for x in arrays["levels"])
        axes = _Axes(arrays["label"], arrays["life"], arrays["dv_m_s"], unit_levels, life_per_step)
        return cls(
            config,
            density_scale,
            grid,
            float(arrays["solve_s"]),
            model,
            axes,
            StageValues.from_arrays(arrays),
            arrays["rows"],
            arrays["cumulative"],
            certain,
            _tail_states(model, axes),
        )

    @property
    def num_states(self) -> int:
        """Grid states per stage."""
        return self._axes.size

    @property
    def stored_values(self) -> int:
        """Values stored over all stages (the decision states)."""
        return int(self._rows[1:].sum())

    @property
    def task(self) -> Task:
        """The task solved: the config's, with the density known at ``density_scale``."""
        return self.model.task

    def coast_days(self, stage: int, rows: NDArray[np.intp]) -> FloatArray:
        """The days of ``stage`` coasts from the grid states ``rows`` (flat indices) that outlive them [days]."""
        axes = self._axes
        unit_rows = axes.unit_levels * axes.plane
        out = np.empty(rows.shape)
        unit = rows < unit_rows
        shift = stage * axes.life_per_step * axes.plane
        out[unit] = self._cumulative[rows[unit]] - self._cumulative[rows[unit] - shift]
        tail = np.flatnonzero(~unit)
        for start in range(0, tail.size, CHUNK_STATES):
            chunk = tail[start : start + CHUNK_STATES]
            out[chunk] = self.model.coast_days(self._tail.take(rows[chunk] - unit_rows), stage)
        return out

    def stage_values(self, stage: int, rows: Any = None) -> FloatArray:
        """V_stage at flat grid states (default: all of them) [days]."""
        rows = np.arange(self.num_states) if rows is None else np.asarray(rows, dtype=np.intp)
        if stage == 0:
            return np.zeros(rows.shape)
        out = np.empty(rows.shape)
        stored = rows < self._rows[stage]
        out[stored] = self._stages.get(stage)[rows[stored]] * VALUE_QUANTUM_DAYS
        if not stored.all():
            out[~stored] = self.coast_days(stage, rows[~stored])
        return out

    def q_values(self, states: BatchState, steps_left: NDArray[np.intp]) -> FloatArray:
        """r_a + V_{k-1}(successor_a) for each state (rows) and action (columns) [days]; 0 at k = 0."""
        stage = np.clip(steps_left - 1, 0, self.config.horizon_steps - 1)
        q = np.empty((states.size, len(self.config.burn_sizes_m_s)))
        for a, burn in enumerate(self.config.burn_sizes_m_s):
            step = self.model.step(states, burn)
            future = np.zeros(q.shape[0])
            # A successor that outlives the mission coasts: its days are summed exactly.
            exact = (stage <= self.coast_certain_stages) & (step.life >= stage)
            if exact.any():
                future[exact] = self.model.coast_days(step.state.take(exact), stage[exact])
            index, weight = _interpolation(self._axes, step.state.label, step.life, step.state.dv_left_m_s)
            for s in np.unique(stage[~exact]):
                mine = ~exact & (stage == s)
                future[mine] = (self.stage_values(int(s), index[mine]) * weight[mine]).sum(axis=1)
            q[:, a] = step.reward + future
        # A re-entered satellite or an ended mission earns nothing more.
        q[(steps_left <= 0) | (states.tau <= 0.0)] = 0.0
        return q

    def no_choice(self, states: BatchState, steps_left: NDArray[np.intp]) -> NDArray[np.bool_]:
        """States with nothing to decide: an empty tank, or a satellite that outlives the mission coasting.

        Coasting is proven optimal there up to the stage ``coast_certain_stages`` (see the module).
        """
        outlives = (steps_left <= self.coast_certain_stages) & task_model.outlives(self.task, states, steps_left)
        return (states.dv_left_m_s <= 0.0) | outlives

    def burns_m_s(self, states: BatchState, steps_left: NDArray[np.intp]) -> FloatArray:
        """The one-step DP policy's burns [m/s]: argmax_a r_a + V_{k-1}(successor_a) (`q_values`)."""
        sizes = np.asarray(self.config.burn_sizes_m_s, dtype=np.float64)
        return sizes[np.argmax(self.q_values(states, steps_left), axis=1)]

    def value(self, perigee_km: Any, apogee_km: Any, dv_left_m_s: Any, steps_left: Any) -> FloatArray:
        """The optimum's expected return from a state [days] (arrays broadcast).

        The one-step look-ahead of the policy, max_a r_a + V_{k-1}(successor), so
        it is what `DPPolicy` expects to earn from there.

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
        k = k.ravel().astype(np.intp)
        states = task_model.states_at_orbits(self.model.task, hp.ravel(), ha.ravel(), dv.ravel(), horizon - k)
        return self.q_values(states, k).max(axis=1).reshape(shape)


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


def _transitions(model: DPModel, axes: _Axes, decision_rows: int) -> tuple[NDArray[np.float32], list[Any], Any]:
    """Rewards (actions, states), the actions' interpolation matrices and the tail's coast matrix.

    The actions are the coast first (if the config has one), then the burns in
    the config's order; the burns' matrices cover the states that ever decide
    (the first ``decision_rows``). Coasts from the life levels up to the
    horizon + 1 land on the level below (checked) and need no matrix; coasts
    from the tail do where its states decide (None otherwise).
    """
    config = model.config
    n, unit_rows = axes.size, axes.unit_levels * axes.plane
    has_coast = 0.0 in config.burn_sizes_m_s
    burns = [b for b in config.burn_sizes_m_s if b != 0.0] if has_coast else list(config.burn_sizes_m_s)
    actions = [0.0] * has_coast + burns
    rewards = np.zeros((len(actions), n), np.float32)
    # Each matrix is filled in place: at most 8 entries a row, reserved (np.empty: untouched pages
    # take no memory) so that no chunk lists are joined at the end, which doubled the peak.
    index_dtype = np.int32 if 8 * n < np.iinfo(np.int32).max else np.int64
    counts = [np.zeros(n, np.uint8) for _ in actions]
    indices = [np.empty(8 * n, index_dtype) for _ in actions]
    data = [np.empty(8 * n, np.float32) for _ in actions]
    filled = [0 for _ in actions]
    down = axes.life_per_step * axes.plane
    for start in range(0, n, CHUNK_STATES):
        rows = np.arange(start, min(start + CHUNK_STATES, n))
        states = _grid_states(model, axes, rows)
        alive = states.tau > 0.0
        for a, burn in enumerate(actions):
            coasting = has_coast and a == 0
            if not coasting and start >= decision_rows:
                continue
            step = model.step(states, burn)
            index, weight = _interpolation(axes, step.state.label, step.life, step.state.dv_left_m_s)
            keep = (weight > 0.0) & alive[:, None]
            rewards[a, rows] = np.where(alive, step.reward, 0.0)
            if coasting:
                unit = alive & (rows < unit_rows) & (rows >= down)
                assert np.all(keep[unit].sum(axis=1) == 1), "a coast between life levels must land on a level"
                assert np.all(index[unit][keep[unit]] == rows[unit] - down), "a coast moves one step down"
                keep &= (rows >= unit_rows)[:, None]
            keep &= (rows < decision_rows)[:, None]
            counts[a][rows] = keep.sum(axis=1)
            begin, end = filled[a], filled[a] + int(counts[a][rows].sum())
            indices[a][begin:end] = index[keep]
            data[a][begin:end] = weight[keep]
            filled[a] = end
    matrices = []
    for a in range(len(actions)):
        indptr = np.concatenate([np.zeros(1, index_dtype), np.cumsum(counts[a], dtype=index_dtype)])
        matrix = sp.csr_matrix((data[a][: filled[a]], indices[a][: filled[a]], indptr), shape=(n, n))
        # One index type for both, so that the stages' row prefixes copy nothing.
        assert matrix.indptr.dtype == matrix.indices.dtype == index_dtype
        matrices.append(matrix)
    tail_coast = None
    if has_coast:
        coast_matrix = matrices.pop(0)
        tail_coast = coast_matrix[unit_rows:] if decision_rows > unit_rows else None
    return rewards, matrices, tail_coast


def _prefix(matrix: Any, rows: int) -> Any:
    """The first ``rows`` rows of a CSR matrix, sharing its arrays."""
    return sp.csr_matrix((matrix.data, matrix.indices, matrix.indptr[: rows + 1]), shape=(rows, matrix.shape[1]))


#: The disk cache's kind for DP solutions.
CACHE_KIND = "dp"


def _cache_description(config: OrbitRaisingConfig, grid: tuple[int, int, int], density_scale: float) -> str | None:
    return cache.describe((config, grid, density_scale))


def _tail_states(model: DPModel, axes: _Axes) -> BatchState:
    """The states of the life axis' tail (above the horizon + 1)."""
    return _grid_states(model, axes, np.arange(axes.unit_levels * axes.plane, axes.size))


@lru_cache(maxsize=4)
def _solve(config: OrbitRaisingConfig, grid: tuple[int, int, int], density_scale: float, progress: bool) -> DPSolution:
    description = _cache_description(config, grid, density_scale)
    arrays = cache.load(CACHE_KIND, description)
    if arrays is not None:
        if progress:
            print("dp: solution read from the disk cache", file=sys.stderr)
        return DPSolution.from_arrays(config, grid, density_scale, arrays)
    solution = _backward_induction(config, grid, density_scale, progress)
    # Stored uncompressed: the stages are compressed already.
    cache.store(CACHE_KIND, description, solution.to_arrays(), compress=False)
    return solution


def _backward_induction(
    config: OrbitRaisingConfig, grid: tuple[int, int, int], density_scale: float, progress: bool
) -> DPSolution:
    start = time.perf_counter()
    model = DPModel(config, density_scale)
    axes = _axes(model, grid)
    n, plane, unit_rows = axes.size, axes.plane, axes.unit_levels * axes.plane
    horizon = config.horizon_steps
    has_coast = 0.0 in config.burn_sizes_m_s
    certain = _coast_certain_stages(model) if has_coast else 0
    rows = np.array([0] + [(k * axes.life_per_step + 1) * plane if k <= certain else n for k in range(1, horizon + 1)])
    rewards, matrices, tail_coast = _transitions(model, axes, int(rows.max()))
    if progress:
        print(f"dp: {n} states x {len(rewards)} actions built in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    down = axes.life_per_step * plane
    # Sums of the coasts' days along the life levels: V_k = C[n] - C[n - k] where n >= k.
    cumulative = np.zeros(unit_rows, np.float32)
    if has_coast:
        levels = rewards[0, :unit_rows].astype(np.float64).reshape(axes.unit_levels, plane)
        for residue in range(axes.life_per_step):
            levels[residue :: axes.life_per_step] = np.cumsum(levels[residue :: axes.life_per_step], axis=0)
        cumulative = levels.ravel().astype(np.float32)
    # Values are stored as uint16 in steps of VALUE_QUANTUM_DAYS, far below the grid's own
    # error, each stage compressed (see the module).
    stages = StageValues(rows)
    top = np.iinfo(np.uint16).max * VALUE_QUANTUM_DAYS
    solution = DPSolution(
        config,
        density_scale,
        grid,
        0.0,
        model,
        axes,
        stages,
        rows,
        cumulative,
        certain,
        _tail_states(model, axes),
    )
    # The tail's states that a burn from a deciding state lands next to (the others are never read).
    referenced = max((int(m.indices.max(initial=0)) for m in [*matrices, tail_coast] if m is not None), default=0)
    tail_rows = np.arange(unit_rows, max(unit_rows, (referenced // plane + 1) * plane))
    v, new = np.zeros(n, np.float32), np.zeros(n, np.float32)
    scratch = np.empty(n, np.float32)
    for k in range(1, horizon + 1):
        r = int(rows[k])
        best = new[:r]
        if has_coast:
            # Coasts move one life level down (exactly) from the levels up to the horizon + 1.
            below = min(r, unit_rows)
            best[:down] = rewards[0, :down]
            np.add(rewards[0, down:below], v[: below - down], out=best[down:below])
            if r > unit_rows:
                np.add(rewards[0, unit_rows:r], tail_coast[: r - unit_rows] @ v, out=best[unit_rows:])
            burn_rewards = rewards[1:]
        else:
            best.fill(-np.inf)
            burn_rewards = rewards
        for reward, matrix in zip(burn_rewards, matrices, strict=True):
            q = _prefix(matrix, r) @ v
            q += reward[:r]
            np.maximum(best, q, out=best)
        if r < n:
            np.subtract(cumulative[r:unit_rows], cumulative[r - k * down : unit_rows - k * down], out=new[r:unit_rows])
            new[tail_rows] = solution.coast_days(k, tail_rows)
        stored = scratch[:r]
        np.maximum(best, 0.0, out=stored)
        stored *= 1.0 / VALUE_QUANTUM_DAYS
        np.rint(stored, out=stored)
        # The values grow with the steps left (every coast earns >= 0 days): checked on the last stage.
        if k == horizon and stored.max(initial=0.0) > np.iinfo(np.uint16).max:
            raise ValueError(f"values above {top:g} days: horizon too long")
        stages.append(stored.astype(np.uint16))
        v, new = new, v
        if progress and k % 73 == 0:
            print(f"dp: stage {k}/{horizon}, {time.perf_counter() - start:.1f} s", file=sys.stderr)
    stages.finish()
    solution.solve_s = time.perf_counter() - start
    return solution


#: Steps from the mission's start in which the rollout policy decides by rollouts; later, and
#: wherever the tank is empty or coasting is proven optimal, it acts as the base DP policy.
ROLLOUT_STEPS = 20
#: The base policy's burns recorded per rollout for the burn-early continuations.
ROLLOUT_MAX_BURNS = 16
#: A candidate replaces the base policy's action only if it earns more than this [days]: the
#: rollout plans from the decoded observation, whose heights located again on the curves sit up
#: to some 30 m from the env's. Measured on the 1000 evaluation episodes: with 1e-9 the rollout
#: lost to the base on 1 (OrbitRaising-v0, 0.003 day) and 4 (the continuous variant, up to 0.29
#: day) of them; with 0.005 on 0 and 2 (up to 0.16 day).
ROLLOUT_TIE_DAYS = 0.005


def rollout_returns(
    solution: DPSolution,
    states: BatchState,
    prefix_m_s: FloatArray,
    steps_left: NDArray[np.intp],
    last_step: float = np.inf,
) -> FloatArray:
    """Exact returns of burning ``prefix_m_s`` (rows, m) on the next m steps, then the best continuation.

    The continuations, played in the task model (no interpolation): the base DP policy
    to the end (a choice only while there is one, `DPSolution.no_choice`; then the coasts' days
    summed exactly), and the base policy's first j burns on consecutive steps, then
    coasting, for j = 0, 1, ... (the base's deferred burns brought forward), among
    those whose burns end before step ``last_step`` (after it the rollout policy acts
    as the base). ``states`` is not changed.

    Args:
        solution: The base policy's DP solution.
        states: The states (n satellites).
        prefix_m_s: The burns to make first, shape (n, m) [m/s].
        steps_left: Steps left in the mission, shape (n,).
        last_step: Burns of the burn-early continuations happen before this step.

    Returns:
        The returns [days], shape (n,).
    """
    task = solution.task
    s = states.copy()
    k = np.asarray(steps_left, dtype=np.intp).copy()
    total = np.zeros(s.size)
    for column in np.asarray(prefix_m_s, dtype=np.float64).reshape(s.size, -1).T:
        going = (s.tau > 0.0) & (k > 0)
        result = task_model.step(task, s, np.where(going, column, 0.0))
        total += np.where(going, result.reward, 0.0)
        k -= going
    origin, origin_k, origin_total = s.copy(), k.copy(), total.copy()
    burns = np.zeros((s.size, ROLLOUT_MAX_BURNS))
    count = np.zeros(s.size, np.intp)
    alive = (s.tau > 0.0) & (k > 0)
    done = alive & solution.no_choice(s, k)
    if done.any():
        total[done] += task_model.lookahead(task, s.take(done), 0.0, k[done])[0]
    active = np.flatnonzero(alive & ~done)
    while active.size:
        # The base policy on the satellites that still have a choice, all at the same stages
        # when the states came from one step of a vector env (one stage read per step).
        batch = s.take(active)
        result = task_model.step(task, batch, solution.burns_m_s(batch, k[active]))
        total[active] += result.reward
        burned = (np.asarray(result.burn_m_s) > 0.0) & (count[active] < ROLLOUT_MAX_BURNS)
        recorded = active[burned]
        burns[recorded, count[recorded]] = np.asarray(result.burn_m_s)[burned]
        count[recorded] += 1
        k[active] -= 1
        s.put(active, batch)
        alive = (batch.tau > 0.0) & (k[active] > 0)
        done = alive & solution.no_choice(batch, k[active])
        if done.any():
            finished = active[done]
            total[finished] += task_model.lookahead(task, batch.take(done), 0.0, k[finished])[0]
        active = active[alive & ~done]
    # The burn-early continuations, grown one burn at a time: after j burns, coast to the end.
    rows = np.flatnonzero((origin.tau > 0.0) & (origin_k > 0))
    early, early_k, early_total = origin.take(rows), origin_k[rows], origin_total[rows]
    room = last_step - origin.steps[rows]
    for j in range(int(count.max(initial=0)) + 1):
        coasting = task_model.lookahead(task, early, 0.0, early_k)[0]
        np.maximum.at(total, rows, early_total + coasting)
        more = (count[rows] > j) & (room > j) & (early.tau > 0.0) & (early_k > 0)
        if not more.any():
            break
        rows, early, early_k, early_total, room = (
            rows[more],
            early.take(more),
            early_k[more],
            early_total[more],
            room[more],
        )
        result = task_model.step(task, early, burns[rows, j])
        early_total = early_total + result.reward
        early_k = early_k - 1
    return total


class DPPolicy(Predicts):
    """The optimum's policy, in Stable-Baselines3's ``predict`` protocol.

    It recovers the state from the observation (heights, delta-v left -> mass by
    the rocket equation, steps left from the mission clock) and takes
    argmax_a r_a + V_{k-1}(successor_a) with the env's own step.

    Args:
        config: The env's config (default: ``OrbitRaisingConfig()``).
        grid: The DP grid (see `solve`).
        density_scale: The density scale the planner knows.
        solution: A solution to act on, instead of solving (its config wins).
        lookahead: Decisions taken exactly before the grid's values are read: 1 (the
            default) reads V_{k-1} at each action's successor; 2 takes the max over the
            next action too, r_a + max_b (r_b + V_{k-2}), so that the grid's
            interpolation enters one step later. On 200 evaluation starts
            (``orbit-env evaluate --certify``'s search) 2 halves the mean gap found, from
            0.047 to 0.025 day (worst 1.49 to 1.15 days), with four q-value evaluations per step.
        rollout: 0 (the default): act on the grid's values as ``lookahead`` says. 1 or 2:
            a rollout policy on the one-step DP policy (the base): in the first
            ``rollout_steps`` steps, wherever there is a choice, every action (1) or every
            pair of actions on the next two steps (2) is played in the task model and
            followed by the best of the base policy to the end and the base's burns
            brought forward (`rollout_returns`), all exact; the first action of the best
            is taken. Deterministic: it earns at least the base's return from the state it
            plans from, up to the continuations it cannot follow later (see docs/dp.md).
        rollout_steps: The steps from the mission's start in which the rollout decides.
    """

    name = "dp"

    def __init__(
        self,
        config: OrbitRaisingConfig | None = None,
        *,
        grid: tuple[int, int, int] = DEFAULT_GRID,
        density_scale: float = 1.0,
        solution: DPSolution | None = None,
        lookahead: int = 1,
        rollout: int = 0,
        rollout_steps: int = ROLLOUT_STEPS,
    ) -> None:
        if lookahead not in (1, 2):
            raise ValueError(f"lookahead={lookahead!r} is invalid; allowed: 1 or 2")
        if rollout not in (0, 1, 2) or isinstance(rollout, bool):
            raise ValueError(f"rollout={rollout!r} is invalid; allowed: 0, 1 or 2")
        if rollout and lookahead != 1:
            raise ValueError(
                f"lookahead={lookahead!r} with rollout={rollout!r}: the rollout's base looks one step ahead"
            )
        if not (isinstance(rollout_steps, (int, np.integer)) and rollout_steps >= 0):
            raise ValueError(f"rollout_steps={rollout_steps!r} is invalid; allowed: an integer >= 0")
        self.solution = solution if solution is not None else solve(config, grid=grid, density_scale=density_scale)
        self.config = self.solution.config
        self.lookahead = lookahead
        self.rollout = int(rollout)
        self.rollout_steps = int(rollout_steps)

    def burns_m_s(self, observation: Any) -> FloatArray:
        """The burns chosen for a batch of observations (n, 7) or one (7,), as an array (n,) [m/s]."""
        sizes = np.asarray(self.config.burn_sizes_m_s, dtype=np.float64)
        states = task_model.decode(self.solution.task, observation)
        steps_left = (self.config.horizon_steps - states.steps).astype(np.intp)
        if self.lookahead == 1:
            q = self.solution.q_values(states, steps_left)
        else:
            q = np.empty((states.size, sizes.size))
            for a, burn in enumerate(self.config.burn_sizes_m_s):
                step = self.solution.model.step(states, burn)
                q[:, a] = step.reward + self.solution.q_values(step.state, steps_left - 1).max(axis=1)
            q[(steps_left <= 0) | (states.tau <= 0.0)] = 0.0
        burns = sizes[np.argmax(q, axis=1)]
        if self.rollout:
            deciding = (steps_left > 0) & (states.tau > 0.0) & (states.steps < self.rollout_steps)
            rows = np.flatnonzero(deciding & ~self.solution.no_choice(states, steps_left))
            if rows.size:
                burns[rows] = self._improve(states.take(rows), steps_left[rows], burns[rows])
        return burns

    def _improve(self, states: BatchState, steps_left: NDArray[np.intp], base_m_s: FloatArray) -> FloatArray:
        """The rollout's burns: the best first burn of the candidates (the base's where none earns more)."""
        sizes = np.asarray(self.config.burn_sizes_m_s, dtype=np.float64)
        n, m = states.size, sizes.size
        prefixes = sizes[:, None] if self.rollout == 1 else np.stack(np.meshgrid(sizes, sizes, indexing="ij"), -1)
        prefixes = prefixes.reshape(-1, self.rollout)
        per_row = prefixes.shape[0]
        every = np.arange(n)
        returns = rollout_returns(
            self.solution,
            states.take(np.repeat(every, per_row)),
            np.tile(prefixes, (n, 1)),
            np.repeat(steps_left, per_row),
            self.rollout_steps,
        ).reshape(n, m, -1)
        first = returns.max(axis=2)
        base = np.abs(base_m_s[:, None] - sizes).argmin(axis=1)
        best = np.argmax(first, axis=1)
        value = first[every, base]
        better = first[every, best] > value + ROLLOUT_TIE_DAYS
        return np.where(better, sizes[best], base_m_s)

    def actions_of(self, observation: Any) -> NDArray[np.int64]:
        """The index of the config's burn size chosen (`burns_m_s`) for observations (7,) or (n, 7): (n,)."""
        burns = self.burns_m_s(observation)
        return np.abs(burns[:, None] - np.asarray(self.config.burn_sizes_m_s)).argmin(axis=1).astype(np.int64)
