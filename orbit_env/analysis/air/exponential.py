"""An isothermal exponential law, for comparison with other tools; heights above the WGS84 equator by default."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from orbit_env.analysis.air.base import Air
from orbit_env.physics.atmosphere import ExponentialAtmosphere
from orbit_env.physics.atmosphere.exponential import ORBITAL_LAW


@dataclass(frozen=True)
class ExponentialAir(Air):
    """rho0 exp(-(h - h0) / H) (`orbit_env.physics.atmosphere.exponential`).

    Args:
        rho0_kg_m3: Density at ``h0_m`` (default: the orbital-height law `ORBITAL_LAW`).
        h0_m: Reference height.
        scale_height_m: Scale height H.
    """

    name: ClassVar[str] = "exponential"
    options: ClassVar[tuple[str, ...]] = ("rho0", "h0_km", "scale_height_km")
    # Any law a user gives, the sea-level ones too, whose curves may not be tabulable.
    curves_by_default: ClassVar[bool] = False

    rho0_kg_m3: float = ORBITAL_LAW[0]
    h0_m: float = ORBITAL_LAW[1]
    scale_height_m: float = ORBITAL_LAW[2]

    def __post_init__(self) -> None:
        self.profile(0.0)  # checks the law's values at once

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> ExponentialAir:
        """``--rho0``, ``--h0-km``, ``--scale-height-km``: all three, or none for the orbital-height law."""
        typed = [options.get(name) for name in cls.options]
        if any(value is None for value in typed) and any(value is not None for value in typed):
            # A density from one law and a scale height from another make a third that nobody measured.
            raise ValueError(
                "give --rho0, --h0-km and --scale-height-km together (one law's three values), "
                "or none for the orbital-height law"
            )
        rho0, h0_km, scale_height_km = typed
        if rho0 is None:
            return cls()
        return cls(rho0, h0_km * 1e3, scale_height_km * 1e3)

    def profile(self, inclination_deg: float, scale: float = 1.0) -> ExponentialAtmosphere:
        """The law (the same at every inclination)."""
        return ExponentialAtmosphere(self.rho0_kg_m3, self.h0_m, self.scale_height_m, scale)

    def in_sphere_heights(self, reference: str, inclination_deg: float) -> ExponentialAir:
        """Heights above the equator: the law at the geodetic altitude along the orbit, in the sphere's heights."""
        if reference != "equatorial":
            return self
        from orbit_env.analysis.heights import exponential_at_geodetic_altitude

        law = exponential_at_geodetic_altitude(self.profile(inclination_deg), inclination_deg)
        return ExponentialAir(law.rho0_kg_m3, law.h0_m, law.scale_height_m)

    def describe(self, inclination_deg: float, details: str = "") -> str:
        """The law's three values, and whether it is the default law."""
        law = (self.rho0_kg_m3, self.h0_m, self.scale_height_m)
        default = " (the default law for orbital heights: Vallado 2013, Table 8-4)" if law == ORBITAL_LAW else ""
        return (
            f"exponential, {self.rho0_kg_m3:.4g} kg/m^3 at {self.h0_m / 1e3:g} km, "
            f"scale height {self.scale_height_m / 1e3:g} km{details}{default}"
        )
