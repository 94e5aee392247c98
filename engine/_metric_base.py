"""Small helpers shared by :mod:`engine.metrics` and :mod:`engine.tileset_metrics`."""

from __future__ import annotations

import numbers

import numpy as np

from engine._validate import as_image
from engine.errormap import colour_channels


def colour(image, name: str, *, min_size: int = 1) -> np.ndarray:
    """The colour channels of ``image`` (alpha dropped, gray kept as one channel)."""
    return colour_channels(as_image(image, name, min_size=min_size))


def ratio(num: float, den: float) -> float:
    """``num / den``; 1.0 when both are zero, ``inf`` when only ``den`` is."""
    if den > 0:
        return float(num / den)
    return 1.0 if num == 0 else float("inf")


def pair(period, name: str = "period") -> tuple[int, int]:
    """An int or a (rows, cols) pair of positive ints as (rows, cols)."""
    if isinstance(period, numbers.Integral) and not isinstance(period, bool):
        period = (period, period)
    try:
        ph, pw = (int(v) for v in period)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an int or a (ph, pw) pair, got {period!r}") from None
    if ph < 1 or pw < 1:
        raise ValueError(f"{name} must be positive, got {(ph, pw)}")
    return ph, pw
