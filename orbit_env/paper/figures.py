"""The paper's Fig. 2: decay curves and lines of equal lifetime (needs matplotlib, the ``plot`` extra)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import NU_REF, universal_curves
from orbit_env.optional import pyplot

#: Levels of the lines nu = const drawn in Fig. 2 [m^3/(kg s^2)].
FIG2_NU_LEVELS = (0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1e3, 3e3, 1e4, 3e4)


def fig2_curves(
    start_perigees_km: np.ndarray,
    start_apogee_km: float = 1600.0,
    points: int = 300,
    model: DecayModel | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Decay curves from (start perigee, start apogee) to re-entry.

    Returns perigee [km], apogee [km] and nu left, each of shape (curves, points).
    """
    curves = universal_curves(model)
    hp0 = np.asarray(start_perigees_km, dtype=np.float64) * 1e3
    start = curves.locate(hp0, np.full_like(hp0, start_apogee_km * 1e3))
    fraction = np.linspace(1.0, 0.0, points)
    tau = start.tau[:, None] * fraction[None, :]
    hp, ha, _ = curves.at(start.label[:, None], tau)
    return hp / 1e3, ha / 1e3, NU_REF * np.expm1(tau)


def plot_fig2(path: str | Path, model: DecayModel | None = None) -> Path:
    """Draw the paper's Fig. 2: decay curves and lines nu = const in the (apogee, perigee) plane."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 6.5), dpi=120)
    labelled = np.arange(160.0, 501.0, 20.0)
    hp, ha, _ = fig2_curves(labelled, model=model)
    for k in range(labelled.size):
        ax.plot(ha[k], hp[k], color="tab:blue", lw=1.0)
        ax.annotate(
            f"{labelled[k]:.0f}",
            (1600, labelled[k]),
            xytext=(3, 0),
            textcoords="offset points",
            fontsize=7,
            va="center",
            color="tab:blue",
        )
    dense = np.linspace(160.0, 500.0, 200)
    hp_d, ha_d, nu_d = fig2_curves(dense, points=4000, model=model)
    for level in FIG2_NU_LEVELS:
        # On each curve, the point where nu left crosses the level.
        index = np.argmax(nu_d <= level, axis=1)
        reached = nu_d[:, 0] > level
        x, y = ha_d[reached, index[reached]], hp_d[reached, index[reached]]
        if x.size > 1:
            ax.plot(x, y, color="tab:red", lw=0.8, ls="--")
            ax.annotate(
                f"ν={level:g}", (x[-1], y[-1]), xytext=(2, 2), textcoords="offset points", fontsize=7, color="tab:red"
            )
    ax.plot([100, 500], [100, 500], color="0.5", lw=0.8)
    ax.set_xlim(100, 1700)
    ax.set_ylim(100, 510)
    ax.set_xlabel("apogee height $h_a$ [km]")
    ax.set_ylabel("perigee height $h_\\pi$ [km]")
    ax.set_title(
        "Fig. 2: decay curves (blue, labelled by start perigee at $h_a$ = 1600 km)\n"
        "and lines of equal lifetime ν [m³/(kg s²)] (red)",
        fontsize=10,
    )
    ax.grid(alpha=0.3)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out)
    plt.close(fig)
    return out
