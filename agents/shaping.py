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

with W = Int P dnu of the universal curves (`orbit_env.envs.task.lookahead`
without a burn, over the rest of the mission, clamped at re-entry). Phi is 0 at re-entry (W = 0)
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
  accepts (`burns_cannot_pay_once_the_mission_is_covered` checks it over the
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

from orbit_env.optional import TRAIN_EXTRA

try:
    from stable_baselines3.common.vec_env import VecEnv, VecEnvWrapper, VecMonitor
except ImportError as error:  # pragma: no cover - depends on the installation
    raise ImportError(f"reward shaping needs stable-baselines3 and torch: {TRAIN_EXTRA}") from error

from orbit_env.envs import task as task_model
from orbit_env.envs.config import OrbitRaisingConfig
from orbit_env.envs.rocket import period_gain_days_per_m_s_per_step
from orbit_env.envs.state import AnyState
from orbit_env.envs.task import Task

FloatArray = NDArray[np.float64]

#: The shaping options of a training config (``shaping = ...`` in the TOML file).
SHAPINGS = ("none", "never_burn_value")


def outlook(task: Task, state: AnyState) -> tuple[FloatArray, NDArray[np.bool_]]:
    """Phi and "decided" of every satellite of a state of the task model.

    Phi: the days never burning again still earns within the mission, at the
    density of now (`orbit_env.envs.task.lookahead` without a burn).
    Decided: the tank is empty, or the satellite outlives the mission without
    another burn (see the module).
    """
    steps_left = task.config.horizon_steps - state.steps
    phi, _ = task_model.lookahead(task, state, 0.0, steps_left)
    decided = task_model.outlives(task, state, steps_left) | (state.dv_left_m_s <= 0.0)
    return np.maximum(phi, 0.0), decided


def period_gain_days_per_m_s(config: OrbitRaisingConfig) -> float:
    """The most mission days a perigee burn can add per m/s by lengthening the period alone.

    `orbit_env.envs.rocket.period_gain_days_per_m_s_per_step` for each
    of the mission's steps.
    """
    return period_gain_days_per_m_s_per_step(config.revolutions_per_step) * config.horizon_steps


def burns_cannot_pay_once_the_mission_is_covered(config: OrbitRaisingConfig) -> bool:
    """Whether coasting is optimal wherever the satellite outlives the mission (see the module)."""
    return period_gain_days_per_m_s(config) < config.propellant_cost_per_m_s


def _monitored(venv: VecEnv) -> bool:
    """Whether a ``VecMonitor`` is among the wrappers of ``venv``."""
    while isinstance(venv, VecEnvWrapper):
        if isinstance(venv, VecMonitor):
            return True
        venv = venv.venv
    return False


class NeverBurnValueShaping(VecEnvWrapper):
    """Reward r + Phi(s') - Phi(s), Phi(s') = 0 where the episode ended (see the module).

    ``infos[i]["unshaped_reward"]`` keeps the environment's reward;
    ``infos[i]["decided_end"]`` marks an episode ended because it was decided; at
    every episode's end ``infos[i]["mission_return"]`` is the mission's return, the
    plain environment's (what ``orbit-env evaluate`` scores): the unshaped rewards,
    plus Phi(s') where a decided episode was ended (the return coasting on earns).

    Args:
        venv: The SB3 view of an orbit-raising vector env (`orbit_env.envs.sb3`);
            with ``end_decided`` > 0, unmonitored (``make_sb3_vec_env(..., monitor=False)``).
        end_decided: Probability that a step from a decided state ends its episode
            (0: never; see the module).
        seed: Seed of those draws.

    Raises:
        ValueError: ``end_decided`` outside [0, 1], or > 0 where it would not be
            exact: a drifting or unknown density, or burns that can pay by the period;
            or > 0 above a ``VecMonitor``.
    """

    def __init__(self, venv: VecEnv, end_decided: float = 0.0, seed: int | None = None) -> None:
        env = venv.unwrapped.env  # the Gymnasium vector env under SB3VecEnv
        if not 0.0 <= end_decided <= 1.0:
            raise ValueError(f"end_decided={end_decided!r} is invalid; allowed: a probability in [0, 1]")
        if end_decided > 0.0:
            low, high = env.density.scale_range
            if env.density.varies or low != high:
                raise ValueError(
                    "end_decided needs a known, constant density: with another the mission is never covered"
                )
            if not burns_cannot_pay_once_the_mission_is_covered(env.config):
                raise ValueError(
                    f"end_decided is not exact for this config: a burn may add "
                    f"{period_gain_days_per_m_s(env.config):.3f} mission days per m/s by the period, "
                    f"more than its cost {env.config.propellant_cost_per_m_s}"
                )
            if _monitored(venv):
                raise ValueError(
                    "end_decided ends episodes by resetting the vector env under a VecMonitor, whose returns "
                    "would then run on into the next episode: wrap make_sb3_vec_env(..., monitor=False) "
                    "and put the VecMonitor above the shaping"
                )
        super().__init__(venv)
        self.env = env
        self.end_decided = float(end_decided)
        self.phi = np.zeros(self.num_envs)
        self.decided = np.zeros(self.num_envs, dtype=bool)
        self.unshaped_return = np.zeros(self.num_envs)  # each episode's plain rewards so far
        self.rng = np.random.default_rng(seed)

    def _outlook(self) -> tuple[FloatArray, NDArray[np.bool_]]:
        return outlook(self.env.task, self.env.task_state)

    def reset(self) -> Any:
        """Reset the environments and take the potential of the start states."""
        obs = self.venv.reset()
        self.phi, self.decided = self._outlook()
        self.unshaped_return[:] = 0.0
        return obs

    def step_wait(self) -> Any:
        """Step, shape the rewards, and end decided episodes with probability ``end_decided``."""
        obs, rewards, dones, infos = self.venv.step_wait()
        # Finished satellites have restarted: obs and state are the new episode's s_0.
        phi_next, decided_next = self._outlook()
        shaped = rewards + np.where(dones, 0.0, phi_next) - self.phi
        for info, reward in zip(infos, rewards, strict=True):
            info["unshaped_reward"] = float(reward)
        self.unshaped_return += rewards
        mission = self.unshaped_return
        if self.end_decided > 0.0:
            end = self.decided & ~dones & (self.rng.random(self.num_envs) < self.end_decided)
            if end.any():
                # shaped already holds r + Phi(s') - Phi(s) there: the optimal continuation's value.
                dones = dones | end
                mission = mission + np.where(end, phi_next, 0.0)  # coasting on from s' earns Phi(s')
                for i in np.flatnonzero(end):
                    infos[i]["terminal_observation"] = obs[i].copy()
                    infos[i]["decided_end"] = True
                obs, _ = self.env.reset(options={"reset_mask": end})
                phi_new, decided_new = self._outlook()
                phi_next = np.where(end, phi_new, phi_next)
                decided_next = np.where(end, decided_new, decided_next)
        for i in np.flatnonzero(dones):
            infos[i]["mission_return"] = float(mission[i])
        self.unshaped_return[dones] = 0.0
        self.phi, self.decided = phi_next, decided_next
        return obs, shaped.astype(np.float32), dones, infos


def never_burn_value_shaping(venv: Any, end_decided: float = 0.0, seed: int | None = None) -> NeverBurnValueShaping:
    """Wrap an SB3 ``VecEnv`` of an orbit-raising vector env with `NeverBurnValueShaping`."""
    return NeverBurnValueShaping(venv, end_decided=end_decided, seed=seed)
