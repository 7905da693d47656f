"""A satellite's decay history as a figure (needs matplotlib, the ``plot`` extra)."""

from __future__ import annotations

from pathlib import Path

from orbit_env.analysis.lifetime import LifetimeResult
from orbit_env.optional import pyplot


def plot_history(result: LifetimeResult, path: str | Path) -> Path:
    """Perigee and apogee against time for one decay."""
    plt = pyplot()
    history = result.history
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=120)
    ax.plot(history.days, history.apogee_km, label="apogee")
    ax.plot(history.days, history.perigee_km, label="perigee")
    ax.set_xlabel("days since start")
    ax.set_ylabel("height [km]")
    ax.set_title(
        f"{result.perigee_km:g} x {result.apogee_km:g} km: {result.days:.1f} days, "
        f"{result.revolutions:.0f} revolutions ({result.method})",
        fontsize=10,
    )
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out)
    plt.close(fig)
    return out
