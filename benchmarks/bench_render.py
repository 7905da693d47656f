"""The cost of an rgb_array frame (what Gymnasium's RecordVideo asks for every step), against a full redraw.

``python benchmarks/bench_render.py`` steps ``OrbitRaising-v0`` with random actions and times
``env.render()``: the frames as shipped (the background kept as pixels, only the track,
burns, current point and title drawn) and, in the same run, the reference: the same frames
with the whole figure redrawn each time (as before blitting). Medians over ``--frames``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import gymnasium as gym

import orbit_env  # noqa: F401  (registers the environments)


def frame_times(frames: int, full_redraw: bool) -> list[float]:
    """Seconds per ``env.render()`` over ``frames`` steps of one episode."""
    env = gym.make("OrbitRaising-v0", render_mode="rgb_array")
    env.reset(seed=0)
    env.action_space.seed(0)
    env.render()
    renderer = env.unwrapped._renderer
    times = []
    for _ in range(frames):
        env.step(env.action_space.sample())
        if full_redraw:
            renderer._background = None
        start = time.perf_counter()
        env.render()
        times.append(time.perf_counter() - start)
    env.close()
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100, help="frames timed (default 100)")
    args = parser.parse_args()
    blitted = statistics.median(frame_times(args.frames, full_redraw=False))
    full = statistics.median(frame_times(args.frames, full_redraw=True))
    print(f"rgb_array frame, 640 x 480: {blitted * 1e3:.1f} ms blitted, {full * 1e3:.1f} ms redrawn whole")
    print(f"ratio: {full / blitted:.1f} x faster")


if __name__ == "__main__":
    main()
