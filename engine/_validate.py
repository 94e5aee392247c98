"""Eager input validation and conversion helpers shared by the engine."""

from __future__ import annotations

import math
import numbers

import numpy as np
from skimage.util import img_as_float32


def as_rng(rng: int | np.random.Generator | None) -> np.random.Generator:
    """Resolve ``rng`` (seed, Generator or None) into a Generator."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, numbers.Integral):
        return np.random.default_rng(rng)
    raise TypeError(f"rng must be an int, a numpy Generator or None, got {type(rng).__name__}")


def as_image(image, name: str = "image", *, min_size: int = 1) -> np.ndarray:
    """Return ``image`` as float32 (H, W, C) in [0, 1] without changing the input.

    Accepts (H, W) and (H, W, C) arrays of any integer or float dtype; integer
    images are scaled by their dtype range (uint8 -> /255, uint16 -> /65535).
    """
    a = np.asarray(image)
    if a.dtype == bool:
        a = a.astype(np.float32)
    if not (np.issubdtype(a.dtype, np.integer) or np.issubdtype(a.dtype, np.floating)):
        raise TypeError(f"{name} must be a numeric array, got dtype {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3:
        raise ValueError(f"{name} must be shaped (H, W) or (H, W, C), got shape {a.shape}")
    if a.shape[0] < min_size or a.shape[1] < min_size or a.shape[2] < 1:
        raise ValueError(
            f"{name} must be at least {min_size}x{min_size} pixels, got {a.shape[1]}x{a.shape[0]}"
        )
    out = img_as_float32(a)
    if out is a:
        out = out.copy()
    if np.issubdtype(a.dtype, np.floating) and not np.all(np.isfinite(out)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return out


def as_error_map(error, name: str = "error") -> np.ndarray:
    """Return a 2-D float64 error map of finite, non-negative values."""
    e = np.asarray(error, dtype=np.float64)
    if e.ndim != 2:
        raise ValueError(f"{name} must be a 2-D array, got shape {e.shape}")
    if e.shape[0] < 1 or e.shape[1] < 1:
        raise ValueError(f"{name} must not be empty, got shape {e.shape}")
    if not np.all(np.isfinite(e)):
        raise ValueError(f"{name} must be finite")
    if e.min() < 0:
        raise ValueError(f"{name} must be non-negative, got minimum {e.min():g}")
    return e


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
