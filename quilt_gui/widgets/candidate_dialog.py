"""One candidate opened large: the tile (wrapped) with its closed seam, the patch source
with the same seam, the scores, and pick / lock / re-roll."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import (
    QDialog,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from engine.candidate import CandidateTile
from quilt_gui.document import Document
from quilt_gui.widgets.canvas import ImageCanvas, PixelSetItem
from quilt_gui.widgets.tile_view import TiledImageView

LOOP_COLOR = "#ff8c3f"

#: The engine's candidate scores as the dialog names them (fractions shown as percentages).
SCORE_LABELS = {
    "criterion": ("Seam criterion (sum of the error along the seam)", False),
    "peak": ("Seam peak (largest error on the seam)", False),
    "band_error": ("Mean error in the ring where the seam may run", False),
    "changed": ("Pixels that differ from the template", True),
    "coverage": ("Share of the tile inside the seam (patch pixels)", True),
}
#: yes/no scores (1.0 / 0.0 in the engine)
FLAG_LABELS = {"gradient_blend": "Cut re-blended in the gradient domain (its step showed)"}


def score_lines(entry: CandidateTile) -> list[str]:
    """The candidate's figures, one line each, in words."""
    lines = []
    if entry.score is not None:
        lines.append(f"Mean error along the closed seam: <b>{entry.score:.4f}</b>")
    for key, value in entry.scores.items():
        if not isinstance(value, float):
            continue
        if key in FLAG_LABELS:
            lines.append(f"{FLAG_LABELS[key]}: {'yes' if value else 'no'}")
            continue
        label, percent = SCORE_LABELS.get(key, (key, False))
        lines.append(f"{label}: {value:.0%}" if percent else f"{label}: {value:.4g}")
    return lines


class CandidateDialog(QDialog):
    """Non-modal: follows the document (undo, re-roll) while it is open."""

    reroll_requested = Signal(int)

    def __init__(self, doc: Document, index: int, parent=None) -> None:
        super().__init__(parent)
        self.setModal(False)
        self.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose, False)
        self.doc = doc
        self.index = index
        self.view = TiledImageView()
        self.loop_item = PixelSetItem(LOOP_COLOR)
        self.view.canvas.add_item(self.loop_item)
        self.view.canvas.setToolTip("The candidate tile; orange: its closed seam")
        self.patch_view = ImageCanvas()
        self.patch_view.hide_scrollbars()
        self.patch_view.setToolTip(
            "Where the patch comes from in the source, with the same seam: inside it the "
            "tile shows these pixels"
        )
        self.patch_loop = PixelSetItem(LOOP_COLOR)
        self.patch_view.add_item(self.patch_loop)
        patch_box = QWidget()
        pl = QVBoxLayout(patch_box)
        pl.setContentsMargins(2, 2, 2, 2)
        self.patch_label = QLabel()
        self.patch_label.setWordWrap(True)
        pl.addWidget(QLabel("<b>Patch source</b>"))
        pl.addWidget(self.patch_view, 1)
        pl.addWidget(self.patch_label)
        split = QSplitter(Qt.Orientation.Horizontal)
        split.addWidget(self.view)
        split.addWidget(patch_box)
        split.setSizes([560, 300])
        self.info = QLabel()
        self.info.setWordWrap(True)
        self.pick_button = QPushButton()
        self.pick_button.setToolTip("Keep this tile in the set (Space in the gallery)")
        self.pick_button.clicked.connect(self._toggle_pick)
        self.lock_button = QPushButton()
        self.lock_button.setToolTip("A locked tile survives Generate and cannot be re-rolled (L)")
        self.lock_button.clicked.connect(self._toggle_lock)
        self.reroll_button = QPushButton("Re-roll")
        self.reroll_button.setToolTip("A new random patch for this candidate (R)")
        self.reroll_button.clicked.connect(self._reroll)
        close = QPushButton("Close")
        close.clicked.connect(self.close)
        row = QHBoxLayout()
        for b in (self.pick_button, self.lock_button, self.reroll_button):
            row.addWidget(b)
        row.addStretch(1)
        row.addWidget(close)
        lay = QVBoxLayout(self)
        lay.addWidget(split, 1)
        lay.addWidget(self.info)
        lay.addLayout(row)
        self.resize(900, 640)
        self.view.repeats_changed.connect(self._place_loop)
        doc.tileset.candidate_changed.connect(self._on_changed)
        doc.tileset.candidates_reset.connect(self._on_reset)
        doc.tileset.picks_changed.connect(self._refresh_buttons)
        self.set_index(index)

    def entry(self) -> CandidateTile | None:
        cands = self.doc.tileset.candidates
        return cands[self.index] if 0 <= self.index < len(cands) else None

    def set_index(self, index: int) -> None:
        self.index = index
        e = self.entry()
        if e is None:
            self.close()
            return
        self.setWindowTitle(f"Candidate #{index + 1}")
        self.view.set_tile(np.asarray(e.tile))
        self._place_loop()
        self._show_patch(e)
        lines = score_lines(e)
        if e.seed is not None:
            lines.append(f"Seed {e.seed}")
        self.info.setText("<br>".join(lines))
        self._refresh_buttons()

    def _show_patch(self, e: CandidateTile) -> None:
        """The patch's source window, with the seam mapped from tile to source pixels."""
        src = self.doc.source
        if e.patch_rect is None or src is None:
            self.patch_view.set_image(None)
            self.patch_loop.hide()
            self.patch_label.setText("No patch source recorded.")
            return
        x, y, w, h = e.patch_rect
        self.patch_view.set_image(src.main[y : y + h, x : x + w], fit=True)
        if e.loop is not None and e.target_rect is not None:
            tx, ty = e.target_rect[:2]
            self.patch_loop.set_points(np.asarray(e.loop) - (ty, tx))
            self.patch_loop.show()
        else:
            self.patch_loop.hide()
        self.patch_label.setText(
            f"{w}×{h} at ({x}, {y}): the orange rectangle on the source; drag it there to "
            "rebuild this candidate from another place."
        )

    @Slot()
    def _place_loop(self, *_args) -> None:
        e = self.entry()
        if e is None or e.loop is None or self.view.tile is None:
            self.loop_item.hide()
            return
        h, w = self.view.tile.shape[:2]
        k = self.view.repeats // 2
        self.loop_item.set_points(e.loop, (k * w, k * h))
        self.loop_item.show()

    @Slot()
    def _refresh_buttons(self) -> None:
        e = self.entry()
        if e is None:
            return
        self.pick_button.setText("Unpick" if self.index in self.doc.tileset.picks else "Pick")
        self.lock_button.setText("Unlock" if e.locked else "Lock")
        self.reroll_button.setEnabled(not e.locked)

    @Slot(int)
    def _on_changed(self, index: int) -> None:
        if index == self.index:
            self.set_index(index)

    @Slot()
    def _on_reset(self) -> None:
        self.set_index(self.index)

    @Slot()
    def _toggle_pick(self) -> None:
        self.doc.tileset.toggle_pick(self.index)

    @Slot()
    def _toggle_lock(self) -> None:
        self.doc.tileset.set_locked(self.index, not self.doc.tileset.candidates[self.index].locked)

    @Slot()
    def _reroll(self) -> None:
        self.reroll_requested.emit(self.index)
