"""Where the reference crops of issue 10's tile-set metrics come from.

The frame, ring tone and lattice compare a tile set with *random crops of the source* of the
tile's size: what the texture itself looks like in tiles. On a stochastic texture any position
will do. On a periodic one (brick courses, weave, shelves, ceramic tiles) a good set is aligned
with its template — every structure continues across every joint (issue 10, item 2) — so its
mortar lines lie at the same distance from the tile edge in every tile, and when the tile holds
a whole number of periods its layout *is* the periodic texture. Crops at random phases have
their lines anywhere: against them the texture's own period reads as a frame and as a lattice
(an oracle — crops of a clean periodic texture at positions congruent to the template's — read
frame 1.78 and lattice +19.7 dB against random-phase crops).

So along every axis where :func:`engine.tiles.scale.structure_scale` finds a period and the
tile holds a whole number of them, a reference crop is still drawn at a random position, then
moved to the nearest position of the template's phase class: the best match of the template's
structure (luminance minus its lighting, normalised cross-correlation) within one period around
the drawn position, along the periodic axes only (the other coordinate stays where it was
drawn). The crops stay random — uniform over the members of the phase class — and on axes
without a period nothing changes: the draws are exactly the plain random crops'. A texture
that repeats *exactly* (every in-phase crop a copy of the template, so no set of distinct
aligned tiles exists) keeps random crops too.
[REC: our design; the oracle test is tests/engine/test_metrics_periodic.py]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from engine._validate import as_rng

__all__ = ["ReferenceCrops", "phase_axes", "random_origins", "structure_match"]

#: a texture that repeats exactly (the in-phase crops match the template's structure this
#: well: copies of it, no set of distinct aligned tiles exists) keeps random crops
REPEAT_LEVEL = 0.97
REPEAT_PROBES = 32  # in-phase positions that test it


def random_origins(shape, size, count: int, rng) -> np.ndarray:
    """(count, 2) uniformly random top-left corners (y, x) of ``size`` crops in ``shape``."""
    H, W = shape
    h, w = size
    if h > H or w > W:
        raise ValueError(f"tiles ({w}x{h}) are larger than the source ({W}x{H}): no crop fits")
    g = as_rng(rng)
    return np.column_stack([g.integers(0, H - h + 1, count), g.integers(0, W - w + 1, count)])


def phase_axes(scale, size) -> tuple[bool, bool]:
    """Per axis (y, x): whether the texture is periodic there (``scale``: a
    :class:`engine.tiles.scale.Scale`) and a tile of ``size`` (h, w) holds a whole number of
    its periods (:func:`engine.tiles.scale.holds_whole`) — the axes along which a layout of
    aligned tiles is the texture itself."""
    from engine.tiles.scale import holds_whole

    y, x = (bool(scale.periodic[i] and holds_whole(scale.size[i], size[i])) for i in range(2))
    return y, x


def _smooth(Y: np.ndarray, sigma: float) -> np.ndarray:
    """About a Gaussian blur of ``sigma`` (three box filters, reflected): cheap at any sigma."""
    from scipy import ndimage

    size = max(1, round(math.sqrt(4 * sigma * sigma + 1)))
    for _ in range(3):
        Y = ndimage.uniform_filter(Y, size, mode="reflect")
    return Y


def _window_sums(a: np.ndarray, h: int, w: int) -> np.ndarray:
    """Sums of ``a`` over every h x w window (valid positions), by an integral image."""
    c = np.zeros((a.shape[0] + 1, a.shape[1] + 1))
    c[1:, 1:] = a.cumsum(0).cumsum(1)
    return c[h:, w:] - c[:-h, w:] - c[h:, :-w] + c[:-h, :-w]


def _match_map(S: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Normalised cross-correlation of the template's structure with the source's at every
    valid position: both luminances minus their lighting (a blur of a quarter of the tile)."""
    from scipy import fft

    h, w = T.shape
    H, W = S.shape
    sigma = max(h, w) / 4
    hs = S - _smooth(S, sigma)
    ht = T - _smooth(T, sigma)
    ht = ht - ht.mean()
    shape = (fft.next_fast_len(H, real=True), fft.next_fast_len(W, real=True))
    spec = fft.rfft2(hs, shape) * np.conj(fft.rfft2(ht, shape))
    num = fft.irfft2(spec, shape)[: H - h + 1, : W - w + 1]  # no wrap at valid positions
    sums = _window_sums(hs, h, w)
    energy = _window_sums(hs * hs, h, w) - sums * sums / (h * w)
    norm = np.sqrt(np.maximum(energy, 1e-12) * max(float((ht * ht).sum()), 1e-12))
    return num / norm


def structure_match(source_lum: np.ndarray, template_lum: np.ndarray) -> np.ndarray:
    """(H - h + 1, W - w + 1): how well the template's structure matches the source's at every
    tile-sized window (the score the crops are moved by; the candidates' patch search keeps
    its patches in the same phase class: :mod:`engine.tiles.patch_phase`)."""
    return _match_map(np.asarray(source_lum, np.float64), np.asarray(template_lum, np.float64))


@dataclass(frozen=True)
class ReferenceCrops:
    """The reference crops' positions for tiles of ``size`` (h, w) in a source of ``shape``.

    ``axes`` (y, x): the axes whose coordinate is moved into the template's phase;
    ``period`` (y, x) the texture's period there (px); ``score`` the structure match of
    every valid position with the template (None when no axis is in phase)."""

    shape: tuple[int, int]
    size: tuple[int, int]
    axes: tuple[bool, bool] = (False, False)
    period: tuple[float, float] = (0.0, 0.0)
    score: np.ndarray | None = None

    @classmethod
    def build(cls, source_lum: np.ndarray, size, template_lum=None) -> ReferenceCrops:
        """Plain random crops without a template; with one, in its phase along the periodic
        axes that the tile holds whole (:func:`phase_axes`)."""
        shape = tuple(int(v) for v in source_lum.shape)
        size = (int(size[0]), int(size[1]))
        if template_lum is None or size[0] > shape[0] or size[1] > shape[1]:
            return cls(shape, size)
        from engine.tiles.scale import structure_scale

        scale = structure_scale(source_lum)
        axes = phase_axes(scale, size)
        if not any(axes):
            return cls(shape, size)
        score = _match_map(source_lum, np.asarray(template_lum, dtype=np.float64))
        found = cls(shape, size, axes, (float(scale.height), float(scale.width)), score)
        probe = found.origins(REPEAT_PROBES, 0)
        if np.median(score[probe[:, 0], probe[:, 1]]) >= REPEAT_LEVEL:
            return cls(shape, size)  # every in-phase crop is a copy of the template
        return found

    def origins(self, count: int, rng) -> np.ndarray:
        """(count, 2) top-left corners (y, x): uniformly random ones (the same draws as
        without a phase), each moved to the template's best-matching phase within one period
        along the in-phase axes."""
        org = random_origins(self.shape, self.size, count, rng)
        if self.score is None:
            return org
        out = org.copy()
        limits = self.score.shape
        for k, p in enumerate(org):
            lo, hi = p.copy(), p + 1
            for i in range(2):
                if self.axes[i]:
                    span = min(limits[i], max(1, math.ceil(self.period[i])))
                    lo[i] = min(max(0, p[i] - span // 2), limits[i] - span)
                    hi[i] = lo[i] + span
            win = self.score[lo[0] : hi[0], lo[1] : hi[1]]
            out[k] = lo + np.unravel_index(int(np.argmax(win)), win.shape)
        return out
