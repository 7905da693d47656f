"""Hand-coded policies for the orbit-raising environments.

Each answers Stable-Baselines3's ``predict(obs, state=None, episode_start=None,
deterministic=True) -> (action, state)`` for one observation of shape (7,) or a batch
(n, 7), in the discrete and the continuous variants alike. They read the orbit and the
propellant from the observation (scales of :mod:`orbit_env.envs.orbit_raising`) and the
satellite from the environment's config, as a flight engineer would.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import SECONDS_PER_DAY
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, nu_per_revolution, universal_curves
from orbit_env.envs.orbit_raising import (
    DV_SCALE_M_S,
    HEIGHT_SCALE_M,
    DensityConfig,
    OrbitRaisingConfig,
    perigee_burn,
)
from orbit_env.physics.orbit import dv_for_apogee_m_s

FloatArray = NDArray[np.float64]


def observation_batch(observation: Any) -> FloatArray:
    """One observation (7,) or a batch (n, 7) as a finite float64 batch (n, 7).

    Raises:
        ValueError: another shape, or a value that is not finite.
    """
    obs = np.asarray(observation, dtype=np.float64)
    if obs.ndim not in (1, 2) or obs.shape[-1:] != (7,) or not np.all(np.isfinite(obs)):
        raise ValueError(f"observation must be finite with shape (7,) or (n, 7), got shape {obs.shape}")
    return np.atleast_2d(obs)


class BurnPolicy:
    """Shared plumbing: decode observations, encode burns as actions.

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
        self.config = config or OrbitRaisingConfig()
        self.density = density or DensityConfig()
        self.continuous = continuous
        self.sizes = np.asarray(self.config.burn_sizes_m_s, dtype=np.float64)

    def decode(self, obs: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Perigee [m], apogee [m], delta-v left [m/s] and mission clock from a batch of observations."""
        perigee = obs[:, 0].astype(np.float64) * HEIGHT_SCALE_M
        apogee = np.maximum(obs[:, 1].astype(np.float64) * HEIGHT_SCALE_M, perigee)
        return perigee, apogee, obs[:, 2].astype(np.float64) * DV_SCALE_M_S, obs[:, 3].astype(np.float64)

    def mass_kg(self, dv_left_m_s: FloatArray) -> FloatArray:
        """Mass from the delta-v left, by the rocket equation."""
        return self.config.dry_mass_kg * np.exp(dv_left_m_s / self.config.exhaust_velocity_m_s)

    def encode(self, dv_m_s: FloatArray) -> Any:
        """Actions for the requested burns: the largest discrete size not above each, or a Box value."""
        if self.continuous:
            return np.clip(dv_m_s / self.config.max_burn_m_s, 0.0, 1.0).astype(np.float32)[:, None]
        index = np.searchsorted(self.sizes, dv_m_s + 1e-9, side="right") - 1
        return np.maximum(index, 0).astype(np.int64)

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """The burn each satellite asks for [m/s] (subclasses)."""
        raise NotImplementedError

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[Any, Any]:
        """Actions for one observation (7,) or a batch (n, 7); SB3's signature."""
        obs = observation_batch(observation)
        actions = self.encode(self.burns_m_s(obs))
        return (actions[0] if np.ndim(observation) == 1 else actions), state


class NeverBurn(BurnPolicy):
    """Never fire the engine: the satellite decays as the paper's curves say."""

    name = "never"

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """No burn, ever."""
        return np.zeros(obs.shape[0])


class AllAtOnce(BurnPolicy):
    """Spend the whole budget at the start: the largest burn every step until the tank is empty."""

    name = "all_at_once"

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """The largest burn while propellant is left."""
        _, _, dv_left, _ = self.decode(obs)
        largest = self.config.max_burn_m_s if self.continuous else float(self.sizes.max())
        return np.where(dv_left > 1e-6, largest, 0.0)


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

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """The burn to the target apogee where the apogee is below the threshold."""
        perigee, apogee, dv_left, _ = self.decode(obs)
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

    For each burn it could make now, it computes with the universal curves the days
    the satellite would then live within the mission (at the nominal density, with the
    mass the burn leaves) minus the propellant's cost, and takes the best, coasting
    when no burn buys more days than it costs.
    """

    name = "greedy"

    def candidates(self) -> FloatArray:
        """Burns considered [m/s]: the discrete sizes, or a fine ladder for the continuous action."""
        if self.continuous:
            return np.linspace(0.0, self.config.max_burn_m_s, 21)
        return self.sizes

    def burns_m_s(self, obs: FloatArray) -> FloatArray:
        """The burn with the best days-within-mission minus cost."""
        perigee, apogee, dv_left, clock = self.decode(obs)
        config = self.config
        mass = self.mass_kg(dv_left)
        burns = self.candidates()
        n, m = perigee.size, burns.size
        grid = (np.repeat(perigee, m), np.repeat(apogee, m), np.repeat(mass, m))
        dv, apogee_after, mass_after = perigee_burn(
            grid[0], grid[1], grid[2], config.dry_mass_kg, config.exhaust_velocity_m_s, np.tile(burns, n)
        )
        point = universal_curves().locate(grid[0], apogee_after)
        drag = config.drag_coefficient * config.area_m2 / mass_after
        days = point.weighted_s / (nu_per_revolution(drag, self.density.nominal_scale) * SECONDS_PER_DAY)
        # Days left in the mission: steps left times the current orbit's period.
        period_days = point.mean_period_s / SECONDS_PER_DAY
        steps_left = np.repeat((1.0 - clock) * config.horizon_steps, m)
        mission_days = steps_left * config.revolutions_per_step * period_days
        score = (np.minimum(days, mission_days) - config.propellant_cost_per_m_s * dv).reshape(n, m)
        # The request, not the burn made: the env cuts it to the tank as the burn did here.
        return burns[np.argmax(score, axis=1)]


#: The hand-coded policies by their public names.
HAND_CODED: dict[str, type[BurnPolicy]] = {cls.name: cls for cls in (NeverBurn, AllAtOnce, ApogeeThreshold, Greedy)}
