"""Disposal-rule check: re-entry within N years, and the smallest perigee-lowering burn that achieves it.

SI units (m, m/s, days). The burn is a single retrograde tangential burn at apogee:
it keeps the apogee and lowers the perigee (exact vis-viva), the cheapest way to
shorten the life of a near-circular or eccentric orbit with one burn. Since the
lifetime grows monotonically with the perigee at a fixed apogee, the smallest burn
is found by a vectorized search over perigee heights: three passes of
``CANDIDATES`` = 16 heights each, which cut the bracket around the highest
complying perigee into 17 parts, so every pass brackets it 17 times more finely
(resolution (h_p - 100 km) / 17^3 = (h_p - 100 km) / 4913, 0.18 km for a 1000 km
perigee). The perigee reported complies; the burn is rounded up, never down.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from orbit_env.checks import check_number
from orbit_env.constants import DAYS_PER_YEAR, REENTRY_ALTITUDE_M
from orbit_env.physics.orbit import dv_to_lower_perigee_m_s

FloatArray = NDArray[np.float64]
#: Lifetimes of many (perigee, apogee, satellite index) at once: (days, re-entered).
LifetimeFunction = Callable[[FloatArray, FloatArray, NDArray[np.intp]], tuple[FloatArray, NDArray[np.bool_]]]

#: Candidate perigees per pass of the search.
CANDIDATES = 16
#: Passes of the search.
PASSES = 3


@dataclass(frozen=True)
class RuleCheck:
    """Outcome of `check_disposal_rule`, arrays over satellites.

    Attributes:
        rule_years: The limit.
        lifetime_days: Lifetime of the orbit as it is (capped a little beyond the
            rule on time-stepped paths: then ``reentered`` is False).
        reentered: False where the satellite was still up at the cap.
        complies: Lifetime within the rule.
        new_perigee_m: Perigee after the smallest complying burn (the perigee itself if it complies).
        dv_m_s: That burn (0 if it complies).
    """

    rule_years: float
    lifetime_days: FloatArray
    reentered: NDArray[np.bool_]
    complies: NDArray[np.bool_]
    new_perigee_m: FloatArray
    dv_m_s: FloatArray


def check_disposal_rule(
    perigee_m: ArrayLike, apogee_m: ArrayLike, rule_years: float, lifetime_days: LifetimeFunction
) -> RuleCheck:
    """Check the rule for each satellite and find the smallest complying perigee-lowering burn.

    The burn is retrograde, at apogee: it keeps the apogee and lowers the perigee.

    Args:
        perigee_m: Perigee heights [m].
        apogee_m: Apogee heights [m].
        rule_years: Re-entry must come within this many years.
        lifetime_days: Vectorized lifetimes (see `LifetimeFunction`).

    Raises:
        ValueError: ``rule_years`` not positive.
    """
    rule_years = check_number(rule_years, "rule_years", unit="years", low=0.0, low_inclusive=False)
    hp = np.atleast_1d(np.asarray(perigee_m, dtype=np.float64))
    ha = np.broadcast_to(np.asarray(apogee_m, dtype=np.float64), hp.shape)
    limit = rule_years * DAYS_PER_YEAR
    index = np.arange(hp.size)
    days, reentered = lifetime_days(hp, ha, index)
    complies = reentered & (days <= limit)
    new_hp = hp.copy()
    todo = np.flatnonzero(~complies)
    # Bracket [lo, hi]: lo complies (100 km re-enters at once), hi does not.
    lo = np.full(todo.size, REENTRY_ALTITUDE_M)
    hi = hp[todo].copy()
    fractions = np.arange(1, CANDIDATES + 1) / (CANDIDATES + 1)
    for _ in range(PASSES if todo.size else 0):
        candidates = lo[:, None] + (hi - lo)[:, None] * fractions[None, :]
        which = np.repeat(todo, CANDIDATES)
        cand_days, cand_in = lifetime_days(candidates.ravel(), ha[which], which)
        ok = (cand_in & (cand_days <= limit)).reshape(candidates.shape)
        # Monotone in perigee: the highest complying candidate and the next one up bracket the answer.
        n_ok = ok.sum(axis=1)
        below = np.where(n_ok > 0, candidates[np.arange(todo.size), np.maximum(n_ok - 1, 0)], lo)
        above = np.where(n_ok < CANDIDATES, candidates[np.arange(todo.size), np.minimum(n_ok, CANDIDATES - 1)], hi)
        lo, hi = below, above
    new_hp[todo] = lo
    dv = np.where(complies, 0.0, dv_to_lower_perigee_m_s(hp, ha, new_hp))
    return RuleCheck(
        rule_years=float(rule_years),
        lifetime_days=days,
        reentered=reentered,
        complies=complies,
        new_perigee_m=new_hp,
        dv_m_s=dv,
    )
