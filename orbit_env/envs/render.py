"""Pictures of an orbit-raising mission: the (apogee, perigee) plane of the paper's Fig. 2.

Heights arrive in metres (SI, as everywhere inside the package) and are drawn in km.
The background is the paper's two families of curves: decay curves h_pi = f(h_a)
(Eq. 4.2) and lines of equal lifetime nu = const (Eq. 4.3), both taken from the
universal curves. On top: the satellite's track (one point per step) and its
burns, which jump horizontally (a perigee burn raises only the apogee).

Matplotlib is optional (``pip install 'orbit-env[plot]'``); the text rendering
needs nothing.
"""

from __future__ import annotations

import os
import sys
import warnings
from typing import Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, NU_REF, universal_curves

#: Lifetimes nu [m^3/(kg s^2)] of the drawn lines of equal lifetime (Eq. 4.3).
NU_LEVELS = (1.0, 10.0, 100.0, 1e3, 1e4, 1e5)
#: Start perigees [m] of the drawn decay curves, all from a 1600 km apogee as in the paper.
CURVE_PERIGEES_M = tuple(h * 1e3 for h in (160, 200, 250, 300, 350, 400, 450, 500))
#: Figure size [inches] and resolution [dots per inch] of the rgb_array frames (640 x 480).
FIGURE_SIZE_IN = (6.4, 4.8)
FIGURE_DPI = 100


def _matplotlib() -> Any:
    try:
        import matplotlib
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError(
            "rendering the orbit-raising environment as pictures needs matplotlib; "
            "install it with: pip install 'orbit-env[plot]' (or use render_mode='ansi')"
        ) from error
    return matplotlib


def render_ansi(
    *,
    step: int,
    time_days: float,
    perigee_m: float,
    apogee_m: float,
    dv_left_m_s: float,
    burn_m_s: float,
    reentered: bool,
) -> str:
    """One line of text describing the mission now."""
    status = "  RE-ENTERED" if reentered else ""
    burn = f"  burn {burn_m_s:5.1f} m/s" if burn_m_s > 0.0 else ""
    return (
        f"step {step:4d}  t {time_days:8.2f} d  perigee {perigee_m / 1e3:7.1f} km  "
        f"apogee {apogee_m / 1e3:7.1f} km  delta-v left {dv_left_m_s:6.1f} m/s{burn}{status}"
    )


def background_curves() -> tuple[list[NDArray[np.float64]], list[NDArray[np.float64]]]:
    """The paper's Fig. 2 families in km: decay curves and lines of equal nu, as (n, 2) [apogee, perigee]."""
    curves = universal_curves()
    starts = curves.locate(np.array(CURVE_PERIGEES_M), np.full(len(CURVE_PERIGEES_M), 1600e3))
    decay = []
    for label, tau in zip(starts.label, starts.tau, strict=True):
        taus = np.linspace(0.0, float(tau), 200)
        perigee_m, apogee_m, _ = curves.at(np.full_like(taus, label), taus)
        decay.append(np.column_stack([apogee_m, perigee_m]) / 1e3)
    labels = np.linspace(float(starts.label.min()) - 3.0, float(starts.label.max()) + 0.5, 300)
    levels = []
    for nu in NU_LEVELS:
        tau = np.full_like(labels, np.log1p(nu / NU_REF))
        perigee_m, apogee_m, _ = curves.at(labels, tau)
        keep = apogee_m <= CURVES_MAX_APOGEE_M
        levels.append(np.column_stack([apogee_m[keep], perigee_m[keep]]) / 1e3)
    return decay, levels


#: Matplotlib backends that draw into files or memory, never a window.
FILE_BACKENDS = frozenset({"agg", "cairo", "pdf", "pgf", "ps", "svg", "template"})


def missing_window(backend: str) -> str | None:
    """Why ``render_mode="human"`` can open no window here, or None if it can.

    Without a display matplotlib falls back to a backend that draws into memory, and a
    "human" render would show nothing at all.

    Args:
        backend: Matplotlib's backend (``matplotlib.get_backend()``).

    Returns:
        None where a window can open; else a message that names the backend, the
        display variables (on Linux) and the render modes that need no window.
    """
    name = backend.lower()
    if name not in FILE_BACKENDS:
        return None
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        missing = "a display: neither DISPLAY nor WAYLAND_DISPLAY is set"
    else:
        missing = "an interactive matplotlib backend (MPLBACKEND or matplotlib.use, e.g. TkAgg or QtAgg)"
    return (
        f"render_mode='human' opens a window, which needs {missing}, and matplotlib's backend is "
        f"{backend!r}, which draws no window, so the environment draws nothing; use "
        "render_mode='rgb_array' (frames as arrays) or 'ansi' (text)"
    )


class TrackRenderer:
    """Draws a mission's track on the (apogee, perigee) plane.

    In human mode where no window can open (no display: CI machines, clusters) it
    warns once (`missing_window`) and draws nothing, so that Gymnasium's ``check_env``,
    which makes every declared render mode, passes there.

    Args:
        human: Show the figure in a window (pyplot) instead of returning pixels.
        fps: Frames per second of the window in human mode.
    """

    def __init__(self, human: bool, fps: float) -> None:
        matplotlib = _matplotlib()
        self.human = human
        self.fps = fps
        self.figure: Any = None
        if human:
            missing = missing_window(matplotlib.get_backend())
            if missing is not None:
                warnings.warn(missing, UserWarning, stacklevel=2)
                return  # no figure: draw() shows nothing
            import matplotlib.pyplot as plt

            self._plt = plt
            self.figure = plt.figure(figsize=FIGURE_SIZE_IN, dpi=FIGURE_DPI)
        else:
            from matplotlib.backends.backend_agg import FigureCanvasAgg
            from matplotlib.figure import Figure

            self.figure = Figure(figsize=FIGURE_SIZE_IN, dpi=FIGURE_DPI)
            FigureCanvasAgg(self.figure)
        from matplotlib.collections import LineCollection

        axes = self.figure.add_subplot()
        decay, levels = background_curves()
        for line in decay:
            axes.plot(line[:, 0], line[:, 1], color="0.6", linewidth=0.8)
        for nu, line in zip(NU_LEVELS, levels, strict=True):
            axes.plot(line[:, 0], line[:, 1], color="0.8", linewidth=0.6, linestyle="--")
            visible = line[(line[:, 0] <= 1650.0) & (line[:, 1] <= 540.0)]
            if visible.size:
                axes.annotate(f"nu={nu:g}", visible[np.argmax(visible[:, 0])], fontsize=6, color="0.5")
        axes.plot([0, 5000], [0, 5000], color="0.4", linewidth=0.6)  # circular orbits, h_a = h_pi
        axes.set_xlabel("apogee height h_a [km]")
        axes.set_ylabel("perigee height h_pi [km]")
        axes.set_xlim(REENTRY_ALTITUDE_M / 1e3, 1700.0)
        axes.set_ylim(REENTRY_ALTITUDE_M / 1e3, 550.0)
        (self._track,) = axes.plot([], [], color="tab:blue", linewidth=1.5, marker=".", markersize=3)
        self._burns = LineCollection([], colors="tab:red", linewidths=2.0)
        axes.add_collection(self._burns)
        (self._now,) = axes.plot([], [], "o", color="tab:blue")
        self._title = axes.set_title(" ", fontsize=9)
        self._axes = axes
        # rgb_array frames are blitted: the background (the curves, the axes) is drawn once per pair of axis
        # ranges and kept as pixels; a frame restores it and draws only what changes (85 ms a frame -> a few ms).
        self._moving = (self._track, self._burns, self._now, self._title)
        for artist in self._moving:
            artist.set_animated(not human)
        self._background: Any = None
        self._background_limits: tuple[tuple[float, float], tuple[float, float]] | None = None

    def draw(
        self, track: list[tuple[float, float, float]], *, time_days: float, dv_left_m_s: float
    ) -> NDArray[np.uint8] | None:
        """Draw the track [(perigee [m], apogee [m], burn [m/s]), ...]; pixels (rgb_array) or None (human)."""
        if self.figure is None:
            return None  # human mode without a window
        points = np.array([(apogee, perigee) for perigee, apogee, _ in track]) / 1e3 if track else np.zeros((0, 2))
        self._track.set_data(points[:, 0], points[:, 1])
        self._now.set_data(points[-1:, 0], points[-1:, 1])
        segments = [points[k - 1 : k + 1] for k in range(1, len(track)) if track[k][2] > 0.0]
        self._burns.set_segments(segments)
        if points.size:  # the paper's frame, widened to hold the track (the solar task flies perigees to 580 km)
            self._axes.set_xlim(REENTRY_ALTITUDE_M / 1e3, max(1700.0, 1.05 * points[:, 0].max()))
            self._axes.set_ylim(REENTRY_ALTITUDE_M / 1e3, max(550.0, 1.05 * points[:, 1].max()))
        self._title.set_text(f"t = {time_days:.1f} d, delta-v left {dv_left_m_s:.0f} m/s")
        if self.human:
            self._plt.pause(1.0 / self.fps)
            return None
        canvas = self.figure.canvas
        limits = (self._axes.get_xlim(), self._axes.get_ylim())
        if self._background is None or limits != self._background_limits:
            canvas.draw()  # everything but the animated artists
            self._background, self._background_limits = canvas.copy_from_bbox(self.figure.bbox), limits
        else:
            canvas.restore_region(self._background)
        for artist in self._moving:
            self._axes.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()

    def close(self) -> None:
        """Close the window (human mode) and free the figure."""
        if self.human and self.figure is not None:
            self._plt.close(self.figure)
