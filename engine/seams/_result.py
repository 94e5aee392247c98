"""The one result type every seam method returns, and helpers to build it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage


@dataclass(frozen=True, slots=True)
class Seam:
    """A cut through an overlap error map (rows run top to bottom).

    Attributes
    ----------
    path : (N, 2) int ndarray
        The path pixels as (row, col), from the top row to the bottom row.
    mask : (h, w) bool ndarray
        True where the output pixel comes from R1 (the left region); path
        pixels belong to R1.
    criterion : float
        Sum of the error over the path pixels.
    peak : float
        Largest error on the path.
    method : str
        The method key that produced it.
    """

    path: np.ndarray
    mask: np.ndarray
    criterion: float
    peak: float
    method: str = ""

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape


def mask_from_columns(cols: np.ndarray, width: int) -> np.ndarray:
    """Mask for a one-point-per-row path: True for every column <= cols[row]."""
    cols = np.asarray(cols)
    return np.arange(width)[None, :] <= cols[:, None]


def mask_from_path(path: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Mask of an arbitrary (winding) 8-connected top-to-bottom path.

    The path is a barrier; the region 4-connected to the right edge (R2 side)
    outside the barrier is R2, everything else (left region and path) is R1.
    """
    h, w = shape
    barrier = np.zeros(shape, dtype=bool)
    barrier[path[:, 0], path[:, 1]] = True
    labels, _ = ndimage.label(~barrier)  # default structure = 4-connectivity
    right = labels[:, w - 1]
    right_labels = np.unique(right[right > 0])
    r2 = np.isin(labels, right_labels) if right_labels.size else np.zeros(shape, bool)
    return ~r2


def make_seam(error: np.ndarray, path, method: str, mask: np.ndarray | None = None) -> Seam:
    """Build a :class:`Seam` from a path, computing criterion, peak and mask."""
    path = np.asarray(path, dtype=np.intp).reshape(-1, 2)
    values = error[path[:, 0], path[:, 1]]
    if mask is None:
        mask = mask_from_path(path, error.shape)
    path.setflags(write=False)
    mask = np.asarray(mask, dtype=bool)
    mask.setflags(write=False)
    return Seam(path=path, mask=mask, criterion=float(values.sum()), peak=float(values.max()), method=method)
