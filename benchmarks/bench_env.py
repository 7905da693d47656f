"""Steps per second of every orbit-raising env against CartPole, measured in the same run.

Targets (issue 12): every registered id (``orbit_env.envs.ENV_IDS``), single through
``gymnasium.make``, at least 1.0x ``gymnasium.make("CartPole-v1")``; the vector env at
4096 envs at least 1.0x Gymnasium's ``CartPoleVectorEnv`` at 4096 envs.

Both sides get uniformly random actions drawn beforehand (so the action sampler is
not timed; ``bench_all.py`` runs Gymnasium's ``benchmark_step``, which times it) and
reset when an episode ends (the vector envs reset themselves, both in Gymnasium's
default ``AutoresetMode.NEXT_STEP``: like is compared with like). Every variant is
timed twice: with random actions, which burn until the tank is empty (every burn
re-locates the orbit on the curves), and coasting (no burn, what a satellite does
most of its life). Each measurement is the best of ``--repeats`` runs, taken in turn
with its reference so that both see the same machine load.

Under random actions a vector env at 4096 has some satellites burning in every
step (the ones that restarted lately, tanks full): the vis-viva burn, the rocket
equation and ``locate`` on the curves for that subset, numpy calls whose fixed cost
hardly shrinks with the subset. CartPole has no counterpart of that, so the
random-action ratio is the one that matters for training.

The solar task (``OrbitRaisingSolar-v0`` and its continuous twin, issue 28: the same targets) is timed last, on
fewer steps (``--solar-steps``; its step is costlier), each run in turn with CartPole's on as many steps;
the vector env on a mission's steps and its restart (``--solar-vector-steps``), in which (nearly) every
env ends its mission and restarts once.

Run: ``python benchmarks/bench_env.py [--steps N] [--vector-steps N] [--repeats R] [--warmup W]``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.envs.classic_control.cartpole import CartPoleVectorEnv

from orbit_env.envs import ENV_IDS, SOLAR_ENV_IDS, register_envs

NUM_ENVS = 4096


def time_single(env: gym.Env, actions: list[Any]) -> float:
    """Seconds for ``len(actions)`` steps of a single env, resetting at episode ends."""
    env.reset(seed=0)
    step = env.step
    reset = env.reset
    start = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, _ = step(action)
        if terminated or truncated:
            reset()
    return time.perf_counter() - start


def time_vector(env: gym.vector.VectorEnv, actions: list[np.ndarray], warmup: int) -> float:
    """Seconds for ``len(actions)`` batched steps of a vector env, after ``warmup`` untimed ones."""
    env.reset(seed=0)
    for k in range(warmup):  # to the steady state: missions ending and restarting every step
        env.step(actions[k % len(actions)])
    step = env.step
    start = time.perf_counter()
    for action in actions:
        step(action)
    return time.perf_counter() - start


def best_of(repeats: int, *runs: Callable[[], float]) -> list[float]:
    """Best time of each run over ``repeats`` rounds, the runs interleaved."""
    best = [float("inf")] * len(runs)
    for _ in range(repeats):
        for k, run in enumerate(runs):
            best[k] = min(best[k], run())
    return best


def draw_actions(space: gym.Space, rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    """Uniformly random actions of a single env's space, ``shape`` of them (Discrete or a Box)."""
    if isinstance(space, gym.spaces.Discrete):
        return rng.integers(0, space.n, shape)
    return rng.uniform(space.low, space.high, (*shape, *space.shape)).astype(space.dtype)


def coasting_action(space: gym.Space) -> Any:
    """The action that never burns: index 0, or the Box's low end (a burn of max(a, 0) = 0)."""
    if isinstance(space, gym.spaces.Discrete):
        return 0
    return space.low.copy()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000, help="single-env steps per run")
    parser.add_argument("--vector-steps", type=int, default=300, help="vector-env steps per run")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--warmup",
        type=int,
        default=400,
        help="untimed vector steps first: after about 300 steps the first missions end and restarting "
        "satellites (full tanks) burn every step, the state training runs in",
    )
    parser.add_argument("--solar-steps", type=int, default=3000, help="single solar-env steps per run")
    parser.add_argument(
        "--solar-vector-steps",
        type=int,
        default=None,
        help="solar vector-env steps per run (default: a mission's and its restart, a cycle of every env)",
    )
    args = parser.parse_args()
    register_envs()
    rng = np.random.default_rng(0)
    n, m = args.steps, args.vector_steps

    cartpole = gym.make("CartPole-v1")
    cart_actions = rng.integers(0, 2, n).tolist()
    runs: list[Callable[[], float]] = [lambda: time_single(cartpole, cart_actions)]
    labels = []
    for env_id in ENV_IDS:
        env = gym.make(env_id)
        space = env.action_space
        random = draw_actions(space, rng, (n,))
        random_actions = random.tolist() if random.ndim == 1 else list(random)
        coast_actions = [coasting_action(space)] * n
        runs += [lambda e=env, a=random_actions: time_single(e, a), lambda e=env, a=coast_actions: time_single(e, a)]
        labels += [f"{env_id}, random actions", f"{env_id}, coasting"]
    t_cart, *times = best_of(args.repeats, *runs)
    print(f"single env, {n} steps, best of {args.repeats}")
    print(f"  {'CartPole-v1 (gymnasium.make)':<45} {n / t_cart:>12,.0f} steps/s")
    for label, t in zip(labels, times, strict=True):
        print(f"  {label:<45} {n / t:>12,.0f} steps/s  ratio {t_cart / t:.2f}")

    cart_vec = CartPoleVectorEnv(num_envs=NUM_ENVS)
    cart_vec_actions = [rng.integers(0, 2, NUM_ENVS) for _ in range(m)]
    runs = [lambda: time_vector(cart_vec, cart_vec_actions, args.warmup)]
    for env_id in ENV_IDS:
        env = gym.make_vec(env_id, num_envs=NUM_ENVS, autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP)
        assert env.metadata["autoreset_mode"] == cart_vec.metadata["autoreset_mode"]
        space = env.single_action_space
        random_actions = [draw_actions(space, rng, (NUM_ENVS,)) for _ in range(m)]
        coast = coasting_action(space)
        coast_actions = [np.full(NUM_ENVS, coast) if np.ndim(coast) == 0 else np.tile(coast, (NUM_ENVS, 1))] * m
        runs += [
            lambda e=env, a=random_actions: time_vector(e, a, args.warmup),
            lambda e=env, a=coast_actions: time_vector(e, a, args.warmup),
        ]
    t_cart, *times = best_of(args.repeats, *runs)
    per = m * NUM_ENVS
    print(f"vector env, {NUM_ENVS} envs x {m} steps, best of {args.repeats}, autoreset NEXT_STEP on both")
    print(f"  {'CartPoleVectorEnv':<45} {per / t_cart:>12,.0f} steps/s")
    for label, t in zip(labels, times, strict=True):
        print(f"  {label:<45} {per / t:>12,.0f} steps/s  ratio {t_cart / t:.2f}")
    solar(args, rng)


def solar(args: argparse.Namespace, rng: np.random.Generator) -> None:
    """The solar task's ids (``OrbitRaisingSolar-v0``, its continuous twin) against CartPole, random actions."""
    for env_id in SOLAR_ENV_IDS:
        solar_one(env_id, args, rng)


def solar_one(env_id: str, args: argparse.Namespace, rng: np.random.Generator) -> None:
    """One solar id against CartPole: single env, then vector env at `NUM_ENVS`."""
    n = args.solar_steps
    cartpole = gym.make("CartPole-v1")
    cart_actions = rng.integers(0, 2, n).tolist()
    env = gym.make(env_id)
    drawn = draw_actions(env.action_space, rng, (n,))
    actions = drawn.tolist() if drawn.ndim == 1 else list(drawn)
    t_cart, t_env = best_of(
        args.repeats, lambda: time_single(cartpole, cart_actions), lambda: time_single(env, actions)
    )
    print(f"{env_id}, random actions, single env, {n} steps, best of {args.repeats}")
    print(f"  {'CartPole-v1':<45} {n / t_cart:>12,.0f} steps/s")
    print(f"  {env_id:<45} {n / t_env:>12,.0f} steps/s  ratio {t_cart / t_env:.4f}")
    cart_vec = CartPoleVectorEnv(num_envs=NUM_ENVS)
    vec = gym.make_vec(env_id, num_envs=NUM_ENVS)
    horizon = vec.unwrapped.task.config.horizon_steps
    m = horizon + 1 if args.solar_vector_steps is None else args.solar_vector_steps
    cart_vec_actions = [rng.integers(0, 2, NUM_ENVS) for _ in range(m)]
    vec_actions = [draw_actions(vec.single_action_space, rng, (NUM_ENVS,)) for _ in range(m)]
    # The batch's missions start together and end together after `horizon` steps; under NEXT_STEP the step
    # after restarts them: a cycle of horizon + 1 steps. Timed over one cycle from the second step, (nearly:
    # an early re-entry ends twice) every env ends its mission, its rule judged, and restarts once: the mean
    # step is the steady state's, as in training, where the missions' ends spread over the steps.
    warmup = 1
    t_cart, t_env = best_of(
        args.repeats,
        lambda: time_vector(cart_vec, cart_vec_actions, warmup),
        lambda: time_vector(vec, vec_actions, warmup),
    )
    per = m * NUM_ENVS
    print(f"{env_id}, random actions, vector env, {NUM_ENVS} envs x {m} steps, best of {args.repeats}")
    print(f"  {'CartPoleVectorEnv':<45} {per / t_cart:>12,.0f} steps/s")
    print(f"  {env_id:<45} {per / t_env:>12,.0f} steps/s  ratio {t_cart / t_env:.4f}")


if __name__ == "__main__":
    main()
