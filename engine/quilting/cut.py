"""How a block joins what lies under it: the cut through its overlap and the blend across it.

The L-shaped overlap (top and left arms) is cut as one path joined in the corner
(:func:`engine.stitch.l_cut`), wrap-around arms (bottom, right) get a seam each; ``blend``
softens the cut (``"feather"``: a fixed width; ``"adaptive"``: ρ-adaptive half-widths, §1.3).
A straight overlap is a hard edge or a linear cross-fade.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.blend import ramp_from_mask
from engine.seams import SeamSpec, find_seam
from engine.stitch import from_canonical, l_cut, map_points, to_canonical

__all__ = ["Cut", "blend_alpha", "cut_overlap", "straight_alpha"]


#: orientation (engine.stitch) of each overlap arm: where the new block (R2) lies from the old
#: content (R1) that the arm keeps on its outer side
_ARM_ORIENTATION = {"top": "bottom", "left": "right", "bottom": "top", "right": "left"}


def _arm_window(side: str, k: int, h: int, w: int) -> tuple[slice, slice]:
    return {
        "top": (slice(0, k), slice(0, w)),
        "left": (slice(0, h), slice(0, k)),
        "bottom": (slice(h - k, h), slice(0, w)),
        "right": (slice(0, h), slice(w - k, w)),
    }[side]


@dataclass
class Cut:
    """A block's overlap cut: where the old content stays, the path, its criterion and peak."""

    keep_old: np.ndarray
    path: np.ndarray
    criterion: float
    peak: float


def cut_overlap(err, arms, *, seam: SeamSpec, cancel=None) -> Cut:
    """Cut a block's overlap (arms = top, left, bottom, right widths) with ``seam``'s method.

    The left and top arms are cut as one L joined in the corner (:func:`engine.stitch.l_cut`);
    wrap-around arms (bottom, right) get a seam each, oriented so the old content is R1; the old
    content is kept wherever one of the cuts keeps it. Returns the keep-old mask, the path pixels,
    criterion and peak.
    """
    h, w = err.shape
    t, left, b, r = arms
    keep = np.zeros((h, w), dtype=bool)
    paths, crit, peak = [], 0.0, 0.0
    if t or left:
        lc = l_cut(err, overlap_left=left, overlap_top=t, seam=seam, cancel=cancel)
        keep |= np.asarray(lc.mask, dtype=bool)
        paths.append(np.asarray(lc.path, dtype=np.intp).reshape(-1, 2))
        crit, peak = float(lc.criterion), float(lc.peak)
    for side, k in (("bottom", b), ("right", r)):
        if not k:
            continue
        rows, cols = _arm_window(side, k, h, w)
        orient = _ARM_ORIENTATION[side]
        strip = err[rows, cols]
        cut = find_seam(np.ascontiguousarray(to_canonical(strip, orient)), seam=seam, cancel=cancel)
        keep[rows, cols] |= from_canonical(np.asarray(cut.mask), orient)
        pts = map_points(np.asarray(cut.path), orient, strip.shape, inverse=True)
        paths.append(pts + (rows.start, cols.start))
        crit += cut.criterion
        peak = max(peak, cut.peak)
    path = np.concatenate(paths).astype(np.intp) if paths else np.zeros((0, 2), np.intp)
    return Cut(keep, path, crit, peak)


def straight_alpha(arms, shape, blend: str) -> np.ndarray:
    """Weight of the old content over a straight overlap: 0 (hard), or a linear cross-fade."""
    h, w = shape
    alpha = np.zeros((h, w), np.float32)
    if blend == "none":
        return alpha
    t, left, b, r = arms
    yy = np.arange(h, dtype=np.float32)[:, None]
    xx = np.arange(w, dtype=np.float32)[None, :]
    for k, d in ((t, yy), (left, xx), (b, h - 1 - yy), (r, w - 1 - xx)):
        if k:
            alpha = np.maximum(alpha, np.clip(1 - (d + 0.5) / k, 0, 1))
    return alpha


def _adaptive_half_width_map(keep, path, err, overlap, rho: int) -> np.ndarray:
    """ρ-adaptive half-widths (§1.3) for any path: b = min(⌊ρ ẽ / Ē⌋, 2ρ) with ẽ the path error
    smoothed over ±ρ path pixels and Ē the mean error of the overlap; read at the nearest path
    pixel."""
    from scipy import ndimage

    e = err[path[:, 0], path[:, 1]].astype(np.float64)
    k = np.ones(2 * rho + 1)
    sm = np.convolve(e, k, mode="same") / np.convolve(np.ones(e.size), k, mode="same")
    ebar = float(err[overlap].mean()) if overlap.any() else 0.0
    if ebar <= 0:
        return np.zeros(keep.shape)
    b = np.minimum(np.floor(rho * sm / ebar), 2 * rho)
    on = np.full(keep.shape, -1, dtype=np.intp)
    on[path[:, 0], path[:, 1]] = np.arange(len(path))
    _, idx = ndimage.distance_transform_edt(on < 0, return_indices=True)
    return b[on[idx[0], idx[1]]]


def blend_alpha(cut: Cut, err, overlap, *, seam: SeamSpec) -> np.ndarray:
    """Weight of the old content for a cut after ``seam``'s blend (hard, feathered ``width``
    pixels, or ρ-adaptive), 0 outside the overlap."""
    if seam.blend == "none" or len(cut.path) == 0:
        alpha = cut.keep_old.astype(np.float32)
    elif seam.blend == "feather":
        alpha = ramp_from_mask(cut.keep_old, seam.width / 2.0)
    else:
        bmap = _adaptive_half_width_map(cut.keep_old, cut.path, err, overlap, seam.rho)
        alpha = ramp_from_mask(cut.keep_old, bmap)
    alpha[~overlap] = 0
    return alpha
