"""The isothermal exponential law rho0 exp(-(h - h0) / H), SI units (m, kg/m^3), for comparison with other tools."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number


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
        check_number(self.rho0_kg_m3, "rho0_kg_m3", unit="kg/m^3", low=0.0, low_inclusive=False)
        check_number(self.h0_m, "h0_m", unit="m")
        check_number(self.scale_height_m, "scale_height_m", unit="m", low=0.0, low_inclusive=False)
        check_number(self.scale, "scale", low=0.0, low_inclusive=False)

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m]."""
        y = np.asarray(altitude_m, dtype=np.float64)
        return (self.scale * self.rho0_kg_m3) * np.exp(-(y - self.h0_m) / self.scale_height_m)
