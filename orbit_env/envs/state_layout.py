"""The layout of a task state, declared once: its fields, and their rows in a batch's array.

`orbit_env.envs.task.TaskState` holds the fields as Python floats, `orbit_env.envs.task.BatchState`
as the rows of one (fields + segment rows, n) float64 array, and the compiled loops of
`orbit_env.envs.kernel` read that array by the row numbers `ROW` gives. All three take
the fields from `StateFields`, so a field added or moved there moves everywhere.
SI units (m, kg, s, m/s); days only in the mission's clock.
"""

from __future__ import annotations

from typing import NamedTuple


class StateFields(NamedTuple):
    """The fields of a satellite's state, in the order of a batch's rows (each value: that field's row)."""

    label: int  # mu, the universal curve the orbit decays along
    tau: int  # ln(1 + nu / NU_REF), the position along it
    nu: int  # universal lifetime left [m^3/(kg s^2)]
    period_s: int  # mean period over the rest of the decay, W / nu [s]
    perigee_m: int  # heights as the curves give the point [m]
    apogee_m: int
    perigee_drop_m: int  # drops over the last coast [m] (0 at the start)
    apogee_drop_m: int
    mass_kg: int
    dry_mass_kg: int
    exhaust_m_s: int  # effective exhaust velocity Isp g0 [m/s]
    drag_area_m2: int  # c_x F
    density_base: int  # s0, the episode's density scale
    density_phase_rad: int  # phi of the solar-cycle-like modulation
    density_scale: int  # s(t), held over the coming step
    nu_per_rev: int  # g c s per revolution [m^3/(kg s^2)]
    nominal_w_per_day: int  # g c s_nominal x 1 day: W over it is the predicted lifetime [days]
    dv_left_m_s: int  # delta-v the propellant on board still gives [m/s]
    time_days: int  # mission time [days]
    steps: int  # steps taken (whole numbers, exact in float64)


#: The names of the fields, in the order of a batch's rows.
STATE_FIELDS: tuple[str, ...] = StateFields._fields
#: The row of each field in a batch's array (``ROW.mass_kg``).
ROW = StateFields(*range(len(STATE_FIELDS)))
#: The first row below the fields: each orbit's cell of the curves' table B
#: (`orbit_env.decay.curves.BilinearGrid.segments`: the cell index j, then the three
#: values' bases, then their slopes), kept between steps so a coast needs no gather.
SEGMENT_ROW = len(STATE_FIELDS)
#: Rows of the cell of table B.
SEGMENT_ROWS = 7
