"""The paper's air: Eq. (1.1) with Table 1 above the paper's 6371 km sphere, still air by default."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from orbit_env.analysis.air.base import Air
from orbit_env.physics.atmosphere import PaperAtmosphere


@dataclass(frozen=True)
class PaperAir(Air):
    """The paper's density law (`orbit_env.physics.atmosphere.paper`).

    Args:
        rho100_kg_m3: Density at 100 km (None: the value calibrated against Table II).
    """

    name: ClassVar[str] = "paper"
    options: ClassVar[tuple[str, ...]] = ("rho100",)
    height_reference: ClassVar[str] = "sphere"  # the paper's numbers stay as printed

    rho100_kg_m3: float | None = None

    def __post_init__(self) -> None:
        self.profile(0.0)  # checks rho100 at once, in the user's terms

    @classmethod
    def from_options(cls, options: Mapping[str, Any]) -> PaperAir:
        """``--rho100``."""
        return cls(options.get("rho100"))

    def profile(self, inclination_deg: float, scale: float = 1.0) -> PaperAtmosphere:
        """The law (the same at every inclination)."""
        if self.rho100_kg_m3 is None:
            return PaperAtmosphere(scale=scale)
        return PaperAtmosphere(self.rho100_kg_m3, scale)

    def describe(self, inclination_deg: float, details: str = "") -> str:
        """``paper, rho(100 km) = ...``."""
        return f"paper, rho(100 km) = {self.profile(inclination_deg).rho100_kg_m3:.4g} kg/m^3{details}"
