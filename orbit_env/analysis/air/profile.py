"""A density profile of the user's own (any `orbit_env.physics.atmosphere.Atmosphere`), from the Python API."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from orbit_env.analysis.air.base import Air
from orbit_env.physics.atmosphere import Atmosphere


@dataclass(frozen=True)
class ProfileAir(Air):
    """A fixed profile given as an object with ``density_kg_m3(altitude_m)``, in heights above the 6371 km sphere.

    Args:
        atmosphere: The profile; scale it in the model itself (``scale`` is refused here, so a
            scale never applies twice).
    """

    name: ClassVar[str] = "profile"
    height_reference: ClassVar[str] = "sphere"
    curves_by_default: ClassVar[bool] = False  # any law: its curves may not be tabulable

    atmosphere: Atmosphere

    def profile(self, inclination_deg: float, scale: float = 1.0) -> Atmosphere:
        """The profile as given.

        Raises:
            ValueError: ``scale`` is not 1.
        """
        if scale != 1.0:
            raise ValueError("density_scale applies to the package's atmospheres only; scale your own model instead")
        return self.atmosphere

    def describe(self, inclination_deg: float, details: str = "") -> str:
        """The profile's type."""
        return f"{type(self.atmosphere).__name__} (a user's profile){details}"
