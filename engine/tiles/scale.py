"""The texture's structure scale, and tile sizes that hold whole structures (issue 10, item 6).

When a texture's structures (brick courses, shelves, planks, coins) are larger than about a
third of the tile, every tile is a cut window whatever its patch: a layout shows the cut
structures at every tile edge. :func:`structure_scale` estimates the structures' size along
each axis from the autocorrelation of the source's luminance, with the low-frequency lighting
removed and each row (for the horizontal scale) or column (vertical) centred, so that a
lighting gradient or a structure of the other axis (a shelf board seen along a row) adds no
correlation:

* a **period**: the first clear peak of the autocorrelation (a peak at least
  :data:`PEAK_LEVEL` high and :data:`PEAK_PROMINENCE` above the dip before it) — the course
  height of a brick wall, the pitch of shelves or planks;
* else the **decorrelation length**: the first lag where the autocorrelation falls below
  :data:`DECORRELATION_LEVEL` (about the size of a blob or a grain — or of one large landmark).

:func:`whole_structure_range` narrows the template search's range, along each periodic axis,
to tiles that hold a whole number of periods, :data:`STRUCTURES_PER_TILE` of them where the
requested range allows, and says in words when it cannot (the requested largest tile holds
fewer), or when the range holds no whole number of periods at all (a fixed tile of 160 px
over 48 px planks). [REC: our design; measured on the evaluation set, README]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

__all__ = [
    "DECORRELATION_LEVEL",
    "PEAK_LEVEL",
    "PEAK_PROMINENCE",
    "PERIOD_SLACK",
    "STRUCTURES_PER_TILE",
    "Scale",
    "WHOLE_SLACK",
    "holds_whole",
    "luminance32",
    "structure_scale",
    "whole_structure_range",
]

#: a tile side should hold this many structures (the issue: structures larger than about a
#: third of the tile make every tile a cut window)
STRUCTURES_PER_TILE = 3.0
PEAK_LEVEL = 0.25  # an autocorrelation peak at least this high is a period...
PEAK_PROMINENCE = 0.1  # ...when it rises this much above the dip before it
DECORRELATION_LEVEL = 0.2  # no period: the structure ends where the correlation falls below
#: a tile within 1 % (at least 1 px) of a multiple of the period holds whole periods: a
#: periodic layout shows any larger difference as a step at every tile edge (shelves at 57 px
#: instead of 64 across a 185 px tile), and the search's strip mismatch does not see it
PERIOD_SLACK = 0.01
#: a tile *holds* whole periods (the judgement, :func:`holds_whole`) within this fraction (at
#: least 1 px) of a multiple: PERIOD_SLACK with room for the period's estimate
WHOLE_SLACK = 0.02
MAX_SIDE = 1024  # larger sources are measured on a block-mean reduction (scale x the factor)


@dataclass(frozen=True, slots=True)
class Scale:
    """Structure size in source pixels along y (``height``) and x (``width``); ``periodic``
    says per axis (y, x) whether it is a period (an autocorrelation peak) or a decorrelation
    length. ``size`` is (height, width) as the tile sizes are given."""

    height: float
    width: float
    periodic: tuple[bool, bool] = (False, False)

    @property
    def size(self) -> tuple[float, float]:
        return (self.height, self.width)

    def to_dict(self) -> dict:
        return {
            "height": round(self.height, 1),
            "width": round(self.width, 1),
            "periodic": {"y": self.periodic[0], "x": self.periodic[1]},
        }


def luminance32(S: np.ndarray) -> np.ndarray:
    """float32 BT.709 luminance of (H, W[, C]) (``engine.metrics.LUMA``'s weights; a gray
    image is its own, a two-channel one its first channel): the cheap figure for structure
    and step measurements, where float64 would only cost time."""
    S = np.asarray(S, dtype=np.float32)
    if S.ndim == 2:
        return S
    if S.shape[2] >= 3:
        return S[..., 0] * 0.2125 + S[..., 1] * 0.7154 + S[..., 2] * 0.0721
    return S[..., 0]


def _smooth(Y: np.ndarray, sigma: float) -> np.ndarray:
    """About a Gaussian blur of ``sigma`` (three box filters of the same variance, reflected
    at the border): linear in the pixels whatever ``sigma``, where a Gaussian of σ = 128 on
    a 1024 px image costs seconds."""
    size = max(1, round(math.sqrt(4 * sigma * sigma + 1)))
    for _ in range(3):
        Y = ndimage.uniform_filter(Y, size, mode="reflect")
    return Y


def _acf_rows(Y: np.ndarray, max_lag: int) -> np.ndarray:
    """Autocorrelation along axis 1 of every row of ``Y`` (rows centred), summed over the rows
    and normalised to 1 at lag 0; lags 0..max_lag (no wrap: zero-padded FFT, each lag divided
    by the number of pixel pairs it has)."""
    n = Y.shape[1]
    Z = Y - Y.mean(axis=1, keepdims=True)
    size = 1 << int(math.ceil(math.log2(2 * n)))
    F = np.fft.rfft(Z, size, axis=1)
    c = np.fft.irfft((F * F.conj()).real.sum(axis=0), size)[: max_lag + 1]
    c = c / (n - np.arange(max_lag + 1))
    return c / c[0] if c[0] > 0 else np.zeros_like(c)


def _axis_scale(acf: np.ndarray) -> tuple[float, bool]:
    """(scale, periodic) of one axis from its autocorrelation (lags 0..); 0 for a flat one."""
    if acf.size < 3 or acf[0] <= 0:
        return 0.0, False
    below = np.flatnonzero(acf < DECORRELATION_LEVEL)
    dip = None
    for k in range(2, acf.size - 1):  # the first clear peak after a dip
        dip = acf[1 : k + 1].min() if dip is None else min(dip, acf[k])
        peak = acf[k] >= acf[k - 1] and acf[k] > acf[k + 1] and acf[k] >= PEAK_LEVEL
        if peak and acf[k] - dip >= PEAK_PROMINENCE:
            a, b, c = acf[k - 1], acf[k], acf[k + 1]  # the peak's lag refined by a parabola
            den = a - 2 * b + c
            off = 0.5 * (a - c) / den if den < 0 else 0.0
            return float(k + off), True
    if below.size:
        k = int(below[0])  # interpolate the crossing between k - 1 and k
        a, b = acf[k - 1], acf[k]
        return float(k - 1 + (a - DECORRELATION_LEVEL) / (a - b) if a != b else k), False
    return float(acf.size - 1), False


def structure_scale(source) -> Scale:
    """The structure scale of ``source`` (H, W[, C], values in [0, 1]) along y and x.

    >>> yy = np.arange(256)[:, None] * np.ones((1, 256))
    >>> s = structure_scale((yy % 32 < 4).astype(float))  # a line every 32 rows
    >>> round(s.height), s.periodic[0]
    (32, True)
    """
    Y = luminance32(source)
    H, W = Y.shape
    f = max(1, math.ceil(max(H, W) / MAX_SIDE))
    if f > 1:
        Y = Y[: H // f * f, : W // f * f].reshape(H // f, f, W // f, f).mean(axis=(1, 3))
    Y = Y.astype(np.float64)
    h, w = Y.shape
    # lighting out: the structures are far smaller than a quarter of the source
    Y = Y - _smooth(Y, max(h, w) / 8)
    sy, py = _axis_scale(_acf_rows(Y.T, max(2, h // 2)))
    sx, px = _axis_scale(_acf_rows(Y, max(2, w // 2)))
    return Scale(sy * f, sx * f, (py, px))


def _axis_range(period: float, lo: int, hi: int, per_tile: float) -> tuple[int, int]:
    """The sizes along one periodic axis that hold whole periods: about the smallest multiple
    of ``period`` of at least ``per_tile`` periods within [lo, hi] (else the largest multiple
    the range holds), ± :data:`PERIOD_SLACK` (the estimate's error grows with the multiple);
    [lo, hi] when no multiple fits."""
    slack = lambda n: max(1.0, PERIOD_SLACK * n)  # noqa: E731
    first = max(math.ceil(per_tile - 1e-9), math.ceil((lo - slack(lo)) / period))
    k = first if first * period - slack(first * period) <= hi else math.floor(hi / period + 0.01)
    if k < 1 or k * period + slack(k * period) < lo:
        return lo, hi
    n = k * period
    a, b = max(lo, math.ceil(n - slack(n))), min(hi, math.floor(n + slack(n)))
    return (a, b) if a <= b else (lo, hi)


def holds_whole(period, n) -> bool:
    """Whether ``n`` px holds a whole number (at least one) of ``period`` px periods, within
    :data:`WHOLE_SLACK` of ``n`` (at least 1 px): the one test of the Auto sizes, the Wang
    set's phase, the reference crops and the fixed-size warning, so the warning never asks to
    change a size Auto kept. 2 %, not the search's 1 % :data:`PERIOD_SLACK` (which only
    narrows the search to the middle of a multiple): the period estimate's own error takes
    most of 1 % (up to 0.77 px at 128 px on clean stripes), the warning is for a size between
    two multiples (planks at 160 px: 16 px off), and 2 % keeps the evaluation set's Auto
    sizes (the Wang set's phase and Auto already used it)."""
    p, n = float(period), float(n)
    k = round(n / p) if p > 0 else 0
    return k >= 1 and abs(n - k * p) <= max(1.0, WHOLE_SLACK * n)


def _holds_whole(period: float, lo: int, hi: int) -> bool:
    """Whether some size in [lo, hi] holds whole periods (:func:`holds_whole`)."""
    return any(holds_whole(period, n) for n in range(int(lo), int(hi) + 1))


def _per_tile(p: float, lo: int, hi: int) -> str:
    return f"{lo / p:.2f}" if lo == hi else f"{lo / p:.2f}-{hi / p:.2f}"


def whole_structure_range(scale: Scale, lo, hi, *, per_tile: float = STRUCTURES_PER_TILE):
    """``(lo, hi, notes)``: the template search's range (h, w) narrowed, along each axis where
    the texture is periodic, to tiles that hold whole periods — about ``per_tile`` of them
    where ``hi`` allows (a structure cut at the tile edge continues in the next tile then, and
    a tile holds three); ``notes`` says in words when the requested largest tile holds fewer,
    or when no tile of the range holds a whole number of periods (a fixed size between two
    multiples: every tile line of a layout then breaks the pattern — planks at a fixed 160 px,
    3.33 boards: frame 1.74, lattice +11.2 dB against 1.06, +2.1 at the searched 144 px).
    Axes without a period (a decorrelation length only: blobs, grain, but also one large
    landmark such as a fovea) keep the range: their measure is too unsure to act on."""
    new_lo, new_hi = list(lo), list(hi)
    short, broken = [], []
    for i, axis in enumerate(("tall", "wide")):
        if not scale.periodic[i] or scale.size[i] <= 0:
            continue
        p = scale.size[i]
        new_lo[i], new_hi[i] = _axis_range(p, lo[i], hi[i], per_tile)
        if hi[i] < per_tile * p * 0.95:
            short.append((axis, p, i))
        elif not _holds_whole(p, lo[i], hi[i]):
            broken.append((axis, p, i))
    notes = []
    if broken:
        what = " and ".join(
            f"{p:.0f} px {axis} ({_per_tile(p, lo[i], hi[i])} per tile; "
            f"{round(math.floor(lo[i] / p) * p)} "
            f"or {round(math.ceil(hi[i] / p) * p)} px hold whole ones)"
            for axis, p, i in broken
        )
        notes.append(
            f"the texture repeats about every {what}, measured by autocorrelation: no tile of "
            "the requested size holds a whole number of periods, so every tile cuts the pattern "
            "and a layout breaks it at every tile line (a structure of another size there); "
            "choose a tile size that holds whole periods (--tile-min/--tile-max, or Tile size "
            "in the editor)"
        )
    if short:
        what = " and ".join(f"{p:.0f} px {axis}" for axis, p, _ in short)
        need = list(hi)
        for _, p, i in short:
            need[i] = math.ceil(per_tile * p)
        notes.append(
            f"the texture repeats about every {what} (measured by autocorrelation), more than a "
            f"third of the largest tile {hi[1]}x{hi[0]}: every tile cuts its structures and a "
            f"layout shows the cuts at the tile edges; try a tile of at least "
            f"{need[1]}x{need[0]} (a larger tile size: --tile-max, or Tile size in the editor), or "
            "a Wang set"
        )
    return tuple(new_lo), tuple(new_hi), notes
