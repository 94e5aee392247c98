"""Numeric kernels of the candidate tiles (:mod:`engine.tiles.candidates`): the ring-band
error of the local search, changed-pixel counts, mask runs, whether a cut shows, and the
interior tone of every patch window."""

from __future__ import annotations

import math

import numpy as np

from engine._jit import njit
from engine.tiles.scale import luminance32

__all__ = [
    "band_costs",
    "count_changed",
    "cut_shows",
    "coarse_interior_means",
    "coarse_interior_steps",
    "interior_means",
    "natural_step",
    "to_origins",
    "true_runs",
]

#: σ (px) of the blur before the steps of :func:`cut_shows` / :func:`natural_step`: the frame
#: metric's (:data:`engine.metrics.FRAME_SIGMA`), what a person sees at 100 %
STEP_SIGMA = 1.0


@njit(cache=True, nogil=True)
def band_costs(S, Up, runs, y0, x0, out):  # pragma: no cover
    """out[i, j] = mean over the band pixels (r, c) of d(S[y0+i+r, x0+j+c], U[r, c]).

    ``S`` is (H, W, C) float32, ``Up`` channel-planar (C, h, w) float32; the band is given
    as runs ``(r, c0, c1)`` of columns c0..c1-1 in row r. Positions j are the innermost loop
    (SIMD); each run's sum is accumulated in float32, the total in float64.
    """
    ny, nx = out.shape
    C = Up.shape[0]
    n = 0
    for k in range(runs.shape[0]):
        n += runs[k, 2] - runs[k, 1]
    acc = np.zeros((ny, nx))
    row = np.empty(nx, dtype=np.float32)
    for k in range(runs.shape[0]):
        r, c0, c1 = runs[k, 0], runs[k, 1], runs[k, 2]
        for i in range(ny):
            y = y0 + i + r
            row[:] = 0.0
            for c in range(c0, c1):
                x = x0 + c
                if C == 3:
                    u0, u1, u2 = Up[0, r, c], Up[1, r, c], Up[2, r, c]
                    for j in range(nx):
                        d0 = S[y, x + j, 0] - u0
                        d1 = S[y, x + j, 1] - u1
                        d2 = S[y, x + j, 2] - u2
                        row[j] += math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                else:
                    for j in range(nx):
                        t = np.float32(0.0)
                        for ch in range(C):
                            d = S[y, x + j, ch] - Up[ch, r, c]
                            t += d * d
                        row[j] += math.sqrt(t)
            for j in range(nx):
                acc[i, j] += row[j]
    for i in range(ny):
        for j in range(nx):
            out[i, j] = acc[i, j] / n


@njit(cache=True, nogil=True)
def count_changed(a, b):  # pragma: no cover
    """Number of pixels of (h, w, C) ``a`` and ``b`` that differ in any channel."""
    n = 0
    for y in range(a.shape[0]):
        for x in range(a.shape[1]):
            for c in range(a.shape[2]):
                if a[y, x, c] != b[y, x, c]:
                    n += 1
                    break
    return n


def true_runs(mask: np.ndarray) -> np.ndarray:
    """The True runs of a 2-D mask as rows ``(r, c0, c1)`` (columns c0..c1-1), row-major."""
    m = np.pad(mask.astype(np.int8), ((0, 0), (1, 1)))
    d = np.diff(m, axis=1)
    r0, c0 = np.nonzero(d == 1)
    _, c1 = np.nonzero(d == -1)
    return np.ascontiguousarray(np.column_stack([r0, c0, c1]), dtype=np.int64)


def _steps(lum: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|vertical| and |horizontal| neighbour steps of a 2-D image blurred by STEP_SIGMA."""
    from scipy import ndimage

    b = ndimage.gaussian_filter(lum.astype(np.float32, copy=False), STEP_SIGMA, mode="nearest")
    return np.abs(np.diff(b, axis=0)), np.abs(np.diff(b, axis=1))


def natural_step(lum: np.ndarray) -> float:
    """The texture's own mean neighbour step of a (H, W) luminance, blurred as in
    :func:`cut_shows`."""
    dy, dx = _steps(lum)
    return float((dy.mean() + dx.mean()) / 2)


def cut_shows(lum: np.ndarray, mask: np.ndarray, natural: float, limit: float) -> bool:
    """Whether a cut shows: the mean step of the blurred luminance ``lum`` (h, w) between
    4-neighbours on either side of ``mask``'s boundary is above ``limit`` x ``natural``."""
    dy, dx = _steps(lum)
    across = np.concatenate([dy[np.diff(mask, axis=0)], dx[np.diff(mask, axis=1)]])
    return bool(across.size) and float(across.mean()) > limit * natural


def interior_means(lum: np.ndarray, shape, inset: int) -> np.ndarray:
    """Mean of every ``shape`` (h, w) window of the 2-D ``lum`` over its interior (the pixels
    at least ``inset`` from the window's edge): (H - h + 1, W - w + 1), window origins."""
    h, w = shape
    i = int(inset)
    ih, iw = max(1, h - 2 * i), max(1, w - 2 * i)
    H, W = lum.shape
    c = np.zeros((H + 1, W + 1))
    np.cumsum(lum, axis=0, dtype=np.float64, out=c[1:, 1:])
    np.cumsum(c[1:, 1:], axis=1, out=c[1:, 1:])
    ny, nx = H - h + 1, W - w + 1
    a, b = c[i : i + ny], c[i + ih : i + ih + ny]
    s = (
        b[:, i + iw : i + iw + nx]
        - b[:, i : i + nx]
        - a[:, i + iw : i + iw + nx]
        + a[:, i : i + nx]
    )
    return (s / (ih * iw)).astype(np.float32)


def coarse_interior_means(image: np.ndarray, shape, inset: int, step: int) -> np.ndarray:
    """:func:`interior_means` of the luminance of ``image`` (H, W, C) sampled every ``step``
    px (a low-frequency figure: windows of ~128 samples a side are enough, and a 4096 px
    photo's whole luminance would cost ~0.5 s), repeated back to every window origin:
    (H - h + 1, W - w + 1)."""
    from engine.metrics import luminance

    k = max(1, int(step))
    h, w = shape
    lum = luminance(image[::k, ::k]).astype(np.float32)
    m = interior_means(lum, (max(1, h // k), max(1, w // k)), -(-int(inset) // k))
    return to_origins(m, image.shape, shape, k)


def coarse_interior_steps(image: np.ndarray, shape, inset: int, step: int):
    """Mean |vertical| and |horizontal| neighbour step of the luminance of ``image`` (H, W, C)
    over the interior (at least ``inset`` px in) of the ``shape`` (h, w) windows whose origins
    lie every ``step`` k px: two maps on that grid (:func:`to_origins` repeats a map back to
    every origin). With k > 1 the steps are taken between true neighbours on every k-th row
    only (and the row below it, for the vertical ones), averaged over k px along the row (a
    4096 px photo: ~2 % of its pixels, as :func:`coarse_interior_means`)."""
    k = max(1, int(step))
    H, W = image.shape[:2]
    h, w = shape
    hk, wk = H // k, W // k
    if k == 1:
        L = luminance32(image)
        dy = np.abs(np.diff(L, axis=0))
        dy = np.concatenate([dy, dy[-1:]])
    else:  # rows k*i and k*i + 1 (contiguous reads: a column-strided copy costs 5x)
        L = luminance32(image[: hk * k : k])
        dy = np.abs(luminance32(image[1 : hk * k : k]) - L)
        dy = dy[:, : wk * k].reshape(hk, wk, k).mean(axis=2)
    dx = np.abs(np.diff(L, axis=1))
    dx = np.concatenate([dx, dx[:, -1:]], axis=1)[:hk, : wk * k].reshape(hk, wk, k).mean(axis=2)
    size, inner = (max(1, h // k), max(1, w // k)), -(-int(inset) // k)
    return interior_means(dy, size, inner), interior_means(dx, size, inner)


def to_origins(coarse: np.ndarray, image_shape, shape, step: int) -> np.ndarray:
    """A map on the origins every ``step`` px (:func:`coarse_interior_steps`) repeated to
    every window origin: (H - h + 1, W - w + 1) for an (H, W) image and (h, w) windows."""
    k = max(1, int(step))
    if k == 1:
        return coarse
    ny, nx = image_shape[0] - shape[0] + 1, image_shape[1] - shape[1] + 1
    iy = np.minimum(np.arange(ny) // k, coarse.shape[0] - 1)
    ix = np.minimum(np.arange(nx) // k, coarse.shape[1] - 1)
    return coarse[iy[:, None], ix[None, :]]
