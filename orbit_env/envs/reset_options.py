"""The reset options of the environments: their names, and merging them over a drawn start with checks.

``env.reset(options=...)`` pins the orbit, the atmosphere or the satellite of the new
missions (`RESET_OPTIONS`); this is the public edge, so every value is checked
(``ValueError`` naming the option, the value and the allowed range) and heights are in km.
The orbit is pinned by its heights or by its point on the universal curves (`CURVE_OPTIONS`),
which is how `START_OPTIONS` give a start back exactly: heights are located through
table A, whose point's heights (table B's, the ones reported) locate to a slightly other point.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from orbit_env.checks import check_array
from orbit_env.constants import REENTRY_ALTITUDE_M
from orbit_env.decay.curves import CURVES_MAX_APOGEE_M, CURVES_MAX_PERIGEE_M
from orbit_env.envs.config import OrbitRaisingConfig, validate_satellite

if TYPE_CHECKING:
    from orbit_env.decay.curves import UniversalCurves

#: Reset options that pin the satellite (names of `OrbitRaisingConfig` fields).
SATELLITE_OPTIONS = ("drag_coefficient", "area_m2", "dry_mass_kg", "propellant_mass_kg", "isp_s")
#: Reset options that pin the orbit and the atmosphere.
ORBIT_OPTIONS = ("perigee_km", "apogee_km", "density_scale", "density_phase_rad")
#: Reset options that pin the orbit by its point on the universal curves instead of its heights:
#: the curve's label mu and the place tau along it (the state's ``label`` and ``tau``), given together.
CURVE_OPTIONS = ("curve_label", "curve_tau")
RESET_OPTIONS = ORBIT_OPTIONS + CURVE_OPTIONS + SATELLITE_OPTIONS
#: The options that give a start back bit for bit (``env.unwrapped.start_options``), in this order.
START_OPTIONS = (*CURVE_OPTIONS, "density_scale", "density_phase_rad", *SATELLITE_OPTIONS)


def resolve_options(
    options: Mapping[str, Any] | None,
    drawn: dict[str, Any],
    config: OrbitRaisingConfig,
    size: int | None = None,
    curves: UniversalCurves | None = None,
) -> dict[str, Any]:
    """Merge reset options over the drawn start and the config's satellite, and validate.

    Options may be scalars or, for the vector environment, arrays of shape (num_envs,).
    With `CURVE_OPTIONS` the result holds ``curve_label`` and ``curve_tau`` instead of the
    heights, checked against ``curves`` (needed then).

    Raises:
        ValueError: an unknown option, or a value out of range (named, with the range).
    """
    options = dict(options or {})
    unknown = sorted(set(options) - set(RESET_OPTIONS))
    if unknown:
        raise ValueError(f"unknown reset option(s) {unknown}; allowed: {list(RESET_OPTIONS)}")
    on_curves = [name for name in CURVE_OPTIONS if name in options]
    if on_curves:
        if len(on_curves) < len(CURVE_OPTIONS):
            raise ValueError(f"reset option {on_curves[0]} needs {list(CURVE_OPTIONS)} together: a point")
        heights = [name for name in ("perigee_km", "apogee_km") if name in options]
        if heights:
            raise ValueError(
                f"reset options {heights} and {list(CURVE_OPTIONS)} both pin the orbit; "
                "give the heights or the point on the curves"
            )
    merged: dict[str, Any] = {name: getattr(config, name) for name in SATELLITE_OPTIONS}
    merged.update(drawn)
    if not options:
        # The config's satellite and draws from its ranges, both checked when the config was made:
        # every automatic reset, where the checks would cost ten times the rest.
        return merged
    for name, value in options.items():
        array = option_array(name, value, size)
        merged[name] = float(array) if array.shape == () else array  # a number pins every satellite
    if "perigee_km" in options and "apogee_km" not in options:
        # A pinned perigee above the drawn apogee makes the drawn orbit circular.
        merged["apogee_km"] = np.maximum(merged["apogee_km"], merged["perigee_km"])
    if "apogee_km" in options and "perigee_km" not in options:
        merged["perigee_km"] = np.minimum(merged["perigee_km"], merged["apogee_km"])
    if size is None:
        merged["perigee_km"], merged["apogee_km"] = float(merged["perigee_km"]), float(merged["apogee_km"])
    validate_satellite(**{name: merged[name] for name in SATELLITE_OPTIONS})
    if on_curves:
        assert curves is not None, "curve options need the curves"
        del merged["perigee_km"], merged["apogee_km"]
        check_curve_point(merged["curve_label"], merged["curve_tau"], curves)
        check_array(merged["density_scale"], "density_scale", low=0.0, low_inclusive=False)
        return merged
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


def option_array(name: str, value: Any, size: int | None) -> np.ndarray:
    """A numeric reset option checked: finite numbers, one or an array of shape ``(size,)`` (a copy).

    ``size`` None: a single environment's, a number only.

    Raises:
        ValueError: text, a bool, a complex number, another shape, or a value not finite (named).
    """
    shape = () if size is None else (size,)
    try:
        given = np.asarray(value)
    except ValueError:  # a ragged sequence
        given = np.asarray(None)
    if given.dtype.kind not in "iuf" or given.shape not in ((), shape):
        raise ValueError(f"reset option {name}={value!r} must be a number or an array of shape {shape}")
    array = given.astype(np.float64)  # a copy: later changes to the caller's array do not move the start
    if not np.all(np.isfinite(array)):
        raise ValueError(f"reset option {name}={value!r} must be finite")
    return array


def check_curve_point(label: Any, tau: Any, curves: UniversalCurves) -> None:
    """Check reset options ``curve_label`` and ``curve_tau``: on the tabulated curves, at an orbit of the domain.

    Raises:
        ValueError: a label outside the curves' labels, a negative tau, or a point whose
            heights lie outside the curves' domain (named, with the range).
    """
    label, tau = np.broadcast_arrays(np.asarray(label, dtype=np.float64), np.asarray(tau, dtype=np.float64))
    low, high = float(curves.labels[0]), float(curves.labels[-1])
    check_array(label, "curve_label", low=low, high=high, why="the universal curves' labels")
    check_array(tau, "curve_tau", low=0.0, why="tau = ln(1 + nu / NU_REF) is 0 at re-entry")
    perigee_m, apogee_m, _ = curves.at(label, tau)
    outside = (perigee_m < REENTRY_ALTITUDE_M) | (perigee_m > CURVES_MAX_PERIGEE_M) | (apogee_m > CURVES_MAX_APOGEE_M)
    outside |= ~(np.isfinite(perigee_m) & np.isfinite(apogee_m))
    if np.any(outside):
        i = np.unravel_index(np.argmax(outside), outside.shape)
        where = f"[{i[0]}]" if outside.ndim else ""
        raise ValueError(
            f"reset options curve_label{where}={float(label[i])!r}, curve_tau{where}={float(tau[i])!r} are at perigee "
            f"{perigee_m[i] / 1e3:.3f} km, apogee {apogee_m[i] / 1e3:.3f} km, outside the universal curves' domain "
            f"(perigee {REENTRY_ALTITUDE_M / 1e3:g}-{CURVES_MAX_PERIGEE_M / 1e3:g} km, "
            f"apogee up to {CURVES_MAX_APOGEE_M / 1e3:g} km)"
        )
