"""Patch sources in the template's phase on periodic textures (issue 10, item 2) [REC].

The global patch search (:mod:`engine.tiles.candidates`) draws every candidate's patch among
the positions whose ring band matches the template's. On a periodic texture (shelves every
64 px, brick courses) that band match barely sees a small phase error: the band is 2 px wide
and its error is dominated by what varies from period to period (the colours of the jars on a
shelf), so patches 2-3 px or half a period off the template's phase were drawn as often as
aligned ones — every such candidate showed its boards doubled or stepped 2-3 px just inside its
ring (the frame of the shelves set read 1.22 at 5-7 px from the tile edge).

The tile-set metrics already define which positions are aligned with the template
(:mod:`engine.reference_crops`): along every axis where the texture has a period and the tile
holds a whole number of them, a reference crop is the best structure match with the template
(normalised cross-correlation) within one period. :func:`phase_class` keeps the positions that
are the best match of the one-period window around them (the local peaks of that match, one
per period), widened by ``tolerance`` px along those axes; the search draws patches from them
first and only then, when they cannot give enough distinct candidates, from the others.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from engine.reference_crops import phase_axes, structure_match
from engine.tiles.scale import Scale, structure_scale

__all__ = ["PHASE_TOLERANCE", "patch_phase_class", "phase_class", "window_maxima"]

#: px around each aligned position that still count as aligned (the period's estimate and the
#: texture's own jitter; 2-3 px off already shows as a stepped board or mortar line)
PHASE_TOLERANCE = 1
#: the structure scale is measured on a central crop of at most this size when the caller has
#: none (the template search's own measure is passed on by the pipeline)
SCALE_CROP = 1024


def window_maxima(score: np.ndarray, span) -> np.ndarray:
    """Bool mask of the positions of ``score`` (2-D) that are the maximum (ties included) of
    the ``span`` (sy, sx) window around them — centred, and moved inside the array at its
    borders, as the reference crops' search windows are (:mod:`engine.reference_crops`)."""
    s = np.asarray(score, dtype=np.float64)
    sy, sx = (max(1, min(int(v), n)) for v, n in zip(span, s.shape, strict=True))
    best = ndimage.maximum_filter(s, size=(sy, sx), mode="nearest")
    # the maxima of the windows that fit, by their start (a centred filter's window starts
    # s // 2 before its centre)
    starts = best[sy // 2 : s.shape[0] - sy + sy // 2 + 1, sx // 2 : s.shape[1] - sx + sx // 2 + 1]
    ly = np.clip(np.arange(s.shape[0]) - sy // 2, 0, s.shape[0] - sy)
    lx = np.clip(np.arange(s.shape[1]) - sx // 2, 0, s.shape[1] - sx)
    return s >= starts[np.ix_(ly, lx)]


def phase_class(
    source, template, *, scale: Scale | None = None, tolerance: int = PHASE_TOLERANCE
) -> np.ndarray | None:
    """Bool mask over the tile-sized windows of ``source`` (H - h + 1, W - w + 1): the
    positions in ``template``'s phase (module docstring); None when the texture has no period
    the tile holds whole (every position is as good as any other).

    ``scale``: the texture's structure scale when already measured
    (:func:`engine.tiles.scale.structure_scale`), else it is measured here on a central crop.
    """
    from engine.metrics import luminance

    H, W = np.shape(source)[:2]
    h, w = np.shape(template)[:2]
    if h > H or w > W:
        return None
    if scale is None:
        y, x = max(0, (H - SCALE_CROP) // 2), max(0, (W - SCALE_CROP) // 2)
        crop = np.asarray(source)[y : y + SCALE_CROP, x : x + SCALE_CROP]
        scale = structure_scale(luminance(crop).astype(np.float64))
    axes = phase_axes(scale, (h, w))
    if not any(axes):
        return None  # (before the whole source's luminance: a large photo pays nothing)
    S = luminance(source).astype(np.float64)
    score = structure_match(S, luminance(template).astype(np.float64))
    span = [math.ceil(p) if a else 1 for p, a in zip(scale.size, axes, strict=True)]
    aligned = window_maxima(score, span)
    grow = [2 * tolerance + 1 if a else 1 for a in axes]
    return ndimage.maximum_filter(aligned, size=grow, mode="constant", cval=False)


def patch_phase_class(source, template, patch_shape, *, scale: Scale | None = None):
    """:func:`phase_class` over the positions of patches of ``patch_shape`` (ph, pw) centred in
    the tile, as the candidates' search indexes them (None: no phase to keep)."""
    tile = phase_class(source, template, scale=scale)
    if tile is None:
        return None
    H, W = np.shape(source)[:2]
    ph, pw = patch_shape
    th, tw = np.shape(template)[:2]
    ty, tx = (th - ph) // 2, (tw - pw) // 2
    out = np.zeros((H - ph + 1, W - pw + 1), dtype=bool)
    # the patch at p fills the tile whose window starts at p - (ty, tx)
    part = tile[: out.shape[0] - ty, : out.shape[1] - tx]
    out[ty : ty + part.shape[0], tx : tx + part.shape[1]] = part
    return out
