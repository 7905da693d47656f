"""A lifetime under NRLMSIS through the universal curves against the integrations, ratios in one run.

Run: python benchmarks/bench_msis.py   (needs pymsis)

1. Fixed profile (constant activity): one orbit by the curves (cold: the NRLMSIS
   table and the curves built from nothing; warm: cached), against the averaged
   ODE (DOP853) and the direct integration of the equations of motion, same orbit
   and same atmosphere object. The orbit is short-lived so that the direct
   integration takes seconds, not hours; the curves' cost does not depend on it.
2. Changing activity (the smooth solar cycle, 20-day chunks): the chunked curves
   against the averaged equations integrated in time with a fresh profile every day.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from orbit_env import cache
from orbit_env.decay.averaged import DecayModel, integrate_averaged
from orbit_env.decay.chunked import SolarDecayModel, cached_curves, propagate
from orbit_env.decay.direct import integrate_direct
from orbit_env.decay.reference_path import integrate_reference
from orbit_env.decay.solar import CycleActivity, unix_days
from orbit_env.physics.atmosphere.msis import MsisAtmosphere, _cached_log_density_table

INCLINATION_DEG = 51.6
DRAG_PARAMETER_M2_KG = 2.2 * 0.03 / 4.0  # a 3U cubesat: 4 kg, 0.03 m^2, c_x 2.2


def timed(function: Callable[[], object], repeats: int = 1) -> tuple[float, object]:
    best, value = float("inf"), None
    for _ in range(repeats):
        start = time.perf_counter()
        value = function()
        best = min(best, time.perf_counter() - start)
    return best, value


def main() -> None:
    cache.disable()  # "cold" builds the tables; the disk cache would hand them over
    hp, ha = 300e3, 300e3
    c = DRAG_PARAMETER_M2_KG

    def cold() -> float:
        _cached_log_density_table.cache_clear()
        cached_curves.cache_clear()
        atmosphere = MsisAtmosphere(150.0, 150.0, 15.0, INCLINATION_DEG)
        point = cached_curves(DecayModel(atmosphere)).locate(hp, ha)
        return float(point.weighted_s) / (9.81 * c) / 86400

    atmosphere = MsisAtmosphere(150.0, 150.0, 15.0, INCLINATION_DEG)
    model = DecayModel(atmosphere)
    cold_s, days_curves = timed(cold, 3)
    warm_s, _ = timed(lambda: cached_curves(model).locate(hp, ha), 20)
    ode_s, path = timed(lambda: integrate_averaged(hp, ha, model), 3)
    days_ode = float(path.weighted_s[-1]) / (9.81 * c) / 86400
    direct_s, direct = timed(lambda: integrate_direct(hp, ha, c, atmosphere=atmosphere), 1)
    print(f"1. {hp / 1e3:g} x {ha / 1e3:g} km, NRLMSIS F10.7 150, Ap 15, {INCLINATION_DEG} deg, c = {c:.4g} m^2/kg")
    print(
        f"   lifetime: curves {days_curves:.3f} d, averaged ODE {days_ode:.3f} d, direct {direct.time_s / 86400:.3f} d"
    )
    print(f"   curves, cold (table + curves built)  {cold_s:8.3f} s")
    print(f"   curves, warm (cached)                {warm_s * 1e6:8.1f} us")
    ratios = f"{ode_s / warm_s:8.0f} x warm, {ode_s / cold_s:.2f} x cold"
    print(f"   averaged ODE (DOP853)                {ode_s:8.3f} s   = {ratios}")
    print(
        f"   direct ({direct.revolutions:.0f} revolutions)        {direct_s:8.3f} s   = "
        f"{direct_s / warm_s:8.0f} x warm, {direct_s / cold_s:.1f} x cold"
    )

    start = unix_days("2024-01-01")
    solar = SolarDecayModel(CycleActivity(), start, INCLINATION_DEG)
    hp2 = ha2 = 380e3
    chunked_s, result = timed(lambda: propagate(hp2, ha2, c, solar), 1)
    again_s, _ = timed(lambda: propagate(hp2, ha2, c, solar), 1)
    reference_s, days_ref = timed(lambda: integrate_reference(hp2, ha2, c, solar), 1)
    days_chunked = float(result.days[0])
    print(f"2. {hp2 / 1e3:g} km circular, smooth solar cycle from 2024-01-01, 20-day chunks")
    print(f"   lifetime: chunked curves {days_chunked:.2f} d, daily-profile averaged ODE {days_ref:.2f} d")
    print(f"   chunked curves, first run            {chunked_s:8.3f} s ({result.bins_used} curve families built)")
    print(f"   chunked curves, cached               {again_s:8.3f} s")
    ratios = f"{reference_s / chunked_s:.1f} x first run, {reference_s / again_s:.0f} x cached"
    print(f"   averaged ODE, a profile a day        {reference_s:8.3f} s   = {ratios}")


if __name__ == "__main__":
    main()
