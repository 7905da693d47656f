"""The isothermal exponential law rho0 exp(-(h - h0) / H), SI units (m, kg/m^3), for comparison with other tools."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.physics.atmosphere.base import _check_positive


@dataclass(frozen=True)
class ExponentialAtmosphere:
    """Isothermal law rho0 * exp(-(h - h0) / H), for comparison with other tools.

    Args:
        rho0_kg_m3: Density at the reference altitude.
        h0_m: Reference altitude.
        scale_height_m: Scale height H.
        scale: Multiplier on the whole profile.
    """

    rho0_kg_m3: float = 1.3
    h0_m: float = 0.0
    scale_height_m: float = 8.5e3
    scale: float = 1.0

    def __post_init__(self) -> None:
        _check_positive("rho0_kg_m3", self.rho0_kg_m3)
        _check_positive("scale_height_m", self.scale_height_m)
        _check_positive("scale", self.scale)
        if not np.isfinite(self.h0_m):
            raise ValueError(f"h0_m must be finite, got {self.h0_m!r}")

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m]."""
        y = np.asarray(altitude_m, dtype=np.float64)
        return (self.scale * self.rho0_kg_m3) * np.exp(-(y - self.h0_m) / self.scale_height_m)
