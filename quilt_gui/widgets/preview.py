"""The preview: picked tiles assembled by the random index matrix, with its grid score and the
set's interior figures (issue 10: frame, ring tone, duplicates, lattice, template share) and their
warnings in words, measured in the background."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QLineF, Qt, Slot
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QCheckBox,
    QGraphicsLineItem,
    QHBoxLayout,
    QLabel,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from quilt_gui import jobs, params, settings
from quilt_gui.document import Document
from quilt_gui.widgets.canvas import ImageCanvas, cosmetic_pen

WARN_STYLE = "color: #e8a33d;"  # the warnings' colour (readable on the light and dark themes)


#: where the controls the advice names are (the Advanced view shows every parameter)
_WHERE = {
    "flatten": "Parameters ▸ Advanced ▸ Tile",
    "patch_overlap": "Parameters ▸ Advanced ▸ Candidates",
}


def _control(key: str) -> str:
    """A parameter's label as on screen, and where it is when the Basic view hides it."""
    where = f" ({_WHERE[key]})" if key in _WHERE else ""
    return f"“{params.BY_KEY[key].label}”{where}"


def editor_advice(flattened: bool) -> dict[str, str]:
    """What exceeding each of issue 10's limits means and what to try, in the editor's words
    (the controls it has: the engine's advice also names the command line's patch search and
    minimum distance); Flatten lighting is suggested only while it is off, else said to be on."""
    ring, size = _control("patch_overlap"), _control("tile_size")
    if flattened:
        tone = " although Flatten lighting is on"
        frame_try, ring_try = f"a narrower {ring}", "another tile position"
    else:
        tone, flatten = "", f"“{params.BY_KEY['flatten'].label}”: On ({_WHERE['flatten']})"
        frame_try = f"{flatten} or a narrower {ring}"
        ring_try = f"{flatten} or another tile position"
    return {
        "frame": f"the tiles show a frame (frame {{v:.2f}} > {{lim}}){tone}: try {frame_try}",
        "ring_tone": "the shared ring differs in tone from the patches (ring tone {v:.2f} > "
        f"{{lim}}){tone}: try {ring_try}",
        "duplicates": "{v} candidate(s) repeat the template or each other: use a larger source, "
        f"a smaller {size} or fewer candidates ({_control('n_candidates')})",
        "lattice": "a layout shows a lattice at the tile period ({v:+.1f} dB above the floor of "
        f"a shared border): structured textures may need a narrower {ring}, a larger {size} "
        "or a Wang set (the Wang tiles tab)",
    }


def editor_warnings(q: dict, flattened: bool) -> list[str]:
    """:func:`engine.metrics.quality_warnings` of the figures ``q`` in the editor's words."""
    from engine.metrics import quality_warnings

    return quality_warnings(q, editor_advice(flattened))


def set_quality(tiles, source, template, settings, *, cancel=None) -> dict:
    """:func:`engine.metrics.tileset_quality` of the picked tiles and its ``warnings`` in the
    editor's words (worker thread); ``settings`` are the resolved TilesetSettings (ring w_P,
    margin, and flatten: tiles of a flattened source are compared with it, and the warnings
    know it is on). ``{"error": text}`` when the source has nothing to measure (flat)."""
    from engine.metrics import tileset_quality
    from engine.tiles.pipeline import working_source

    source = working_source(source, settings)
    ring, margin = int(settings.patch_overlap), int(settings.margin)
    try:
        q = tileset_quality(tiles, source, template=template, ring=ring, margin=margin)
    except ValueError as exc:
        return {"error": str(exc)}
    q["warnings"] = editor_warnings(q, bool(settings.flatten))
    return q


def quality_text(q: dict) -> str:
    """One line of the set's figures (what the CLI summary prints)."""
    return (
        f"frame {q['frame']:.2f} · ring tone {q['ring_tone']:.2f} · duplicates "
        f"{q['duplicates']} · lattice {q['lattice']:+.1f} dB · template share "
        f"{q['template_share']:.0%}"
    )


class PreviewView(QWidget):
    """Canvas of ``doc.tileset.preview`` with an optional tile grid, the grid score and the
    picked set's interior figures with their warnings (:func:`set_quality`)."""

    def __init__(self, doc: Document, reroll_action=None, grid_action=None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.canvas = ImageCanvas()
        self.grid = settings.get("preview_grid")
        self._lines: list[QGraphicsLineItem] = []
        bar = QHBoxLayout()
        bar.setContentsMargins(4, 2, 4, 2)
        if reroll_action is not None:
            b = QToolButton()
            b.setDefaultAction(reroll_action)
            b.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
            bar.addWidget(b)
        self.grid_box = QCheckBox("Grid overlay")
        self.grid_box.setToolTip("Draw the tile borders over the preview (G)")
        self.grid_box.setChecked(self.grid)
        self.grid_box.toggled.connect(self.set_grid)
        bar.addWidget(self.grid_box)
        self.grid_action = grid_action  # the window's toggle (shortcut G), kept in step
        if grid_action is not None:
            grid_action.setChecked(self.grid)
            grid_action.toggled.connect(self.set_grid)
        self.info = QLabel()
        self.info.setWordWrap(True)  # long texts must not widen the window
        self.info.setToolTip(
            "Grid score: autocorrelation at one tile period minus the source's "
            "own (0 = no visible grid; one tile repeated scores about 1).\n"
            "Frame: edge-to-centre sharpness profile of the tiles vs. random crops of the "
            "photo (1 = no frame).\nRing tone: how much the shared ring differs in tone "
            "from the centres, vs. crops (1 = as anywhere in the photo).\nDuplicates: tiles "
            "equal to the template or to each other.\nLattice: power at the tile period in "
            "an 8×8 layout, dB above what any set sharing a border reaches.\nTemplate share: "
            "the part of each tile that is the template's."
        )
        bar.addWidget(self.info, 1)
        self.quality: dict | None = None  # the last figures measured (None: none yet)
        self.warnings = QLabel()
        self.warnings.setWordWrap(True)
        self.warnings.setStyleSheet(WARN_STYLE)
        self.warnings.setContentsMargins(6, 0, 6, 2)
        self.warnings.setVisible(False)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(self.warnings)
        lay.addWidget(self.canvas, 1)
        lay.addStretch(0)  # holds the bar at the top while the canvas is hidden (no preview)
        self._shape = None
        self._cells = ""
        doc.tileset.preview_changed.connect(self._on_preview_changed)
        self._on_preview_changed()

    @Slot(bool)
    def set_grid(self, on: bool) -> None:
        self.grid = bool(on)
        settings.set("preview_grid", self.grid)
        self.grid_box.setChecked(self.grid)
        if self.grid_action is not None:
            self.grid_action.setChecked(self.grid)
        self._draw_grid()

    @Slot()
    def _on_preview_changed(self) -> None:
        img = self.doc.tileset.preview
        fit = img is None or self._shape != (None if img is None else img.shape)
        self._shape = None if img is None else img.shape
        self.canvas.set_image(img, fit=fit)
        self.canvas.setVisible(img is not None)
        if img is None:
            self.info.setText("Pick tiles in the Candidates gallery to see them assembled here.")
        else:
            lay = self.doc.tileset.layout
            n = len(self.doc.tileset.picks)
            score = self.doc.tileset.grid_score
            s = "n/a" if score is None else f"{score:.3f}"
            rows, cols = lay.shape if lay is not None else (0, 0)
            self._cells = (
                f"grid score {s} · {rows}×{cols} cells from {n} picked tile{'s' if n != 1 else ''}"
            )
            self.info.setText(f"{self._cells} · measuring the set…")
        self._measure()
        self._draw_grid()

    def _measure(self) -> None:
        """Start measuring the picked tiles (superseding an earlier measurement)."""
        self.quality = None
        self.warnings.setVisible(False)
        doc = self.doc
        picks, st = doc.tileset.picked_entries(), doc.tileset.seamless
        if doc.tileset.preview is None or not picks or st is None or doc.source is None:
            return
        from engine.tiles.pipeline import resolve

        s = doc.tileset.working_settings()
        s = resolve(s, doc.source.shape, overlap=doc.tileset.overlap())
        jobs.start(
            "set_quality",
            set_quality,
            [np.asarray(c.tile) for c in picks],
            doc.source.main,
            np.asarray(st.tile),
            s,
            label="Measuring the tile set",
            on_done=self._on_quality,
        )

    def _on_quality(self, q: dict) -> None:
        self.quality = q
        if "error" in q:
            self.info.setText(self._cells)
            return
        self.info.setText(f"{self._cells}\n{quality_text(q)}")
        warn = q["warnings"]
        self.warnings.setText("\n".join(f"⚠ {w[0].upper()}{w[1:]}" for w in warn))
        self.warnings.setVisible(bool(warn))

    def _draw_grid(self) -> None:
        for item in self._lines:
            self.canvas.scene().removeItem(item)
        self._lines = []
        lay, picks = self.doc.tileset.layout, self.doc.tileset.picked_entries()
        if not self.grid or self.doc.tileset.preview is None or lay is None or not picks:
            return
        th, tw = picks[0].tile.shape[:2]
        self._lines = grid_items(self.canvas, *lay.shape, th, tw)


def grid_items(canvas, rows: int, cols: int, th: int, tw: int) -> list[QGraphicsLineItem]:
    """Dashed lines along the tile borders of a rows x cols layout of th x tw tiles, added to
    ``canvas``'s scene; returns them (to remove them later)."""
    pen = cosmetic_pen(QColor(255, 255, 255, 150), 1, Qt.PenStyle.DashLine)
    lines = [QLineF(c * tw, 0, c * tw, rows * th) for c in range(1, cols)]
    lines += [QLineF(0, r * th, cols * tw, r * th) for r in range(1, rows)]
    items = []
    for line in lines:
        item = QGraphicsLineItem(line)
        item.setPen(pen)
        item.setZValue(10)
        canvas.scene().addItem(item)
        items.append(item)
    return items
