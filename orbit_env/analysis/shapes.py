"""A satellite's shape -> its free-molecular drag coefficient at the orbit's conditions (needs pymsis).

The coefficient comes from `orbit_env.physics.drag` (Sentman 1961, diffuse
re-emission, full energy accommodation, wall at 300 K). The gas's speed ratio and
temperature are NRLMSIS 2.1's at the start: at the orbit's mean height, over its
latitudes and local times (`orbit_env.physics.atmosphere.msis.orbit_samples`),
on the epoch's date with its indices, the coefficient density-weighted over these
samples; it is then held for the whole life (along a decay from 500 km it falls by a
few per cent, see docs/validation-modern.md).

A box, a cylinder or a CubeSat is taken as tumbling at random, the attitude of an
uncontrolled body: a convex body's free-molecular drag averaged over all orientations is
the sphere's coefficient on the body's mean cross-section, a quarter of its surface
(Cauchy; `orbit_env.physics.drag.tumbling_drag_area_m2`). A body held in one attitude
takes ``--area`` and ``--cx`` (or `flown_nose_first` in Python).

Units: SI (m, m^2, kg, K, m/s); heights above the package's 6371 km sphere.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from orbit_env.physics.atmosphere.msis import geodetic_altitude_m, orbit_samples, require_pymsis
from orbit_env.physics.drag import WALL_TEMPERATURE_K, panel_drag_area_m2, speed_ratio, sphere_drag_coefficient
from orbit_env.physics.orbit import air_speed_at_perigee_m_s, perigee_velocity_m_s
from orbit_env.physics.satellite_bounds import AREA_RANGE_M2

#: Energy accommodation of the drag model (Sentman's diffuse, fully accommodated re-emission).
ACCOMMODATION = 1.0
#: The date of the gas when no epoch is given (an equinox, at noon UTC).
DEFAULT_GAS_DATE = "2000-03-20T12:00"
#: The shapes the CLI knows (``--shape``: a sphere, and convex bodies tumbling at random) and the dimensions
#: each takes, in its maker's order (`make_shape`; the command line's ``--diameter-m``, ...).
SHAPE_DIMENSIONS: dict[str, tuple[str, ...]] = {
    "sphere": ("diameter_m",),
    "box": ("size_m",),
    "cylinder": ("diameter_m", "length_m"),
    "cubesat": ("form_factor",),
}
SHAPES: tuple[str, ...] = tuple(SHAPE_DIMENSIONS)
#: CubeSat envelopes [m] by form factor: the CubeSat Design Specification Rev. 14.1 (Cal Poly, 2022),
#: as the cubesat-specs package tabulates it (PyPI, version 0.1.1's description: width x depth x height
#: in mm). The structure with its rails and anything stowed; panels deployed in orbit are not included.
#: The copy of that page read here cuts the 12U row after its second number: its 366 mm height is the
#: 6U's, as the specification has it from memory.
CUBESAT_FORM_FACTORS_M: dict[str, tuple[float, float, float]] = {
    "0.5U": (0.1, 0.1, 0.05675),
    "1U": (0.1, 0.1, 0.1135),
    "1.5U": (0.1, 0.1, 0.17025),
    "2U": (0.1, 0.1, 0.227),
    "3U": (0.1, 0.1, 0.3405),
    "3U+": (0.1, 0.1, 0.36),
    "6U": (0.2263, 0.1, 0.366),
    "12U": (0.2263, 0.2263, 0.366),
}


@dataclass(frozen=True)
class Shape:
    """What the air sees: a sphere, or flat panels at fixed incidence (flown in a fixed attitude).

    Attributes:
        reference_area_m2: The frontal area the drag coefficient refers to.
        sphere: True for a sphere of that cross-section, or a convex body tumbling at random on its mean
            cross-section (the same coefficient, `tumbling`); the panels are then unused.
        panel_areas_m2: Panel areas (one side each; a thin wing is two panels).
        panel_cos_incidence: Cosine between each panel's outward normal and the direction the air comes from.
        description: What the body is, for reports (``"sphere 0.3 m"``).
    """

    reference_area_m2: float
    sphere: bool = False
    panel_areas_m2: tuple[float, ...] = ()
    panel_cos_incidence: tuple[float, ...] = ()
    description: str = ""

    def drag_coefficient(
        self, s: np.ndarray, wall_to_gas: np.ndarray, accommodation: float = ACCOMMODATION
    ) -> np.ndarray:
        """Drag coefficient on the reference area for speed ratios ``s`` and T_w / T (arrays alike)."""
        if self.sphere:
            return sphere_drag_coefficient(s, wall_to_gas, accommodation)
        areas = np.array(self.panel_areas_m2)
        gamma = np.array(self.panel_cos_incidence)
        return panel_drag_area_m2(areas, gamma, s, wall_to_gas, accommodation) / self.reference_area_m2


def sphere(diameter_m: float) -> Shape:
    """A sphere of this diameter."""
    from orbit_env.checks import check_number

    largest = math.floor(20.0 * math.sqrt(AREA_RANGE_M2[1] / math.pi)) / 10.0  # 356.8 m
    why = f"a cross-section of at most {AREA_RANGE_M2[1]:g} m^2"
    d = check_number(diameter_m, "diameter_m", unit="m", low=0.0, low_inclusive=False, high=largest, why=why)
    return Shape(math.pi * d**2 / 4.0, sphere=True, description=f"sphere {d:g} m")


def tumbling(surface_m2: float, description: str) -> Shape:
    """A convex body of this surface tumbling at random: the sphere's C_D on a quarter of the surface.

    A quarter of a convex body's surface is its cross-section averaged over all orientations
    (Cauchy), and its free-molecular drag so averaged is the sphere's coefficient on that area
    (`orbit_env.physics.drag.tumbling_drag_area_m2`, tested against the faces' drag averaged over
    random directions).

    Raises:
        ValueError: a mean cross-section outside `AREA_RANGE_M2`.
    """
    from orbit_env.checks import check_number

    low, high, why = AREA_RANGE_M2
    name = f"the {description.split(' ')[0]}'s area (a quarter of its surface)"
    area = check_number(surface_m2 / 4.0, name, unit="m^2", low=low, low_inclusive=False, high=high, why=why)
    return Shape(area, sphere=True, description=f"{description}, tumbling")


def _lengths(values: tuple[float, ...], name: str) -> tuple[float, ...]:
    """Positive finite lengths [m] (the error names ``name``)."""
    from orbit_env.checks import check_number

    why = "larger than any body in orbit"
    return tuple(check_number(v, name, unit="m", low=0.0, low_inclusive=False, high=1e3, why=why) for v in values)


def box(size_m: tuple[float, float, float]) -> Shape:
    """A rectangular box of these three edges [m], tumbling at random (`tumbling`)."""
    if len(size_m) != 3:
        raise ValueError(f"a box has three edges; got {len(size_m)}")
    x, y, z = _lengths(tuple(size_m), "size_m")
    return tumbling(2.0 * (x * y + y * z + z * x), f"box {x:g} x {y:g} x {z:g} m")


def cylinder(diameter_m: float, length_m: float) -> Shape:
    """A closed cylinder [m], tumbling at random (`tumbling`): a rocket stage, a tank."""
    (d,) = _lengths((diameter_m,), "diameter_m")
    (length,) = _lengths((length_m,), "length_m")
    return tumbling(math.pi * d * length + math.pi * d**2 / 2.0, f"cylinder {d:g} m x {length:g} m")


def cubesat(form_factor: str) -> Shape:
    """A CubeSat of this form factor (`CUBESAT_FORM_FACTORS_M`: ``"3U"``, ...), tumbling at random.

    Raises:
        ValueError: an unknown form factor (the message lists the known ones).
    """
    if form_factor not in CUBESAT_FORM_FACTORS_M:
        known = ", ".join(CUBESAT_FORM_FACTORS_M)
        raise ValueError(f"unknown CubeSat form factor {form_factor!r}; known: {known}")
    x, y, z = CUBESAT_FORM_FACTORS_M[form_factor]
    return replace(box((x, y, z)), description=f"{form_factor} CubeSat ({x:g} x {y:g} x {z:g} m), tumbling")


def flown_nose_first(front_m2: float, parallel_m2: float) -> Shape:
    """A prism flown along its axis: a front face, the same area in the wake, and flow-parallel surfaces."""
    return Shape(
        front_m2,
        panel_areas_m2=(front_m2, front_m2, parallel_m2),
        panel_cos_incidence=(1.0, -1.0, 0.0),
        description=f"prism flown nose first, front {front_m2:g} m^2",
    )


@dataclass(frozen=True)
class DragAtStart:
    """The drag coefficient on the reference area and the gas it was computed in (density-weighted means)."""

    drag_coefficient: float
    speed_ratio: float
    temperature_k: float


def drag_at_start(
    shape: Shape,
    height_m: float,
    inclination_deg: float,
    indices: tuple[float, float, float],
    date: str | None = None,
    *,
    ascending_node_local_time_h: float | None = None,
    rotating_atmosphere: bool = True,
    accommodation: float = ACCOMMODATION,
) -> DragAtStart:
    """The free-molecular drag coefficient of ``shape`` at the mean height ``height_m`` (above the sphere).

    Args:
        shape: What the air sees.
        height_m: The orbit's mean height above the 6371 km sphere.
        inclination_deg: The orbit's inclination (sets the latitudes sampled).
        indices: F10.7, its 81-day mean [sfu] and Ap of the date.
        date: ISO date and time (None: `DEFAULT_GAS_DATE`).
        ascending_node_local_time_h: Sun-synchronous orbits: the node's local time.
        rotating_atmosphere: Whether the speed is taken against co-rotating air.
        accommodation: Energy accommodation coefficient, 0-1 (default: full, Sentman's case).
    """
    msis = require_pymsis()
    lat, local_time = orbit_samples(inclination_deg, ascending_node_local_time_h)
    start = np.datetime64(date or DEFAULT_GAS_DATE, "s")
    ut_h = (start - start.astype("datetime64[D]")).astype(np.int64) / 3600.0
    lon = np.mod((local_time - ut_h) * 15.0, 360.0)
    f107, f107a, ap = (float(x) for x in indices)
    out = msis.calculate(
        np.full(lat.size, start),
        lon,
        lat,
        geodetic_altitude_m(height_m, lat) / 1e3,
        f107s=np.full(lat.size, f107),
        f107as=np.full(lat.size, f107a),
        aps=np.full((lat.size, 7), ap),
        version=2.1,
    )
    rho, temperature = out[:, 0], out[:, 10]
    molecular_mass = rho / np.nansum(out[:, 1:10], axis=1)
    # A circular orbit's speed, through the co-rotating air if it turns (the wind along the track: omega r cos i).
    speed = float(
        air_speed_at_perigee_m_s(height_m, height_m, inclination_deg)
        if rotating_atmosphere
        else perigee_velocity_m_s(height_m, height_m)
    )
    s = speed_ratio(speed, temperature, molecular_mass)
    cd = shape.drag_coefficient(s, WALL_TEMPERATURE_K / temperature, accommodation)
    weight = rho / rho.sum()
    return DragAtStart(float(np.sum(weight * cd)), float(np.sum(weight * s)), float(np.sum(weight * temperature)))


def make_shape(name: str, **dimensions: Any) -> Shape:
    """The shape ``name`` (one of `SHAPES`) of these dimensions (`SHAPE_DIMENSIONS`)."""
    makers: dict[str, Callable[..., Shape]] = {"sphere": sphere, "box": box, "cylinder": cylinder, "cubesat": cubesat}
    return makers[name](*(dimensions[key] for key in SHAPE_DIMENSIONS[name]))
