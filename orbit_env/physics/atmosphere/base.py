"""What the decay core asks of an atmosphere: a vectorized density against altitude, SI units.

Every model is a small frozen dataclass with one vectorized method,
``density_kg_m3(altitude_m)``. The decay core accepts any object with that method,
or any plain vectorized function of altitude (see `as_atmosphere`), so a user
can plug in a density profile of their own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray


@runtime_checkable
class Atmosphere(Protocol):
    """Anything with a vectorized density against altitude."""

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at geometric altitude [m] above the spherical Earth."""
        ...


@dataclass(frozen=True)
class FunctionAtmosphere:
    """Wraps a user's vectorized function ``altitude_m -> density_kg_m3``."""

    function: Callable[[NDArray[np.float64]], ArrayLike]

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m], as the wrapped function gives it."""
        return np.asarray(self.function(np.asarray(altitude_m, dtype=np.float64)), dtype=np.float64)


def as_atmosphere(model: Atmosphere | Callable[[NDArray[np.float64]], ArrayLike] | None) -> Atmosphere:
    """Return ``model`` as an `Atmosphere` (``None`` gives the paper's law)."""
    if model is None:
        from orbit_env.physics.atmosphere.paper import PaperAtmosphere

        return PaperAtmosphere()
    if isinstance(model, Atmosphere):
        return model
    if callable(model):
        return FunctionAtmosphere(model)
    raise TypeError(
        "atmosphere must have a density_kg_m3(altitude_m) method or be a function of "
        f"altitude in metres, got {type(model).__name__}"
    )
