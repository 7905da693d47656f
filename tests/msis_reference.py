"""NRLMSIS's orbit mean straight from pymsis, one call per universal time: the tests' reference for the package's."""

import numpy as np
import pytest

from orbit_env.physics.atmosphere.msis import geodetic_altitude_m, orbit_samples


def pymsis_orbit_mean(
    heights_m, inclination_deg, node_h, day_of_year, f107, f107a, slots, latitude_nodes=12, local_time_nodes=12
):
    """The mean over ``slots`` of pymsis's density [kg/m^3] at ``heights_m`` averaged over an orbit's samples.

    ``slots``: (universal time [h], ap) pairs; ``ap`` a number is the daily Ap (NRLMSIS's daily mode), seven
    numbers an ap history (its storm-time mode). A day of the year with a fraction moves the universal time; each
    sample's longitude is the one where it is the sample's local time then. Written apart from
    `orbit_env.physics.atmosphere.msis` (its sampling of the orbit aside), as `pymsis.calculate` documents its
    inputs; the mean over a slot's samples in float64, as the package takes it.
    """
    pymsis = pytest.importorskip("pymsis")
    lat, local_time = orbit_samples(inclination_deg, node_h, latitude_nodes, local_time_nodes)
    alts_km = geodetic_altitude_m(heights_m[None, :], lat[:, None]) / 1e3  # (samples, heights)
    n = alts_km.size
    total = np.zeros(heights_m.size)
    for ut_h, ap in slots:
        hours = (day_of_year - 1.0) * 24.0 + ut_h
        date = np.datetime64("2001-01-01T00:00") + np.timedelta64(round(hours * 3600.0), "s")
        history = np.broadcast_to(np.asarray(ap, dtype=np.float64), (7,))
        storm = {"geomagnetic_activity": -1} if np.ndim(ap) else {}
        out = pymsis.calculate(
            np.full(n, date),
            np.repeat(np.mod((local_time - hours) * 15.0, 360.0), heights_m.size),
            np.repeat(lat, heights_m.size),
            alts_km.ravel(),
            np.full(n, f107),
            np.full(n, f107a),
            np.tile(history, (n, 1)),
            version=2.1,
            **storm,
        )
        # pymsis returns float32: the mean is taken in float64, as the package does.
        total += np.asarray(out[:, 0], dtype=np.float64).reshape(lat.size, heights_m.size).mean(axis=0)
    return total / len(slots)
