"""Index matrices: which tile sits in which cell of a tiled layout (-1 = empty cell).

A leaf shared by the tile-set layouts (:mod:`engine.tiles.layout`) and the export bundle's
preview (:mod:`engine.export`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["assemble_layout", "check_index_matrix"]


def assemble_layout(tiles: Sequence[np.ndarray], index_matrix) -> np.ndarray:
    """The preview image: tile ``index_matrix[r, c]`` at cell (r, c); -1 cells stay 0."""
    m = check_index_matrix(index_matrix, len(tiles))
    first = np.asarray(tiles[0])
    h, w = first.shape[:2]
    out = np.zeros((m.shape[0] * h, m.shape[1] * w) + first.shape[2:], dtype=first.dtype)
    for (r, c), k in np.ndenumerate(m):
        if k >= 0:
            out[r * h : (r + 1) * h, c * w : (c + 1) * w] = tiles[k]
    return out


def check_index_matrix(index_matrix, count: int) -> np.ndarray:
    """``index_matrix`` as an int64 (rows, cols) array of tile ids in [0, count) or -1."""
    m = np.asarray(index_matrix)
    if m.ndim != 2 or m.size == 0:
        raise ValueError(
            f"index_matrix must be a non-empty 2-D (rows, cols) array, got shape {m.shape}"
        )
    if not np.issubdtype(m.dtype, np.integer) and (
        not np.issubdtype(m.dtype, np.floating) or not np.all(m == np.round(m))
    ):
        raise TypeError(f"index_matrix must hold integers, got dtype {m.dtype}")
    m = m.astype(np.int64)
    if m.min() < -1 or m.max() >= count:
        raise ValueError(
            f"index_matrix values must be tile ids in [0, {count - 1}] or -1 (empty), "
            f"got range [{m.min()}, {m.max()}]"
        )
    return m
