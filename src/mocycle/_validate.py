"""Argument checks in one place, in the spirit of scikit-learn's parameter constraints.

Each check returns the value in its normal form (``int``, ``float``, the chosen word) or raises
:class:`~mocycle.errors.OptionError` naming the parameter, e.g.
``OptionError("cycles", "must be an integer >= 1; got 0")``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping

from .errors import OptionError


def choice(name: str, value, choices: Iterable[str]):
    """``value`` if it is one of ``choices`` (compared as given), else an OptionError listing them."""
    choices = tuple(choices)
    if isinstance(value, str) and value in choices:
        return value
    raise OptionError(name, f"must be one of {', '.join(choices)}; got {value!r}")


def _describe(low, high, low_open: bool = False, high_open: bool = False) -> str:
    if low is not None and high is not None:
        return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
    if low is not None:
        return f"{'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{'<' if high_open else '<='} {high:g}"
    return "finite"


def integer(name: str, value, low: int | None = None, high: int | None = None, *,
            words: Mapping[str, object] | None = None, note: str = ""):
    """An ``int`` in ``[low, high]`` (``None``: unbounded); numeric strings such as ``"3"`` are accepted.

    ``words`` maps accepted words to what they stand for (``{"auto": "auto", "none": None}``); ``note`` says
    where the bounds come from (``"half the take"``).
    """
    words = dict(words or {})
    if isinstance(value, str) and value in words:
        return words[value]
    number = value
    if isinstance(value, str):
        try:
            number = int(value.strip())
        except ValueError:
            number = None
    ok = isinstance(number, numbers.Integral) and not isinstance(number, bool)
    if ok:
        number = int(number)
        ok = (low is None or number >= low) and (high is None or number <= high)
    if not ok:
        what = f"an integer {_describe(low, high)}" if (low, high) != (None, None) else "an integer"
        if low == 1 and high is None:
            what = "a positive integer"
        if words:
            what = " or ".join(repr(w) for w in words) + " or " + what
        raise OptionError(name, f"must be {what}{f' ({note})' if note else ''}; got {value!r}")
    return number


def real(name: str, value, low: float | None = None, high: float | None = None, *,
         low_open: bool = False, high_open: bool = False) -> float:
    """A finite ``float`` in the interval (closed ends unless ``low_open``/``high_open``)."""
    try:
        number = float(value) if not isinstance(value, bool) else math.nan
    except (TypeError, ValueError):
        number = math.nan
    ok = math.isfinite(number)
    if ok and low is not None:
        ok = number > low if low_open else number >= low
    if ok and high is not None:
        ok = number < high if high_open else number <= high
    if not ok:
        what = "a positive number" if (low == 0 and low_open and high is None) else \
            f"a number {_describe(low, high, low_open, high_open)}"
        raise OptionError(name, f"must be {what}; got {value!r}")
    return number


def positive(name: str, value) -> float:
    """A finite number > 0."""
    return real(name, value, 0, low_open=True)


def renamed(old: str, new: str, old_value, new_value, default=None, *, stacklevel: int = 3):
    """The value of a keyword argument renamed from ``old`` to ``new``: ``old_value`` (given under the old name,
    with a ``DeprecationWarning``; for one release) unless ``new_value`` is given too (not ``default``), then
    an OptionError; else ``new_value``."""
    if old_value is None:
        return new_value
    if new_value is not default:
        raise OptionError(old, f"is the old name of {new}; give {new} only")
    import warnings

    warnings.warn(f"{old} is now called {new}; {old} is accepted until the next release", DeprecationWarning,
                  stacklevel=stacklevel)
    return old_value
