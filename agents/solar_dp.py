r"""The optimum of the solar task per episode: backward induction on the episode's own solar path.

It knows the Sun's future (the record after the start day), which no agent does: an upper
yardstick. SI units inside; values and rewards in days, as the env's.

The grid spans the orbit's point on the universal curves, the label $\mu$ (`grid_labels`) and
$\tau = \ln(1 + \nu / \nu_{ref})$ (uniform, `TAU_POINTS`), and the delta-v left on the levels the
burns land on (the tank less whole multiples of the smallest burn, and empty). A step is the
solar task's own: a burn (`orbit_env.envs.task.burn`, computed once per task for every grid point
and burn), then a month of decay by the episode's drag clock (`orbit_env.envs.solar_task.coast_block`,
per stage, at three masses and interpolated between them in the drag parameter), and at the end
the rule (`orbit_env.envs.solar_task.disposal` on every grid point: the cheapest compliant burn's
cost, or the penalty). Then $U_k = r_{coast} + V_{k+1}(\text{coast})$ (interpolated in $\tau$) and
$V_k = \max_a (-\text{cost}\,a + U_k(\text{burn}_a))$ (bilinear in $(\mu, \tau)$).

`SolarDPPolicy` acts in the environment by the one-step look-ahead on $U_k$ from the true state:
its return is what the `dp` row reports (a return really flown, so a lower bound of the optimum),
and $V_0$ at the start the grid's estimate of the optimum; their gap is the certificate
(`orbit-env evaluate --certify`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.decay.curves import NU_REF, nu_per_revolution
from orbit_env.envs import solar_task
from orbit_env.envs import task as task_model
from orbit_env.envs.rocket import mass_from_delta_v_left_kg
from orbit_env.envs.solar_task import SolarTask
from orbit_env.envs.state import BatchState

FloatArray = NDArray[np.float64]

#: Points of the tau axis (uniform from 0 to the top of the reachable orbits).
TAU_POINTS = 160
#: Points of the label axis (quantiles of the labels of the orbits a mission can fly).
LABEL_POINTS = 48
#: Lowest label on the grid: below it orbits are circular to within metres (the known-density DP's floor).
MU_LOW = -14.0
#: Masses at which a month's coast is computed per stage (full, half and empty tank; interpolated between).
COAST_MASSES = 3
#: Months from the start in which `SolarDP.rollout_burns_m_s` decides by flying every burn size to the end.
ROLLOUT_STEPS = 6


#: The continuous twin's DP burns every multiple of this up to the largest burn [m/s] (the discrete task's
#: smallest burn, 5 m/s, halved): a lower bound of the continuous optimum, as the known-density continuous
#: variant's DP on its 10 m/s grid (`orbit_env.agents.evaluate.CONTINUOUS_DP_STEP_M_S`).
CONTINUOUS_DP_STEP_M_S = 2.5


def dp_task(task: SolarTask) -> SolarTask:
    """The task the DP solves: the task itself, or for the continuous twin burns on a `CONTINUOUS_DP_STEP_M_S` grid.

    The DP's policy asks for burns [m/s], which either task flies as they are.
    """
    if not task.continuous:
        return task
    top = task.config.max_burn_m_s
    sizes = tuple(float(b) for b in np.arange(0.0, top + 1e-9, CONTINUOUS_DP_STEP_M_S))
    return replace(task, config=replace(task.config, burn_sizes_m_s=sizes))


@dataclass(frozen=True)
class SolarGrid:
    """The DP's axes and the burns' transitions on them (the same for every episode of a task)."""

    labels: FloatArray  # (L,)
    taus: FloatArray  # (T,)
    levels: FloatArray  # (K,) delta-v left [m/s], ascending, 0 first
    perigee_m: FloatArray  # (L, T) heights of the grid points
    apogee_m: FloatArray
    nu: FloatArray  # (L, T)
    burn_index: NDArray[np.intp]  # (A, K) level after action a from level k
    burn_made: FloatArray  # (A, K) the burn made [m/s]
    burn_points: dict[float, tuple[FloatArray, FloatArray]]  # made -> (label, tau) after it, each (L, T)


@lru_cache(maxsize=4)
def solar_grid(task: SolarTask) -> SolarGrid:
    """The grid of a task (cached: the burns' relocations are the same for every episode)."""
    curves = task.curves
    config = task.config
    # Labels of the orbits a mission flies: perigees 100-600 km, apogees up to the tank's reach.
    hp = np.linspace(REENTRY_ALTITUDE_M + 5e3, config.start_perigee_km[1] * 1e3 + 20e3, 40)
    span = np.geomspace(10.0, 1200e3, 60)
    hp_s, span_s = np.meshgrid(hp, span)
    labels = np.maximum(curves.locate(hp_s.ravel(), (hp_s + span_s).ravel()).label, MU_LOW)
    label_axis = np.unique(np.quantile(labels, np.linspace(0.0, 1.0, LABEL_POINTS)))
    label_axis[0] = MU_LOW
    top = curves.locate(np.array([config.start_perigee_km[1] * 1e3]), np.array([1600e3])).tau
    tau_axis = np.linspace(0.0, float(top[0]), TAU_POINTS)
    mu, tau = np.meshgrid(label_axis, tau_axis, indexing="ij")
    perigee, apogee, _ = curves.at(mu, tau)
    capacity = config.delta_v_capacity_m_s
    quantum = min(b for b in config.burn_sizes_m_s if b > 0.0)
    full = capacity - quantum * np.arange(int(capacity // quantum) + 1)
    levels = np.unique(np.concatenate([[0.0], full[full > 1e-9]]))
    sizes = np.array(config.burn_sizes_m_s)
    burn_made = np.minimum(sizes[:, None], levels[None, :])
    after = levels[None, :] - burn_made
    burn_index = np.abs(after[:, :, None] - levels[None, None, :]).argmin(axis=2)
    points: dict[float, tuple[FloatArray, FloatArray]] = {}
    for made in np.unique(burn_made[burn_made > 0.0]):
        states = task_model.states_on_curves(task, mu.ravel(), tau.ravel(), capacity, 0.0)
        task_model.burn(task, states, float(made))
        points[float(made)] = (
            np.maximum(states.label, MU_LOW).reshape(mu.shape),
            states.tau.copy().reshape(mu.shape),
        )
    return SolarGrid(
        label_axis, tau_axis, levels, perigee, apogee, NU_REF * np.expm1(tau), burn_index, burn_made, points
    )


def _weights(axis: FloatArray, x: FloatArray) -> tuple[NDArray[np.intp], FloatArray]:
    """Lower cell index and upper weight of x on a sorted axis, clamped to its ends."""
    x = np.clip(x, axis[0], axis[-1])
    i = np.clip(np.searchsorted(axis, x, side="right") - 1, 0, axis.size - 2)
    return i, (x - axis[i]) / (axis[i + 1] - axis[i])


def _corners(
    grid: SolarGrid, label: FloatArray, tau: FloatArray
) -> tuple[NDArray[np.intp], FloatArray, NDArray[np.intp], FloatArray]:
    """The grid cells of points (label, tau) and their upper weights (with an axis for the levels)."""
    i, wi = _weights(grid.labels, np.maximum(label, MU_LOW))
    j, wj = _weights(grid.taus, tau)
    return i, wi[..., None], j, wj[..., None]


def _interpolate(
    table: FloatArray, i: NDArray[np.intp], wi: FloatArray, j: NDArray[np.intp], wj: FloatArray
) -> FloatArray:
    """``table`` (L, T, K) bilinear in (label, tau) at `_corners`: shape (*S, K)."""
    return (1.0 - wi) * ((1.0 - wj) * table[i, j] + wj * table[i, j + 1]) + wi * (
        (1.0 - wj) * table[i + 1, j] + wj * table[i + 1, j + 1]
    )


def _grid_states(task: SolarTask, grid: SolarGrid, dv_left: float, day: float) -> BatchState:
    """The grid's points as states of the task's satellite with ``dv_left`` on day ``day``."""
    mu, tau = np.meshgrid(grid.labels, grid.taus, indexing="ij")
    states = task_model.states_on_curves(task, mu.ravel(), tau.ravel(), dv_left, 0.0)
    states.start_day = day
    return states


class SolarDP:
    """Backward induction for one episode: the solar path from ``start_day`` (see the module).

    Args:
        task: The solar task.
        start_day: The episode's first day (clock days; `orbit_env.envs.solar_task.start_options`).
    """

    def __init__(self, task: SolarTask, start_day: float) -> None:
        self.task = task
        self.start_day = float(start_day)
        self.grid = grid = solar_grid(task)
        # Where each burn lands, as interpolation corners (the same for every stage).
        self._burn_corners = {made: _corners(grid, *point) for made, point in grid.burn_points.items()}
        config, block = task.config, task.mission.block_days
        n_l, n_t, n_k = grid.labels.size, grid.taus.size, grid.levels.size
        cost = config.propellant_cost_per_m_s
        # The rule at the end, on every point, at the mass of a half-full tank (the judgement's mass
        # moves lives by a few tenths of a percent over the tank).
        end_day = self.start_day + task.mission_days
        ending = _grid_states(task, grid, 0.5 * grid.levels[-1], end_day)
        need, _ = solar_task.disposal(task, ending)
        need = need.reshape(n_l, n_t)
        # As the task charges it (`solar_task._rule_at_the_end`): the burn's propellant, or the penalty alone
        # where the tank cannot pay the burn (no burn is made then).
        value = np.where(
            need[:, :, None] > grid.levels[None, None, :] + 1e-9, -task.penalty_days, -cost * need[:, :, None]
        )
        value[:, 0, :] = 0.0  # re-entered: nothing left to dispose of
        # Masses for the coasts (tank full, half, empty) and each level's drag parameter.
        masses = mass_from_delta_v_left_kg(
            np.linspace(grid.levels[-1], 0.0, COAST_MASSES), config.dry_mass_kg, config.exhaust_velocity_m_s
        )
        drag_area = config.drag_coefficient * config.area_m2
        c_nodes = drag_area / masses  # ascending
        c_levels = drag_area / mass_from_delta_v_left_kg(grid.levels, config.dry_mass_kg, config.exhaust_velocity_m_s)
        c_index, c_weight = _weights(c_nodes, c_levels)
        label_flat = np.repeat(grid.labels, n_t)
        self.after_burn: list[FloatArray] = [np.empty(0)] * config.horizon_steps
        for k in range(config.horizon_steps - 1, -1, -1):
            day = self.start_day + k * block
            taus_c, lived_c = [], []
            for c in c_nodes:
                after = solar_task.coast_block(
                    task.clock,
                    label_flat,
                    grid.nu.ravel(),
                    grid.perigee_m.ravel(),
                    grid.apogee_m.ravel(),
                    np.full(label_flat.size, nu_per_revolution(c, 1.0)),
                    np.full(label_flat.size, day),
                    float(block),
                )
                taus_c.append(after.tau.reshape(n_l, n_t))
                lived_c.append(after.lived_days.reshape(n_l, n_t))
            taus_c, lived_c = np.stack(taus_c), np.stack(lived_c)  # (C, L, T)
            # Each level's coast: between its two mass nodes.
            tau_k = (1.0 - c_weight)[None, None, :] * taus_c[c_index].transpose(1, 2, 0) + c_weight[
                None, None, :
            ] * taus_c[c_index + 1].transpose(1, 2, 0)
            lived_k = (1.0 - c_weight)[None, None, :] * lived_c[c_index].transpose(1, 2, 0) + c_weight[
                None, None, :
            ] * lived_c[c_index + 1].transpose(1, 2, 0)
            i, w = _weights(grid.taus, tau_k)  # (L, T, K)
            l_idx = np.arange(n_l)[:, None, None]
            k_idx = np.arange(n_k)[None, None, :]
            after = lived_k + (1.0 - w) * value[l_idx, i, k_idx] + w * value[l_idx, i + 1, k_idx]
            after[:, 0, :] = 0.0
            self.after_burn[k] = after
            value = self._decide(after)
        self.start_values = value

    def _decide(self, after: FloatArray) -> FloatArray:
        """V_k on the grid from U_k: the best of each action's cost plus U_k after its burn."""
        grid, cost = self.grid, self.task.config.propellant_cost_per_m_s
        best = after.copy()
        for a in range(1, grid.burn_index.shape[0]):
            for made in np.unique(grid.burn_made[a]):
                if made <= 0.0:
                    continue
                levels = np.flatnonzero(grid.burn_made[a] == made)
                # Only the levels the burn lands on are interpolated (each level's numbers are its own).
                corners = self._burn_corners[float(made)]
                q = _interpolate(after[:, :, grid.burn_index[a, levels]], *corners) - cost * made
                best[:, :, levels] = np.maximum(best[:, :, levels], q)
        best[:, 0, :] = 0.0
        return best

    def _bilinear(self, table: FloatArray, label: FloatArray, tau: FloatArray) -> FloatArray:
        """``table`` (L, T, K) at points (label, tau) of any shape S: shape (*S, K)."""
        return _interpolate(table, *_corners(self.grid, label, tau))

    def _at_level(self, values: FloatArray, dv_left: FloatArray) -> FloatArray:
        """Rows of ``values`` (n, K) interpolated at each row's delta-v left."""
        k, w = _weights(self.grid.levels, dv_left)
        rows = np.arange(values.shape[0])
        return (1.0 - w) * values[rows, k] + w * values[rows, k + 1]

    def value(self, state: BatchState) -> FloatArray:
        """V_0 at the states' starts: the grid's estimate of the optimum's return [days]."""
        return self._at_level(self._bilinear(self.start_values, state.label, state.tau), state.dv_left_m_s)

    def rollout_burns_m_s(self, state: BatchState) -> FloatArray:
        """The rollout policy on the DP: early on, the burn whose mission flown on with `burns_m_s` returns most.

        In the first `ROLLOUT_STEPS` months every burn size is flown to the mission's end (the task's own
        steps, not the grid), the DP policy acting after it; later the DP policy acts alone. Every
        candidate's return is flown, and `burns_m_s`'s own burn is a candidate that wins ties, so the
        rollout's return is never below the DP policy's (policy improvement on a deterministic task).
        """
        base = self.burns_m_s(state)
        if int(state.steps[0]) >= ROLLOUT_STEPS:
            return base
        from orbit_env.agents.solar import fly_from

        sizes = np.asarray(self.task.config.burn_sizes_m_s, dtype=np.float64)
        n, a = state.size, sizes.size
        first = [np.tile(sizes, n)]  # the first step: every size from every state; then the DP's policy

        def act(flying: BatchState) -> FloatArray:
            return first.pop() if first else self.burns_m_s(flying)

        total = fly_from(self.task, state.take(np.repeat(np.arange(n), a)), act).returns.reshape(n, a)
        own = np.abs(sizes[None, :] - base[:, None]).argmin(axis=1)
        best = total.argmax(axis=1)
        rows = np.arange(n)
        keep = total[rows, own] >= total[rows, best] - 1e-9
        return np.where(keep, base, sizes[best])

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """The burn each state should request now: the one-step look-ahead on U_k of its step."""
        task = self.task
        step = int(state.steps[0])
        after = self.after_burn[min(step, len(self.after_burn) - 1)]
        best_value = np.full(state.size, -np.inf)
        best = np.zeros(state.size)
        for size in task.config.burn_sizes_m_s:
            trial = state.copy()
            made = task_model.burn(task, trial, np.full(state.size, size))
            q = self._at_level(self._bilinear(after, trial.label, trial.tau), trial.dv_left_m_s)
            q = q - task.config.propellant_cost_per_m_s * made
            better = q > best_value + 1e-9
            best_value = np.where(better, q, best_value)
            best = np.where(better, size, best)
        return best
