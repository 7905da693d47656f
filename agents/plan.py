"""The continuous variant's yardstick: the DP policy's plan, refined by a search over burn sizes.

`OrbitRaisingContinuous-v0` burns any size up to 100 m/s, and its DP
(`orbit_env.agents.dp`) chooses among burns 10 m/s apart: a lower bound on its
optimum. The task is deterministic once the density is known, so from a state
the best action sequence can be searched for directly, every candidate played in
the task model (no interpolation), and then played open loop. `PlanPolicy` does
that:

1. the base, the DP policy on its 10 m/s burns, is played from the state to the
   end of its burns; its burns are the first plan (burns on the first
   ``window`` steps, or up to the base's last burn if later; coasting after them);
2. coordinate search: for each step size h in `PLAN_STEPS_M_S` (40 m/s down to
   0.16 m/s), sweeps over the plan's steps from the last to the first, where the
   satellite has a choice (propellant left, and not one that outlives the mission,
   where coasting is proven optimal: `orbit_env.agents.dp`), trying the burn
   +- h, h moved to or from the next step, and the burn swapped with the one
   `PLAN_SWAPS` steps later; a change is kept if it earns more. Sweeps repeat
   (up to `PLAN_SWEEPS`) while they gain. Every candidate is played from the
   state before its first changed step (kept per sweep: the sweep runs backwards,
   so those states stay valid) to the end of the plan, then the coasts' days are
   summed exactly;
3. the plan is played open loop, coasting after its burns. Each plan keeps the
   track the task model predicts to the mission's end (heights and delta-v left
   per step); an observation that matches a
   track (same step, heights within `TRACK_HEIGHT_M`, delta-v left within
   `TRACK_DV_M_S`) gets that plan's burn; any other is planned anew from its
   state. The decoded state is the env's up to the observation's float32
   rounding (`orbit_env.envs.task.decode`: some 0.1 m of apogee), so a track and
   the env stay close; the tolerances are wide (they date from a decode that
   was up to 1.3 km of apogee off), and the nearest track is taken.

The search starts from the base's own plan and keeps only gains, so a plan
earns at least the base's return in the task model from the decoded state. It
proves no optimum: `orbit-env evaluate --certify` is the independent check (a
random search from the policy's own plan, in the environment).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.agents.dp import DPPolicy
from orbit_env.agents.protocol import Predicts
from orbit_env.envs import task as task_model
from orbit_env.envs.state import BatchState

FloatArray = NDArray[np.float64]

#: The plan's burns are searched on at least this many steps from where it is made.
PLAN_WINDOW_STEPS = 60
#: Step sizes of the coordinate search, in turn [m/s].
PLAN_STEPS_M_S = (40.0, 20.0, 10.0, 5.0, 2.5, 1.25, 0.625, 0.3125, 0.15625)
#: A burn is tried swapped with the one this many steps later.
PLAN_SWAPS = (1, 2, 3, 5, 8)
#: Sweeps per step size at most (they stop once a sweep gains less than `PLAN_SWEEP_GAIN_DAYS`).
PLAN_SWEEPS = 3
#: A sweep that gains less than this over all satellites planned ends its step size [days].
PLAN_SWEEP_GAIN_DAYS = 1e-3
#: A change is kept if it earns more than this [days] (round-off of a played plan).
PLAN_TIE_DAYS = 1e-7
#: An observation follows a plan's track if its heights are within this of the track's [m]...
TRACK_HEIGHT_M = 30000.0
#: ... and its delta-v left within this [m/s] (a burn the env cuts differently leaves the track).
TRACK_DV_M_S = 0.05
#: Plans kept for lookup (the oldest batches are dropped beyond it).
PLAN_CACHE_ROWS = 16384


@dataclass(frozen=True)
class _Plans:
    """Plans made together: start steps (n,), burns (n, L), predicted tracks to the mission's end (n, M + 1, 3)."""

    start: NDArray[np.intp]
    burns: FloatArray
    track: FloatArray  # perigee [m], apogee [m], delta-v left [m/s] before each step's burn


def _features(states: BatchState) -> FloatArray:
    """What a track records of a state: perigee, apogee [m], delta-v left [m/s]."""
    return np.stack([states.perigee_m, states.apogee_m, states.dv_left_m_s], axis=-1)


class PlanPolicy(Predicts):
    """Open-loop plans refined from the DP policy's (see the module); SB3's ``predict`` protocol.

    Args:
        base: The DP policy whose plans are refined (its config is the continuous
            variant's with the DP's burn sizes; burns of any size up to
            ``max_burn_m_s`` are played).
        window: The plan's burns are searched on at least this many steps.
        steps_m_s: The coordinate search's step sizes [m/s], in turn.
        progress: Print a line per batch of plans to stderr.
    """

    name = "dp"

    def __init__(
        self,
        base: DPPolicy,
        *,
        window: int = PLAN_WINDOW_STEPS,
        steps_m_s: tuple[float, ...] = PLAN_STEPS_M_S,
        progress: bool = False,
    ) -> None:
        if not (isinstance(window, (int, np.integer)) and window >= 1):
            raise ValueError(f"window={window!r} is invalid; allowed: an integer >= 1")
        if not all(np.isfinite(h) and h > 0.0 for h in steps_m_s):
            raise ValueError(f"steps_m_s={steps_m_s!r} is invalid; allowed: sizes > 0 [m/s]")
        self.base = base
        self.solution = base.solution
        self.config = base.config
        self.task = self.solution.task
        # The task the plans act in: the same satellite, with the Box action (`Task.encode`).
        self._acting = task_model.Task(self.config, self.task.density, continuous=True)
        self.window = int(window)
        self.steps_m_s = tuple(float(h) for h in steps_m_s)
        self.progress = progress
        self._batches: list[_Plans] = []

    def burns_m_s(self, observation: Any) -> FloatArray:
        """The burns for a batch of observations (n, 7) or one (7,), as an array (n,) [m/s]."""
        states = task_model.decode(self.task, observation)
        horizon = self.config.horizon_steps
        steps = states.steps.astype(np.intp)
        burns = np.zeros(states.size)
        deciding = (steps < horizon) & (states.tau > 0.0)
        rows = np.flatnonzero(deciding & ~self.solution.no_choice(states, horizon - steps))
        if not rows.size:
            return burns
        found, planned = self._lookup(_features(states.take(rows)), steps[rows])
        burns[rows[found]] = planned[found]
        new = rows[~found]
        if new.size:
            plans = self._plan(states.take(new))
            burns[new] = plans.burns[:, 0]
        return burns

    def actions_of(self, observation: Any) -> Any:
        """Box actions a = burn / max burn for observations (7,) or (n, 7): (n, 1)."""
        return self._acting.encode(self.burns_m_s(observation))

    def _lookup(self, features: FloatArray, steps: NDArray[np.intp]) -> tuple[NDArray[np.bool_], FloatArray]:
        """The burn of the plan whose track each state follows (newest plans first), and which were found."""
        found = np.zeros(steps.size, dtype=bool)
        burns = np.zeros(steps.size)
        scale = np.array([TRACK_HEIGHT_M, TRACK_HEIGHT_M, TRACK_DV_M_S])
        for plans in reversed(self._batches):
            rows = np.flatnonzero(~found)
            if not rows.size:
                break
            length, last = plans.burns.shape[1], plans.track.shape[1] - 1
            offset = steps[rows, None] - plans.start[None, :]
            on = (offset >= 0) & (offset <= last)
            if not on.any():
                continue
            at = np.clip(offset, 0, last)
            distance = np.abs(plans.track[np.arange(plans.start.size)[None, :], at] - features[rows, None, :]) / scale
            distance = np.where(on, distance.max(axis=2), np.inf)
            nearest = distance.argmin(axis=1)
            hit = distance[np.arange(rows.size), nearest] <= 1.0
            which, when = nearest[hit], at[np.arange(rows.size), nearest][hit]
            burns[rows[hit]] = np.where(when < length, plans.burns[which, np.minimum(when, length - 1)], 0.0)
            found[rows[hit]] = True
        return found, burns

    def _plan(self, states: BatchState) -> _Plans:
        """Plans from ``states`` (see the module), kept for `_lookup`."""
        start_time = time.perf_counter()
        burns = self._base_plan(states)
        best = self._play(states, burns)
        base = best.copy()
        # Or coasting, if that earns more (a plan made where an earlier plan ended coasts on).
        coasting = self._play(states, np.zeros((states.size, 0)))
        better = coasting > best
        burns[better], best[better] = 0.0, coasting[better]
        for h in self.steps_m_s:
            for _ in range(PLAN_SWEEPS):
                if self._sweep(states, burns, best, h) < PLAN_SWEEP_GAIN_DAYS:
                    break
        # The track to the mission's end: after its burns the plan coasts, and so does the policy.
        horizon = self.config.horizon_steps
        steps_left = int(horizon - states.steps.min())
        track = np.empty((states.size, steps_left + 1, 3))
        for t, s, _ in self._walk(states, burns, steps_left):
            track[:, t] = _features(s)
        plans = _Plans(start=states.steps.astype(np.intp), burns=burns, track=track)
        self._batches.append(plans)
        while sum(p.start.size for p in self._batches) > PLAN_CACHE_ROWS and len(self._batches) > 1:
            self._batches.pop(0)
        if self.progress:
            print(
                f"plan: {states.size} satellites, {burns.shape[1]} steps, base {base.mean():.3f} -> "
                f"{best.mean():.3f} days, {time.perf_counter() - start_time:.1f} s",
                file=sys.stderr,
            )
        return plans

    def _base_plan(self, states: BatchState) -> FloatArray:
        """The base DP policy's burns from ``states`` (n, L): L = the window, or to its last burn."""
        horizon = self.config.horizon_steps
        s = states.copy()
        recorded = np.zeros((s.size, horizon))
        active = np.arange(s.size)
        for t in range(horizon):
            here = s.take(active)
            k = horizon - here.steps.astype(np.intp)
            choosing = (here.tau > 0.0) & (k > 0) & ~self.solution.no_choice(here, k)
            active, k = active[choosing], k[choosing]
            if not active.size:
                break
            batch = here.take(choosing)
            recorded[active, t] = task_model.step(self.task, batch, self.solution.burns_m_s(batch, k)).burn_m_s
            s.put(active, batch)
        burned = np.flatnonzero(recorded.any(axis=0))
        room = int(horizon - states.steps.min())
        length = min(max(self.window, int(burned.max(initial=-1)) + 1), max(room, 1))
        return recorded[:, :length].copy()

    def _walk(self, states: BatchState, burns: FloatArray, steps: int) -> Iterator[tuple[int, BatchState, FloatArray]]:
        """A plan played from ``states``: (t, the state before step t, the return earned before it), t = 0..steps.

        ``burns`` (rows, m) on consecutive steps, coasting past them; a satellite that
        re-entered or reached the horizon stays. The state yielded is stepped in place
        after it: copy what is kept.
        """
        horizon = self.config.horizon_steps
        s, total = states.copy(), np.zeros(states.size)
        for t in range(steps):
            yield t, s, total
            going = (s.tau > 0.0) & (s.steps < horizon)
            burn = np.where(going, burns[:, t] if t < burns.shape[1] else 0.0, 0.0)
            total = total + np.where(going, task_model.step(self.task, s, burn).reward, 0.0)
        yield steps, s, total

    def _play(self, states: BatchState, burns: FloatArray) -> FloatArray:
        """Returns of burning ``burns`` (rows, m) from ``states`` on consecutive steps, then coasting to the end."""
        *_, (_, s, total) = self._walk(states, burns, burns.shape[1])
        left = np.maximum(self.config.horizon_steps - s.steps, 0.0)
        alive = (s.tau > 0.0) & (left > 0.0)
        if alive.any():
            total[alive] += task_model.lookahead(self.task, s.take(alive), 0.0, left[alive])[0]
        return total

    def _sweep(self, states: BatchState, burns: FloatArray, best: FloatArray, h: float) -> float:
        """One backward sweep of the coordinate search at step size ``h``, in place; returns the days gained."""
        horizon, top = self.config.horizon_steps, self.config.max_burn_m_s
        length = burns.shape[1]
        # The states before each step under the current plan, and the rewards earned before them.
        before, earned = [], np.zeros((states.size, length))
        for t, s, total in self._walk(states, burns, length - 1):
            before.append(s.copy())
            earned[:, t] = total
        gained = 0.0
        for t in range(length - 1, -1, -1):
            at = before[t]
            rows = np.flatnonzero((at.tau > 0.0) & ~self.solution.no_choice(at, horizon - at.steps.astype(np.intp)))
            if not rows.size:
                continue
            now = burns[rows, t:]
            candidates = []
            for sign in (-1.0, 1.0):
                c = now.copy()
                c[:, 0] = np.clip(c[:, 0] + sign * h, 0.0, top)
                candidates.append(c)
            if t + 1 < length:
                for sign in (-1.0, 1.0):  # h from this step to the next, or back
                    c = now.copy()
                    moved = np.minimum(h, c[:, 0] if sign < 0 else c[:, 1])
                    c[:, 0] = np.clip(c[:, 0] + sign * moved, 0.0, top)
                    c[:, 1] = np.clip(c[:, 1] - sign * moved, 0.0, top)
                    candidates.append(c)
            for later in PLAN_SWAPS:
                if t + later < length:
                    c = now.copy()
                    c[:, [0, later]] = c[:, [later, 0]]
                    candidates.append(c)
            stack = np.stack(candidates, axis=1)
            n, m = stack.shape[:2]
            played = self._play(at.take(np.repeat(rows, m)), stack.reshape(n * m, -1)).reshape(n, m)
            played += earned[rows, t][:, None]
            pick = played.argmax(axis=1)
            top_return = played[np.arange(n), pick]
            better = top_return > best[rows] + PLAN_TIE_DAYS
            kept = rows[better]
            gained += float(np.sum(top_return[better] - best[kept]))
            burns[kept, t:] = stack[np.flatnonzero(better), pick[better]]
            best[kept] = top_return[better]
        return gained
