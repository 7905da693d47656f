"""What a height is measured from: the WGS84 equatorial radius or the paper's 6371 km sphere.

The decay core (`orbit_env.physics.orbit`) measures heights above the paper's
spherical Earth of radius ``EARTH_RADIUS_M`` = 6371 km, which reproduces the paper's
Table II. Catalogues and element sets quote heights above the WGS84 equatorial radius
6378.137 km (``a (1 - e) - 6378.137 km``). This module converts at the edge:

* ``equatorial``: a height h is the radius 6378.137 km + h, i.e. h + 7.137 km above the
  sphere. The default of NRLMSIS and the exponential law.
* ``sphere``: the radius 6371 km + h. The default of the paper's atmosphere, so the
  paper's numbers stay as printed.

NRLMSIS already evaluates its density at the geodetic altitude of every sample on the
orbit (`orbit_env.physics.atmosphere.msis.geodetic_altitude_m`), so for it only
the radius changes. The exponential law rho0 exp(-(h - h0) / H) is made to do the same by
`exponential_at_geodetic_altitude`. Re-entry stays at a perigee 100 km above the
sphere (92.9 km above the equator), where a satellite has hours left.

Units: km (the user's), converted nowhere else.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

from orbit_env.constants import EARTH_EQUATORIAL_RADIUS_M, EARTH_RADIUS_M
from orbit_env.physics.atmosphere import ExponentialAtmosphere
from orbit_env.physics.atmosphere.msis import WGS84_FLATTENING

HeightReference = Literal["equatorial", "sphere"]
HEIGHT_REFERENCES: tuple[str, ...] = ("equatorial", "sphere")
#: Height of the equatorial radius above the paper's sphere [km]: 6378.137 - 6371.
EQUATORIAL_OFFSET_KM = (EARTH_EQUATORIAL_RADIUS_M - EARTH_RADIUS_M) / 1e3


def offset_km(reference: str) -> float:
    """What to add to a height above ``reference`` for the height above the sphere [km]."""
    if reference not in HEIGHT_REFERENCES:
        raise ValueError(f"height_reference must be one of {', '.join(HEIGHT_REFERENCES)}, got {reference!r}")
    return EQUATORIAL_OFFSET_KM if reference == "equatorial" else 0.0


def describe(reference: str) -> str:
    """One line for the CLI."""
    if reference == "equatorial":
        return "heights above the equatorial radius 6378.137 km (WGS84)"
    return "heights above the 6371 km sphere (the paper's Earth)"


def exponential_at_geodetic_altitude(
    atmosphere: ExponentialAtmosphere, inclination_deg: float
) -> ExponentialAtmosphere:
    """The exponential law evaluated at the geodetic altitude along the orbit, as a law in the sphere's height.

    A point at height h above the sphere and geocentric latitude phi is at the geodetic
    altitude h - 7.137 km + a f sin^2(phi) (first order in the flattening f). Averaged over
    the argument of latitude u (sin phi = sin i sin u, u uniform: J2 turns the perigee
    through all latitudes over a life), rho0 exp(-(h_geod - h0) / H) becomes

        rho0 E exp(-(h - (h0 + 7.137 km)) / H),  E = exp(-k/2) I0(k/2),  k = a f sin^2(i) / H,

    with I0 the modified Bessel function. At i = 0 it is the law in the height above the
    equator; at the poles the orbit passes 21.4 km closer to the surface in places, and E < 1.
    """
    k = EARTH_EQUATORIAL_RADIUS_M * WGS84_FLATTENING * math.sin(math.radians(inclination_deg)) ** 2
    k /= atmosphere.scale_height_m
    factor = math.exp(-0.5 * k) * float(np.i0(0.5 * k))
    return ExponentialAtmosphere(
        atmosphere.rho0_kg_m3 * factor,
        atmosphere.h0_m + EQUATORIAL_OFFSET_KM * 1e3,
        atmosphere.scale_height_m,
        atmosphere.scale,
    )
