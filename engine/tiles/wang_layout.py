"""Random valid Wang layouts (Cohen et al. 2003, "scanline" tiling).

A layout is valid when every pair of neighbouring cells shows the same colour on the edge they
share: ``S`` of a cell equals ``N`` of the cell below, ``E`` equals ``W`` of the cell to the
right. :func:`wang_layout` fills the cells in raster order, drawing each among the tiles that
match its north and west neighbours (by ``weights``); with ``wrap`` the last row and column
also match the first, so the layout itself tiles. A complete set always has a matching tile.
"""

from __future__ import annotations

import numpy as np

from engine._validate import as_rng, positive_int
from engine.export.wang import check_signatures, layout_mismatches
from engine.tiles.layout import tile_weights

__all__ = ["check_signatures", "layout_mismatches", "wang_layout"]


def wang_layout(
    signatures,
    rows: int,
    cols: int,
    *,
    rng=None,
    weights=None,
    wrap: bool = False,
    no_equal_neighbours: bool = False,
) -> np.ndarray:
    """A (rows, cols) index matrix of a random valid Wang tiling.

    Parameters
    ----------
    signatures : (n, 4) array_like
        (N, E, S, W) of every tile (e.g. ``[t.signature for t in wang_set.tiles]``).
    rows, cols : int
    rng : int, Generator or None
        Seed; the same seed gives the same matrix.
    weights : (n,) array or None
        Relative frequency of every tile among those that fit a cell (0 = never used).
    wrap : bool
        The last row (column) also matches the first: the layout tiles toroidally.
    no_equal_neighbours : bool
        A cell avoids the tile of its left and upper neighbours whenever another tile fits
        (with K >= 2 colours one always does, except where ``wrap`` fixes all four edges).

    Raises ValueError naming the cell and the colours it needed when no tile fits (an
    incomplete set, or weights that rule the fitting tiles out).

    Examples
    --------
    >>> sigs = [(n, e, s, w) for n in (0, 1) for e in (0, 1) for s in (0, 1) for w in (0, 1)]
    >>> m = wang_layout(sigs, 3, 4, rng=0)
    >>> layout_mismatches(sigs, m)
    0
    """
    sig = check_signatures(signatures)
    n = sig.shape[0]
    rows = positive_int(rows, "rows")
    cols = positive_int(cols, "cols")
    w = tile_weights(weights, n)
    gen = as_rng(rng)
    out = np.empty((rows, cols), np.int64)
    u = gen.random((rows, cols))
    for r in range(rows):
        for c in range(cols):
            need = {}
            if r > 0:
                need[0] = sig[out[r - 1, c], 2]
            if c > 0:
                need[3] = sig[out[r, c - 1], 1]
            if wrap and r == rows - 1 and rows > 1:
                need[2] = sig[out[0, c], 0]
            if wrap and c == cols - 1 and cols > 1:
                need[1] = sig[out[r, 0], 3]
            ok = np.ones(n, bool)
            for side, colour in need.items():
                ok &= sig[:, side] == colour
            allowed = np.where(ok, w, 0.0)
            if no_equal_neighbours:
                other = allowed.copy()
                if r > 0:
                    other[out[r - 1, c]] = 0
                if c > 0:
                    other[out[r, c - 1]] = 0
                if other.sum() > 0:
                    allowed = other
            total = allowed.sum()
            if total <= 0:
                names = ", ".join(f"{'nesw'[k]}={v}" for k, v in sorted(need.items()))
                raise ValueError(
                    f"no tile with a positive weight fits cell ({r}, {c}) (needs {names}): the "
                    "set is incomplete or its weights exclude every fitting tile"
                )
            cdf = np.cumsum(allowed) / total
            k = min(int(np.searchsorted(cdf, u[r, c], side="right")), n - 1)
            while allowed[k] <= 0:  # float edges of the cdf
                k -= 1
            out[r, c] = k
    return out
