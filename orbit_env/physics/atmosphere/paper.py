"""The paper's density law, Table 1 and Eq. (1.1), SI units (m, kg/m^3).

The law::

    rho = rho1 * Delta(y),   Delta(y) = chi / (1 + (y - y0) / a) ** k

in three bands (100-150, 150-250, 250-900 km), the top band extended above 900 km
as the paper does (section 3). The paper does not print rho1, the density at
100 km; `RHO100_CALIBRATED_KG_M3` is its least-squares fit to Table II
(`orbit_env.paper.table2.calibrate_rho100`; docs: the paper's reproduction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number

#: rho1 of Eq. (1.1): least squares in log(nu) over all 351 cells of Table II,
#: made by `orbit_env.paper.table2.calibrate_rho100` (median of the log residuals
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


#: Bounds of the density at 100 km [kg/m^3], and why (outside them the decay equations break down).
RHO100_RANGE_KG_M3 = (1e-8, 1e-4, "every model and season puts 100 km between 2e-7 and 2e-6 kg/m^3")


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
        low, high, why = RHO100_RANGE_KG_M3
        check_number(self.rho100_kg_m3, "rho100_kg_m3", unit="kg/m^3", low=low, high=high, why=why)
        check_number(self.scale, "scale", low=0.0, low_inclusive=False)

    def density_kg_m3(self, altitude_m: ArrayLike) -> NDArray[np.float64]:
        """Density [kg/m^3] at altitude [m]."""
        return (self.scale * self.rho100_kg_m3) * paper_delta(altitude_m)
