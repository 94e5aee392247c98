"""Help ▸ Getting started and Help ▸ Keyboard and mouse: two non-modal dialogs.

The shortcut sheet reads its keyboard rows from the window's actions and the buttons with a key
on the tab shown (so it cannot drift from the menus, and says what a key does on that tab: Ctrl+G
on the Wang tab is its Generate button), and adds the mouse gestures, which no action describes.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtGui import QKeySequence
from PySide6.QtWidgets import (
    QAbstractButton,
    QDialog,
    QDialogButtonBox,
    QHeaderView,
    QLabel,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
)

#: (where, gesture, what it does)
MOUSE = (
    ("Any image", "Wheel", "Zoom about the cursor"),
    ("Any image", "Space+drag, middle-drag", "Pan"),
    ("Source", "Drag on the image", "Draw the tile rectangle"),
    ("Source", "Drag the yellow rectangle or a handle", "Move or resize the tile"),
    ("Source", "Arrow keys (Shift: 10 px)", "Nudge the tile rectangle"),
    ("Source", "Ctrl+click an overlap", "Add a waypoint the seam must pass"),
    ("Source", "Right-click a waypoint", "Remove it"),
    ("Source", "Shift+drag / Shift+right-drag", "Paint / erase pixels never to use"),
    ("Source", "Ctrl+Shift+click", "Never use this colour"),
    ("Source", "Alt+drag / Alt+right-drag", "Paint / erase the region to heal"),
    ("Source", "Drag the orange rectangle", "Move a candidate's patch (rebuilds it)"),
    ("Overlaps panel", "Click / right-click", "Add / remove a waypoint"),
    ("Candidates", "Click, Shift+click", "Pick a tile, pick a range"),
    ("Candidates", "Space, Ctrl+A", "Pick the current tile, pick all"),
    ("Candidates", "Enter, double-click", "Open the tile large"),
    ("Candidates", "L, R, right-click", "Lock, re-roll, preview weight"),
    ("Quilting", "Click a block of the output", "Inspect its overlap, error and cut"),
    ("Quilting", "Ctrl+click the sample", "Never use this colour"),
)

GETTING_STARTED = """
<h3>Photo to seamless tile</h3>
<ol>
<li><b>Open</b> a photo (File ▸ Open, or drop it on the window). The best tile is searched at
once and shown on the source with its seams; the seamless tile appears on the right.</li>
<li><b>Tile size</b> in the Parameters panel: 64 … 2048 px squares, or Any (the search picks
the size between a minimum and a maximum).</li>
<li><b>File ▸ Export seamless tile</b> (Ctrl+Shift+E) writes it, one file per material map.</li>
</ol>
<h3>Tile set</h3>
<ol>
<li><b>Generate</b> (Ctrl+G) makes candidate tiles that all connect to each other.</li>
<li><b>Pick</b> tiles in the Candidates gallery (click; Shift+click picks a range); the
Preview tab assembles them at random.</li>
<li><b>Export</b> (Ctrl+E): tiles, atlases, Tiled and Godot files.</li>
</ol>
<h3>Also</h3>
<ul>
<li><b>Heal</b>: paint a region with Alt+drag, then Tile set ▸ Heal painted region (fills it
from the rest of the photo).</li>
<li><b>Quilting</b> tab: a larger texture from the source; File ▸ Save output.</li>
<li>Parameters: <b>Basic</b> shows what most photos need, <b>Advanced</b> everything.</li>
</ul>
"""


def _plain(text: str) -> str:
    return text.replace("&", "").replace("…", "").strip()


def shortcut_rows(actions, buttons=()) -> list[tuple[str, str]]:
    """(what, keys) of every action with a shortcut, in menu words, and of every button shown
    with one (its name and tooltip, without the key the tooltip names)."""
    rows = []
    for a in actions:
        keys = a.shortcut().toString(QKeySequence.SequenceFormat.NativeText)
        if keys and a.text():
            rows.append((_plain(a.text()), keys))
    for b in buttons:
        keys = b.shortcut().toString(QKeySequence.SequenceFormat.NativeText)
        if keys and b.text():
            tip = b.toolTip().replace(f" ({keys})", "")
            tip = f": {tip[:1].lower()}{tip[1:]}" if tip else ""
            rows.append((_plain(b.text()) + tip, keys))
    return sorted(set(rows), key=lambda r: r[0].lower())


class ShortcutSheet(QDialog):
    """Every keyboard shortcut of the window (as on the tab shown: the sheet follows the
    window's tabs) and every mouse gesture, in one table."""

    def __init__(self, actions, parent=None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Keyboard and mouse")
        self.setModal(False)
        self._actions = list(actions)
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["Where", "Keys / mouse", "Does"])
        self.table.verticalHeader().hide()
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
        self.refresh()
        tabs = getattr(parent, "tabs", None)
        if tabs is not None:  # after the window's own handler, which moves the keys
            tabs.currentChanged.connect(self.refresh)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.Stretch)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.close)
        lay = QVBoxLayout(self)
        lay.addWidget(self.table)
        lay.addWidget(buttons)
        self.resize(640, 560)

    def refresh(self, _index=None) -> None:
        """The rows of the keys as they act now (a button's key only on its tab, when shown)."""
        window = self.parentWidget()
        buttons = []
        if window is not None:
            buttons = [
                b
                for b in window.findChildren(QAbstractButton)
                if b.window() is window and b.isVisibleTo(window)
            ]
        keys = shortcut_rows(self._actions, buttons)
        rows = [("Keyboard", k, what) for what, k in keys] + list(MOUSE)
        self.table.setRowCount(len(rows))
        for r, row in enumerate(rows):
            for c, text in enumerate(row):
                self.table.setItem(r, c, QTableWidgetItem(text))

    def showEvent(self, event) -> None:  # noqa: N802 - Qt API
        self.refresh()
        super().showEvent(event)

    def rows(self) -> list[tuple[str, ...]]:
        t = self.table
        return [tuple(t.item(r, c).text() for c in range(3)) for r in range(t.rowCount())]


class GettingStarted(QDialog):
    """The shortest paths through the editor, in a few lines."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Getting started")
        self.setModal(False)
        self.text = QLabel(GETTING_STARTED)
        self.text.setWordWrap(True)
        self.text.setTextFormat(Qt.TextFormat.RichText)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.close)
        lay = QVBoxLayout(self)
        lay.addWidget(self.text)
        lay.addWidget(buttons)
        self.resize(520, 0)
