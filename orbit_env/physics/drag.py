"""Free-molecular drag coefficients of flat panels and spheres (Sentman 1961), SI units.

Above about 150 km a satellite is far smaller than the mean free path, so each
molecule hits the surface once, undisturbed by the others ("free-molecular" flow).
Its drag then follows from the gas's speed ratio, its temperature and how the
molecules leave the surface. This module uses Sentman's (1961) model as Doornbos
(2012, "Thermospheric density and wind determination from satellite dynamics",
eq. 5.1-5.6) writes it for a flat panel, the model behind the drag coefficients
of the CHAMP, GRACE and GOCE density data sets:

* the molecules arrive with the Maxwell distribution of the air (temperature
  ``T``) shifted by the satellite's speed ``V``; ``S = V / sqrt(2 k T / m)`` is the
  speed ratio (m the mean molecular mass; S is about 6-9 in low orbit);
* they leave diffusely (cosine law), at a speed set by the energy accommodation
  ``alpha``: ``v_re / V = sqrt((1 + alpha (4 k T_w / (m V^2) - 1)) / 2)``, which
  for full accommodation (``alpha = 1``, Sentman's case) is
  ``sqrt(T_w / T) / S``, the thermal speed of the wall temperature ``T_w``.

A panel of area A whose outward normal makes the angle theta with the direction
the air comes from (``gamma = cos theta``: 1 facing the flow, 0 parallel to it,
-1 in the wake) has the drag coefficient, per unit panel area,

    C_D = P / sqrt(pi) + gamma Q Z + (gamma / 2) (v_re / V) (gamma sqrt(pi) Z + P)

with ``P = exp(-gamma^2 S^2) / S``, ``Q = 1 + 1 / (2 S^2)``, ``Z = 1 + erf(gamma S)``.
Limits, checked in ``tests/physics/test_drag.py``: a plate facing the flow gives
``2 + 1/S^2 + sqrt(pi) v_re / V`` (about 2.1); a plate parallel to it gives the
pure shear ``1 / (S sqrt(pi))`` (about 0.08); the wake side gives ~0.

A convex body has no panel shading another, so its drag area is the sum of its
panels' ``C_D A``. Integrating the panel formula over a sphere gives Sentman's
closed form for a sphere (`sphere_drag_coefficient`, on the area pi r^2).
A convex body tumbling at random sees every surface element at a uniformly
distributed gamma, so its mean drag area is that of a sphere of the same surface:
``C_D,sphere * surface / 4``, the surface / 4 being its mean projected area
(Cauchy's theorem) (`tumbling_drag_area_m2`).

Sources: L. H. Sentman, "Free molecule flow theory and its application to the
determination of aerodynamic forces", Lockheed LMSC-448514 (1961); E. Doornbos,
Springer Theses (2012); the same formula is in the open ADBSat toolkit
(University of Manchester, ``coeff_DRIA.m``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

#: Boltzmann constant [J/K].
BOLTZMANN_J_K = 1.380649e-23
#: Atomic mass unit [kg].
ATOMIC_MASS_KG = 1.66053906660e-27
#: Wall temperature of a satellite's skin [K] (the usual choice in the density data sets).
WALL_TEMPERATURE_K = 300.0
_SQRT_PI = math.sqrt(math.pi)


def speed_ratio(speed_m_s: ArrayLike, temperature_k: ArrayLike, molecular_mass_kg: ArrayLike) -> FloatArray:
    """Speed ratio S = V / sqrt(2 k T / m) of a satellite through a gas of temperature T and molecular mass m."""
    t = np.asarray(temperature_k, dtype=np.float64)
    m = np.asarray(molecular_mass_kg, dtype=np.float64)
    return np.asarray(speed_m_s, dtype=np.float64) / np.sqrt(2.0 * BOLTZMANN_J_K * t / m)


def reemission_speed_ratio(
    speed_ratio_: ArrayLike, wall_to_gas_temperature: ArrayLike, accommodation: ArrayLike = 1.0
) -> FloatArray:
    """Mean re-emitted over incident speed, v_re / V, for energy accommodation ``accommodation``.

    ``4 k T_w / (m V^2) = 2 (T_w / T) / S^2``; with full accommodation this is sqrt(T_w / T) / S.
    """
    s = np.asarray(speed_ratio_, dtype=np.float64)
    wall = 2.0 * np.asarray(wall_to_gas_temperature, dtype=np.float64) / (s * s)
    return np.sqrt(0.5 * (1.0 + np.asarray(accommodation, dtype=np.float64) * (wall - 1.0)))


def plate_drag_coefficient(
    cos_incidence: ArrayLike,
    speed_ratio_: ArrayLike,
    wall_to_gas_temperature: ArrayLike,
    accommodation: ArrayLike = 1.0,
) -> FloatArray:
    """Drag coefficient per unit area of one side of a flat plate (Sentman; Doornbos 2012 eq. 5.1).

    Args:
        cos_incidence: gamma, cosine of the angle between the plate's outward normal
            and the direction the air comes from (1 facing the flow, 0 parallel, -1 wake).
        speed_ratio_: S = V / sqrt(2 k T / m).
        wall_to_gas_temperature: T_w / T.
        accommodation: Energy accommodation coefficient alpha (1: full, Sentman's case).

    All arguments broadcast against each other.
    """
    g = np.asarray(cos_incidence, dtype=np.float64)
    s = np.asarray(speed_ratio_, dtype=np.float64)
    p = np.exp(-((g * s) ** 2)) / s
    q = 1.0 + 0.5 / (s * s)
    from scipy.special import erf  # on use: a third of a second of start-up

    z = 1.0 + erf(g * s)
    v_ratio = reemission_speed_ratio(s, wall_to_gas_temperature, accommodation)
    return p / _SQRT_PI + g * q * z + 0.5 * g * v_ratio * (g * _SQRT_PI * z + p)


def sphere_drag_coefficient(
    speed_ratio_: ArrayLike, wall_to_gas_temperature: ArrayLike, accommodation: ArrayLike = 1.0
) -> FloatArray:
    """Drag coefficient of a sphere on its cross-section pi r^2 (Sentman's closed form).

    C_D = (2 S^2 + 1) exp(-S^2) / (sqrt(pi) S^3) + (4 S^4 + 4 S^2 - 1) erf(S) / (2 S^4)
    + (2 sqrt(pi) / 3) v_re / V, with v_re / V = sqrt(T_w / T) / S for full accommodation.
    The hypersonic cold-wall limit is 2; low orbits give about 2.1-2.2.
    """
    s = np.asarray(speed_ratio_, dtype=np.float64)
    s2 = s * s
    from scipy.special import erf

    incident = (2.0 * s2 + 1.0) * np.exp(-s2) / (_SQRT_PI * s2 * s) + (4.0 * s2 * s2 + 4.0 * s2 - 1.0) * erf(s) / (
        2.0 * s2 * s2
    )
    return incident + (2.0 * _SQRT_PI / 3.0) * reemission_speed_ratio(s, wall_to_gas_temperature, accommodation)


def panel_drag_area_m2(
    areas_m2: ArrayLike,
    cos_incidence: ArrayLike,
    speed_ratio_: ArrayLike,
    wall_to_gas_temperature: ArrayLike,
    accommodation: ArrayLike = 1.0,
) -> FloatArray:
    """Drag area sum_i C_D,i A_i [m^2] of a convex body's panels (last axis: the panels).

    Divide by a reference area for a drag coefficient. The conditions (S, T_w / T,
    alpha) broadcast against the leading axes, e.g. one per orbit sample.
    """
    areas = np.asarray(areas_m2, dtype=np.float64)
    s = np.asarray(speed_ratio_, dtype=np.float64)[..., None]
    ratio = np.asarray(wall_to_gas_temperature, dtype=np.float64)[..., None]
    alpha = np.asarray(accommodation, dtype=np.float64)[..., None]
    return np.sum(areas * plate_drag_coefficient(cos_incidence, s, ratio, alpha), axis=-1)


def tumbling_drag_area_m2(
    surface_m2: ArrayLike,
    speed_ratio_: ArrayLike,
    wall_to_gas_temperature: ArrayLike,
    accommodation: ArrayLike = 1.0,
) -> FloatArray:
    """Mean drag area [m^2] of a convex body of this surface tumbling at random: C_D,sphere * surface / 4."""
    surface = np.asarray(surface_m2, dtype=np.float64)
    return sphere_drag_coefficient(speed_ratio_, wall_to_gas_temperature, accommodation) * surface / 4.0
