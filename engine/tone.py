"""Tone preparation of a source (issue 10, item 4a): Flatten lighting.

A photo lit unevenly (a light gradient, a vignette) gives every tile a tone ramp; a tile set
then shows a frame or a lattice whatever the cuts do. :func:`flatten_lighting` removes the
low-frequency illumination: per colour channel, a smooth field (a Gaussian of σ = ``scale``;
the border extended by odd reflection, which continues a gradient) is divided out
(``"divide"``, for light that multiplies the albedo) or subtracted (``"subtract"``), and the
channel's mean is put back, so the mean colour stays. It is for the albedo (colour) map only,
never for normal or height maps, whose values are not lit. Structures larger than ``scale``
are flattened too: tie ``scale`` to the tile size (the pipeline uses the largest tile side).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from engine._validate import as_image, choice, non_negative_number

__all__ = ["FLATTEN_MODES", "flatten_lighting", "flatten_scale"]

FLATTEN_MODES = ("divide", "subtract")


def flatten_scale(tile_max) -> float:
    """σ of the light field for tiles up to ``tile_max`` (an int or (h, w)): the largest tile
    side, so nothing the size of a tile is flattened away."""
    return float(np.max(tile_max))


def flatten_lighting(image, *, scale: float, mode: str = "divide") -> np.ndarray:
    """``image`` (H, W[, C]) with its low-frequency lighting removed, float32 in [0, 1].

    Alpha (C = 2 or 4) is kept as it is. ``scale`` (σ of the smooth field, px) must be > 0.

    Examples
    --------
    >>> ramp = np.linspace(0.2, 0.8, 64)[None, :].repeat(64, axis=0)
    >>> flat = flatten_lighting(ramp * 0.5 + 0.25, scale=8)
    >>> float(np.ptp(flat[:, 16:48])) < 0.01
    True
    """
    x = as_image(image, "image")
    s = non_negative_number(scale, "scale")
    if s <= 0:
        raise ValueError(f"scale must be > 0, got {scale}")
    choice(mode, "mode", FLATTEN_MODES)
    colour = x.shape[2] - (1 if x.shape[2] in (2, 4) else 0)
    out = x.copy()
    for c in range(colour):
        ch = x[:, :, c].astype(np.float64)
        # odd reflection at the border continues a light gradient instead of folding it
        pad = int(min(3 * s + 1, *(n - 1 for n in ch.shape)))
        padded = np.pad(ch, pad, mode="reflect", reflect_type="odd")
        field = ndimage.gaussian_filter(padded, s, mode="nearest")[
            pad : -pad or None, pad : -pad or None
        ]
        mean = ch.mean()
        flat = ch / np.maximum(field, 1e-3) * mean if mode == "divide" else ch - field + mean
        out[:, :, c] = np.clip(flat, 0, 1)
    return out
