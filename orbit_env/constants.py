"""Physical constants of the 1957 paper, in SI units (m, kg, s, rad).

The paper uses a spherical Earth of radius R and the gravitational parameter fM.
R = 6371 km reproduces the perigee velocities of its Table II to a median of
0.4 m/s (R = 6378 km gives 4.7 m/s), so it is the radius used here.
"""

from __future__ import annotations

import math

#: Gravitational parameter of the Earth, fM in the paper [m^3/s^2].
MU_EARTH_M3_S2 = 3.986e14
#: Mean radius of the spherical Earth of the paper [m].
EARTH_RADIUS_M = 6.371e6
#: Standard gravity, the g of Eq. (4.1) that turns weight into mass [m/s^2].
G0_M_S2 = 9.81
#: Re-entry: integration stops when the perigee height reaches 100 km (section 3).
REENTRY_ALTITUDE_M = 100e3
#: Sidereal rotation rate of the Earth (and of the co-rotating atmosphere) [rad/s].
EARTH_ROTATION_RAD_S = 7.2921159e-5
#: Equatorial radius of the Earth, the a of Eq. (5.2) [m].
EARTH_EQUATORIAL_RADIUS_M = 6.378137e6
#: Second zonal harmonic. The paper's epsilon = fM a^2 (alpha - m/2) of Eq. (5.2)
#: equals fM a^2 (3/2) J2 to first order in the flattening.
J2_EARTH = 1.08263e-3
#: Seconds in a day.
SECONDS_PER_DAY = 86400.0
#: Days in a year (the Julian year): every lifetime given in years, every rule's years in days.
DAYS_PER_YEAR = 365.25
#: Two pi, named because it appears in every orbit average.
TWO_PI = 2.0 * math.pi
