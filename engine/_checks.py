"""Scalar argument checks (no numpy: the command line's parsers and the settings types use them).

Every check names the parameter and what it got, in one message style (see
:mod:`engine._validate` for the array checks).
"""

from __future__ import annotations

import math
import numbers

__all__ = ["choice", "non_negative_number", "positive_int"]


def positive_int(value, name: str, *, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


def non_negative_number(value, name: str) -> float:
    """A finite real number >= 0 (not a bool) as float."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number, got {value!r}")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number >= 0, got {value}")
    return float(value)


def choice(value: str, name: str, options) -> str:
    if value not in options:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, options))}, got {value!r}")
    return value
