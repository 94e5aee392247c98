"""The library browser: a folder made by ``quilt-studio batch`` as a list to curate from.

One row per photo with the contact sheet's columns (:data:`engine.batch.library.COLUMNS`), in
its order (failed photos first, then the most warnings); click a header to sort otherwise.
Double-click (or Enter, or *Open*) opens the photo's project in the editor; *Next* opens the
row after the current one, so a person curates one photo after another. Rows already opened
are shown in italics. The library is read in a background job; thumbnails are read when
their row is first drawn.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import (
    QAbstractTableModel,
    QModelIndex,
    QSize,
    QSortFilterProxyModel,
    Qt,
    QUrl,
    Signal,
    Slot,
)
from PySide6.QtGui import QBrush, QColor, QDesktopServices, QFont, QPixmap
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableView,
    QVBoxLayout,
    QWidget,
)

from engine.batch.index import INDEX_HTML
from engine.batch.library import COLUMNS, Entry, read_library
from engine.batch.quality import past_limit
from quilt_gui import jobs

SORT_ROLE = Qt.ItemDataRole.UserRole + 1
ENTRY_ROLE = Qt.ItemDataRole.UserRole + 2
THUMB = 64
NOTES_WIDTH = 300
WARN_COLOR = QColor(200, 110, 0)
FAIL_COLOR = QColor(200, 40, 40)

#: (key, header) of the table's columns: the photo, its warnings or error, the index columns
HEADERS = (("photo", "Photo"), ("notes", "Warnings / error"), *((k, h) for k, h, _ in COLUMNS))


class LibraryModel(QAbstractTableModel):
    """The entries of one library, in the engine's order."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.entries: list[Entry] = []
        self.opened: set[str] = set()
        self._thumbs: dict[str, QPixmap] = {}

    def set_entries(self, entries) -> None:
        self.beginResetModel()
        self.entries = list(entries)
        self._thumbs.clear()
        self.endResetModel()

    def mark_opened(self, row: int) -> None:
        self.opened.add(self.entries[row].key)
        self.dataChanged.emit(self.index(row, 0), self.index(row, len(HEADERS) - 1))

    # ------------------------------------------------------------------ Qt model API
    def rowCount(self, parent=QModelIndex()) -> int:  # noqa: N802, B008 - Qt API
        return 0 if parent.isValid() else len(self.entries)

    def columnCount(self, parent=QModelIndex()) -> int:  # noqa: N802, B008 - Qt API
        return 0 if parent.isValid() else len(HEADERS)

    def headerData(self, section, orientation, role=Qt.ItemDataRole.DisplayRole):  # noqa: N802
        if orientation == Qt.Orientation.Horizontal and role == Qt.ItemDataRole.DisplayRole:
            return HEADERS[section][1]
        return None

    def data(self, index, role=Qt.ItemDataRole.DisplayRole):
        if not index.isValid():
            return None
        e = self.entries[index.row()]
        key = HEADERS[index.column()][0]
        if role == Qt.ItemDataRole.DisplayRole:
            if key == "photo":
                return e.name
            if key == "notes":
                return e.error or "; ".join(e.warnings)
            return e.text(key)
        if role == SORT_ROLE:
            if key == "photo":
                return e.name.lower()
            if key == "notes":
                return len(e.warnings)
            v = e.values.get(key)
            return "" if v is None else v
        if role == ENTRY_ROLE:
            return e
        if role == Qt.ItemDataRole.DecorationRole and key == "photo":
            return self._thumbnail(e)
        if role == Qt.ItemDataRole.ToolTipRole:
            lines = [e.source or e.name, f"folder {e.key}"]
            if e.error:
                lines.append(f"failed: {e.error}")
            lines += [f"warning: {w}" for w in e.warnings]
            return "\n".join(lines)
        if role == Qt.ItemDataRole.ForegroundRole:
            if e.failed:
                return QBrush(FAIL_COLOR)
            if (key == "notes" and e.warnings) or past_limit(key, e.values.get(key)):
                return QBrush(WARN_COLOR)  # as the contact sheet marks the figures past limit
        if role == Qt.ItemDataRole.FontRole and e.key in self.opened:
            f = QFont()
            f.setItalic(True)
            return f
        if role == Qt.ItemDataRole.TextAlignmentRole and key not in ("photo", "notes", "status"):
            return int(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        return None

    def _thumbnail(self, e: Entry) -> QPixmap | None:
        if e.key not in self._thumbs:
            path = e.file("thumbnail")
            pm = QPixmap(str(path)) if path is not None else QPixmap()
            if not pm.isNull():
                pm = pm.scaled(
                    THUMB,
                    THUMB,
                    Qt.AspectRatioMode.KeepAspectRatio,
                    Qt.TransformationMode.SmoothTransformation,
                )
            self._thumbs[e.key] = pm
        pm = self._thumbs[e.key]
        return None if pm.isNull() else pm


class LibraryView(QWidget):
    """The library dock's content: a summary line, the table, Open / Next / index buttons."""

    #: a project file to open in the editor
    open_project = Signal(str)
    #: (level, text): a message for the window's banner
    message = Signal(str, str)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.folder: Path | None = None
        self.model = LibraryModel(self)
        self.proxy = QSortFilterProxyModel(self)
        self.proxy.setSourceModel(self.model)
        self.proxy.setSortRole(SORT_ROLE)
        self.table = QTableView()
        self.table.setModel(self.proxy)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSortingEnabled(True)
        self.table.horizontalHeader().setSortIndicatorShown(False)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().setDefaultSectionSize(THUMB + 6)
        self.table.setIconSize(QSize(THUMB, THUMB))
        self.table.setWordWrap(False)
        self.table.activated.connect(self._on_activated)
        self.summary = QLabel("No library open: File ▸ Open library…")
        self.summary.setWordWrap(True)
        self.open_button = _button(
            "&Open", "Open the selected photo's project (double-click, Enter)", self.open_current
        )
        self.next_button = _button(
            "&Next", "Open the project of the next photo in the list", self.open_next
        )
        self.reload_button = _button("Reload", "Read the library folder again", self.reload)
        self.index_button = _button(
            "Contact sheet", "Open index.html in the web browser", self.open_index
        )
        buttons = QHBoxLayout()
        for b in (self.open_button, self.next_button, self.reload_button, self.index_button):
            buttons.addWidget(b)
        buttons.addStretch(1)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        lay.addWidget(self.summary)
        lay.addWidget(self.table, 1)
        lay.addLayout(buttons)
        self._update_buttons()

    # ------------------------------------------------------------------ loading
    def load(self, folder) -> jobs.Job:
        """Read the library in ``folder`` in the background."""
        self.folder = Path(folder)
        self.summary.setText(f"Reading {self.folder} …")
        return jobs.start(
            "library",
            read_library,
            str(self.folder),
            label=f"Reading the library {self.folder.name}",
            pass_cancel=False,
            on_done=self._on_loaded,
            on_error=self._on_error,
        )

    def reload(self) -> None:
        if self.folder is not None:
            self.load(self.folder)

    def _on_loaded(self, entries) -> None:
        self.proxy.sort(-1)  # back to the engine's order
        self.model.set_entries(entries)
        failed = sum(e.failed for e in entries)
        warned = sum(bool(e.warnings) and not e.failed for e in entries)
        if not entries:
            self.summary.setText(
                f"{self.folder}: no photo folders (make them with quilt-studio batch)"
            )
        else:
            self.summary.setText(
                f"{self.folder}: {len(entries)} photos, {failed} failed, {warned} with "
                "warnings. Double-click a photo to open its project; Next opens the following."
            )
        self.table.resizeColumnsToContents()
        notes = [k for k, _ in HEADERS].index("notes")  # long: elided, whole in the tooltip
        self.table.setColumnWidth(notes, min(self.table.columnWidth(notes), NOTES_WIDTH))
        if entries:
            self.table.selectRow(0)
        self._update_buttons()

    def _on_error(self, exc) -> None:
        self.summary.setText(f"{self.folder}: cannot be read")
        self.message.emit("error", f"Could not read the library {self.folder}: {exc}")

    # ------------------------------------------------------------------ opening
    def current_row(self) -> int:
        """The selected row in the view's order (-1: none)."""
        return self.table.currentIndex().row() if self.table.currentIndex().isValid() else -1

    def entry_at(self, view_row: int) -> Entry:
        return self.proxy.index(view_row, 0).data(ENTRY_ROLE)

    def open_row(self, view_row: int) -> bool:
        """Open the project of the photo in ``view_row``; False when it has none."""
        if not 0 <= view_row < self.proxy.rowCount():
            return False
        self.table.selectRow(view_row)
        e = self.entry_at(view_row)
        project = e.file("project")
        if e.failed or project is None:
            self.message.emit(
                "warning", f"{e.name} has no tile set to open: {e.error or 'no project file'}"
            )
            return False
        self.model.mark_opened(self.proxy.mapToSource(self.proxy.index(view_row, 0)).row())
        self.open_project.emit(str(project))
        return True

    @Slot()
    def open_current(self) -> bool:
        return self.open_row(max(0, self.current_row()))

    @Slot()
    def open_next(self) -> bool:
        """Open the next row after the current one that has a project."""
        for row in range(self.current_row() + 1, self.proxy.rowCount()):
            if self.entry_at(row).file("project") is not None and not self.entry_at(row).failed:
                return self.open_row(row)
        self.message.emit("info", "That was the last photo of the library.")
        return False

    @Slot()
    def open_index(self) -> None:
        if self.folder is not None:
            QDesktopServices.openUrl(QUrl.fromLocalFile(str(self.folder / INDEX_HTML)))

    def _on_activated(self, index) -> None:
        self.open_row(index.row())

    def _update_buttons(self) -> None:
        has = self.model.rowCount() > 0
        for b in (self.open_button, self.next_button):
            b.setEnabled(has)
        self.reload_button.setEnabled(self.folder is not None)
        self.index_button.setEnabled(
            self.folder is not None and (self.folder / INDEX_HTML).is_file()
        )


def _button(text: str, tip: str, slot) -> QPushButton:
    b = QPushButton(text)
    b.setToolTip(tip)
    b.clicked.connect(slot)
    return b
