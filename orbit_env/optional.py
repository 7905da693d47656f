"""Optional dependencies, imported on use: a missing one is an ImportError that names its pip extra."""

from __future__ import annotations

from typing import Any

#: What installs the learning libraries (stable-baselines3, torch): the hint of every error that misses them.
TRAIN_EXTRA = "pip install 'orbit-env[train]'"


def pyplot() -> Any:
    """Import matplotlib's pyplot for files (Agg backend), or say which extra to install."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise ImportError("plotting needs matplotlib: pip install 'orbit-env[plot]'") from error
    return plt
