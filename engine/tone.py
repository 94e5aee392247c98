"""Tone preparation of a source (issue 10, item 4a): Flatten lighting.

A photo lit unevenly (a light gradient, a vignette) gives every tile a tone ramp; a tile set
then shows a frame or a lattice whatever the cuts do. :func:`flatten_lighting` removes the
low-frequency illumination: per colour channel, a smooth field (a Gaussian of σ = ``scale``;
the border extended by odd reflection, which continues a gradient) is divided out
(``"divide"``, for light that multiplies the albedo) or subtracted (``"subtract"``), and the
channel's mean is put back, so the mean colour stays (with ``"divide"``, scaled down where it
would push highlights past the photo's own). It is for the albedo (colour) map only,
never for normal or height maps, whose values are not lit. Structures larger than ``scale``
are flattened too: tie ``scale`` to the tile size (the pipeline uses the largest tile side).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from engine._validate import as_image, choice, non_negative_number

__all__ = ["FIELD_STEP", "FLATTEN_MODES", "flatten_lighting", "flatten_scale", "light_field"]

FLATTEN_MODES = ("divide", "subtract")


def flatten_scale(tile_max) -> float:
    """σ of the light field for tiles up to ``tile_max`` (an int or (h, w)): the largest tile
    side, so nothing the size of a tile is flattened away."""
    return float(np.max(tile_max))


#: the light field is computed on a grid of one sample every ``scale / FIELD_STEP`` px (block
#: means, blurred, interpolated back): a field that smooth loses under 0.3 % of its value, and
#: a σ = 256 blur of a 512 px photo takes 0.15 s instead of 10-30 s
FIELD_STEP = 32


def _blur(a: np.ndarray, sigma: float, mode: str) -> np.ndarray:
    """A Gaussian blur of σ = ``sigma``; from σ >= 2 :data:`FIELD_STEP` on block means,
    interpolated back (the same within 0.3 % for a field that smooth, far faster)."""
    f = max(1, int(sigma // FIELD_STEP))
    if f == 1:
        return ndimage.gaussian_filter(a, sigma, mode=mode)
    H, W = a.shape
    h, w = -(-H // f), -(-W // f)
    blocks = np.pad(a, ((0, h * f - H), (0, w * f - W)), mode="edge")
    small = ndimage.gaussian_filter(
        blocks.reshape(h, f, w, f).mean(axis=(1, 3)), sigma / f, mode=mode
    )
    return ndimage.zoom(small, f, order=1, mode="nearest", grid_mode=True)[:H, :W]


def _odd_pad(a: np.ndarray, pad: int, band: int) -> np.ndarray:
    """``a`` extended by ``pad`` px on every side by odd reflection about the mean of its
    outer ``band`` px (at the band's centre), which continues a linear gradient exactly; about
    a single edge pixel, a dark gap or a bright lid on the border pulled the whole light field
    (a grid of lids flattened to a field at 40 % of the photo's mean, a quarter of its pixels
    clipped to white)."""
    for axis in (0, 1):
        n = a.shape[axis]
        b = max(1, min(band, n // 4))
        p = max(0, min(pad, n - b - 1))
        j = np.arange(1, p + 1)
        lo = 2 * a.take(range(b), axis).mean(axis, keepdims=True) - a.take(b - 1 + j[::-1], axis)
        hi = 2 * a.take(range(n - b, n), axis).mean(axis, keepdims=True) - a.take(n - b - j, axis)
        a = np.concatenate([lo, a, hi], axis=axis)
    return a


def light_field(channel: np.ndarray, scale: float) -> np.ndarray:
    """The smooth light field of one (H, W) float channel: a Gaussian of σ = ``scale``, the
    border extended by odd reflection (:func:`_odd_pad`, about the mean of a band of σ/4),
    which continues a gradient instead of folding it."""
    H, W = channel.shape
    padded = _odd_pad(channel, int(3 * scale + 1), round(scale / 4))
    py, px = (padded.shape[0] - H) // 2, (padded.shape[1] - W) // 2
    return _blur(padded, scale, "nearest")[py : py + H, px : px + W]


#: percentile of the colour values that marks the highlights: ``"divide"`` keeps it at most the
#: photo's own (the mean colour is kept unless that would push highlights past it)
HIGHLIGHT = 99.9


def flatten_lighting(image, *, scale: float, mode: str = "divide") -> np.ndarray:
    """``image`` (H, W[, C]) with its low-frequency lighting removed, float32 in [0, 1].

    Alpha (C = 2 or 4) is kept as it is. ``scale`` (σ of the smooth field, px) must be > 0.
    ``"divide"`` keeps the mean colour unless the highlights of dim parts would then rise past
    the photo's own (:data:`HIGHLIGHT` percentile): then all colour channels are scaled down
    alike so they do not (no clipping to white; the hue stays).

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
    flats = []
    for c in range(colour):
        ch = x[:, :, c].astype(np.float64)
        field = light_field(ch, s)
        mean = ch.mean()
        flats.append(ch / np.maximum(field, 1e-3) * mean if mode == "divide" else ch - field + mean)
    flat = np.stack(flats, axis=2)
    # highlights in the dim parts rise above the photo's own: scale every colour channel alike
    # (the hue stays) so they keep the photo's highlight level instead of clipping to white
    # (a grid of bright lids under a vignette lost a quarter of its pixels to white)
    top = float(np.percentile(flat, HIGHLIGHT))
    if mode == "divide" and top > 0:
        flat *= min(1.0, float(np.percentile(x[:, :, :colour], HIGHLIGHT)) / top)
    out = x.copy()
    out[:, :, :colour] = np.clip(flat, 0, 1)
    return out
