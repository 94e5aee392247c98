"""Index matrices and tiled synthesis (ALGORITHMS.md §1.8 "Synthesis").

Any index matrix works with a mutually connectable tile set: cell (r, c) shows tile
``layout[r, c]``. :func:`random_layout` draws one uniformly (or by per-tile weights),
optionally with no two equal horizontal or vertical neighbours; the same seed gives the same
matrix. :func:`assemble` pastes the tiles.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping

import numpy as np

from engine._validate import as_rng, positive_int
from engine.index_matrix import assemble_layout

__all__ = ["assemble", "assemble_maps", "random_layout"]


def tile_weights(weights, n_tiles: int) -> np.ndarray:
    """Validated relative frequencies of ``n_tiles`` tiles (None: all 1)."""
    if weights is None:
        return np.ones(n_tiles)
    w = np.asarray(weights, dtype=np.float64)
    if w.shape != (n_tiles,):
        raise ValueError(f"weights must have one value per tile ({n_tiles}), got shape {w.shape}")
    if not np.all(np.isfinite(w)) or (w < 0).any():
        raise ValueError("weights must be finite and >= 0")
    if w.sum() <= 0:
        raise ValueError("weights must give at least one tile a positive weight")
    return w


def random_layout(
    n_tiles: int, rows: int, cols: int, *, rng=None, no_equal_neighbours: bool = False, weights=None
) -> np.ndarray:
    """A (rows, cols) int64 index matrix of tiles 0..n_tiles-1.

    Parameters
    ----------
    n_tiles, rows, cols : int
    rng : int, Generator or None
        Seed; the same seed gives the same matrix.
    no_equal_neighbours : bool
        No cell equals its left or upper neighbour (needs at least two tiles with a
        positive weight); cells are drawn in raster order among the allowed tiles.
    weights : (n_tiles,) array or None
        Relative frequency of every tile (0 = never used); default uniform.

    Examples
    --------
    >>> m = random_layout(3, 4, 5, rng=0, no_equal_neighbours=True)
    >>> bool((m[:, 1:] != m[:, :-1]).all() and (m[1:] != m[:-1]).all())
    True
    """
    n = positive_int(n_tiles, "n_tiles")
    rows = positive_int(rows, "rows")
    cols = positive_int(cols, "cols")
    w = tile_weights(weights, n)
    gen = as_rng(rng)
    p = w / w.sum()
    if not no_equal_neighbours:
        return gen.choice(n, size=(rows, cols), p=p).astype(np.int64)
    if np.count_nonzero(w) < 2 and rows * cols > 1:
        raise ValueError(
            "no_equal_neighbours needs at least two tiles with a positive weight, got "
            f"{np.count_nonzero(w)}"
        )
    out = np.empty((rows, cols), dtype=np.int64)
    u = gen.random((rows, cols))
    for r in range(rows):
        for c in range(cols):
            allowed = w.copy()
            if c > 0:
                allowed[out[r, c - 1]] = 0
            if r > 0:
                allowed[out[r - 1, c]] = 0
            total = allowed.sum()
            if total <= 0:  # cannot happen with >= 2 weighted tiles (raster order)
                raise ValueError("no_equal_neighbours cannot be satisfied with these weights")
            cdf = np.cumsum(allowed) / total
            out[r, c] = min(int(np.searchsorted(cdf, u[r, c], side="right")), n - 1)
            while allowed[out[r, c]] <= 0:  # guard against float edges of the cdf
                out[r, c] -= 1
    return out


def _tile_array(t, i: int, map_name: str | None):
    if isinstance(t, np.ndarray):
        return t
    if isinstance(t, Mapping):
        return t[map_name] if map_name is not None else next(iter(t.values()))
    if map_name is not None and hasattr(t, "maps"):
        try:
            return t.maps[map_name]
        except KeyError:
            raise KeyError(f"tiles[{i}] has no map {map_name!r}") from None
    if hasattr(t, "tile"):
        return t.tile
    return np.asarray(t)


def assemble(tiles, layout, *, map_name: str | None = None) -> np.ndarray:
    """Paste ``tiles[layout[r, c]]`` at cell (r, c); -1 cells stay 0.

    ``tiles`` are arrays, {map: array} dicts, or objects with ``.tile`` (and ``.maps`` for
    ``map_name``) such as :class:`CandidateTile` / :class:`SeamlessTile`; all the same shape.
    """
    arrs = [_tile_array(t, i, map_name) for i, t in enumerate(tiles)]
    if not arrs:
        raise ValueError("tiles must not be empty")
    shape = np.shape(arrs[0])
    for i, a in enumerate(arrs):
        if np.shape(a) != shape:
            raise ValueError(
                f"tiles[{i}] is shaped {np.shape(a)}, tiles[0] {shape}: all must match"
            )
    if isinstance(layout, numbers.Integral):
        raise TypeError("layout must be a 2-D index matrix")
    return assemble_layout(arrs, layout)


def assemble_maps(tiles, layout, names) -> dict:
    """:func:`assemble` for every map of ``names`` (``"main"`` first: the tiles' ``tile``,
    the others from their ``maps``): the preview of a layout per map."""
    return {m: assemble(tiles, layout, map_name=None if m == names[0] else m) for m in names}
