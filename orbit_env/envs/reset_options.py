"""The reset options of the environments: their names, and merging them over a drawn start with checks.

``env.reset(options=...)`` pins the orbit, the atmosphere or the satellite of the new
missions (`RESET_OPTIONS`); this is the public edge, so every value is checked
(``ValueError`` naming the option, the value and the allowed range) and heights are in km.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from orbit_env.checks import check_array
from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M
from orbit_env.envs.config import OrbitRaisingConfig, validate_satellite

#: Reset options that pin the satellite (names of `OrbitRaisingConfig` fields).
SATELLITE_OPTIONS = ("drag_coefficient", "area_m2", "dry_mass_kg", "propellant_mass_kg", "isp_s")
#: Reset options that pin the orbit and the atmosphere.
ORBIT_OPTIONS = ("perigee_km", "apogee_km", "density_scale", "density_phase_rad")
RESET_OPTIONS = ORBIT_OPTIONS + SATELLITE_OPTIONS


def resolve_options(
    options: Mapping[str, Any] | None, drawn: dict[str, Any], config: OrbitRaisingConfig, size: int | None = None
) -> dict[str, Any]:
    """Merge reset options over the drawn start and the config's satellite, and validate.

    Options may be scalars or, for the vector environment, arrays of shape (num_envs,).

    Raises:
        ValueError: an unknown option, or a value out of range (named, with the range).
    """
    options = dict(options or {})
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ValueError(f"unknown reset option(s) {unknown}; allowed: {list(RESET_OPTIONS)}")
    merged: dict[str, Any] = {name: getattr(config, name) for name in SATELLITE_OPTIONS}
    merged.update(drawn)
    if not options:
        # The config's satellite and draws from its ranges, both checked when the config was made:
        # every automatic reset, where the checks would cost ten times the rest.
        return merged
    shape = () if size is None else (size,)
    for name, value in options.items():
        array = np.asarray(value, dtype=np.float64) if not isinstance(value, (str, bytes)) else None
        if array is None or (array.shape != () and array.shape != shape):
            raise ValueError(f"reset option {name}={value!r} must be a number or an array of shape {shape}")
        if not np.all(np.isfinite(array)):
            raise ValueError(f"reset option {name}={value!r} must be finite")
        merged[name] = float(array) if array.shape == () else array.copy()  # a number pins every satellite
    if "perigee_km" in options and "apogee_km" not in options:
        # A pinned perigee above the drawn apogee makes the drawn orbit circular.
        merged["apogee_km"] = np.maximum(merged["apogee_km"], merged["perigee_km"])
    if "apogee_km" in options and "perigee_km" not in options:
        merged["perigee_km"] = np.minimum(merged["perigee_km"], merged["apogee_km"])
    if size is None:
        merged["perigee_km"], merged["apogee_km"] = float(merged["perigee_km"]), float(merged["apogee_km"])
    validate_satellite(**{name: merged[name] for name in SATELLITE_OPTIONS})
    domain = "the universal curves' domain"
    # Checked together: a pinned apogee's bound is each satellite's perigee, drawn or pinned.
    perigee_km, apogee_km = np.broadcast_arrays(merged["perigee_km"], merged["apogee_km"])
    check_array(
        perigee_km, "perigee_km", unit="km", low=REENTRY_ALTITUDE_M / 1e3, high=CURVES_MAX_PERIGEE_M / 1e3, why=domain
    )
    check_array(
        apogee_km,
        "apogee_km",
        unit="km",
        low=perigee_km,
        low_name="perigee_km",
        high=CURVES_MAX_APOGEE_M / 1e3,
        why=domain,
    )
    check_array(merged["density_scale"], "density_scale", low=0.0, low_inclusive=False)
    return merged
