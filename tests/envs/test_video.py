"""``gymnasium.wrappers.RecordVideo`` on the env: the ``video`` extra (MoviePy, with ffmpeg in its imageio-ffmpeg)."""

import gymnasium as gym
import numpy as np
import pytest

import orbit_env  # noqa: F401  (registers the environments)

pytest.importorskip("moviepy", reason="needs orbit-env[video]")
pytest.importorskip("matplotlib", reason="needs orbit-env[plot]")


def test_record_video_writes_a_short_mp4_offline(tmp_path):
    import imageio.v3 as iio
    import matplotlib

    matplotlib.use("Agg")
    env = gym.make("OrbitRaising-v0", render_mode="rgb_array", horizon_steps=12)
    folder = tmp_path / "videos"
    env = gym.wrappers.RecordVideo(env, str(folder), episode_trigger=lambda episode: True, disable_logger=True)
    env.reset(seed=0, options={"perigee_km": 300.0, "apogee_km": 600.0})
    steps = 0
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(1 if steps == 0 else 0)
        steps += 1
        done = terminated or truncated
    env.close()
    videos = sorted(folder.glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000
    frames = np.stack(list(iio.imiter(videos[0])))
    assert frames.shape[0] == steps + 1  # the reset's frame and one per step
    assert frames.shape[-1] == 3 and frames.std() > 0.0  # a picture, not a blank
