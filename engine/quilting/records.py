"""What quilting produces: one record per placed block, the streamed event, the result."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine.events import Item
from engine.quilting.layout import axis_positions
from engine.seams import SeamSpec

__all__ = ["EMPTY_PATH", "BlockPlaced", "BlockRecord", "QuiltResult", "read_only"]


def read_only(a: np.ndarray) -> np.ndarray:
    """Mark an array the engine just created read-only (it is handed out in events)."""
    a.setflags(write=False)
    return a


EMPTY_PATH = read_only(np.zeros((0, 2), dtype=np.intp))


@dataclass(frozen=True, slots=True)
class BlockRecord:
    """Everything about one placed block, small enough to keep for every block.

    Attributes
    ----------
    index : int
        Placement number (0, 1, ...), in the order the blocks were placed and streamed (the
        dependency order of the module docstring; sort by ``position`` for raster order).
    position : (int, int)
        (row, col) of the block's top-left pixel in the output (on a tileable output, pixels
        past the right or bottom edge wrap around).
    size : (int, int)
        (h, w) of the placed (possibly cropped) block.
    source : (int, int, int, int)
        (x, y, w, h) of the sample window copied.
    arms : (int, int, int, int)
        Overlap widths (top, left, bottom, right); bottom and right only on wrap-around.
    error : (h, w) float32 ndarray or None
        Error map of the overlap (old content vs the new block, ``metric``); 0 outside it.
    keep_old : (h, w) bool ndarray or None
        True where the cut kept the old content (the new block fills the rest).
    path : (N, 2) int ndarray
        The cut's pixels (row, col) in block coordinates (empty for a straight overlap).
    criterion, peak : float
        Sum and maximum of ``error`` over the path (nan without a cut).
    match_error : float
        Overlap SSD of the chosen window (nan without an overlap or search).
    best_error : float
        Smallest overlap SSD among the candidates searched (nan without a search).
    candidates : int
        Number of windows the choice was drawn from.
    depth : int
        Adaptive split depth (0 = a full block).
    territory : (h, w) int8 ndarray or None
        Bhatia only: 0 own block, 1 left neighbour's extension, 2 top neighbour's extension,
        3 diagonal neighbour's extension.
    """

    index: int
    position: tuple[int, int]
    size: tuple[int, int]
    source: tuple[int, int, int, int]
    arms: tuple[int, int, int, int]
    error: np.ndarray | None
    keep_old: np.ndarray | None
    path: np.ndarray
    criterion: float
    peak: float
    match_error: float
    best_error: float
    candidates: int
    depth: int = 0
    territory: np.ndarray | None = None

    @property
    def overlap(self) -> np.ndarray:
        """(h, w) bool: the pixels that overlapped existing content."""
        h, w = self.size
        t, left, b, r = self.arms
        m = np.zeros((h, w), dtype=bool)
        m[:t] = True
        m[:, :left] = True
        if b:
            m[h - b :] = True
        if r:
            m[:, w - r :] = True
        return m


@dataclass(frozen=True, slots=True)
class BlockPlaced(Item):
    """A block was placed: its record and its composited pixels as written to the output."""

    record: BlockRecord
    pixels: np.ndarray

    @property
    def position(self) -> tuple[int, int]:
        return self.record.position

    @property
    def size(self) -> tuple[int, int]:
        return self.record.size

    @property
    def source(self) -> tuple[int, int, int, int]:
        return self.record.source


@dataclass(frozen=True)
class QuiltResult:
    """The synthesized image and the record of every block (see :class:`BlockRecord`).

    ``step`` is the block grid's period (block - overlap; the block for Bhatia), ``band`` the
    width of the strip after each grid line in which the cuts run (the overlap, or Bhatia's
    cut band). ``seam`` is the :class:`engine.seams.SeamSpec` the cuts were made with.
    """

    image: np.ndarray
    blocks: tuple[BlockRecord, ...]
    block: tuple[int, int]
    overlap: int
    step: tuple[int, int]
    band: int
    tileable: bool
    select: str
    seam: SeamSpec
    params: dict = field(default_factory=dict)

    @property
    def torus_lines(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Row and column positions where the blocks of a tileable result start (evenly spaced
        on the torus, not multiples of ``step``); None when the output does not wrap."""
        if not self.tileable:
            return None
        (H, W), (bh, bw) = self.image.shape[:2], self.block
        if self.select == "bhatia":
            return np.arange(0, H, bh), np.arange(0, W, bw)
        return (
            np.array(axis_positions(H, bh, self.overlap, True)),
            np.array(axis_positions(W, bw, self.overlap, True)),
        )
