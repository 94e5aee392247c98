"""The template search's detail term (issue 10, item 3) [REC].

A low strip mismatch is easy where the texture is flat or blurred (a page's empty margin,
the out-of-focus part of a photo), so the paper's criterion alone drifts there: the template
then has less detail than the photo and every tile set made from it looks blurred. The
search therefore adds, for every scored footprint (the tile rectangle plus w_T),

    κ · C · max(0, 1 − q),   q = e(footprint) / ē(size)

* ``e`` is the footprint's mean *high-frequency energy*: the squared 4-neighbour Laplacian of
  each colour channel, averaged over channels (:func:`detail_energy`; its mean over a tile is
  the tile's Laplacian variance, the numerator of :func:`engine.metrics.detail_ratio`);
* ``ē(size)`` is the upper quartile of ``e`` over the windows of the footprint's size in the
  source (the source's distribution over windows of the same size: their top-left corners on
  an even grid of up to 64 x 64 positions, means from a summed-area table);
* ``C`` is the mismatch of unrelated pixels (:func:`unrelated_distance`), the unit of the
  strip mismatch, so κ (``detail_weight``) is unit-free: κ = 1 makes a footprint with no
  detail at all pay as much as two unrelated strips would.

Footprints at least as detailed as the busier quarter of the source pay nothing; the term
never rewards more detail than that (a bright landmark is not preferred). κ = 0 gives the
paper's criterion.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
from scipy import ndimage

from engine import _jit as jit
from engine._jit import njit

__all__ = [
    "DETAIL_WEIGHT",
    "DetailTerm",
    "check_detail_weight",
    "detail_energy",
    "kernel_pays",
    "unrelated_distance",
]

#: κ: weight of the detail deficit (chosen on the evaluation set, see the README).
DETAIL_WEIGHT = 1.0
#: ē is this quantile of the window means: a footprint must be as detailed as the busier
#: quarter of the source to pay nothing (the mean would let a half-blurred photo's
#: footprints reach into the blurred half).
REFERENCE_QUANTILE = 0.75
#: Window positions per axis whose means make the distribution.
REFERENCE_GRID = 64
#: Below this many pixels a run without numba loaded keeps to the numpy path (same values).
SMALL_PIXELS = 1 << 20


def kernel_pays(pixels: int, small: int = SMALL_PIXELS) -> bool:
    """Whether the compiled kernels (the numpy paths' bit-for-bit twins) are worth it for
    ``pixels`` (or another measure of the work): always once numba is loaded, else only from
    ``small`` on (small jobs do not pay numba's start-up)."""
    return pixels >= small or jit.loaded()


def check_detail_weight(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"detail_weight must be a number, got {value!r}")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"detail_weight must be finite and >= 0, got {value!r}")
    return float(value)


def detail_energy(S: np.ndarray) -> np.ndarray:
    """(H, W) float64: squared 4-neighbour Laplacian of every channel of ``S`` (H, W, C)
    (reflected at the border), averaged over the channels."""
    if not kernel_pays(S.shape[0] * S.shape[1]):
        return _detail_energy_numpy(S)
    out = np.empty(S.shape[:2])
    _energy_kernel(np.ascontiguousarray(S), out)
    return out


def _detail_energy_numpy(S: np.ndarray) -> np.ndarray:
    """:func:`detail_energy` from ``scipy.ndimage.laplace`` (the kernel's bit-for-bit twin)."""
    out = np.zeros(S.shape[:2])
    for c in range(S.shape[2]):
        lap = ndimage.laplace(S[:, :, c].astype(np.float64), mode="reflect")
        out += lap * lap
    return out / S.shape[2]


@njit(cache=True, nogil=True)
def _energy_kernel(S, out):  # pragma: no cover - compiled
    """:func:`_detail_energy_numpy` in one pass, with its float64 operations in its order
    (ndimage's symmetric correlation: ``x * -2 + (next + previous)`` per axis, the two axes
    added, the channels' squares summed from 0, divided by C): the same bits."""
    H, W, C = S.shape
    for y in range(H):
        yu = y - 1 if y > 0 else 0
        yd = y + 1 if y < H - 1 else H - 1
        for x in range(W):
            xl = x - 1 if x > 0 else 0
            xr = x + 1 if x < W - 1 else W - 1
            acc = 0.0
            for c in range(C):
                v = np.float64(S[y, x, c])
                d0 = v * -2.0 + (np.float64(S[yd, x, c]) + np.float64(S[yu, x, c]))
                d1 = v * -2.0 + (np.float64(S[y, xr, c]) + np.float64(S[y, xl, c]))
                lap = d0 + d1
                acc += lap * lap
            out[y, x] = acc / C


@njit(cache=True, nogil=True)
def _table_kernel(E, T):  # pragma: no cover - compiled
    """``T[1:, 1:] = E.cumsum(0).cumsum(1)`` (row 0 and column 0 of ``T`` zero), summed in
    numpy's order (sequential accumulations): the same bits."""
    H, W = E.shape
    col = np.zeros(W)
    for x in range(W + 1):
        T[0, x] = 0.0
    for y in range(H):
        T[y + 1, 0] = 0.0
        run = 0.0
        for x in range(W):
            col[x] = E[y, x] if y == 0 else col[x] + E[y, x]
            run = col[x] if x == 0 else run + col[x]
            T[y + 1, x + 1] = run


def summed_area(E: np.ndarray) -> np.ndarray:
    """(H + 1, W + 1) summed-area table of ``E`` with a zero first row and column."""
    if not kernel_pays(E.size):
        return np.pad(E.cumsum(axis=0).cumsum(axis=1), ((1, 0), (1, 0)))
    T = np.empty((E.shape[0] + 1, E.shape[1] + 1))
    _table_kernel(np.ascontiguousarray(E, dtype=np.float64), T)
    return T


def unrelated_distance(S: np.ndarray) -> float:
    """Mean RGB Euclidean distance between pixels far apart (a few fixed offsets, wrapped,
    on every 4th pixel): what a strip mismatch of unrelated strips is worth."""
    H, W = S.shape[:2]
    sub = S[::4, ::4].astype(np.float64)
    h, w = sub.shape[:2]
    vals = []
    for fy, fx in ((1 / 2, 1 / 2), (1 / 3, 3 / 5), (5 / 7, 1 / 4)):
        o = np.roll(sub, (int(h * fy), int(w * fx)), axis=(0, 1))
        vals.append(np.sqrt(((sub - o) ** 2).sum(axis=2)).mean())
    return float(np.mean(vals))


def _grid(last: int) -> np.ndarray:
    """At most :data:`REFERENCE_GRID` window starts spread evenly over 0 .. ``last``."""
    return np.unique(np.linspace(0, last, min(last + 1, REFERENCE_GRID)).round().astype(np.int64))


class DetailTerm:
    """The detail term of one search image (full resolution or the coarse one).

    ``E`` (H, W) is the high-frequency energy, ``weight`` κ and ``unit`` C; ``scale`` = κ·C
    is the penalty of a footprint without any detail (0 on a source without any).
    """

    def __init__(self, E: np.ndarray, weight: float, unit: float):
        self.E = E
        self.H, self.W = E.shape
        self._table = summed_area(E)
        self.weight = float(weight)
        self.scale = self.weight * float(unit) if float(E.mean()) > 0 else 0.0

    @classmethod
    def of(cls, S: np.ndarray, weight: float, E: np.ndarray | None = None) -> DetailTerm | None:
        """The term of image ``S`` (H, W, C) with weight κ (``E``: its energy when already
        known); None when κ is 0."""
        if weight == 0:
            return None
        return cls(detail_energy(S) if E is None else E, weight, unrelated_distance(S))

    def reference(self, heights, widths) -> np.ndarray:
        """ē for footprints of ``heights`` x ``widths`` (broadcast 1-D arrays): the
        :data:`REFERENCE_QUANTILE` of the window means of ``E`` over the windows of that size
        in the image (their top-left corners on a grid of at most :data:`REFERENCE_GRID`
        positions per axis, spread evenly from the first to the last; NaN where the size does
        not fit)."""
        hs, ws = np.broadcast_arrays(np.atleast_1d(heights), np.atleast_1d(widths))
        T = self._table
        out = np.full(hs.shape, np.nan)
        for k, (hf, wf) in enumerate(zip(hs.tolist(), ws.tolist(), strict=True)):
            if not (0 < hf <= self.H and 0 < wf <= self.W):
                continue
            y = _grid(self.H - hf)[:, None]
            x = _grid(self.W - wf)[None, :]
            sums = T[y + hf, x + wf] - T[y, x + wf] - T[y + hf, x] + T[y, x]
            out[k] = np.quantile(sums / (hf * wf), REFERENCE_QUANTILE)
        return out

    def penalty(self, mean_energy, reference) -> np.ndarray:
        """κ·C·max(0, 1 − q) for footprints of mean energy ``mean_energy`` and reference ē."""
        if self.scale == 0:
            return np.zeros(np.broadcast(mean_energy, reference).shape)
        with np.errstate(invalid="ignore", divide="ignore"):
            q = np.where(reference > 0, mean_energy / np.where(reference > 0, reference, 1), 1.0)
        return self.scale * np.clip(1.0 - q, 0.0, 1.0)

    def rect_detail(self, rect, overlap: int) -> tuple[float, float]:
        """(q, penalty) of the footprint of ``rect`` = (x, y, w, h)."""
        x, y, a, b = rect
        hf, wf = b + overlap, a + overlap
        e = float(self.E[y : y + hf, x : x + wf].mean())
        ref = float(self.reference(hf, wf)[0])
        q = e / ref if ref > 0 else 1.0
        return q, float(self.penalty(np.float64(e), np.float64(ref)))

    def line_energy(self, rows, cols=None, *, transposed: bool = False) -> np.ndarray:
        """Sum of ``E`` over ``rows`` (a (start, stop) pair) per column — or, ``transposed``,
        over the columns ``cols`` per row: what a scan's footprints add up."""
        if transposed:
            c0, c1 = cols
            return self.E[:, c0:c1].sum(axis=1)
        r0, r1 = rows
        return self.E[r0:r1].sum(axis=0)
