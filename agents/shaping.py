"""Potential-based reward shaping for PPO's training (``shaping = "never_burn_value"``).

Ng, Harada and Russell (1999), "Policy invariance under reward transformations":
adding F = gamma Phi(s') - Phi(s) to every reward, with Phi = 0 at the terminal
states, changes every episode's return by -Phi(s_0) only, a constant of the start
state that no action changes, so the optimal policy (and the ranking of all
policies) stays what it was. Training uses gamma = 1 and treats the mission's end
as terminal (``bootstrap_at_horizon = false``), so the theorem applies as stated.

The potential here is the return of never burning again: the days the satellite
would still live within the mission if it coasted from s to the end,

    Phi(s) = (W(s) - W(s advanced by steps_left x K revolutions)) / (g c s x 1 day),

with W = Int P dnu of the universal curves (:func:`orbit_env.envs.orbit_raising.coast`
over the rest of the mission, clamped at re-entry). Phi is 0 at re-entry (W = 0)
and at the horizon (no steps left). A coasting step's shaped reward is then 0 up to
rounding (the coast moves nu by the same amount the potential's coast does), and
a burn's is at once its gain in days within the mission minus the propellant's
cost: the credit for a burn no longer has to travel back over hundreds of steps.
Evaluation (``orbit-env evaluate``) always scores the unshaped environment.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.curves import CurvePoint, nu_per_revolution, universal_curves
from orbit_env.envs.orbit_raising import OrbitRaisingConfig, coast

FloatArray = NDArray[np.float64]

#: The shaping options of a training config (``shaping = ...`` in the TOML file).
SHAPINGS = ("none", "never_burn_value")


def never_burn_days(
    config: OrbitRaisingConfig,
    label: FloatArray,
    tau: FloatArray,
    mass_kg: FloatArray,
    density_scale: FloatArray,
    steps_left: FloatArray,
) -> FloatArray:
    """Days each satellite still lives within the mission if it never burns again.

    Args:
        config: The environment's config (drag coefficient, area, revolutions per step).
        label: Curve label mu of each satellite (the env's ``state["label"]``).
        tau: Position tau on the curve (``state["tau"]``).
        mass_kg: Current mass [kg].
        density_scale: Current density scale, held for the rest of the mission.
        steps_left: Steps left in the mission (0 at the horizon).

    Returns:
        Phi(s) [days], 0 for re-entered satellites and at the horizon.
    """
    curves = universal_curves()
    label = np.asarray(label, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    _, _, period_s = curves.at(label, tau)
    point = CurvePoint(label=label, tau=tau, mean_period_s=period_s)
    drag_parameter = config.drag_coefficient * config.area_m2 / np.asarray(mass_kg, dtype=np.float64)
    nu_per_rev = nu_per_revolution(drag_parameter, np.asarray(density_scale, dtype=np.float64))
    revolutions = np.maximum(np.asarray(steps_left, dtype=np.float64), 0.0) * config.revolutions_per_step
    return np.maximum(coast(curves, point, revolutions, nu_per_rev).days, 0.0)


def potential(env: Any, observations: NDArray[np.float32]) -> FloatArray:
    """Phi of every satellite of an orbit-raising vector env, read from its public state.

    The steps taken come from the observation's mission clock (steps / horizon,
    exact in float32 for any horizon below 2^24 steps).
    """
    config = env.config
    state = env.state
    steps = np.rint(np.asarray(observations, dtype=np.float64)[:, 3] * config.horizon_steps)
    return never_burn_days(
        config, state["label"], state["tau"], state["mass_kg"], state["density_scale"], config.horizon_steps - steps
    )


def never_burn_value_shaping(venv: Any) -> Any:
    """Wrap an SB3 ``VecEnv`` of an orbit-raising vector env with :class:`NeverBurnValueShaping`."""
    from stable_baselines3.common.vec_env import VecEnvWrapper

    class NeverBurnValueShaping(VecEnvWrapper):
        """Reward r + Phi(s') - Phi(s), Phi(s') = 0 where the episode ended (see the module).

        ``infos[i]["unshaped_reward"]`` keeps the environment's reward.
        """

        def __init__(self, inner: Any) -> None:
            super().__init__(inner)
            self.env = inner.unwrapped.env  # the Gymnasium vector env under SB3VecEnv
            self.phi = np.zeros(self.num_envs)

        def reset(self) -> Any:
            obs = self.venv.reset()
            self.phi = potential(self.env, obs)
            return obs

        def step_wait(self) -> Any:
            obs, rewards, dones, infos = self.venv.step_wait()
            # Finished satellites have restarted: obs and state are the new episode's s_0.
            phi_next = potential(self.env, obs)
            shaped = rewards + np.where(dones, 0.0, phi_next) - self.phi
            for info, reward in zip(infos, rewards, strict=True):
                info["unshaped_reward"] = float(reward)
            self.phi = phi_next
            return obs, shaped.astype(np.float32), dones, infos

    return NeverBurnValueShaping(venv)
