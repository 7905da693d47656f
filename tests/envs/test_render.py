"""render_mode="human" where no window can open: one warning naming what is missing, then nothing drawn.

Gymnasium's ``check_env`` makes every declared render mode, "human" too, and CI machines and
clusters have no display: there the check must pass, as it does for Gymnasium's own envs.
"""

import json
import os
import subprocess
import sys
import warnings

import pytest

HEADLESS_CHECK = """
import json, warnings
import gymnasium as gym
from gymnasium.utils.env_checker import check_env
import orbit_env
from orbit_env.envs import ENV_IDS

caught_by_id = {}
for env_id in ENV_IDS:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(gym.make(env_id).unwrapped)  # Gymnasium's defaults: every render mode
    caught_by_id[env_id] = [str(w.message) for w in caught]
print(json.dumps(caught_by_id))
"""


def test_gymnasium_check_env_passes_without_a_display():
    pytest.importorskip("matplotlib")
    headless = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    done = subprocess.run(
        [sys.executable, "-c", HEADLESS_CHECK], env=headless, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    caught = json.loads(done.stdout.strip().splitlines()[-1])
    for env_id, messages in caught.items():
        # One warning, from the "human" env the checker made: no window, nothing drawn.
        assert len(messages) == 1, (env_id, messages)
        assert "render_mode='human'" in messages[0] and "draws nothing" in messages[0], messages[0]


def test_human_rendering_without_a_window_warns_once_and_draws_nothing(monkeypatch):
    pytest.importorskip("matplotlib")
    import gymnasium as gym
    import matplotlib

    import orbit_env  # noqa: F401  (registers the envs)

    monkeypatch.setattr(matplotlib, "get_backend", lambda: "agg")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    env = gym.make("OrbitRaising-v0", render_mode="human")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        env.reset(seed=0)
        for _ in range(5):
            env.step(0)
        assert env.render() is None
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1, messages  # once per environment, not per frame
    message = messages[0]
    assert "render_mode='human'" in message and "'agg'" in message and "draws nothing" in message
    if sys.platform.startswith("linux"):
        assert "neither DISPLAY nor WAYLAND_DISPLAY is set" in message
    assert "render_mode='rgb_array'" in message  # what works instead
    env.close()
    env.close()  # twice, as check_env does

    monkeypatch.setenv("DISPLAY", ":0")  # a display, but a backend that draws no window
    env = gym.make("OrbitRaising-v0", render_mode="human")
    with pytest.warns(UserWarning, match="an interactive matplotlib backend"):
        env.reset(seed=0)
    env.close()


def test_rgb_array_frames_are_blitted_and_equal_a_full_redraw():
    import numpy as np

    from orbit_env.envs.render import TrackRenderer

    # Frames restore the background's pixels and draw only the track, the burns, the current point and
    # the title; each must be the very image a full redraw gives (also after the x range grows past
    # 1700 km, or the y range past 550 km, as the solar task's perigees need: each redraws the background).
    renderer = TrackRenderer(human=False, fps=8.0)
    wide = [(300e3 + k * 1e3, 800e3 + k * 40e3, 1.0 if k % 3 == 0 else 0.0) for k in range(30)]
    high = [(450e3 + k * 5e3, 600e3 + k * 10e3, 1.0 if k % 3 == 0 else 0.0) for k in range(30)]
    # apogee up to 1960 km from k = 24 on; perigee up to 595 km from k = 20 on
    for track, k in [(wide, 1), (wide, 5), (wide, 20), (wide, 30), (high, 10), (high, 20), (high, 30)]:
        frame = renderer.draw(track[:k], time_days=float(k), dv_left_m_s=100.0 - k)
        for artist in renderer._moving:
            artist.set_animated(False)
        renderer.figure.canvas.draw()
        full = np.asarray(renderer.figure.canvas.buffer_rgba())[:, :, :3]
        np.testing.assert_array_equal(frame, full)
        for artist in renderer._moving:
            artist.set_animated(True)
        renderer._background = None  # the full redraw drew the moving artists into the canvas
