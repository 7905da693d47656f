"""Table II of the paper against this package: the reproduction and the calibration.

Table II (shipped as ``orbit_env/paper/data/table2.csv``) gives the universal lifetime
nu [m^3/(kg s^2)] and the perigee velocity for 351 initial orbits. The paper does
not print rho1, its density at 100 km; since nu is inversely proportional to it,
the least-squares fit in log(nu) over all cells has a closed form (the geometric
mean of the ratios).

Most of the remaining deviation is the authors' numerical method, not the physics:
they integrated Eq. (3.12) by Euler's method in steps of 5 km in p (10 km once the
apogee is above 700 km), which overestimates nu where the density scale height
is short. `paper_scheme_nu` repeats that scheme on our averaged equations;
it reproduces Table II to a median of 1.9% (90th percentile 4.9%).

A cell is flagged as a likely misprint when its log error differs by more than
``MISPRINT_LOG_JUMP`` from the median of its neighbours in the table (the cells
beside it in its row and column): our errors are smooth across the table, so a
jump belongs to the printed cell. Its velocity is flagged when it is more than
``MISPRINT_VELOCITY_M_S`` from the exact vis-viva value (the table rounds to 1 m/s).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from importlib import resources

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import EARTH_RADIUS_M, REENTRY_ALTITUDE_M
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.curves import universal_curves
from orbit_env.physics.atmosphere import RHO100_CALIBRATED_KG_M3, PaperAtmosphere
from orbit_env.physics.orbit import elements_from_heights, perigee_velocity_m_s

FloatArray = NDArray[np.float64]

#: Log-error jump from the neighbours' median that flags a nu misprint (10%).
MISPRINT_LOG_JUMP = 0.1
#: Velocity difference that flags a v_pi misprint [m/s].
MISPRINT_VELOCITY_M_S = 4.0


@dataclass(frozen=True)
class Table2:
    """The paper's Table II as arrays (one entry per cell)."""

    perigee_km: FloatArray
    apogee_km: FloatArray
    nu: FloatArray
    v_perigee_m_s: FloatArray


def load_table2() -> Table2:
    """Read the 351 cells of Table II from the package data."""
    text = resources.files("orbit_env.paper").joinpath("data/table2.csv").read_text()
    rows = list(csv.DictReader(text.splitlines()))
    column = {key: np.array([float(row[key]) for row in rows]) for key in rows[0]}
    return Table2(column["perigee_km"], column["apogee_km"], column["nu_paper"], column["v_perigee_paper_m_s"])


def model_nu(table: Table2, model: DecayModel | None = None) -> FloatArray:
    """The universal lifetime nu of every cell of ``table``, by the curves of ``model``."""
    curves = universal_curves(model or DecayModel())
    return curves.locate(table.perigee_km * 1e3, table.apogee_km * 1e3).nu


def paper_scheme_nu(
    perigee_m: NDArray[np.float64], apogee_m: NDArray[np.float64], model: DecayModel | None = None
) -> FloatArray:
    """Nu by the authors' own scheme (section 3): Euler in p, 5 km steps (10 km above 700 km apogee).

    The rates are this package's averaged equations; only the integrator is the
    paper's (the integrand at the start of each step, whole steps until the
    perigee is below 100 km). All orbits step together.
    """
    model = model or DecayModel()
    p, e = elements_from_heights(perigee_m, apogee_m)
    nu = np.zeros_like(p)
    active = p / (1.0 + e) - EARTH_RADIUS_M > REENTRY_ALTITUDE_M
    while active.any():
        pa, ea = p[active], e[active]
        dp_dnu, de_dnu = model.rates_per_nu(pa, ea)
        step_m = np.where(pa / (1.0 - ea) - EARTH_RADIUS_M <= 700e3, 5e3, 10e3)
        nu[active] += step_m / -dp_dnu
        e[active] = np.maximum(ea - de_dnu / dp_dnu * step_m, 0.0)
        p[active] = pa - step_m
        active &= p / (1.0 + e) - EARTH_RADIUS_M > REENTRY_ALTITUDE_M
    return nu


def calibrate_rho100(table: Table2 | None = None) -> float:
    """Least-squares rho1 [kg/m^3] in log(nu) over all cells (closed form)."""
    table = table or load_table2()
    reference = PaperAtmosphere(rho100_kg_m3=RHO100_CALIBRATED_KG_M3)
    nu = model_nu(table, DecayModel(reference))
    return RHO100_CALIBRATED_KG_M3 * float(np.exp(np.mean(np.log(nu / table.nu))))


def _neighbour_median(table: Table2, values: FloatArray) -> FloatArray:
    """Median of each cell's row and column neighbours in the printed table."""
    perigees = np.unique(table.perigee_km)
    apogees = np.unique(table.apogee_km)
    grid = np.full((perigees.size, apogees.size), np.nan)
    i = np.searchsorted(perigees, table.perigee_km)
    j = np.searchsorted(apogees, table.apogee_km)
    grid[i, j] = values
    padded = np.pad(grid, 1, constant_values=np.nan)
    neighbours = np.stack([padded[i, j + 1], padded[i + 2, j + 1], padded[i + 1, j], padded[i + 1, j + 2]])
    return np.nanmedian(neighbours, axis=0)


@dataclass(frozen=True)
class Table2Comparison:
    """Every cell, the paper's values beside ours."""

    table: Table2
    nu: FloatArray
    nu_paper_scheme: FloatArray
    paper_scheme_rho100_kg_m3: float
    v_perigee_m_s: FloatArray
    nu_misprint: NDArray[np.bool_]
    v_misprint: NDArray[np.bool_]

    @property
    def rel_error(self) -> FloatArray:
        """(ours - paper) / paper for nu."""
        return self.nu / self.table.nu - 1.0

    def rows(self) -> list[dict[str, float | bool]]:
        """One record per cell, with the public keys of ``orbit-env table2 --json``."""
        t = self.table
        return [
            {
                "perigee_km": float(t.perigee_km[k]),
                "apogee_km": float(t.apogee_km[k]),
                "nu_paper": float(t.nu[k]),
                "nu": float(self.nu[k]),
                "nu_paper_scheme": float(self.nu_paper_scheme[k]),
                "rel_error": float(self.rel_error[k]),
                "v_perigee_paper": float(t.v_perigee_m_s[k]),
                "v_perigee": float(self.v_perigee_m_s[k]),
                "nu_misprint": bool(self.nu_misprint[k]),
                "v_perigee_misprint": bool(self.v_misprint[k]),
            }
            for k in range(t.nu.size)
        ]

    def summary(self) -> dict[str, float | int]:
        """Median and 90th percentile of |relative error|, and the flagged cells."""
        error = np.abs(self.rel_error)
        clean = error[~self.nu_misprint]
        scheme = np.abs(self.nu_paper_scheme / self.table.nu - 1.0)
        return {
            "cells": int(error.size),
            "median_abs_rel_error": float(np.median(error)),
            "p90_abs_rel_error": float(np.percentile(error, 90)),
            "max_abs_rel_error": float(error.max()),
            "nu_misprints": int(self.nu_misprint.sum()),
            "median_abs_rel_error_without_misprints": float(np.median(clean)),
            "p90_abs_rel_error_without_misprints": float(np.percentile(clean, 90)),
            "v_perigee_misprints": int(self.v_misprint.sum()),
            "paper_scheme_rho100_kg_m3": self.paper_scheme_rho100_kg_m3,
            "paper_scheme_median_abs_rel_error": float(np.median(scheme)),
            "paper_scheme_p90_abs_rel_error": float(np.percentile(scheme, 90)),
        }


def compare_table2(model: DecayModel | None = None) -> Table2Comparison:
    """Compute all 351 cells of Table II and flag the printed cells that look misprinted."""
    table = load_table2()
    nu = model_nu(table, model)
    # The authors' Euler scheme, with its own least-squares rho1 (nu is inversely
    # proportional to rho1, so the fit is a factor).
    scheme = paper_scheme_nu(table.perigee_km * 1e3, table.apogee_km * 1e3, model)
    scheme_factor = float(np.exp(np.mean(np.log(scheme / table.nu))))
    log_error = np.log(nu / table.nu)
    jump = np.abs(log_error - _neighbour_median(table, log_error))
    v = perigee_velocity_m_s(table.perigee_km * 1e3, table.apogee_km * 1e3)
    return Table2Comparison(
        table=table,
        nu=nu,
        nu_paper_scheme=scheme / scheme_factor,
        paper_scheme_rho100_kg_m3=scheme_factor * RHO100_CALIBRATED_KG_M3,
        v_perigee_m_s=v,
        nu_misprint=jump > MISPRINT_LOG_JUMP,
        v_misprint=np.abs(v - table.v_perigee_m_s) > MISPRINT_VELOCITY_M_S,
    )
