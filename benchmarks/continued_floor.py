"""A candidate set's lattice above a floor that *continues* the template's margin (issue 10).

:func:`engine.metrics.lattice` subtracts the lattice of layouts of random source crops whose
outer ``margin`` pixels are replaced by the template's ("the floor of any set that shares a
border"). A set of candidates must also *join* that shared margin: next to it every tile
continues the same pixels, over the texture's correlation length, so the tiles resemble each
other there and that resemblance sits on the lattice's harmonics. The oracle
(``python -m benchmarks.candidate_oracle``): ideal candidate sets of a Gaussian field — every
tile an exact draw of the field given the template's 1 px ring, no cut, no blend, no
selection — score far above the pasted floor (README "Interior metrics": +3 dB at 2 px
correlation, +9 dB at 8 px, on 64 px tiles), so on smooth textures the pasted floor rejects
flawless sets.

The floor here is the one :mod:`benchmarks.wang_lattice` uses for Wang sets, for the
candidates' single shared ring: each reference crop carries the template's outer ``margin``
pixels *and* is continued from them by the texture's own linear prediction, simple kriging
with the source's luminance autocovariance, ``x = c + C_ib C_bb^-1 (t_b - c_b)`` (exact for a
Gaussian field). The tiles' own figure is computed exactly as by
:func:`engine.metrics.lattice` (same crops' positions, same index matrices, same generator
draws), so ``value`` equals the engine's and only the floor differs.

**Reported only**: issue 10's acceptance is judged on :func:`engine.metrics.lattice`; this
column tells how much of a lattice figure a flawless set sharing the same ring would show.
"""

from __future__ import annotations

import numpy as np

from benchmarks.wang_lattice import NUGGET, autocovariance
from engine.metrics import LATTICE_LAYOUTS, edge_distance, lattice, luminance
from engine.reference_crops import ReferenceCrops

__all__ = ["continued_floor_lattice", "kriging_gain_rect"]

CHUNK = 4096  # pixels per block of the cross-covariance (memory: CHUNK x border x 16 bytes)


def kriging_gain_rect(L: np.ndarray, size, margin: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(gain (h*w, nb) float32, border (h, w) bool): the simple-kriging weights predicting
    every pixel of an h x w crop of the texture ``L`` from its outer ``margin`` pixels (the
    autocovariance of ``L`` over the pixel pairs it has; a nugget of :data:`NUGGET` x the
    variance on the border's own covariance, as :mod:`benchmarks.wang_lattice`)."""
    h, w = int(size[0]), int(size[1])
    reach_y, reach_x = h - 1, w - 1
    acov = autocovariance(np.asarray(L, np.float64), max(reach_y, reach_x))
    r = max(reach_y, reach_x)
    border = edge_distance((h, w)) < margin
    b = np.argwhere(border)
    every = np.argwhere(np.ones((h, w), bool))

    def cov(p, q):
        d = p[:, None, :] - q[None, :, :] + r
        return acov[d[..., 0], d[..., 1]]

    Cbb = cov(b, b)
    Cbb = 0.5 * (Cbb + Cbb.T) + NUGGET * float(acov[r, r]) * np.eye(len(b))
    inv = np.linalg.inv(Cbb)
    gain = np.empty((h * w, len(b)), np.float32)
    for s in range(0, h * w, CHUNK):
        gain[s : s + CHUNK] = (cov(every[s : s + CHUNK], b) @ inv).astype(np.float32)
    return gain, border


def continued_floor_lattice(
    tiles, source, *, template, margin: int = 1, layouts: int = LATTICE_LAYOUTS, rng=0
) -> tuple[float, float, float]:
    """(value, floor, above) in dB: the tiles' lattice exactly as :func:`engine.metrics.lattice`
    (``template``, ``margin``, random 8x8 layouts, crops in the template's phase on periodic
    textures) and the floor of the same crops carrying the template's outer ``margin`` pixels
    continued by kriging (module docstring)."""
    stack = np.stack([luminance(getattr(t, "tile", t)) for t in tiles])
    n, h, w = stack.shape
    t = luminance(getattr(template, "tile", template))
    S = luminance(source)
    gain, border = kriging_gain_rect(S, (h, w), margin)
    g = np.random.default_rng(rng)
    where = ReferenceCrops.build(S, (h, w), t)
    floors = []
    for _ in range(int(layouts)):  # the engine's draws: each layout's crops, then its indices
        org = where.origins(n, g)
        crops = np.stack([S[y : y + h, x : x + w] for y, x in org])
        idx = g.integers(0, n, (8, 8))
        miss = (t[border][None] - crops[:, border]).astype(np.float32)  # (n, nb)
        cont = crops + (miss @ gain.T).reshape(n, h, w)
        cont[:, border] = t[border]
        floors.append(lattice(list(cont[..., None]), source, margin=0, layouts=[idx]).value)
    v = lattice(tiles, source, template=template, margin=margin, layouts=layouts, rng=rng).value
    f = float(np.mean(floors))
    return v, f, v - f
