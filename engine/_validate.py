"""Eager input validation and conversion helpers shared by the engine.

The scalar checks (``positive_int``, ``non_negative_number``, ``choice``) live in
:mod:`engine._checks` (no numpy) and are re-exported here.
"""

from __future__ import annotations

import numbers

import numpy as np
from skimage.util import img_as_float32

from engine._checks import choice, non_negative_number, positive_int


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


__all__ = [
    "as_error_map",
    "as_image",
    "as_rng",
    "choice",
    "non_negative_number",
    "positive_int",
]
