"""Bit depth: float pixels in [0, 1] to 8- or 16-bit integers (rounded or dithered) and back.

A leaf of the engine: image files (:mod:`engine.io`), project files and export bundles all store
pixels through :func:`quantize` and read them back through :func:`to_float`, so an 8-bit source
saved at 8 bits or a 16-bit source at 16 bits round-trips exactly.
"""

from __future__ import annotations

import numpy as np

from engine._validate import as_rng

__all__ = ["quantize", "to_float"]


def quantize(pixels, bit_depth: int, *, dither: bool = True, rng=None) -> np.ndarray:
    """Float [0, 1] (or uint8/uint16) pixels -> uint8 or uint16 at ``bit_depth``.

    Values already on the target grid (e.g. an 8-bit source exported at 8 bits,
    a 16-bit source at 16 bits) are copied exactly. Other values are rounded; with
    ``dither=True`` triangular (TPDF, +-1 LSB) noise is added before rounding so a
    smooth 16-bit gradient reduced to 8 bits shows no banding and keeps its local
    mean. ``rng`` seeds the noise (int or Generator).
    """
    if bit_depth not in (8, 16) or isinstance(bit_depth, bool):
        raise ValueError(f"bit_depth must be 8 or 16, got {bit_depth!r}")
    raw = np.asarray(pixels)
    if raw.dtype == np.uint8 and bit_depth == 8:
        return raw.copy()
    if raw.dtype == np.uint16 and bit_depth == 16:
        return raw.copy()
    if raw.dtype == np.uint8 and bit_depth == 16:
        return raw.astype(np.uint16) * np.uint16(257)
    gen = as_rng(rng)
    if raw.dtype == bool:
        a = raw.astype(np.float64)
    elif np.issubdtype(raw.dtype, np.integer):
        info = np.iinfo(raw.dtype)
        if info.min < 0:
            raise TypeError(f"pixels must be float in [0, 1] or unsigned integers, got {raw.dtype}")
        a = raw.astype(np.float64) / info.max
    elif np.issubdtype(raw.dtype, np.floating):
        a = raw.astype(np.float64)
        if not np.all(np.isfinite(a)):
            raise ValueError("pixels contains NaN or infinite values")
    else:
        raise TypeError(f"pixels must be a numeric array, got dtype {raw.dtype}")
    top = 255.0 if bit_depth == 8 else 65535.0
    x = np.clip(a, 0.0, 1.0) * top
    r = np.round(x)
    if dither:
        off = np.abs(x - r) > 1e-2  # float32 k/65535 is off the grid by up to ~0.004 LSB
        if off.any():
            n = gen.random(int(off.sum())) - gen.random(int(off.sum()))
            r[off] = np.round(x[off] + n)
    return np.clip(r, 0, top).astype(np.uint8 if bit_depth == 8 else np.uint16)


def to_float(q: np.ndarray) -> np.ndarray:
    """uint8 / uint16 -> float32 in [0, 1], divided exactly as every reader of the engine does
    (255 or 65535), so stored pixels come back as the floats they were made from."""
    a = np.asarray(q)
    if a.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"expected uint8 or uint16 pixels, got {a.dtype}")
    return a.astype(np.float32) / (255.0 if a.dtype == np.uint8 else 65535.0)
