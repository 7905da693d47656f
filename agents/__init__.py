"""Agents for the orbit-raising environments: hand-coded baselines, the DP optimum and PPO.

Every agent answers Stable-Baselines3's ``predict(obs, state=None, episode_start=None,
deterministic=True) -> (action, state)`` (`orbit_env.agents.protocol`), so one evaluation scores them
all; but the solar task's optimum, a DP per mission that knows the mission's Sun to come, which acts
on the task's states (`orbit_env.agents.solar_dp`).
"""

#: Default seed of the evaluation episodes (training uses 0). Here, not in `orbit_env.agents.evaluate`
#: (which has them too): the command line's help reads them without importing the agents.
EVAL_SEED = 12345
#: Default number of episodes: with 1000 the paired difference of two good policies has a
#: standard error of about 0.1 day (0.3 with 200), below the gaps between them.
EVAL_EPISODES = 1000
#: Seed of the validation missions: training's validation score (`orbit_env.agents.train`) and, on the solar
#: task, the missions the operators' rules are tuned on (`orbit_env.agents.solar`): one seed, so that the
#: shipped solar recipe is validated on the missions its yardsticks were tuned on.
VALIDATION_SEED = 777
