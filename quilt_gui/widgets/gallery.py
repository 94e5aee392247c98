"""Candidates gallery: a list model over the document's candidates and its thumbnail view.

Rows are inserted with ``beginInsertRows`` as candidates stream in (no widget per tile).
Picking: click toggles a tile's pick, Shift+click picks the range from the last clicked
tile, Space toggles the current one, Ctrl+A picks all; the delegate draws the pick order.
Double-click or Enter opens a candidate large; L locks, R re-rolls.
"""

from __future__ import annotations

from functools import partial

from PySide6.QtCore import (
    QAbstractListModel,
    QModelIndex,
    QRect,
    QSize,
    Qt,
    Signal,
    Slot,
)
from PySide6.QtGui import QAction, QColor, QFont, QGuiApplication, QPainter, QPen, QPixmap
from PySide6.QtWidgets import QListView, QMenu, QStyle, QStyledItemDelegate

from engine.candidate import CandidateTile
from quilt_gui import settings
from quilt_gui.document import Document
from quilt_gui.imaging import to_qimage

PICK_ROLE = Qt.ItemDataRole.UserRole + 1  # 1-based pick order, 0 = not picked
LOCKED_ROLE = Qt.ItemDataRole.UserRole + 2
SCORE_ROLE = Qt.ItemDataRole.UserRole + 3
ENTRY_ROLE = Qt.ItemDataRole.UserRole + 4

PICK_COLOR = QColor(255, 190, 40)
#: How often a picked tile appears in the preview layout, relative to the others.
PREVIEW_WEIGHTS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)


class CandidateModel(QAbstractListModel):
    """One row per candidate (in the order they arrived), thumbnails cached per entry."""

    def __init__(self, doc: Document, thumb: int | None = None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.thumb = int(thumb or settings.get("thumbnail_size"))
        self._rows: list[CandidateTile] = list(doc.tileset.candidates)
        self._pick_order: dict[int, int] = {}
        self._thumbs: dict[int, QPixmap] = {}  # id(entry) -> pixmap
        doc.tileset.candidate_inserted.connect(self._on_inserted)
        doc.tileset.candidate_changed.connect(self._on_changed)
        doc.tileset.candidates_reset.connect(self._on_reset)
        doc.tileset.picks_changed.connect(self._on_picks_changed)
        self._on_picks_changed()

    # ------------------------------------------------------------------ Qt model API
    def rowCount(self, parent=None) -> int:  # noqa: N802 - Qt API
        return 0 if parent is not None and parent.isValid() else len(self._rows)

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid() or not 0 <= index.row() < len(self._rows):
            return None
        row = index.row()
        e = self._rows[row]
        if role == Qt.ItemDataRole.DisplayRole:
            score = "" if e.score is None else f"  {e.score:.3f}"
            return f"#{row + 1}{score}"
        if role == Qt.ItemDataRole.DecorationRole:
            return self.thumbnail(e)
        if role == Qt.ItemDataRole.ToolTipRole:
            lines = [f"Candidate #{row + 1}"]
            if e.score is not None:
                lines.append(f"mean seam error {e.score:.4f}")
            lines += [f"{k}: {v:.4g}" for k, v in e.scores.items() if isinstance(v, float)]
            if e.patch_origin is not None:
                lines.append(f"patch from row {e.patch_origin[0]}, col {e.patch_origin[1]}")
            if e.seed is not None:
                lines.append(f"seed {e.seed}")
            if e.weight != 1.0:
                lines.append(f"preview weight {e.weight:g}")
            lines.append("locked" if e.locked else "")
            return "\n".join(s for s in lines if s)
        if role == PICK_ROLE:
            return self._pick_order.get(row, 0)
        if role == LOCKED_ROLE:
            return e.locked
        if role == SCORE_ROLE:
            return e.score
        if role == ENTRY_ROLE:
            return e
        if role == Qt.ItemDataRole.AccessibleTextRole:
            return f"candidate {row + 1}" + (" picked" if row in self._pick_order else "")
        return None

    def flags(self, index):
        if not index.isValid():
            return Qt.ItemFlag.NoItemFlags
        return (
            Qt.ItemFlag.ItemIsEnabled
            | Qt.ItemFlag.ItemIsSelectable
            | Qt.ItemFlag.ItemNeverHasChildren
        )

    def thumbnail(self, entry: CandidateTile) -> QPixmap:
        key = id(entry)
        pm = self._thumbs.get(key)
        if pm is None:
            dpr = QGuiApplication.instance().devicePixelRatio()  # crisp on high-DPI screens
            side = int(round(self.thumb * dpr))
            img = to_qimage(entry.tile).scaled(
                side,
                side,
                Qt.AspectRatioMode.KeepAspectRatio,
                Qt.TransformationMode.SmoothTransformation,
            )
            pm = QPixmap.fromImage(img)
            pm.setDevicePixelRatio(dpr)
            self._thumbs[key] = pm
        return pm

    # ------------------------------------------------------------------ document -> model
    @Slot(int)
    def _on_inserted(self, row: int) -> None:
        self.beginInsertRows(QModelIndex(), row, row)
        self._rows.insert(row, self.doc.tileset.candidates[row])
        self.endInsertRows()

    @Slot(int)
    def _on_changed(self, row: int) -> None:
        old = self._rows[row]
        self._thumbs.pop(id(old), None)
        self._rows[row] = self.doc.tileset.candidates[row]
        ix = self.index(row)
        self.dataChanged.emit(ix, ix)

    @Slot()
    def _on_reset(self) -> None:
        self.beginResetModel()
        self._rows = list(self.doc.tileset.candidates)
        alive = {id(e) for e in self._rows}
        self._thumbs = {k: v for k, v in self._thumbs.items() if k in alive}
        self._pick_order = {
            i: k + 1 for k, i in enumerate(self.doc.tileset.picks) if i < len(self._rows)
        }
        self.endResetModel()

    @Slot()
    def _on_picks_changed(self) -> None:
        old = set(self._pick_order)
        self._pick_order = {
            i: k + 1 for k, i in enumerate(self.doc.tileset.picks) if i < len(self._rows)
        }
        rows = old | set(self._pick_order)
        if rows and self._rows:
            lo, hi = min(rows), min(max(rows), len(self._rows) - 1)
            if lo <= hi:
                self.dataChanged.emit(self.index(lo), self.index(hi), [PICK_ROLE])


class CandidateDelegate(QStyledItemDelegate):
    """Thumbnail, caption, pick badge and lock mark."""

    def __init__(self, thumb: int, parent=None) -> None:
        super().__init__(parent)
        self.thumb = thumb

    def sizeHint(self, option, index) -> QSize:  # noqa: N802 - Qt API
        """The thumbnail's own shape (a 192×64 strip leaves no square of empty cell), wide
        enough for the caption."""
        pm = index.data(Qt.ItemDataRole.DecorationRole)
        if not isinstance(pm, QPixmap):
            return QSize(self.thumb + 12, self.thumb + 30)
        size = pm.deviceIndependentSize()
        w = max(int(round(size.width())), min(self.thumb, 72))
        return QSize(w + 12, int(round(size.height())) + 30)

    def paint(self, painter: QPainter, option, index) -> None:
        painter.save()
        r = option.rect.adjusted(3, 3, -3, -3)
        selected = bool(option.state & QStyle.StateFlag.State_Selected)
        pick = index.data(PICK_ROLE) or 0
        pal = option.palette
        painter.fillRect(r, pal.highlight() if selected else pal.base())
        pm = index.data(Qt.ItemDataRole.DecorationRole)
        if isinstance(pm, QPixmap):
            size = pm.deviceIndependentSize()
            x = r.x() + int(r.width() - size.width()) // 2
            painter.drawPixmap(x, r.y() + 3, pm)
        text_rect = QRect(r.x(), r.bottom() - 20, r.width(), 20)
        painter.setPen(pal.highlightedText().color() if selected else pal.text().color())
        painter.drawText(text_rect, Qt.AlignmentFlag.AlignCenter, index.data() or "")
        if pick:
            pen = QPen(PICK_COLOR, 3)
            painter.setPen(pen)
            painter.drawRect(r.adjusted(1, 1, -2, -2))
            badge = QRect(r.x() + 4, r.y() + 4, 22, 18)
            painter.fillRect(badge, PICK_COLOR)
            painter.setPen(QColor(0, 0, 0))
            f = QFont(painter.font())
            f.setBold(True)
            painter.setFont(f)
            painter.drawText(badge, Qt.AlignmentFlag.AlignCenter, str(pick))
        entry = index.data(ENTRY_ROLE)
        if entry is not None and entry.weight != 1.0:
            tag = QRect(r.right() - 44, r.bottom() - 44, 40, 18)
            painter.fillRect(tag, QColor(40, 40, 40, 200))
            painter.setPen(QColor(255, 255, 255))
            painter.drawText(tag, Qt.AlignmentFlag.AlignCenter, f"×{entry.weight:g}")
        if index.data(LOCKED_ROLE):
            lock = QRect(r.right() - 24, r.y() + 4, 20, 18)
            painter.fillRect(lock, QColor(40, 40, 40, 200))
            painter.setPen(QColor(255, 255, 255))
            painter.drawText(lock, Qt.AlignmentFlag.AlignCenter, "L")
        painter.restore()


class CandidateView(QListView):
    """The thumbnail grid; picks go to the document, the current row is the "focus" tile."""

    open_requested = Signal(int)
    reroll_requested = Signal(int)
    current_changed = Signal(int)  # row or -1

    def __init__(self, doc: Document, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.model_ = CandidateModel(doc, parent=self)
        self.setModel(self.model_)
        self.setItemDelegate(CandidateDelegate(self.model_.thumb, self))
        self.setViewMode(QListView.ViewMode.IconMode)
        self.setFlow(QListView.Flow.LeftToRight)
        self.setWrapping(True)
        self.setResizeMode(QListView.ResizeMode.Adjust)
        self.setMovement(QListView.Movement.Static)
        self.setUniformItemSizes(True)
        self.setSpacing(2)
        self.setSelectionMode(QListView.SelectionMode.SingleSelection)
        self.setContextMenuPolicy(Qt.ContextMenuPolicy.CustomContextMenu)
        self.customContextMenuRequested.connect(self._context_menu)
        self.selectionModel().currentChanged.connect(self._on_current)
        self._anchor: int | None = None
        self._click = None  # (row, undo step) of the last click's pick toggle
        self.setToolTip("")
        self.setWhatsThis(
            "Click: pick / unpick · Shift+click: pick a range · Space: pick the "
            "current tile · Ctrl+A: pick all · Enter or double-click: open large · "
            "L: lock · R: re-roll"
        )

    def current_row(self) -> int:
        ix = self.currentIndex()
        return ix.row() if ix.isValid() else -1

    @Slot(QModelIndex, QModelIndex)
    def _on_current(self, current, _previous) -> None:
        self.current_changed.emit(current.row() if current.isValid() else -1)

    def pick_range(self, a: int, b: int) -> None:
        lo, hi = sorted((a, b))
        self.doc.tileset.set_picks([*self.doc.tileset.picks, *range(lo, hi + 1)], text="Pick tiles")

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        index = self.indexAt(event.position().toPoint())
        super().mousePressEvent(event)
        if not index.isValid() or event.button() != Qt.MouseButton.LeftButton:
            return
        row = index.row()
        self._click = None
        if event.modifiers() & Qt.KeyboardModifier.ShiftModifier and self._anchor is not None:
            self.pick_range(self._anchor, row)
        else:
            self._click = (row, self.doc.tileset.toggle_pick(row))
        self._anchor = row

    def mouseDoubleClickEvent(self, event) -> None:  # noqa: N802 - Qt API
        """Open the candidate; the pick toggled by the double-click's first click is retracted."""
        index = self.indexAt(event.position().toPoint())
        if not index.isValid() or event.button() != Qt.MouseButton.LeftButton:
            super().mouseDoubleClickEvent(event)
            return
        row = index.row()
        click, self._click = self._click, None
        if click is not None and click[0] == row:
            self.doc.tileset.retract(click[1])
        self.setCurrentIndex(index)
        self.open_requested.emit(row)
        event.accept()

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt API
        row = self.current_row()
        key = event.key()
        if key == Qt.Key.Key_Space and row >= 0:
            if event.modifiers() & Qt.KeyboardModifier.ShiftModifier and self._anchor is not None:
                self.pick_range(self._anchor, row)
            else:
                self.doc.tileset.toggle_pick(row)
            self._anchor = row
        elif key == Qt.Key.Key_A and event.modifiers() & Qt.KeyboardModifier.ControlModifier:
            self.doc.tileset.set_picks(
                range(len(self.doc.tileset.candidates)), text="Pick all tiles"
            )
        elif key in (Qt.Key.Key_Return, Qt.Key.Key_Enter) and row >= 0:
            self.open_requested.emit(row)
        elif key == Qt.Key.Key_L and row >= 0:
            self.doc.tileset.set_locked(row, not self.doc.tileset.candidates[row].locked)
        elif key == Qt.Key.Key_R and row >= 0:
            self.reroll_requested.emit(row)
        else:
            super().keyPressEvent(event)
            return
        event.accept()

    def _set_weight(self, row: int, weight: float, *_checked) -> None:
        self.doc.tileset.set_weight(row, weight)

    def _menu(self, what: str, row: int, *_checked) -> None:
        if what == "pick":
            self.doc.tileset.toggle_pick(row)
        elif what == "lock":
            self.doc.tileset.set_locked(row, not self.doc.tileset.candidates[row].locked)
        elif what == "reroll":
            self.reroll_requested.emit(row)
        else:
            self.open_requested.emit(row)

    @Slot(object)
    def _context_menu(self, pos) -> None:
        index = self.indexAt(pos)
        if not index.isValid():
            return
        row = index.row()
        entry = self.doc.tileset.candidates[row]
        menu = QMenu(self)
        pick = QAction("Unpick" if row in self.doc.tileset.picks else "Pick", menu)
        pick.triggered.connect(partial(self._menu, "pick", row))
        lock = QAction("Unlock" if entry.locked else "Lock", menu)
        lock.triggered.connect(partial(self._menu, "lock", row))
        reroll = QAction("Re-roll", menu)
        reroll.setEnabled(not entry.locked)
        reroll.triggered.connect(partial(self._menu, "reroll", row))
        large = QAction("Open large", menu)
        large.triggered.connect(partial(self._menu, "open", row))
        for a in (pick, lock, reroll, large):
            menu.addAction(a)
        weights = menu.addMenu("Preview weight")
        weights.setToolTipsVisible(True)
        for w in PREVIEW_WEIGHTS:
            a = weights.addAction(f"{w:g}" if w else "0 (kept, not in the preview)")
            a.setCheckable(True)
            a.setChecked(abs(entry.weight - w) < 1e-9)
            a.triggered.connect(partial(self._set_weight, row, w))
        menu.popup(self.viewport().mapToGlobal(pos))
