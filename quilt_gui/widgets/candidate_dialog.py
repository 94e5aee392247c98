"""One candidate opened large: the tile (wrapped), its closed seam, scores, pick/lock/re-roll."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import QDialog, QHBoxLayout, QLabel, QPushButton, QVBoxLayout

from quilt_gui.document import Document
from quilt_gui.widgets.canvas import PixelSetItem
from quilt_gui.widgets.tile_view import TiledImageView

LOOP_COLOR = "#ff8c3f"


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
        self.info = QLabel()
        self.info.setWordWrap(True)
        self.pick_button = QPushButton()
        self.pick_button.clicked.connect(self._toggle_pick)
        self.lock_button = QPushButton()
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
        lay.addWidget(self.view, 1)
        lay.addWidget(self.info)
        lay.addLayout(row)
        self.resize(620, 680)
        self.view.repeat_buttons.idClicked.connect(self._place_loop)
        doc.candidate_changed.connect(self._on_changed)
        doc.candidates_reset.connect(self._on_reset)
        doc.picks_changed.connect(self._refresh_buttons)
        self.set_index(index)

    def set_index(self, index: int) -> None:
        self.index = index
        if not 0 <= index < len(self.doc.candidates):
            self.close()
            return
        e = self.doc.candidates[index]
        self.setWindowTitle(f"Candidate #{index + 1}")
        self.view.set_tile(np.asarray(e.tile))
        self._place_loop()
        lines = []
        if e.score is not None:
            lines.append(f"Mean error along the closed seam: <b>{e.score:.4f}</b>")
        lines += [f"{k}: {v:.4g}" for k, v in e.scores.items() if isinstance(v, float)]
        if e.patch_rect is not None:
            x, y, w, h = e.patch_rect
            lines.append(
                f"Patch source: {w}×{h} at ({x}, {y}) — the orange rectangle on the "
                "source; drag it to rebuild this candidate from another place."
            )
        if e.seed is not None:
            lines.append(f"Seed {e.seed}")
        self.info.setText("<br>".join(lines))
        self._refresh_buttons()

    @Slot()
    def _place_loop(self, *_args) -> None:
        e = self.doc.candidates[self.index] if 0 <= self.index < len(self.doc.candidates) else None
        if e is None or e.loop is None or self.view.tile is None:
            self.loop_item.hide()
            return
        h, w = self.view.tile.shape[:2]
        k = self.view.repeats // 2
        self.loop_item.set_points(e.loop, (k * w, k * h))
        self.loop_item.show()

    @Slot()
    def _refresh_buttons(self) -> None:
        if not 0 <= self.index < len(self.doc.candidates):
            return
        e = self.doc.candidates[self.index]
        self.pick_button.setText("Unpick" if self.index in self.doc.picks else "Pick")
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
        self.doc.toggle_pick(self.index)

    @Slot()
    def _toggle_lock(self) -> None:
        self.doc.set_locked(self.index, not self.doc.candidates[self.index].locked)

    @Slot()
    def _reroll(self) -> None:
        self.reroll_requested.emit(self.index)
