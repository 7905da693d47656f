"""Upper-atmosphere density models, one module per model.

* `base`: the `Atmosphere` protocol and
  `as_atmosphere` (a user's function of altitude).
* `paper`: the paper's law, Eq. (1.1) with Table 1.
* `exponential`: an isothermal exponential law.
* `msis`: NRLMSIS (2.1, 2.0 or NRLMSISE-00) through ``pymsis``, orbit-averaged
  (imported on use: it needs the ``msis`` extra).
"""

from orbit_env.physics.atmosphere.base import Atmosphere, FunctionAtmosphere, as_atmosphere
from orbit_env.physics.atmosphere.exponential import ExponentialAtmosphere
from orbit_env.physics.atmosphere.paper import RHO100_CALIBRATED_KG_M3, PaperAtmosphere, paper_delta

__all__ = [
    "RHO100_CALIBRATED_KG_M3",
    "Atmosphere",
    "ExponentialAtmosphere",
    "FunctionAtmosphere",
    "PaperAtmosphere",
    "as_atmosphere",
    "paper_delta",
]
