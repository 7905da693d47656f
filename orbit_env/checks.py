"""The one validation helper of the public boundary: errors in the user's words.

Every constructor, API function and CLI argument checks its numbers with
`check_number` (one value), `check_int` (a count) or
`check_array` (arrays: the first bad element and its index). They raise
`InputError`, a ``ValueError`` whose message names the parameter, the value
as it was given (a plain number, never ``np.float64(...)``) and the allowed range
in the parameter's own unit::

    perigee_km=50 is out of range; allowed: 100 to 50000 km
    mass_kg=0 is out of range; allowed: above 0 kg
    inclination_deg=nan is not a finite number; allowed: 0 to 180 deg

How to use it:

* Check the value in the unit the caller typed, **then** convert to SI, so the
  message says ``scale_height_km=-8.5``, not ``scale_height_m=-8500.0``.
* Name the parameter as the caller spells it (the keyword of the function or the
  dataclass field), with its unit in ``unit``; ``why`` adds the reason for a bound.
* A bound that is another parameter (apogee >= perigee) is given as ``low=hp`` with
  ``low_name="perigee_km"``; the message shows both.
* A front end whose words differ (the CLI's ``--perigee`` for ``perigee_km``) catches
  `InputError` and re-renders it with `InputError.message`
  (``label=``, ``value_text=``, ``scale=``, ``unit=``, ``rename=``): the error keeps
  the parameter's name, value, unit and bounds as data for that.

Examples:
    >>> check_number(400, "perigee_km", unit="km", low=100, high=50_000)
    400.0
    >>> check_number(50, "perigee_km", unit="km", low=100, high=50_000)
    Traceback (most recent call last):
    ...
    orbit_env.checks.InputError: perigee_km=50 is out of range; allowed: 100 to 50000 km
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["DATE_RANGE", "InputError", "check_array", "check_date", "check_int", "check_number", "format_number"]

#: Dates an orbit may have (epochs, observations, re-entries), as unix days and ISO dates: from
#: Sputnik 1's launch to the end of 2200, beyond which no solar record, forecast or atmosphere
#: model of this package means anything.
DATE_RANGE = ((-4472.0, "1957-10-04"), (84_370.0, "2200-12-31"))


def format_number(value: Any) -> str:
    """A number as a user reads it: ``50``, ``-8.5``, ``1e+300``, ``nan`` (never a numpy repr)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.ndarray)):
        text = repr(value)
        return text if len(text) <= 40 else text[:37] + "..."
    x = float(value)
    if math.isfinite(x) and x.is_integer() and abs(x) < 1e16:
        return str(int(x))
    return repr(x)


class InputError(ValueError):
    """A value at the public boundary that is not allowed; the message says which, and what is.

    The attributes keep the pieces, so a front end can say the same in its own
    words (see `message`).

    Attributes:
        name: The parameter's name (``perigee_km``).
        value: The offending value as given (for arrays: the bad element).
        index: Index of the bad element in an array, else None.
        problem: ``"number"`` (not a number), ``"integer"``, ``"finite"`` or ``"range"``.
        unit: Unit of the value and the bounds (``"km"``; ``""`` if none).
        low, high: Bounds (None: unbounded); ``low_inclusive``, ``high_inclusive``.
        low_name, high_name: Parameter a bound comes from (None: a fixed bound).
        why: Why the bounds are what they are (may be empty).
        integer: Whether only whole numbers are allowed.
    """

    def __init__(
        self,
        name: str,
        value: Any,
        problem: str,
        *,
        index: tuple[int, ...] | None = None,
        unit: str = "",
        low: float | None = None,
        high: float | None = None,
        low_inclusive: bool = True,
        high_inclusive: bool = True,
        low_name: str | None = None,
        high_name: str | None = None,
        why: str = "",
        integer: bool = False,
    ) -> None:
        assert problem in ("number", "integer", "finite", "range"), problem
        self.name = name
        self.value = value
        self.problem = problem
        self.index = index
        self.unit = unit
        self.low = low
        self.high = high
        self.low_inclusive = low_inclusive
        self.high_inclusive = high_inclusive
        self.low_name = low_name
        self.high_name = high_name
        self.why = why
        self.integer = integer or problem == "integer"
        super().__init__(self.message())

    def message(
        self,
        label: str | None = None,
        *,
        value_text: str | None = None,
        scale: float = 1.0,
        unit: str | None = None,
        rename: Callable[[str], str] | None = None,
        show_index: bool = True,
        shift: float = 0.0,
    ) -> str:
        """The message, optionally in a front end's words.

        Args:
            label: Name to show instead of `name` (``"--perigee"``). A label
                starting with ``-`` is followed by a space, a name by ``=``.
            value_text: The value as the user typed it (default: `value`).
            scale: Factor from `unit` to the shown unit, applied to the bounds
                (and to the value if ``value_text`` is not given).
            unit: The shown unit (default: `unit`).
            rename: Maps the names of bounds taken from other parameters.
            show_index: Append the bad element's index to the label (a front end
                that names the element its own way, say by a date, turns it off).
            shift: Added to the bounds after ``scale`` (and to the value if ``value_text`` is not
                given): a height checked above one surface, shown above the user's.
        """
        rename = rename or (lambda name: name)
        unit = self.unit if unit is None else unit
        label = self.name if label is None else label
        if self.index is not None and show_index:
            label += "[" + ", ".join(str(i) for i in self.index) + "]"
        if value_text is None:
            shown = self.value
            if (scale != 1.0 or shift != 0.0) and self.problem in ("finite", "range", "integer"):
                shown = float(self.value) * scale + shift
            value_text = format_number(shown)
        head = f"{label} {value_text}" if label.startswith("-") else f"{label}={value_text}"
        if self.problem == "number" and isinstance(self.value, (str, np.str_)):
            text = f"{head} is not a number"  # the quotes show it is text
        elif self.problem == "number":
            if isinstance(self.value, (bool, np.bool_)):
                kind = "a bool"
            else:
                kind = "None" if self.value is None else type(self.value).__name__
            text = f"{head} is not a number (got {kind})"
        elif self.problem == "integer":
            text = f"{head} is not an integer"
        elif self.problem == "finite":
            text = f"{head} is not a finite number"
        else:
            text = f"{head} is out of range"
        allowed = self._allowed(scale, unit, rename, show_index, shift)
        if allowed:
            text += f"; allowed: {allowed}"
        if self.why:
            text += f" ({self.why})"
        return text

    def _allowed(self, scale: float, unit: str, rename: Callable[[str], str], show_index: bool, shift: float) -> str:
        def bound(value: float | None, name: str | None) -> str:
            assert value is not None
            number = format_number(float(value) * scale + shift)
            if name is None:
                return number
            index = "" if self.index is None or not show_index else "[" + ", ".join(str(i) for i in self.index) + "]"
            return f"{rename(name)}{index} ({number})"

        low = None if self.low is None else bound(self.low, self.low_name)
        high = None if self.high is None else bound(self.high, self.high_name)
        if low is not None and high is not None:
            if self.low_inclusive and self.high_inclusive:
                text = f"{low} to {high}"
            else:
                lower = f"{'at least' if self.low_inclusive else 'above'} {low}"
                text = f"{lower} and {'at most' if self.high_inclusive else 'below'} {high}"
        elif low is not None:
            text = f"{'at least' if self.low_inclusive else 'above'} {low}"
        elif high is not None:
            text = f"{'at most' if self.high_inclusive else 'below'} {high}"
        else:
            text = ""
        if text and unit:
            text += f" {unit}"
        if not text and self.problem == "finite":
            text = "a finite number"
        if self.integer:
            text = f"an integer{' ' + text if text else ''}"
        return text


def _is_number(value: Any) -> bool:
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, numbers.Real):
        return True
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"


def check_number(
    value: Any,
    name: str,
    *,
    unit: str = "",
    low: float | None = None,
    high: float | None = None,
    low_inclusive: bool = True,
    high_inclusive: bool = True,
    integer: bool = False,
    why: str = "",
    low_name: str | None = None,
    high_name: str | None = None,
) -> float:
    """Check one number of the public boundary and return it as a plain float.

    Args:
        value: What the caller gave.
        name: The parameter's name as the caller spells it (``"perigee_km"``).
        unit: The unit of ``value`` and of the bounds (shown after the range).
        low: Lower bound (None: unbounded below). NaN and infinities are always refused.
        high: Upper bound (None: unbounded above).
        low_inclusive: Whether ``low`` itself is allowed.
        high_inclusive: Whether ``high`` itself is allowed.
        integer: Require a whole number.
        why: A short reason for the bounds, shown in parentheses.
        low_name: Name of the parameter ``low`` comes from (``"perigee_km"``), if any.
        high_name: Name of the parameter ``high`` comes from, if any.

    Raises:
        InputError: ``value`` is a bool or not a real number, is NaN or infinite, is
            not whole (``integer``) or is outside the bounds. The message names
            ``name``, the value and the allowed range.
    """
    bounds: dict[str, Any] = dict(
        unit=unit,
        low=low,
        high=high,
        low_inclusive=low_inclusive,
        high_inclusive=high_inclusive,
        low_name=low_name,
        high_name=high_name,
        why=why,
    )
    if not _is_number(value):
        raise InputError(name, value, "number", **bounds)
    x = float(value)
    if not math.isfinite(x):
        raise InputError(name, value, "finite", **bounds)
    if integer and not x.is_integer():
        raise InputError(name, value, "integer", **bounds)
    if (low is not None and (x < low if low_inclusive else x <= low)) or (
        high is not None and (x > high if high_inclusive else x >= high)
    ):
        raise InputError(name, value, "range", integer=integer, **bounds)
    return x


def check_date(days: float, name: str, *, text: str | None = None) -> float:
    """Check a date given as unix days (days since 1970-01-01) against `DATE_RANGE`.

    Args:
        days: The date as unix days.
        name: The parameter (``"epoch"``) or flag (``"--epoch"``) it came from.
        text: The date as typed, shown in the message (default: ``days``).

    Raises:
        ValueError: the date is not finite or lies outside the range; the message
            names ``name``, the date as typed and the range as dates.
    """
    (low, low_date), (high, high_date) = DATE_RANGE
    shown = format_number(days) if text is None else text
    label = f"{name} {shown}" if name.startswith("-") else f"{name}={shown!r}" if text else f"{name}={shown}"
    if not (math.isfinite(days) and low <= days < high + 1.0):
        raise ValueError(
            f"{label} is out of range; allowed: {low_date} to {high_date} "
            "(no satellite flew before Sputnik 1; the models here do not reach beyond 2200)"
        )
    return float(days)


def check_int(value: Any, name: str, *, low: int | None = None, high: int | None = None, why: str = "") -> int:
    """Check a count (a whole number, ``2`` or ``2.0``; not ``True``) and return it as an int.

    Raises:
        InputError: as `check_number` with ``integer=True``.
    """
    return int(check_number(value, name, low=low, high=high, integer=True, why=why))


def check_array(
    values: ArrayLike,
    name: str,
    *,
    unit: str = "",
    low: ArrayLike | None = None,
    high: ArrayLike | None = None,
    low_inclusive: bool = True,
    high_inclusive: bool = True,
    why: str = "",
    low_name: str | None = None,
    high_name: str | None = None,
) -> NDArray[np.float64]:
    """Check every element of an array (or a scalar) and return it as a float array.

    ``low`` and ``high`` may be arrays broadcasting against ``values`` (a bound
    set by another parameter, named by ``low_name``/``high_name``). The error
    reports the first bad element, its index (for arrays of more than one
    element) and its bound.

    Raises:
        InputError: not numbers, NaN or infinite, or out of bounds; see `check_number`.
    """
    bounds: dict[str, Any] = dict(
        unit=unit,
        low_inclusive=low_inclusive,
        high_inclusive=high_inclusive,
        low_name=low_name,
        high_name=high_name,
        why=why,
    )
    raw = np.asarray(values)
    if raw.dtype.kind not in "iuf":
        bad = next((v for v in raw.flat if not _is_number(v)), raw.flat[0] if raw.size else values)
        raise InputError(name, bad, "number", low=_scalar(low), high=_scalar(high), **bounds)
    x = raw.astype(np.float64)
    lo = None if low is None else np.broadcast_to(np.asarray(low, dtype=np.float64), x.shape)
    hi = None if high is None else np.broadcast_to(np.asarray(high, dtype=np.float64), x.shape)
    for problem, bad in (
        ("finite", ~np.isfinite(x)),
        (
            "range",
            (np.zeros(x.shape, bool) if lo is None else (x < lo if low_inclusive else x <= lo))
            | (np.zeros(x.shape, bool) if hi is None else (x > hi if high_inclusive else x >= hi)),
        ),
    ):
        if bad.any():
            where = tuple(int(i) for i in np.argwhere(bad)[0])
            raise InputError(
                name,
                float(x[where]),
                problem,
                index=where if x.size > 1 else None,
                low=None if lo is None else float(lo[where]),
                high=None if hi is None else float(hi[where]),
                **bounds,
            )
    return x


def _scalar(bound: ArrayLike | None) -> float | None:
    if bound is None:
        return None
    array = np.asarray(bound, dtype=np.float64)
    return float(array.flat[0]) if array.size == 1 else None
