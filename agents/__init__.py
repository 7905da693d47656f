"""Agents for the orbit-raising environments: hand-coded baselines, the DP optimum and PPO.

Every agent answers Stable-Baselines3's ``predict(obs, state=None, episode_start=None,
deterministic=True) -> (action, state)``, so one evaluation scores them all.
"""
