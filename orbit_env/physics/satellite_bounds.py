"""The bounds of a satellite's drag properties, one set for the lifetime API and the environments.

Each bound is ``(low, high, why)``: the low end excluded where it is 0, the high end
included, and the reason shown in the ``ValueError`` of a value outside it. Outside them
a lifetime is a number of 300 digits or of 1e-300 days: no body in orbit has such values.
`orbit_env.analysis.lifetime.Satellite`, the catalogue's rows and
`orbit_env.envs.config.OrbitRaisingConfig` (and the environments' reset options) check
against these. SI units.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_array

#: Drag coefficient c_x (dimensionless).
DRAG_COEFFICIENT_RANGE = (0.0, 10.0, "free-molecular drag coefficients are 2 to 4 for any shape")
#: Mass [kg].
MASS_RANGE_KG = (0.0, 1e6, "the largest satellite, the ISS, is 4.2e5 kg")
#: Reference (cross-section) area [m^2].
AREA_RANGE_M2 = (0.0, 1e5, "a 300 m drag sail; the ISS spans about 2500 m^2")
#: Transverse load G/F, mass over area [kg/m^2].
MASS_PER_AREA_RANGE_KG_M2 = (
    0.01,
    1e5,
    "ten times beyond a solar sail's 0.1 kg/m^2 and a solid metal body's 1e4 kg/m^2, metres across",
)
#: Drag parameter c = c_x F / m [m^2/kg] (Eq. 3.4).
DRAG_PARAMETER_RANGE_M2_KG = (1e-5, 1e3, "c_x A / m within the bounds of c_x and of mass / area")


def check_drag_parameter(values: ArrayLike) -> NDArray[np.float64]:
    """Drag parameters ``drag_parameter_m2_kg`` (a number or an array) within `DRAG_PARAMETER_RANGE_M2_KG`.

    Raises:
        ValueError: one that is not a finite number in the range (the message names it).
    """
    low, high, why = DRAG_PARAMETER_RANGE_M2_KG
    return check_array(values, "drag_parameter_m2_kg", unit="m^2/kg", low=low, high=high, why=why)
