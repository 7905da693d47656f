"""Steps per second of the orbit-raising envs against CartPole, measured in the same run.

Targets (issue 3): the single env through ``gymnasium.make`` at least 0.5x
``gymnasium.make("CartPole-v1")``, and the vector env at 4096 envs at least 0.5x
Gymnasium's ``CartPoleVectorEnv`` at 4096 envs.

Both sides get uniformly random actions drawn beforehand (so the action sampler is
not timed) and reset when an episode ends (the vector envs reset themselves, both in
Gymnasium's default ``AutoresetMode.NEXT_STEP``: like is compared with like).
The orbit env is timed twice: with random actions, which burn in three steps of
four until the tank is empty (the worst case: every burn re-locates the orbit on
the curves), and coasting (action 0, what a satellite does most of its life).
Each measurement is the best of ``--repeats`` runs, taken in turn with its
reference so that both see the same machine load.

Where the vector env stands (2-core machine, numpy 2.4, steady state after the
warm-up): coasting about 0.8x CartPoleVectorEnv, random actions about 0.5x. A
coasting step advances every satellite along its curve with two operations per
value on the table cell it is in (``UniversalCurves.segments``: 4-7% of satellites
enter a new cell per step and get a fresh one), converts to heights, and builds the
reward and the observation: about 60 numpy calls on 4096 floats. Under random actions
about 100 satellites burn per step (the ones that restarted lately, tanks full):
the vis-viva burn, the rocket equation, ``locate`` on table A and a new segment on
table B for that subset, about 150 numpy calls whose fixed cost (about 0.6 us each)
hardly shrinks with the subset. CartPole has no counterpart of that, and at 4096
envs some satellite burns in every step under any policy that burns at all, so the
random-action ratio is the one that matters for training.

Run: ``python benchmarks/bench_env.py [--steps N] [--vector-steps N] [--repeats R] [--warmup W]``.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import gymnasium as gym
import numpy as np
from gymnasium.envs.classic_control.cartpole import CartPoleVectorEnv

from orbit_env.envs import register_envs

NUM_ENVS = 4096


def time_single(env: gym.Env, actions: list[int]) -> float:
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
    args = parser.parse_args()
    register_envs()
    rng = np.random.default_rng(0)

    cartpole = gym.make("CartPole-v1")
    orbit = gym.make("OrbitRaising-v0")
    n = args.steps
    cart_actions = rng.integers(0, 2, n).tolist()
    orbit_actions = rng.integers(0, orbit.action_space.n, n).tolist()
    coast_actions = [0] * n
    t_cart, t_orbit, t_coast = best_of(
        args.repeats,
        lambda: time_single(cartpole, cart_actions),
        lambda: time_single(orbit, orbit_actions),
        lambda: time_single(orbit, coast_actions),
    )
    print(f"single env, {n} steps, best of {args.repeats}")
    print(f"  CartPole-v1 (gymnasium.make)          {n / t_cart:>12,.0f} steps/s")
    print(f"  OrbitRaising-v0, random actions       {n / t_orbit:>12,.0f} steps/s  ratio {t_cart / t_orbit:.2f}")
    print(f"  OrbitRaising-v0, coasting             {n / t_coast:>12,.0f} steps/s  ratio {t_cart / t_coast:.2f}")

    cart_vec = CartPoleVectorEnv(num_envs=NUM_ENVS)
    orbit_vec = gym.make_vec("OrbitRaising-v0", num_envs=NUM_ENVS, autoreset_mode=gym.vector.AutoresetMode.NEXT_STEP)
    assert orbit_vec.metadata["autoreset_mode"] == cart_vec.metadata["autoreset_mode"]
    m = args.vector_steps
    cart_vec_actions = [rng.integers(0, 2, NUM_ENVS) for _ in range(m)]
    orbit_vec_actions = [rng.integers(0, orbit.action_space.n, NUM_ENVS) for _ in range(m)]
    coast_vec_actions = [np.zeros(NUM_ENVS, dtype=np.int64)] * m
    t_cart, t_orbit, t_coast = best_of(
        args.repeats,
        lambda: time_vector(cart_vec, cart_vec_actions, args.warmup),
        lambda: time_vector(orbit_vec, orbit_vec_actions, args.warmup),
        lambda: time_vector(orbit_vec, coast_vec_actions, args.warmup),
    )
    per = m * NUM_ENVS
    print(f"vector env, {NUM_ENVS} envs x {m} steps, best of {args.repeats}, autoreset NEXT_STEP on both")
    print(f"  CartPoleVectorEnv                     {per / t_cart:>12,.0f} steps/s")
    print(f"  OrbitRaising-v0, random actions       {per / t_orbit:>12,.0f} steps/s  ratio {t_cart / t_orbit:.2f}")
    print(f"  OrbitRaising-v0, coasting             {per / t_coast:>12,.0f} steps/s  ratio {t_cart / t_coast:.2f}")


if __name__ == "__main__":
    main()
