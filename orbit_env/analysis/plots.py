"""A satellite's decay history as a figure (needs matplotlib, the ``plot`` extra)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from orbit_env.analysis.lifetime import LifetimeResult
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.solar import SolarActivity
from orbit_env.optional import pyplot


def plot_history(
    result: LifetimeResult,
    path: str | Path,
    *,
    activity: SolarActivity | None = None,
    height_offset_km: float = 0.0,
    band_days: tuple[float, float] | None = None,
    observed: Sequence[tuple[float, float, float]] | None = None,
) -> Path:
    """Perigee and apogee against time for one decay; with a date, against the date, and the F10.7 beneath.

    Args:
        result: The decay.
        path: The PNG to write.
        activity: The solar activity the decay followed (drawn in a panel beneath when the
            result has an epoch).
        height_offset_km: Subtracted from the heights (the equatorial radius's 7.137 km when
            heights are quoted above it).
        band_days: A lifetime band (5th and 95th percentiles, days) to shade.
        observed: Orbits measured before (or during) the decay, drawn as points: (days from the
            decay's start, perigee km, apogee km), heights as the plot gives them (after
            ``height_offset_km``); an element-set history's sets, whose decay the drag was fitted to.
    """
    plt = pyplot()
    history = result.history
    dated = result.epoch_days is not None

    def on_axis(days: Sequence[float] | np.ndarray) -> np.ndarray:
        """Days from the start as the x axis has them: dates to the minute, or the days themselves."""
        if result.epoch_days is None:
            return np.asarray(days, dtype=np.float64)
        minutes = np.round((result.epoch_days + np.asarray(days, dtype=np.float64)) * 1440.0).astype(np.int64)
        return minutes.astype("datetime64[m]")

    x = on_axis(history.days)
    panels = 2 if dated and activity is not None else 1
    fig, axes = plt.subplots(
        panels,
        1,
        figsize=(8, 4.5 + 2.0 * (panels - 1)),
        dpi=120,
        sharex=True,
        squeeze=False,
        gridspec_kw={"height_ratios": [3, 1.3][:panels]},
    )
    ax = axes[0, 0]
    ax.plot(x, history.apogee_km - height_offset_km, label="apogee")
    ax.plot(x, history.perigee_km - height_offset_km, label="perigee")
    if observed:
        sets_days, sets_perigee, sets_apogee = (np.array(column) for column in zip(*observed, strict=True))
        ax.plot(on_axis(sets_days), sets_apogee, "^", ms=4, color="tab:blue", label="apogee, element sets")
        ax.plot(on_axis(sets_days), sets_perigee, "v", ms=4, color="tab:orange", label="perigee, element sets")
    ax.set_ylabel("height [km]")
    if result.reentered:
        what = f"{result.days:.1f} days"
        if result.reentry_date is not None:
            what += f", re-entry {result.reentry_date}"
    else:
        what = f"still in orbit after {result.days / DAYS_PER_YEAR:.0f} years"
    heights = f"{result.perigee_km - height_offset_km:.6g} x {result.apogee_km - height_offset_km:.6g} km"
    ax.set_title(f"{heights}: {what} ({result.method})", fontsize=10)
    if band_days is not None:
        low_x, high_x = on_axis(band_days)
        ax.axvspan(low_x, high_x, color="tab:red", alpha=0.15, label="re-entry, 5-95%")
    ax.grid(alpha=0.3)
    ax.legend()
    if panels == 2:
        assert activity is not None and result.epoch_days is not None
        first = min([0.0, *(days for days, _, _ in observed or ())])
        t = np.linspace(first, float(history.days[-1]), 2000)
        f107, f107a, _ = activity.indices(result.epoch_days + t)
        sun = axes[1, 0]
        t_x = on_axis(t)
        sun.plot(t_x, f107, lw=0.5, color="0.6", label="F10.7, daily")
        sun.plot(t_x, f107a, lw=1.2, color="tab:orange", label="81-day mean")
        sun.set_ylabel("F10.7 [sfu]")
        sun.grid(alpha=0.3)
        sun.legend(fontsize=8)
    axes[-1, 0].set_xlabel("date (UTC)" if dated else "days since start")
    if dated:  # dates that do not overlap however short the decay (a month's full dates did)
        from matplotlib.dates import AutoDateLocator, ConciseDateFormatter

        locator = AutoDateLocator()
        axes[-1, 0].xaxis.set_major_locator(locator)
        axes[-1, 0].xaxis.set_major_formatter(ConciseDateFormatter(locator))
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out)
    plt.close(fig)
    return out
