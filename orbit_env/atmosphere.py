"""Density of the upper atmosphere against altitude, SI units (m, kg/m^3).

Every model is a small frozen dataclass with one vectorized method,
``density_kg_m3(altitude_m)``. The decay core accepts any object with that method,
or any plain vectorized function of altitude (see :func:`as_atmosphere`), so a user
can plug in a density profile of their own.

The paper's law, Table 1 and Eq. (1.1)::

    rho = rho1 * Delta(y),   Delta(y) = chi / (1 + (y - y0) / a) ** k

in three bands (100-150, 150-250, 250-900 km), the top band extended above 900 km
as the paper does (section 3). The paper does not print rho1, the density at
100 km; :data:`RHO100_CALIBRATED_KG_M3` is its least-squares fit to Table II (see
``docs/calibration.md``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: rho1 of Eq. (1.1): least squares in log(nu) over all 351 cells of Table II,
#: made by :func:`orbit_env.table2.calibrate_rho100` (median of the log residuals
#: and their mean agree to 0.5%).
RHO100_CALIBRATED_KG_M3 = 1.633e-6

# Table 1, one entry per band: lower edge [m], chi, a [m], y0 [m], k.
_BAND_EDGES_M = np.array([150e3, 250e3])
_LOG_CHI = np.log([1.0, 5.667e-3, 4.428e-5])
_A_M = np.array([55e3, 100e3, 215e3])
_Y0_M = np.array([100e3, 150e3, 250e3])
_K = np.array([8.0, 7.0, 6.0])


def paper_delta(altitude_m: ArrayLike) -> NDArray[np.float64]:
    """Relative density Delta(y) of Eq. (1.1) and Table 1 (Delta = 1 at 100 km).

    The lowest band's formula is used below 100 km too (it is finite down to 45 km);
    the decay stops at a 100 km perigee, so only the direct integration's last
    fraction of a revolution sees it.
    """
    y = np.asarray(altitude_m, dtype=np.float64)
    band = np.searchsorted(_BAND_EDGES_M, y, side="right")
    return np.exp(_LOG_CHI[band] - _K[band] * np.log1p((y - _Y0_M[band]) / _A_M[band]))


@runtime_checkable
class Atmosphere(Protocol):
    """Anything with a vectorized density against altitude."""

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at geometric altitude [m] above the spherical Earth."""
        ...


def _check_positive(name: str, value: float) -> None:
    if not (np.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")


@dataclass(frozen=True)
class PaperAtmosphere:
    """The paper's density law, Eq. (1.1) with Table 1.

    Args:
        rho100_kg_m3: Density at 100 km, rho1 of Eq. (1.1). Defaults to the value
            calibrated against Table II.
        scale: Multiplier on the whole profile (the paper stresses that density
            was uncertain by orders of magnitude).
    """

    rho100_kg_m3: float = RHO100_CALIBRATED_KG_M3
    scale: float = 1.0

    def __post_init__(self) -> None:
        _check_positive("rho100_kg_m3", self.rho100_kg_m3)
        _check_positive("scale", self.scale)

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m]."""
        return (self.scale * self.rho100_kg_m3) * paper_delta(altitude_m)


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


@dataclass(frozen=True)
class FunctionAtmosphere:
    """Wraps a user's vectorized function ``altitude_m -> density_kg_m3``."""

    function: Callable[[NDArray[np.float64]], ArrayLike]

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m], as the wrapped function gives it."""
        return np.asarray(self.function(np.asarray(altitude_m, dtype=np.float64)), dtype=np.float64)


def as_atmosphere(model: Atmosphere | Callable[[NDArray[np.float64]], ArrayLike] | None) -> Atmosphere:
    """Return ``model`` as an :class:`Atmosphere` (``None`` gives the paper's law)."""
    if model is None:
        return PaperAtmosphere()
    if isinstance(model, Atmosphere):
        return model
    if callable(model):
        return FunctionAtmosphere(model)
    raise TypeError(
        "atmosphere must have a density_kg_m3(altitude_m) method or be a function of "
        f"altitude in metres, got {type(model).__name__}"
    )
