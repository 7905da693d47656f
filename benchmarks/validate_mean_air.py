"""Dated lifetimes in the lifetime's mean air against the time-stepped curves, where both exist.

``orbit_env.decay.lifetime_mean`` answers dated orbits above the universal curves' domain
(a GTO, a Molniya disposal orbit) by the averaged equations in NRLMSIS's mean profile
over the satellite's own lifetime. Inside the domain the time-stepped curves
(``orbit_env.decay.chunked``, validated against the daily reference to 0.5%) give the
same lifetime with the real Sun followed chunk by chunk; this script prints both, for
an upper stage (1000 kg, 10 m^2, c_x 2.2) at 28.5 deg from two epochs half a solar
cycle apart, lives from about a year to decades.

    python benchmarks/validate_mean_air.py
"""

from __future__ import annotations

import time

import numpy as np

from orbit_env.analysis.lifetime import Satellite, lifetime
from orbit_env.constants import DAYS_PER_YEAR
from orbit_env.decay.chunked import SolarDecayModel
from orbit_env.decay.lifetime_mean import mean_air_lifetime
from orbit_env.decay.solar_record import load_record

STAGE = Satellite(2.2, 1000.0, 10.0)
INCLINATION_DEG = 28.5
CASES_KM = ((200.0, 2000.0), (250.0, 3900.0), (300.0, 2000.0), (300.0, 3900.0), (350.0, 1500.0))
EPOCHS = ("2026-12-01", "2031-06-01")


def main() -> None:
    """Print both lifetimes per case, and the spread of their ratio."""
    record = load_record()
    ratios = []
    print(f"{'epoch':<11} {'orbit [km]':<14} {'curves [y]':>10} {'mean air [y]':>12} {'ratio-1':>8} {'s (both)':>8}")
    for epoch in EPOCHS:
        for hp_km, ha_km in CASES_KM:
            start = time.perf_counter()
            # Both in co-rotating air, as a dated lifetime has it (the model's own default is still air:
            # the comparison had set co-rotating curves against a still mean air).
            stepped = lifetime(
                hp_km,
                ha_km,
                satellite=STAGE,
                method="curves",
                epoch=epoch,
                inclination_deg=INCLINATION_DEG,
                rotating_atmosphere=True,
            )
            model = SolarDecayModel(record, stepped.epoch_days, INCLINATION_DEG, rotating_atmosphere=True)
            mean = mean_air_lifetime(hp_km * 1e3, ha_km * 1e3, STAGE.drag_parameter_m2_kg, model)
            ratio = mean.days / stepped.days - 1.0
            ratios.append(ratio)
            print(
                f"{epoch:<11} {hp_km:4.0f} x {ha_km:<7.0f} {stepped.days / DAYS_PER_YEAR:10.3f} "
                f"{mean.days / DAYS_PER_YEAR:12.3f} "
                f"{ratio:+8.2%} {time.perf_counter() - start:8.1f}"
            )
    errors = np.abs(ratios)
    print(f"|ratio - 1|: median {np.median(errors):.2%}, max {errors.max():.2%} over {errors.size} cases")


if __name__ == "__main__":
    main()
