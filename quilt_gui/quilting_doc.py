"""The quilting / texture-transfer workflow's part of the document: the output being
synthesized, its placed blocks, the finished result and the transfer target.

Everything here streams in from a job (no undo steps); the parameters of a run are the
document's (:attr:`quilt_gui.document.Document.params`). A finished output is part of the
project (saved with it); :attr:`QuiltingDocument.unsaved` says it exists nowhere else yet.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject, Signal


class QuiltingDocument(QObject):
    """The synthesized output of ``root``'s source, block by block."""

    reset = Signal()  # a synthesis started (or was cleared)
    block_placed = Signal(int)  # index into blocks
    finished = Signal()
    iteration_finished = Signal(int)  # a texture-transfer pass finished (its number)
    target_changed = Signal()
    restored = Signal()  # an output read from a project (no blocks, no record)

    def __init__(self, root, undo_stack) -> None:
        super().__init__(root)
        self.root = root
        self.undo_stack = undo_stack
        self.output: np.ndarray | None = None  # being synthesized, (H, W, C)
        self.blocks: list = []  # engine BlockRecord per placed block
        self.result = None  # engine QuiltResult / TransferResult when finished
        self.target: np.ndarray | None = None  # the image a transfer imitates
        self.kept: np.ndarray | None = None  # a finished output read from a project
        self.unsaved = False  # a finished output not yet saved (as an image or in a project)

    def start(self, shape: tuple[int, int] | None) -> None:
        """Clear the output (None) or start a new one of ``shape`` (H, W)."""
        source = self.root.source
        if shape is None or source is None:
            self.output = None
        else:
            c = source.main.shape[2]
            self.output = np.zeros((*shape, c), dtype=np.float32)
        self.blocks = []
        self.result = None
        self.kept = None
        self.unsaved = False
        self.reset.emit()

    def place_block(self, record, pixels: np.ndarray) -> int:
        """Paste a placed block into the output (wrapping on a torus) and keep its record."""
        H, W = self.output.shape[:2]
        r, c = record.position
        h, w = pixels.shape[:2]
        rows, cols = (r + np.arange(h)) % H, (c + np.arange(w)) % W
        self.output[np.ix_(rows, cols)] = pixels
        self.blocks.append(record)
        self.block_placed.emit(len(self.blocks) - 1)
        return len(self.blocks) - 1

    def finish_iteration(self, event) -> None:
        """A transfer pass ended: the output is its image; the next pass places new blocks."""
        self.output = np.array(event.image, dtype=np.float32)
        self.blocks = []
        self.iteration_finished.emit(int(event.iteration))

    def finish(self, result) -> None:
        self.result = result
        self.output = np.asarray(result.image, dtype=np.float32)  # the worker's display
        # copy of this very array is cached (imaging.prepare_display): no copy here
        self.blocks = list(result.blocks)
        self.unsaved = True
        self.root.mark_dirty()  # the project keeps it: saving it saves the output
        self.finished.emit()

    @property
    def finished_output(self) -> np.ndarray | None:
        """The finished output (made now or read from the project), None while none is."""
        return self.output if self.result is not None or self.kept is not None else None

    def colour_only(self) -> str:
        """ " (the colour map only: the normal map is not quilted)" when the source has
        material maps, which quilting and texture transfer do not carry; else ""."""
        source = self.root.source
        extra = list(source.extra_maps) if source is not None else []
        if not extra:
            return ""
        are = "maps are" if len(extra) > 1 else "map is"
        return f" (the colour map only: the {', '.join(extra)} {are} not quilted)"

    def restore(self, output: np.ndarray | None, target: np.ndarray | None) -> None:
        """A project's saved output and transfer target (not an undo step)."""
        self.output, self.blocks, self.result = output, [], None
        self.kept, self.unsaved = output, False
        self.target = target
        self.target_changed.emit()
        self.restored.emit()

    def set_target(self, pixels: np.ndarray | None) -> None:
        self.target = pixels
        self.target_changed.emit()

    def block_at(self, row: int, col: int) -> int | None:
        """Index of the last placed block covering output pixel (row, col), or None."""
        if self.output is None:
            return None
        H, W = self.output.shape[:2]
        for i in range(len(self.blocks) - 1, -1, -1):
            rec = self.blocks[i]
            (r, c), (h, w) = rec.position, rec.size
            if (row - r) % H < h and (col - c) % W < w:
                return i
        return None
