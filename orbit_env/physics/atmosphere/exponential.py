"""The isothermal exponential law rho0 exp(-(h - h0) / H), SI units (m, kg/m^3), for comparison with other tools."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number

#: The default law, meant for orbital heights: Vallado, *Fundamentals of Astrodynamics and
#: Applications* (4th ed., 2013), Table 8-4, the band from 400 km: density at ``h0`` [kg/m^3],
#: ``h0`` [m], scale height [m]. (The sea-level law 1.3 kg/m^3, 8.5 km gives lifetimes of
#: millions of years at 400 km; pass it explicitly to compare with tools that use it.)
ORBITAL_LAW = (3.725e-12, 400e3, 58.515e3)
#: Bounds of the law's values, and why.
RHO0_RANGE_KG_M3 = (0.0, 10.0, "air at sea level is 1.2 kg/m^3")
H0_RANGE_M = (0.0, 2000e3, "from sea level to the top of the orbits computed here")
SCALE_HEIGHT_RANGE_M = (1e3, 500e3, "the air's scale height runs from 6 km near the ground to 100 km at 1000 km")


@dataclass(frozen=True)
class ExponentialAtmosphere:
    """Isothermal law rho0 * exp(-(h - h0) / H), for comparison with other tools.

    The defaults are `ORBITAL_LAW`, a law for orbital heights.

    Args:
        rho0_kg_m3: Density at the reference altitude.
        h0_m: Reference altitude.
        scale_height_m: Scale height H.
        scale: Multiplier on the whole profile.
    """

    rho0_kg_m3: float = ORBITAL_LAW[0]
    h0_m: float = ORBITAL_LAW[1]
    scale_height_m: float = ORBITAL_LAW[2]
    scale: float = 1.0

    def __post_init__(self) -> None:
        for value, name, unit, (low, high, why) in (
            (self.rho0_kg_m3, "rho0_kg_m3", "kg/m^3", RHO0_RANGE_KG_M3),
            (self.h0_m, "h0_m", "m", H0_RANGE_M),
            (self.scale_height_m, "scale_height_m", "m", SCALE_HEIGHT_RANGE_M),
        ):
            positive = name == "rho0_kg_m3"  # a density above 0; the heights from their bound on
            check_number(value, name, unit=unit, low=low, high=high, low_inclusive=not positive, why=why)
        check_number(self.scale, "scale", low=0.0, low_inclusive=False)

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m]."""
        y = np.asarray(altitude_m, dtype=np.float64)
        return (self.scale * self.rho0_kg_m3) * np.exp(-(y - self.h0_m) / self.scale_height_m)
