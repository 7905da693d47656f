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

Ending decided episodes (``end_decided`` in the training config). Most of a mission
holds no decision: the satellite already outlives the mission without another burn,
or the tank is empty (93% of the steps of the episodes of the agent shipped before
this option). From such a state coasting is optimal, so its shaped optimal value is 0:

* with the tank empty nothing can be done;
* if the satellite outlives the mission, every mission day is already earned and a
  burn can add only through a longer orbital period (the reward counts the days of
  K revolutions). The period a burn adds at once is at most max dP/dv per m/s, worth
  K x steps left times that, below the propellant's cost for the configs this
  accepts (:func:`burns_cannot_pay_once_the_mission_is_covered` checks it over the
  curves' whole domain: 0.30 day per m/s against a cost of 0.4 for the default
  task). That the decay does not widen the difference later (the raised, lighter
  satellite decays faster) is checked, not proven: the DP solved with every state
  free to burn moves no value by more than its interpolation error (docs/dp.md).

So a training episode may end, as terminal, after the step taken from a decided
state, with the shaped reward r + Phi(s') - Phi(s): the return it is trained on is
then the one an optimal continuation would earn, and the optimal policy is
unchanged. The agent still acts, and learns to coast, in the first decided state of
every episode; with ``end_decided`` = q < 1 each decided step ends the episode with
probability q, so later ones are seen too. Batches then hold the decisions instead
of the hundreds of steps of coasting after them.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.decay.curves import CurvePoint, nu_per_revolution, universal_curves
from orbit_env.envs.orbit_raising import Coast, OrbitRaisingConfig, coast, period_gain_days_per_m_s_per_step

FloatArray = NDArray[np.float64]

#: The shaping options of a training config (``shaping = ...`` in the TOML file).
SHAPINGS = ("none", "never_burn_value")


def coast_to_mission_end(
    config: OrbitRaisingConfig,
    label: FloatArray,
    tau: FloatArray,
    mass_kg: FloatArray,
    density_scale: FloatArray,
    steps_left: FloatArray,
) -> Coast:
    """Coast each satellite, never burning again, to the end of the mission (or re-entry).

    Args:
        config: The environment's config (drag coefficient, area, revolutions per step).
        label: Curve label mu of each satellite (the env's ``state["label"]``).
        tau: Position tau on the curve (``state["tau"]``).
        mass_kg: Current mass [kg].
        density_scale: Current density scale, held for the rest of the mission.
        steps_left: Steps left in the mission (0 at the horizon).

    Returns:
        The coast: ``days`` lived within the mission, ``point.tau`` > 0 where the
        satellite is still in orbit at the mission's end.
    """
    curves = universal_curves()
    label = np.asarray(label, dtype=np.float64)
    tau = np.asarray(tau, dtype=np.float64)
    _, _, period_s = curves.at(label, tau)
    point = CurvePoint(label=label, tau=tau, mean_period_s=period_s)
    drag_parameter = config.drag_coefficient * config.area_m2 / np.asarray(mass_kg, dtype=np.float64)
    nu_per_rev = nu_per_revolution(drag_parameter, np.asarray(density_scale, dtype=np.float64))
    revolutions = np.maximum(np.asarray(steps_left, dtype=np.float64), 0.0) * config.revolutions_per_step
    return coast(curves, point, revolutions, nu_per_rev)


def outlook(env: Any, observations: NDArray[np.float32]) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Phi and "decided" of every satellite of an orbit-raising vector env, from its public state.

    Decided: the tank is empty, or the satellite outlives the mission without
    another burn (see the module). The steps taken come from the observation's
    mission clock (steps / horizon, exact in float32 for any horizon below 2^24 steps).
    """
    config = env.config
    state = env.state
    obs = np.asarray(observations, dtype=np.float64)
    steps_left = config.horizon_steps - np.rint(obs[:, 3] * config.horizon_steps)
    end = coast_to_mission_end(
        config, state["label"], state["tau"], state["mass_kg"], state["density_scale"], steps_left
    )
    decided = (end.point.tau > 0.0) | (obs[:, 2] <= 0.0)
    return np.maximum(end.days, 0.0), decided


def period_gain_days_per_m_s(config: OrbitRaisingConfig) -> float:
    """The most mission days a perigee burn can add per m/s by lengthening the period alone.

    :func:`orbit_env.envs.orbit_raising.period_gain_days_per_m_s_per_step` for each
    of the mission's steps.
    """
    return period_gain_days_per_m_s_per_step(config.revolutions_per_step) * config.horizon_steps


def burns_cannot_pay_once_the_mission_is_covered(config: OrbitRaisingConfig) -> bool:
    """Whether coasting is optimal wherever the satellite outlives the mission (see the module)."""
    return period_gain_days_per_m_s(config) < config.propellant_cost_per_m_s


def never_burn_value_shaping(venv: Any, end_decided: float = 0.0, seed: int | None = None) -> Any:
    """Wrap an SB3 ``VecEnv`` of an orbit-raising vector env with :class:`NeverBurnValueShaping`.

    Args:
        venv: The SB3 view of an orbit-raising vector env (:mod:`orbit_env.envs.sb3`).
        end_decided: Probability that a step from a decided state ends its episode
            (0: never; see the module).
        seed: Seed of those draws.

    Raises:
        ValueError: ``end_decided`` outside [0, 1], or > 0 where it would not be
            exact: a drifting or unknown density, or burns that can pay by the period.
    """
    from stable_baselines3.common.vec_env import VecEnvWrapper

    env = venv.unwrapped.env  # the Gymnasium vector env under SB3VecEnv
    if not 0.0 <= end_decided <= 1.0:
        raise ValueError(f"end_decided={end_decided!r} is invalid; allowed: a probability in [0, 1]")
    if end_decided > 0.0:
        low, high = env.density.scale_range
        if env.density.varies or low != high:
            raise ValueError("end_decided needs a known, constant density: with another the mission is never covered")
        if not burns_cannot_pay_once_the_mission_is_covered(env.config):
            raise ValueError(
                f"end_decided is not exact for this config: a burn may add {period_gain_days_per_m_s(env.config):.3f} "
                f"mission days per m/s by the period, more than its cost {env.config.propellant_cost_per_m_s}"
            )

    class NeverBurnValueShaping(VecEnvWrapper):
        """Reward r + Phi(s') - Phi(s), Phi(s') = 0 where the episode ended (see the module).

        ``infos[i]["unshaped_reward"]`` keeps the environment's reward;
        ``infos[i]["decided_end"]`` marks an episode ended because it was decided.
        """

        def __init__(self, inner: Any) -> None:
            super().__init__(inner)
            self.env = env
            self.phi = np.zeros(self.num_envs)
            self.decided = np.zeros(self.num_envs, dtype=bool)
            self.rng = np.random.default_rng(seed)

        def reset(self) -> Any:
            obs = self.venv.reset()
            self.phi, self.decided = outlook(self.env, obs)
            return obs

        def step_wait(self) -> Any:
            obs, rewards, dones, infos = self.venv.step_wait()
            # Finished satellites have restarted: obs and state are the new episode's s_0.
            phi_next, decided_next = outlook(self.env, obs)
            shaped = rewards + np.where(dones, 0.0, phi_next) - self.phi
            for info, reward in zip(infos, rewards, strict=True):
                info["unshaped_reward"] = float(reward)
            if end_decided > 0.0:
                end = self.decided & ~dones & (self.rng.random(self.num_envs) < end_decided)
                if end.any():
                    # shaped already holds r + Phi(s') - Phi(s) there: the optimal continuation's value.
                    dones = dones | end
                    for i in np.flatnonzero(end):
                        infos[i]["terminal_observation"] = obs[i].copy()
                        infos[i]["decided_end"] = True
                    obs, _ = self.env.reset(options={"reset_mask": end})
                    phi_new, decided_new = outlook(self.env, obs)
                    phi_next = np.where(end, phi_new, phi_next)
                    decided_next = np.where(end, decided_new, decided_next)
            self.phi, self.decided = phi_next, decided_next
            return obs, shaped.astype(np.float32), dones, infos

    return NeverBurnValueShaping(venv)
