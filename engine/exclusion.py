"""Excluded regions of a sample and the block positions that avoid them (Bhatia §3.1).

A sample pixel is *excluded* when its colour falls in a user range (Bhatia's "specified texture
type": e.g. dark roads in an aerial photo of grass) or when the user painted it. A block may be
taken from the sample only if it (plus the extension a method reads beyond it) contains no
excluded pixel. ALGORITHMS.md §4 [FIX]: Bhatia's scan marks the wrong quadrant of anchors; the
correct rule is a box sum of the excluded mask over the block, 0 for a valid anchor, read from
one summed-area table in O(H·W).
"""

from __future__ import annotations

import base64
import numbers
import zlib

import numpy as np

from engine._validate import as_image
from engine.io import to_rgb

__all__ = [
    "MASK_KEY",
    "box_sums",
    "colour_range_around",
    "exclusion_mask",
    "mask_from_json",
    "mask_to_json",
    "valid_anchors",
]


def _bounds(value, name: str, channels: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(channels, float(a))
    if a.ndim != 1 or a.size != channels:
        raise ValueError(
            f"color_range {name} must be a number or {channels} numbers (one per channel), "
            f"got {value!r}"
        )
    if not np.all(np.isfinite(a)):
        raise ValueError(f"color_range {name} must be finite, got {value!r}")
    return a


def exclusion_mask(image, *, color_range=None, painted=None) -> np.ndarray:
    """Mask of the sample pixels a synthesis must not use.

    Parameters
    ----------
    image : (H, W[, C]) ndarray
        The sample (any dtype accepted by :func:`engine._validate.as_image`).
    color_range : (lo, hi) or None
        Per-channel bounds in [0, 1]; a pixel is excluded when ``lo[c] <= pixel[c] <= hi[c]``
        for **every** channel c (an axis-aligned box in colour space). ``lo`` and ``hi`` are
        each a number (the same bound for every channel) or a sequence with one value per
        channel of the image, or three values (R, G, B) for any image (gray is replicated,
        alpha ignored). Example: ``((0, 0, 0), (0.2, 0.2, 0.25))`` excludes dark pixels.
    painted : (H, W) array_like of bool or None
        A user-painted mask, True = excluded; combined with the colour range by OR.

    Returns
    -------
    (H, W) bool ndarray
        True where the pixel is excluded.
    """
    img = as_image(image, "image")
    h, w, c = img.shape
    out = np.zeros((h, w), dtype=bool)
    if color_range is not None:
        if isinstance(color_range, str) or len(color_range) != 2:
            raise ValueError(f"color_range must be a pair (lo, hi), got {color_range!r}")
        lo_raw, hi_raw = color_range
        n = np.asarray(lo_raw).size if not isinstance(lo_raw, numbers.Number) else None
        pix = img
        if n == 3 and c != 3:
            pix = to_rgb(img)
        cc = pix.shape[2]
        lo = _bounds(lo_raw, "lo", cc)
        hi = _bounds(hi_raw, "hi", cc)
        if np.any(lo > hi):
            raise ValueError(f"color_range lo must be <= hi in every channel, got {color_range!r}")
        out |= np.all((pix >= lo) & (pix <= hi), axis=2)
    if painted is not None:
        p = np.asarray(painted)
        if p.shape != (h, w):
            raise ValueError(f"painted must be shaped {(h, w)} like the image, got {p.shape}")
        out |= p.astype(bool)
    return out


def box_sums(mask, box_shape) -> np.ndarray:
    """Number of True pixels of ``mask`` in every ``box_shape`` window, by top-left corner.

    Returns an int64 array shaped ``(H - bh + 1, W - bw + 1)`` (empty when the box does not fit).
    """
    m = np.asarray(mask, dtype=bool)
    bh, bw = int(box_shape[0]), int(box_shape[1])
    h, w = m.shape
    if bh > h or bw > w:
        return np.zeros((max(h - bh + 1, 0), max(w - bw + 1, 0)), dtype=np.int64)
    sat = np.zeros((h + 1, w + 1), dtype=np.int64)
    np.cumsum(np.cumsum(m, axis=0, dtype=np.int64), axis=1, out=sat[1:, 1:])
    return sat[bh:, bw:] - sat[:-bh, bw:] - sat[bh:, :-bw] + sat[:-bh, :-bw]


def valid_anchors(excluded, block_shape, *, extension=(0, 0)) -> np.ndarray:
    """Top-left positions whose block (plus extension) contains no excluded pixel.

    Parameters
    ----------
    excluded : (H, W) array_like of bool
        True = excluded sample pixel (see :func:`exclusion_mask`).
    block_shape : (bh, bw)
        Block height and width.
    extension : (eh, ew)
        Extra rows below and extra columns right of the block that must also be clean
        (the source *extension* a method reads beyond the block, e.g. Bhatia's quilting).

    Returns
    -------
    (H - bh - eh + 1, W - bw - ew + 1) bool ndarray
        True where a block may be anchored (empty when the block does not fit).
    """
    ex = np.asarray(excluded)
    if ex.ndim != 2:
        raise ValueError(f"excluded must be a 2-D mask, got shape {ex.shape}")
    if len(block_shape) != 2 or min(int(v) for v in block_shape) < 1:
        raise ValueError(f"block_shape must be two positive integers, got {block_shape!r}")
    if len(extension) != 2 or min(int(v) for v in extension) < 0:
        raise ValueError(f"extension must be two non-negative integers, got {extension!r}")
    box = (int(block_shape[0]) + int(extension[0]), int(block_shape[1]) + int(extension[1]))
    return box_sums(ex, box) == 0


def colour_range_around(colour: str, tolerance: float):
    """The (lo, hi) range of ``"#rrggbb"`` ± ``tolerance`` per channel, clipped to [0, 1]
    (what the editor's picked colour excludes); None for no colour or a tolerance <= 0."""
    if not colour or not tolerance or tolerance <= 0:
        return None
    rgb = [int(colour[i : i + 2], 16) / 255.0 for i in (1, 3, 5)]
    return (
        [max(0.0, v - tolerance) for v in rgb],
        [min(1.0, v + tolerance) for v in rgb],
    )


#: the key of the excluded-pixel mask in a project's ``extra`` (the project has no field for it)
MASK_KEY = "exclude_painted"


def mask_to_json(mask) -> dict:
    """``{MASK_KEY: ...}`` for a project's ``extra``: the (H, W) mask's shape and its
    bit-packed, zlib-compressed bytes in base64; ``{}`` for no mask (None or all False)."""
    if mask is None or not np.asarray(mask).any():
        return {}
    packed = zlib.compress(np.packbits(np.asarray(mask, bool)).tobytes(), 9)
    return {
        MASK_KEY: {
            "shape": list(np.shape(mask)),
            "packbits_zlib_base64": base64.b64encode(packed).decode("ascii"),
        }
    }


def mask_from_json(extra, shape: tuple[int, int]) -> np.ndarray | None:
    """The mask :func:`mask_to_json` stored in ``extra``; None if absent or not a mask of
    ``shape`` (a damaged entry is dropped, the rest of the project opens)."""
    entry = extra.get(MASK_KEY) if isinstance(extra, dict) else None
    if not isinstance(entry, dict) or entry.get("shape") != list(shape):
        return None
    n = int(shape[0]) * int(shape[1])
    try:
        raw = base64.b64decode(entry["packbits_zlib_base64"], validate=True)
        bits = zlib.decompressobj().decompress(raw, (n + 7) // 8 + 1)
    except (KeyError, TypeError, ValueError, zlib.error):
        return None
    if len(bits) != (n + 7) // 8:
        return None
    mask = np.unpackbits(np.frombuffer(bits, np.uint8), count=n).astype(bool).reshape(shape)
    return mask if mask.any() else None
