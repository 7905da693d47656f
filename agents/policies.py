"""Hand-coded policies for the orbit-raising environments.

Each answers Stable-Baselines3's ``predict(obs, state=None, episode_start=None,
deterministic=True) -> (action, state)`` for one observation of shape (7,) or a batch
(n, 7), in the discrete and the continuous variants alike. They recover the state
from the observation with the task model (`orbit_env.envs.task.decode`: the
orbit, the propellant, the clock, and the satellite from the environment's config,
as a flight engineer would) and plan with its functions at the nominal density.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.agents.protocol import Predicts
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M
from orbit_env.envs import task as task_model
from orbit_env.envs.config import DensityConfig, OrbitRaisingConfig
from orbit_env.envs.state import BatchState
from orbit_env.envs.task import Task
from orbit_env.physics.orbit import dv_for_apogee_m_s

FloatArray = NDArray[np.float64]


class BurnPolicy(Predicts):
    """Shared plumbing: decode observations into planning states, encode burns as actions.

    Args:
        config: The environment's config (satellite, burn sizes, horizon, cost).
        density: The environment's density; policies plan with its nominal scale.
        continuous: Whether the action space is the continuous ``Box(-1, 1)``.
    """

    name = "base"

    def __init__(
        self,
        config: OrbitRaisingConfig | None = None,
        density: DensityConfig | None = None,
        continuous: bool = False,
    ) -> None:
        self.task = Task.of(config, density, continuous).planning
        self.config = self.task.config
        self.continuous = self.task.continuous
        self.sizes = self.task.burn_sizes_m_s

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """The burn each satellite asks for [m/s] (subclasses)."""
        raise NotImplementedError

    def actions_of(self, observation: Any) -> Any:
        """Actions for observations (7,) or (n, 7): the burns' sizes' indices, or Box values (n, 1)."""
        return self.task.encode(self.burns_m_s(task_model.decode(self.task, observation)))


class NeverBurn(BurnPolicy):
    """Never fire the engine: the satellite decays as the paper's curves say."""

    name = "never"

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """No burn, ever."""
        return np.zeros(state.size)


class AllAtOnce(BurnPolicy):
    """Spend the whole budget at the start: the largest burn every step until the tank is empty."""

    name = "all_at_once"

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """The largest burn while propellant is left."""
        largest = self.config.max_burn_m_s if self.continuous else float(self.sizes.max())
        return np.where(state.dv_left_m_s > 1e-6, largest, 0.0)


class ApogeeThreshold(BurnPolicy):
    """The paper's elongated orbit: once the apogee has decayed below a threshold, raise it.

    Section 4: raising 360 x 700 km to 360 x 1000 km costs 78 m/s and multiplies the
    lifetime by 2.2. When the apogee is below ``threshold_km`` the policy asks for the
    burn that lifts it to ``target_km`` (cut to what the discrete sizes offer).
    """

    name = "apogee_threshold"

    def __init__(self, *args: Any, threshold_km: float = 700.0, target_km: float = 1000.0, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if not 100.0 < threshold_km <= target_km <= CURVES_MAX_APOGEE_M / 1e3:
            raise ValueError(f"need 100 < threshold_km <= target_km <= 4000, got {threshold_km!r}, {target_km!r}")
        self.threshold_m, self.target_m = threshold_km * 1e3, target_km * 1e3

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """The burn to the target apogee where the apogee is below the threshold."""
        perigee, apogee, dv_left = state.perigee_m, state.apogee_m, state.dv_left_m_s
        low = (apogee < self.threshold_m) & (dv_left > 1e-6)
        need = np.zeros_like(apogee)
        if low.any():
            target = np.maximum(self.target_m, apogee[low])
            need[low] = np.minimum(dv_for_apogee_m_s(perigee[low], apogee[low], target), dv_left[low])
        if not self.continuous:
            # The smallest discrete burn that reaches the target, or the largest there is.
            index = np.minimum(np.searchsorted(self.sizes, need - 1e-9), self.sizes.size - 1)
            need = np.where(need > 0.0, self.sizes[index], 0.0)
        return need


class Greedy(BurnPolicy):
    """One-step look-ahead with the decay simulator.

    For each burn it could make now it computes, with the task model, the return of
    making that burn and then never burning again until the mission's end
    (`orbit_env.envs.task.lookahead`: the days in orbit within the mission
    minus the propellant's cost, at the nominal density), and takes the best, coasting
    when no burn buys more days than it costs.
    """

    name = "greedy"

    def candidates(self) -> FloatArray:
        """Burns considered [m/s]: the discrete sizes, or a fine ladder for the continuous action."""
        if self.continuous:
            return np.linspace(0.0, self.config.max_burn_m_s, 21)
        return self.sizes

    def burns_m_s(self, state: BatchState) -> FloatArray:
        """The burn with the best return of burning now and coasting to the mission's end."""
        burns = self.candidates()
        steps_left = self.config.horizon_steps - state.steps
        score = np.stack([task_model.lookahead(self.task, state, burn, steps_left)[0] for burn in burns], axis=1)
        # The request, not the burn made: the env cuts it to the tank as the look-ahead did.
        return burns[np.argmax(score, axis=1)]


#: The hand-coded policies by their public names.
HAND_CODED: dict[str, type[BurnPolicy]] = {cls.name: cls for cls in (NeverBurn, AllAtOnce, ApogeeThreshold, Greedy)}
