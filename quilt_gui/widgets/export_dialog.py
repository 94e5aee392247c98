"""Export dialog: the bundle options of :func:`engine.project.export_project`, run in the
background. Non-modal; errors are shown in the dialog and as a message, never a popup."""

from __future__ import annotations

import os
from pathlib import Path

from PySide6.QtCore import Signal, Slot
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from engine.project import export_project
from quilt_gui import jobs, project_io, settings
from quilt_gui.document import Document, safe_name
from quilt_gui.files import default_folder
from quilt_gui.jobs import error_text


def _spin(lo: int, hi: int, value: int, tip: str, special: str | None = None) -> QSpinBox:
    s = QSpinBox()
    s.setRange(lo, hi)
    s.setValue(value)
    s.setToolTip(tip)
    if special:
        s.setSpecialValueText(special)
    return s


def folder_problem(folder: str, *, overwrite: bool) -> str | None:
    """Why the bundle cannot go into ``folder`` (in the dialog's words), or None.

    Checked before the export starts, so the user reads about the Overwrite box rather
    than the engine's keyword, and about a file in the way rather than "File exists".
    """
    path = Path(folder).expanduser()
    if path.exists() and not path.is_dir():
        return f"{path} is a file, not a folder: choose a folder to export into."
    if path.is_dir():
        if not overwrite and any(path.iterdir()):
            return (
                f"The folder {path} is not empty: tick “Overwrite an existing bundle” or "
                "choose another folder."
            )
        parent = path
    else:
        parent = path.parent
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            return f"{path} cannot be created: {parent} is a file, not a folder."
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"{parent} is not writable: choose another folder."
    return None


class ExportDialog(QDialog):
    """Folder, name, atlas layout, bit depth and formats of the export bundle."""

    message = Signal(str, str)  # level, text
    exported = Signal(object)  # the manifest

    def __init__(self, doc: Document, manager: jobs.JobManager, parent=None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export tile set")
        self.setModal(False)
        self.doc = doc
        self.jobs = manager
        self.manifest: dict | None = None
        self.wang = False  # exporting the Wang set (its tab) rather than the picked candidates
        self.folder = QLineEdit()
        self.folder.setToolTip(
            "The bundle is written into this folder (created; it must be "
            "empty unless Overwrite is on)"
        )
        browse = QPushButton("Browse…")
        browse.setAutoDefault(False)  # Enter exports, wherever the focus is
        browse.clicked.connect(self._browse)
        row = QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(self.folder, 1)
        row.addWidget(browse)
        folder_row = QWidget()
        folder_row.setLayout(row)
        self.name = QLineEdit()
        self.name.setToolTip("File-name prefix: {name}_{index:03}_{map}.png")
        self.columns = _spin(0, 256, 0, "Tiles per atlas row (0 = about square)", "auto")
        self.spacing = _spin(0, 64, 0, "Pixels between atlas tiles")
        self.margin = _spin(0, 64, 0, "Pixels around the atlas")
        self.extrude = _spin(
            0,
            16,
            0,
            "Repeat each tile's edge pixels this many times around "
            "it (stops bleeding between atlas tiles)",
        )
        self.bit_depth = QComboBox()
        self.bit_depth.addItems(["Same as the source", "8 bit", "16 bit"])
        self.bit_depth.setToolTip("Bits per channel of the written images")
        self.dither = QCheckBox("Dither when reducing 16 → 8 bit")
        self.dither.setChecked(True)
        self.bit_depth.currentIndexChanged.connect(self._update_dither)
        self.tile_format = QComboBox()
        self.tile_format.addItems(["png", "tif"])
        self.tile_format.setToolTip("Format of the per-tile and preview images (atlases are PNG)")
        self.normal = QComboBox()
        self.normal.addItems(["opengl", "directx"])
        self.normal.setToolTip("Normal-map convention recorded in the manifest")
        self.overwrite = QCheckBox("Overwrite an existing bundle in that folder")
        self.summary = QLabel()
        self.summary.setWordWrap(True)
        self.status = QLabel()
        self.status.setWordWrap(True)
        form = QFormLayout()
        form.addRow("Folder", folder_row)
        form.addRow("Name", self.name)
        form.addRow("Atlas columns", self.columns)
        form.addRow("Spacing", self.spacing)
        form.addRow("Margin", self.margin)
        form.addRow("Edge extrusion", self.extrude)
        form.addRow("Bit depth", self.bit_depth)
        form.addRow("", self.dither)
        form.addRow("Tile format", self.tile_format)
        form.addRow("Normal maps", self.normal)
        form.addRow("", self.overwrite)
        self.buttons = QDialogButtonBox()
        self.export_button = self.buttons.addButton(
            "Export", QDialogButtonBox.ButtonRole.AcceptRole
        )
        close = self.buttons.addButton(QDialogButtonBox.StandardButton.Close)
        close.setAutoDefault(False)  # Enter exports, also after Close was clicked once
        self.export_button.setDefault(True)
        self.buttons.accepted.connect(self.export)
        self.buttons.rejected.connect(self.close)
        lay = QVBoxLayout(self)
        lay.addWidget(self.summary)
        lay.addLayout(form)
        lay.addWidget(self.status)
        lay.addWidget(self.buttons)
        self.resize(560, 0)

    def refresh(self, *, wang: bool = False) -> None:
        """Defaults from the document and the last export folder; ``wang``: export the Wang
        set (with Tiled's Wang set and Godot's terrain set) instead of the picked candidates."""
        doc = self.doc
        self.wang = bool(wang)
        self.setWindowTitle("Export Wang tile set" if self.wang else "Export tile set")
        self.name.setText(doc.name)
        base = default_folder(doc, "last_export_dir")
        suffix = "_wang_export" if self.wang else "_export"
        self.folder.setText(str(Path(base) / f"{doc.name}{suffix}"))
        maps = list(doc.source.maps) if doc.source else []
        depth = doc.source.bit_depth if doc.source else 8
        if self.wang:
            w = doc.wang
            size = w.tile_list()[0].tile.shape[0] if w.tiles else 0
            self.summary.setText(
                f"<b>{len(w.tiles)}</b> Wang tiles ({w.colours} colours per edge direction), "
                f"{size}×{size} px; maps: {', '.join(maps)}; source {depth}-bit; Tiled Wang "
                "set and Godot terrain set included."
            )
        else:
            n = len(doc.tileset.picks) or len(doc.tileset.candidates)
            what = "picked" if doc.tileset.picks else "(none picked: all)"
            size = ""
            if doc.tileset.candidates:
                h, w_ = doc.tileset.candidates[0].tile.shape[:2]
                size = f", {w_}×{h} px"
            lay = (
                ""
                if doc.tileset.layout is None
                else f", preview layout {doc.tileset.layout.shape[0]}×{doc.tileset.layout.shape[1]}"
            )
            self.summary.setText(
                f"<b>{n}</b> tiles {what}{size}; maps: {', '.join(maps)}; source {depth}-bit{lay}."
            )
        self.normal.setEnabled("normal" in (doc.source.kinds.values() if doc.source else ()))
        self._update_dither()
        self.status.setText("")
        self.export_button.setDefault(True)

    def _update_dither(self, *_args) -> None:
        """Dithering applies only where 16-bit pixels are written as 8 bits."""
        sixteen = self.doc.source is not None and self.doc.source.bit_depth == 16
        self.dither.setEnabled(sixteen and self.bit_depth.currentIndex() == 1)

    def options(self) -> dict:
        """Keyword options of :func:`engine.project.export_project` from the widgets."""
        depth = {0: None, 1: 8, 2: 16}[self.bit_depth.currentIndex()]
        return dict(
            columns=self.columns.value() or None,
            spacing=self.spacing.value(),
            margin=self.margin.value(),
            extrude=self.extrude.value(),
            bit_depth=depth,
            dither=self.dither.isChecked() if self.dither.isEnabledTo(self) else None,
            tile_format=self.tile_format.currentText(),
            overwrite=self.overwrite.isChecked(),
            normal_convention=self.normal.currentText(),
        )

    @Slot()
    def _browse(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "Export into folder", self.folder.text())
        if path:
            self.folder.setText(path)

    @Slot()
    def export(self) -> jobs.Job | None:
        """Start the export in the background."""
        folder = self.folder.text().strip()
        problem = (
            folder_problem(folder, overwrite=self.overwrite.isChecked())
            if folder
            else "Choose a folder to export into."
        )
        if problem:
            self._fail(problem)
            return None
        try:
            project = project_io.to_project(self.doc)
            if self.wang:
                project.candidates, project.picks, project.layout = [], [], None
        except ValueError as exc:
            self._fail(str(exc))
            return None
        project.name = safe_name(self.name.text() or self.doc.name)
        self.export_button.setEnabled(False)
        self.status.setText("Exporting…")
        self._folder = folder
        return self.jobs.start(
            "export",
            export_project,
            project,
            folder,
            label="Exporting",
            pass_cancel=False,
            on_done=self._on_done,
            on_error=self._on_error,
            wang=self.wang,
            **self.options(),
        )

    def _on_done(self, manifest: dict) -> None:
        self.manifest = manifest
        self.export_button.setEnabled(True)
        settings.set("last_export_dir", str(Path(self._folder).parent))
        n = len(manifest.get("tiles", []))
        text = f"Exported {n} tiles to {self._folder}."
        self.status.setText(text)
        self.message.emit("info", text)
        self.exported.emit(manifest)

    def _on_error(self, exc) -> None:
        self.export_button.setEnabled(True)
        self._fail(f"Export failed: {error_text(exc)}")

    def _fail(self, text: str) -> None:
        self.status.setText(f"<span style='color:#ff7070'>{text}</span>")
        self.message.emit("error", text)
