"""render_mode="human" where no window can open: a clear error naming what is missing, not a silent None."""

import sys

import pytest


def test_human_rendering_without_a_display_says_what_is_missing(monkeypatch):
    pytest.importorskip("matplotlib")
    import gymnasium as gym
    import matplotlib

    import orbit_env  # noqa: F401  (registers the envs)

    monkeypatch.setattr(matplotlib, "get_backend", lambda: "agg")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    env = gym.make("OrbitRaising-v0", render_mode="human")
    with pytest.raises(RuntimeError) as info:
        env.reset(seed=0)
    message = str(info.value)
    assert "render_mode='human'" in message and "'agg'" in message
    if sys.platform.startswith("linux"):
        assert "neither DISPLAY nor WAYLAND_DISPLAY is set" in message
    assert "render_mode='rgb_array'" in message  # what works instead
    env.close()

    monkeypatch.setenv("DISPLAY", ":0")  # a display, but a backend that draws no window
    env = gym.make("OrbitRaising-v0", render_mode="human")
    with pytest.raises(RuntimeError, match="an interactive matplotlib backend"):
        env.reset(seed=0)
    env.close()
