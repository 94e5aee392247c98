"""Blending after a cut: hard, feather of a fixed width, adaptive (Somol & Haindl, ρ).

ALGORITHMS.md §0 (soft ramp from a hard mask) and §1.3 (adaptive blending). Every
function returns the *weight of R1* (alpha, float32 in [0, 1]) on the canonical overlap
(R1 kept on the left); :func:`composite` mixes any pair of co-registered maps with it,
so the same cut serves the colour image and every material map.

Cut line and half-width
    For a seam with one run of R1 pixels per row (``dp``, ``oscillating``: the mask row is
    True for columns ``0..c_j``), the cut line lies between columns ``c_j`` and ``c_j + 1``
    and the ramp is per row: ``alpha = clip(0.5 - (i - c_j - 0.5) / (2 b_j), 0, 1)``. A pixel
    is blended (0 < alpha < 1) exactly when its centre lies within ``b_j`` of the cut line,
    ``|i - c_j - 0.5| < b_j``; everything else is an exact copy of R1 or R2.
    For winding seams (``dijkstra``, ``minimax``, ``resistance``) the ramp is the Euclidean
    distance-transform ramp of §0 with ``b`` taken from the nearest path pixel's row.

Half-widths ``b_j``
    ``feather``: ``width / 2`` (``width`` pixels blended across a straight cut).
    ``adaptive`` (§1.3): per-row mean error on the path ``e_j``, smoothed over rows
    ``j - ρ .. j + ρ`` (cyclically for a cyclic seam), ``b_j = min(⌊ρ ẽ_j / Ē⌋, 2ρ)`` with ``Ē``
    the mean error of the whole overlap. Rows whose path is better than ``Ē / ρ`` stay sharp.
    [REC, stricter than §1.3's clamps ``c_j + 1`` and ``w - 1 - c_j``] both modes clamp
    ``b_j <= min(c_j + 0.5, w - 1.5 - c_j)``: the first and last columns of the overlap are never
    blended, so they continue what lies beyond the overlap (R1's surroundings on the left, R2's
    on the right). In a template stitch column 0 is the tile's wrap edge, so the ramp never
    crosses the wrap. Winding seams get the same guarantee by keeping those two columns hard.
"""

from __future__ import annotations

import math

import numpy as np
from skimage.util import img_as_float32

from engine._validate import as_error_map, choice, positive_int
from engine.seams.spec import BLEND_MODES, POISSON, TILE_BLEND_MODES, SeamSpec

__all__ = [
    "BLEND_MODES",
    "adaptive_half_widths",
    "blend_weights",
    "clamped_half_widths",
    "composite",
    "cut_columns",
    "ramp_from_mask",
]


def composite(alpha, r1, r2) -> np.ndarray:
    """``alpha * r1 + (1 - alpha) * r2`` for (h, w) or (h, w, C) maps, float32.

    Pixels with ``alpha`` exactly 1 (0) are exact copies of ``r1`` (``r2``). Integer maps are
    scaled to [0, 1] first.
    """
    a = np.asarray(alpha, dtype=np.float32)
    x = img_as_float32(np.asarray(r1))
    y = img_as_float32(np.asarray(r2))
    if x.shape != y.shape:
        raise ValueError(f"r1 and r2 must have the same shape, got {x.shape} and {y.shape}")
    if a.ndim != 2 or a.shape != x.shape[:2]:
        raise ValueError(f"alpha must be shaped {x.shape[:2]} like r1, got {a.shape}")
    if x.ndim == 3:
        a = a[:, :, None]
    return (a * x + (1.0 - a) * y).astype(np.float32, copy=False)


def ramp_from_mask(mask, half_width, *, wrap_rows: bool = False) -> np.ndarray:
    """Soft weight of the True side of ``mask`` (ALGORITHMS §0 EDT ramp), float32.

    ``s = edt(mask) - 0.5`` inside, ``-(edt(~mask) - 0.5)`` outside,
    ``alpha = clip(0.5 + s / (2 b), 0, 1)``. ``half_width`` b is a scalar or an (h, w) array
    (then b is read at the nearest pixel across the boundary); b = 0 gives the hard mask.
    ``wrap_rows``: rows 0 and h - 1 are neighbours (a cyclic seam), the ramp is periodic.
    """
    from scipy import ndimage

    m = np.asarray(mask, dtype=bool)
    if m.ndim != 2:
        raise ValueError(f"mask must be 2-D, got shape {m.shape}")
    hw = np.asarray(half_width, dtype=np.float64)
    if hw.ndim not in (0, 2) or (hw.ndim == 2 and hw.shape != m.shape):
        raise ValueError(f"half_width must be a scalar or shaped {m.shape}, got {hw.shape}")
    if not np.all(np.isfinite(hw)) or (hw < 0).any():
        raise ValueError("half_width must be finite and >= 0")
    bmax = float(hw.max())
    if bmax <= 0 or m.all() or not m.any():
        return m.astype(np.float32)
    pad = 0
    if wrap_rows:
        pad = min(m.shape[0], math.ceil(bmax) + 1)
        m = np.pad(m, ((pad, pad), (0, 0)), mode="wrap")
        if hw.ndim == 2:
            hw = np.pad(hw, ((pad, pad), (0, 0)), mode="wrap")
    din, iin = ndimage.distance_transform_edt(m, return_indices=True)
    dout, iout = ndimage.distance_transform_edt(~m, return_indices=True)
    s = np.where(m, din - 0.5, 0.5 - dout)
    if hw.ndim == 2:
        near = np.where(m[None], iin, iout)
        b = hw[near[0], near[1]]
    else:
        b = np.full(m.shape, float(hw))
    safe = np.where(b > 0, b, 1.0)
    alpha = np.where(b > 0, np.clip(0.5 + s / (2.0 * safe), 0.0, 1.0), m)
    if pad:
        alpha = alpha[pad:-pad]
    return alpha.astype(np.float32)


def cut_columns(mask) -> np.ndarray | None:
    """``c_j`` (last R1 column per row, -1 for none) if every mask row is a run from column 0.

    Returns None for masks of winding seams (some row is not of the form True..True False..).
    """
    m = np.asarray(mask, dtype=bool)
    counts = m.sum(axis=1)
    prefix = np.arange(m.shape[1])[None, :] < counts[:, None]
    return counts - 1 if np.array_equal(prefix, m) else None


def adaptive_half_widths(seam, error, *, rho: int = 3, cyclic: bool = False) -> np.ndarray:
    """Per-row half-widths ``b_j = min(⌊ρ ẽ_j / Ē⌋, 2ρ)`` of §1.3 (before the edge clamp).

    ``e_j`` is the mean error over the path pixels of row j (rows without one borrow from
    their neighbours through the smoothing), ``ẽ_j`` its mean over rows ``j - ρ .. j + ρ``
    (wrapping around when ``cyclic``), ``Ē`` the mean error of the whole map.
    """
    e = as_error_map(error)
    rho = positive_int(rho, "rho", minimum=0)
    h = e.shape[0]
    path = np.asarray(seam.path, dtype=np.intp).reshape(-1, 2)
    if rho == 0:
        return np.zeros(h)
    sums = np.bincount(path[:, 0], weights=e[path[:, 0], path[:, 1]], minlength=h)
    counts = np.bincount(path[:, 0], minlength=h)
    has = (counts > 0).astype(np.float64)
    row_mean = sums / np.maximum(counts, 1)
    smooth = _window_sum(row_mean, rho, cyclic) / np.maximum(_window_sum(has, rho, cyclic), 1.0)
    ebar = float(e.mean())
    if ebar <= 0:
        return np.zeros(h)
    return np.minimum(np.floor(rho * smooth / ebar), 2 * rho)


def blend_weights(
    seam,
    error,
    *,
    spec: SeamSpec | None = None,
    mode: str | None = None,
    width: float | None = None,
    rho: int | None = None,
    cyclic: bool = False,
) -> np.ndarray:
    """Weight of R1 (float32, (h, w)) for a canonical seam; see the module docstring.

    Parameters
    ----------
    seam : engine.seams.Seam
        The cut (``mask`` True on R1's side, path included).
    error : (h, w) array
        The error map the seam was searched on (adaptive mode reads it).
    spec : engine.seams.SeamSpec, optional
        Its ``blend``, ``width`` and ``rho`` (then ``mode``, ``width``, ``rho`` are not given).
    mode : {"none", "feather", "adaptive", "poisson"}
        Hard cut, fixed ramp of ``width`` pixels, or ρ-adaptive half-widths (§1.3);
        ``"poisson"`` is a hard cut here (its gradient-domain solve comes after,
        :mod:`engine.poisson`).
    width : float
        Feather width in pixels (half-width ``width / 2`` each side of the cut line).
    rho : int
        ρ of adaptive blending (0 = hard).
    cyclic : bool
        Rows 0 and h - 1 are neighbours (a cyclic seam): smoothing and ramp wrap around.
    """
    if spec is not None:
        if (mode, width, rho) != (None, None, None):
            raise TypeError("give either spec= or mode/width/rho, not both")
        mode, width, rho = spec.blend, spec.width, spec.rho
    mode = "none" if mode is None else mode
    width = 4 if width is None else width
    rho = 3 if rho is None else rho
    choice(mode, "mode", TILE_BLEND_MODES)
    mask = np.asarray(seam.mask, dtype=bool)
    e = as_error_map(error)
    if e.shape != mask.shape:
        raise ValueError(f"error must be shaped like the seam's mask {mask.shape}, got {e.shape}")
    if isinstance(width, bool) or not np.isfinite(width) or width < 0:
        raise ValueError(f"width must be a finite number >= 0, got {width!r}")
    if mode in ("none", POISSON):
        return mask.astype(np.float32)
    if mode == "feather":
        b_rows = np.full(mask.shape[0], float(width) / 2.0)
    else:
        b_rows = adaptive_half_widths(seam, e, rho=rho, cyclic=cyclic)
    cols = cut_columns(mask)
    if cols is not None:
        return _row_ramp(cols, b_rows, mask.shape[1])
    return _winding_ramp(mask, np.asarray(seam.path, dtype=np.intp), b_rows, cyclic)


def clamped_half_widths(cols: np.ndarray, b_rows: np.ndarray, width: int) -> np.ndarray:
    """``b_j`` clamped so the first and last columns of the overlap stay unblended."""
    c = np.asarray(cols, dtype=np.float64)
    return np.maximum(np.minimum.reduce([np.asarray(b_rows, float), c + 0.5, width - 1.5 - c]), 0)


def _row_ramp(cols: np.ndarray, b_rows: np.ndarray, width: int) -> np.ndarray:
    b = clamped_half_widths(cols, b_rows, width)[:, None]
    i = np.arange(width)[None, :]
    hard = i <= cols[:, None]
    safe = np.where(b > 0, b, 1.0)
    alpha = np.where(b > 0, np.clip(0.5 - (i - cols[:, None] - 0.5) / (2.0 * safe), 0, 1), hard)
    return alpha.astype(np.float32)


def _winding_ramp(mask: np.ndarray, path: np.ndarray, b_rows: np.ndarray, cyclic: bool):
    from scipy import ndimage

    on_path = np.zeros(mask.shape, dtype=bool)
    on_path[path[:, 0], path[:, 1]] = True
    _, idx = ndimage.distance_transform_edt(~on_path, return_indices=True)
    alpha = ramp_from_mask(mask, b_rows[idx[0]], wrap_rows=cyclic)
    alpha[:, 0] = mask[:, 0]
    alpha[:, -1] = mask[:, -1]
    return alpha


def _window_sum(v: np.ndarray, r: int, cyclic: bool) -> np.ndarray:
    """Sum of ``v`` over the window ``j - r .. j + r`` (truncated, or wrapping when cyclic)."""
    n = v.size
    padded = np.pad(np.asarray(v, dtype=np.float64), r, mode="wrap" if cyclic else "constant")
    c = np.concatenate(([0.0], np.cumsum(padded)))
    return c[2 * r + 1 : 2 * r + 1 + n] - c[:n]
