"""Is the source the same texture everywhere? (issue 10, item 3) [REC]

A tile set assumes a stationary texture: any window looks like any other. Two common ways a
photo is not, and what they do to a tile set:

* **lighting** varies (a light gradient, a vignette): tiles from different parts differ in
  tone, and a layout shows tone blocks or a frame — Flatten lighting removes it;
* **detail** varies (depth of field, motion blur, an empty margin around text): the template
  search is drawn to the blurred or empty part, where opposite edges match easily — the
  detail term counters that, excluding that part is better.

:func:`check_stationarity` measures both on a grid of blocks (about 8 along the shorter side,
at least 8 px): ``lighting`` is the range of a smooth (quadratic) field fitted to the blocks'
mean luminance, relative to the mean luminance, times the share of the blocks' variation
that field explains (R²) — a texture's own blotches are not smooth and score low; ``detail``
is the ratio of the 90th to the 10th percentile of the blocks' high-frequency energy
(:func:`engine.tiles.detail.detail_energy`). The limits were set on the evaluation set
(README): stochastic samples score lighting ≤ 0.04 and detail ≤ 2.4; a lighting gradient
of ±20 % scores 0.3-0.5, a page with margins 550.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine._jit import njit
from engine._validate import as_image
from engine.errormap import colour_channels
from engine.tiles.detail import detail_energy, kernel_pays

__all__ = [
    "DETAIL_LIMIT",
    "LIGHTING_LIMIT",
    "Stationarity",
    "check_stationarity",
    "stationarity_of",
]

#: ``lighting`` above this: warn (a smooth trend of ±10 % that explains its blocks' tones).
LIGHTING_LIMIT = 0.2
#: ``detail`` above this: warn (the most detailed blocks hold 4x the energy of the least).
DETAIL_LIMIT = 4.0
BLOCKS = 8  # blocks along the shorter side


@dataclass(frozen=True, slots=True)
class Stationarity:
    """Result of :func:`check_stationarity`: the two figures and the warnings (words)."""

    lighting: float
    detail: float
    warnings: tuple[str, ...] = ()


def _blocks(x: np.ndarray, n: int) -> np.ndarray:
    """Means of (about) n blocks along the shorter side of ``x`` (H, W), centred."""
    H, W = x.shape
    b = max(8, min(H, W) // n)
    gy, gx = H // b, W // b
    oy, ox = (H - gy * b) // 2, (W - gx * b) // 2
    return x[oy : oy + gy * b, ox : ox + gx * b].reshape(gy, b, gx, b).mean(axis=(1, 3))


def _luminance(S: np.ndarray) -> np.ndarray:
    """:func:`engine.metrics.luminance` of a validated image (the same float64 values)."""
    from engine.metrics import LUMA, luminance

    if S.shape[2] not in (1, 3) or not kernel_pays(S.shape[0] * S.shape[1]):
        return luminance(S)
    out = np.empty(S.shape[:2])
    _luminance_kernel(np.ascontiguousarray(S), np.array(LUMA, dtype=np.float64), out)
    return out


@njit(cache=True, nogil=True)
def _luminance_kernel(S, luma, out):  # pragma: no cover - compiled
    """``luminance`` in one pass: ``(r * L0 + g * L1) + b * L2`` in float64 (numpy's order)."""
    H, W, C = S.shape
    for y in range(H):
        for x in range(W):
            if C == 1:
                out[y, x] = np.float64(S[y, x, 0])
            else:
                r = np.float64(S[y, x, 0]) * luma[0]
                g = np.float64(S[y, x, 1]) * luma[1]
                out[y, x] = (r + g) + np.float64(S[y, x, 2]) * luma[2]


def _smooth_fit(M: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares quadratic surface through the block values ``M``, and its R²."""
    gy, gx = M.shape
    yy, xx = np.mgrid[0:gy, 0:gx]
    y = (yy.ravel() + 0.5) / gy - 0.5
    x = (xx.ravel() + 0.5) / gx - 0.5
    A = np.column_stack([np.ones_like(x), x, y, x * x, x * y, y * y])
    c, *_ = np.linalg.lstsq(A, M.ravel(), rcond=None)
    F = (A @ c).reshape(M.shape)
    ss = float(((M - M.mean()) ** 2).sum())
    return F, (1.0 - float(((M - F) ** 2).sum()) / ss) if ss > 0 else 0.0


def check_stationarity(source, *, energy: np.ndarray | None = None) -> Stationarity:
    """How much lighting and detail vary across ``source`` (H, W[, C]); ``energy`` is its
    :func:`~engine.tiles.detail.detail_energy` when already computed. A source of fewer than
    3 x 3 blocks of 8 px is not judged (both figures 0)."""
    return stationarity_of(colour_channels(as_image(source, "source")), energy=energy)


def stationarity_of(S: np.ndarray, *, energy: np.ndarray | None = None) -> Stationarity:
    """:func:`check_stationarity` of an image already validated (float32 (H, W, C) in [0, 1],
    colour channels only, as :func:`engine._validate.as_image` and
    :func:`engine.errormap.colour_channels` give it): no copy of it is made."""
    if min(S.shape[:2]) < 24:
        return Stationarity(0.0, 0.0)
    M = _blocks(_luminance(S), BLOCKS)
    F, r2 = _smooth_fit(M)
    mean = float(M.mean())
    lighting = float((F.max() - F.min()) / mean * max(r2, 0.0)) if mean > 0 else 0.0
    E = _blocks(detail_energy(S) if energy is None else energy, BLOCKS)
    lo, hi = np.percentile(E, [10, 90])
    detail = float(hi / lo) if lo > 0 else (float("inf") if hi > 0 else 1.0)
    notes = []
    if lighting > LIGHTING_LIMIT:
        notes.append(
            f"the lighting varies across the photo (a smooth trend of about ±{50 * lighting:.0f} "
            "% in brightness): tiles from different parts differ in tone and a layout shows "
            "tone blocks; try Flatten lighting (tileset --flatten)"
        )
    if detail > DETAIL_LIMIT:
        ratio = "no detail at all" if not np.isfinite(detail) else f"{detail:.0f}x less detail"
        notes.append(
            f"the sharpness varies across the photo (its calmest parts have {ratio} than its "
            "busiest: blur, depth of field or empty areas): the tile search keeps to the "
            "detailed parts, but excluding the blurred or empty part (an exclusion mask) "
            "gives better tiles"
        )
    return Stationarity(lighting, detail, tuple(notes))
