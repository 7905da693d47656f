"""The reference the dated decay is measured against: the averaged equations in time, day by day. SI units.

No bins, no chunks, no curves: the orbit-averaged NRLMSIS profile at each calendar day's
indices (the record's row, placed at the day's start) and day of the year (on the decay's
storm days, `orbit_env.decay.chunked.STORM_AP`, NRLMSIS's storm-time mode through the day's
eight 3-hour slots, as the decay takes them), its logarithm interpolated linearly in time, and
the averaged rates of `orbit_env.decay.averaged` integrated by scipy's DOP853 to re-entry. Slow (about
25 ms a profile), so it is a yardstick for `orbit_env.decay.chunked.propagate`
(docs/validation-modern/solar-activity.md), not a path users take for speed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from orbit_env.constants import DAYS_PER_YEAR, G0_M_S2, REENTRY_ALTITUDE_M, SECONDS_PER_DAY
from orbit_env.decay.averaged import DecayModel
from orbit_env.decay.solar import calendar_day
from orbit_env.physics.atmosphere import FunctionAtmosphere
from orbit_env.physics.atmosphere.msis import (
    ALTITUDE_GRID_M,
    interpolate_log_density,
)
from orbit_env.physics.orbit import elements_from_heights, heights_from_elements, period_s

if TYPE_CHECKING:
    from orbit_env.decay.chunked import SolarDecayModel

FloatArray = NDArray[np.float64]


def integrate_reference(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    *,
    profile_step_days: float = 1.0,
    rtol: float = 1e-8,
) -> float:
    """Days to re-entry from the averaged equations in time, with a fresh NRLMSIS profile every step.

    The reference for the chunked curves: no bins, no chunks, no curves. The
    profile (orbit-averaged NRLMSIS at the day's indices and day of year) is
    recomputed every ``profile_step_days`` and its logarithm interpolated
    linearly in time; dp/dt and de/dt are the averaged rates of
    `orbit_env.decay.averaged` times dnu/dt = g c / P. Slow: ~25 ms per profile.
    """
    solution = _solve_reference(perigee_m, apogee_m, drag_parameter_m2_kg, model, profile_step_days, rtol)
    if solution.status != 1:
        return model.max_years * DAYS_PER_YEAR
    return float(solution.t_events[0][0]) / SECONDS_PER_DAY


def _solve_reference(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    profile_step_days: float,
    rtol: float,
) -> Any:
    """The ``solve_ivp`` solution behind `integrate_reference` and `reference_path`."""
    profiles: dict[int, FloatArray] = {}
    # The profiles sit at the starts of calendar days (the record's rows, as the decay reads them), from the one
    # that holds the start.
    origin_days = float(calendar_day(model.start_days))

    def log_profile(index: int) -> FloatArray:
        if index not in profiles:
            profiles[index] = np.log(
                model.density_on_day_kg_m3(origin_days + index * profile_step_days, ALTITUDE_GRID_M)
            )
        return profiles[index]

    def rhs(t_s: float, state: FloatArray) -> list[float]:
        p, e = state[0], max(state[1], 0.0)
        x = (t_s / SECONDS_PER_DAY + model.start_days - origin_days) / profile_step_days
        i = math.floor(x)
        w = x - i
        log_rho = (1.0 - w) * log_profile(i) + w * log_profile(i + 1)
        atmosphere = FunctionAtmosphere(lambda h, table=log_rho: interpolate_log_density(h, table))
        decay = DecayModel(atmosphere, model.rotating_atmosphere, model.inclination_deg)
        with np.errstate(invalid="ignore"):  # trial steps past re-entry; the event stops before them
            dp_dnu, de_dnu = decay.rates_per_nu(p, e)
            dnu_dt = G0_M_S2 * drag_parameter_m2_kg / float(period_s(p, e))
        return [float(dp_dnu) * dnu_dt, float(de_dnu) * dnu_dt]

    def reentry(t_s: float, state: FloatArray) -> float:
        return float(heights_from_elements(state[0], max(state[1], 0.0))[0]) - REENTRY_ALTITUDE_M

    reentry.terminal = True  # type: ignore[attr-defined]
    p0, e0 = (float(x) for x in elements_from_heights(perigee_m, apogee_m))
    t_max = model.max_years * DAYS_PER_YEAR * SECONDS_PER_DAY
    from scipy.integrate import solve_ivp  # on use: half a second of start-up

    solution = solve_ivp(
        rhs,
        (0.0, t_max),
        [p0, e0],
        method="DOP853",
        events=reentry,
        rtol=rtol,
        atol=[1e-3, 1e-12],
        max_step=profile_step_days * SECONDS_PER_DAY,
    )
    return solution


def reference_path(
    perigee_m: float,
    apogee_m: float,
    drag_parameter_m2_kg: float,
    model: SolarDecayModel,
    *,
    profile_step_days: float = 1.0,
    rtol: float = 1e-8,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The decay of `integrate_reference` as it goes: days, perigee [m] and apogee [m] at its steps.

    The last point is the re-entry (perigee 100 km), or the state at ``max_years``.
    """
    solution = _solve_reference(perigee_m, apogee_m, drag_parameter_m2_kg, model, profile_step_days, rtol)
    t_s, states = solution.t, solution.y.T
    if solution.status == 1:
        t_s = np.append(t_s[t_s < solution.t_events[0][0]], solution.t_events[0][0])
        states = np.vstack([states[: t_s.size - 1], solution.y_events[0][:1]])
    perigee, apogee = heights_from_elements(states[:, 0], np.maximum(states[:, 1], 0.0))
    return t_s / SECONDS_PER_DAY, np.asarray(perigee, dtype=np.float64), np.asarray(apogee, dtype=np.float64)
