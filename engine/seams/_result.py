"""The one result type every seam method returns, and helpers to build it."""

from __future__ import annotations

import numpy as np


class Seam:
    """A cut through an overlap error map (rows run top to bottom); immutable.

    Attributes
    ----------
    path : (N, 2) int ndarray
        The path pixels as (row, col), from the top row to the bottom row, each pixel once.
        ``dp``, ``dijkstra``, ``minimax`` and ``resistance`` give a walk: consecutive pixels
        are 8-neighbours (``dp``: one pixel per row). The control-point methods
        (``oscillating``, ``oscillating-optimal``) give a pixel set listed row by row, columns
        ascending: row j holds ``mu_j .. c_j`` (ALGORITHMS §1.1), which is 8-connected as a set
        but not a walk in that order (where the cut steps left by more than one column, the
        listing jumps from ``c_j`` back to the first pixel of row j + 1). Draw such a path as
        pixels, or as a polyline through the control points ``c_j`` (each row's last pixel).
    mask : (h, w) bool ndarray
        True where the output pixel comes from R1 (the left region); path
        pixels belong to R1.
    criterion : float
        Sum of the error over the path pixels.
    peak : float
        Largest error on the path.
    method : str
        The method key that produced it.

    The arrays are read-only (writable inputs are copied first). Streamed seams (thousands
    per second from the oscillating search) may be built lazily:
    ``path``, ``mask``, ``criterion`` and ``peak`` are then computed on first access from a
    private copy of the control points (same values as an eager build).
    """

    __slots__ = ("_path", "_mask", "_criterion", "_peak", "method", "_build")

    def __init__(self, path, mask, criterion, peak, method: str = ""):
        for name, value in (
            ("_path", _read_only(path)),
            ("_mask", _read_only(mask)),
            ("_criterion", float(criterion)),
            ("_peak", float(peak)),
            ("method", method),
            ("_build", None),
        ):
            object.__setattr__(self, name, value)

    @classmethod
    def lazy(cls, build, method: str) -> Seam:
        """A seam whose fields come from ``build() -> (path, mask, criterion, peak)``."""
        seam = cls.__new__(cls)  # the value slots stay unset until _fields() fills them
        object.__setattr__(seam, "method", method)
        object.__setattr__(seam, "_build", build)
        return seam

    def _fields(self):
        build = self._build
        if build is not None:
            path, mask, crit, peak = build()
            path.setflags(write=False)
            mask.setflags(write=False)
            for name, value in (
                ("_path", path),
                ("_mask", mask),
                ("_criterion", float(crit)),
                ("_peak", float(peak)),
                ("_build", None),
            ):
                object.__setattr__(self, name, value)
        return self

    @property
    def path(self) -> np.ndarray:
        return self._fields()._path

    @property
    def mask(self) -> np.ndarray:
        return self._fields()._mask

    @property
    def criterion(self) -> float:
        return self._fields()._criterion

    @property
    def peak(self) -> float:
        return self._fields()._peak

    @property
    def shape(self) -> tuple[int, int]:
        return self.mask.shape

    def __setattr__(self, name, value):
        raise AttributeError(f"Seam is immutable (cannot set {name!r})")

    def __delattr__(self, name):
        raise AttributeError(f"Seam is immutable (cannot delete {name!r})")

    def __reduce__(self):
        return (Seam, (self.path, self.mask, self.criterion, self.peak, self.method))

    def __repr__(self) -> str:
        return (
            f"Seam(method={self.method!r}, shape={self.shape}, pixels={len(self.path)}, "
            f"criterion={self.criterion:.6g}, peak={self.peak:.6g})"
        )


def _read_only(a) -> np.ndarray:
    """``a`` itself when it is a read-only array, else a read-only copy."""
    if isinstance(a, np.ndarray) and not a.flags.writeable:
        return a
    out = np.array(a)
    out.setflags(write=False)
    return out


def mask_from_columns(cols: np.ndarray, width: int) -> np.ndarray:
    """Mask for a one-point-per-row path: True for every column <= cols[row]."""
    cols = np.asarray(cols)
    return np.arange(width)[None, :] <= cols[:, None]


def mask_from_path(path: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """Mask of an arbitrary (winding) 8-connected top-to-bottom path.

    The path is a barrier; the region 4-connected to the right edge (R2 side)
    outside the barrier is R2, everything else (left region and path) is R1.
    """
    from scipy import ndimage

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
    return Seam(
        path=path, mask=mask, criterion=float(values.sum()), peak=float(values.max()), method=method
    )
