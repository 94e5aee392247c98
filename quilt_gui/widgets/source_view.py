"""The source image with the template step drawn on it.

Overlays (all on pixel edges): the tile rectangle with handles (drag, resize, arrow-key
nudge), the four overlap regions R_L/R_R/R_T/R_B shaded, each overlap's error map as a
heat overlay, the seams (live while they are searched), waypoints, the patch source
rectangle of the current candidate (drag it to regenerate that candidate), and the excluded
pixels no tile or patch may use (:mod:`quilt_gui.widgets.exclusion`: Shift+drag paints,
Shift+right-drag erases, Ctrl+Shift+click excludes a colour).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QRectF, Qt, Signal, Slot
from PySide6.QtGui import QBrush, QColor, QPen
from PySide6.QtWidgets import QGraphicsEllipseItem, QGraphicsItem

from quilt_gui import params
from quilt_gui.commands import new_merge_id
from quilt_gui.document import Document
from quilt_gui.pipeline import Pipeline
from quilt_gui.widgets.canvas import (
    HeatItem,
    ImageCanvas,
    PixelSetItem,
    ShadeItem,
)
from quilt_gui.widgets.exclusion import ExclusionPainter
from quilt_gui.widgets.rect_item import EditableRect
from quilt_gui.widgets.template_sweep import SweepItem

REGION_COLORS = {"R_L": "#3fc1ff", "R_R": "#3fc1ff", "R_T": "#ff5fd2", "R_B": "#ff5fd2"}
# both stand out on the heat map (black, purple, red, orange, pale yellow)
SEAM_COLORS = {"horizontal": "#7dff5f", "vertical": "#4de8ff"}
WAYPOINT_COLOR = "#ffffff"
MIN_DRAWN = 8  # a drag shorter than this (px of the image) draws nothing


def region_rects(rect, overlap: int) -> dict[str, tuple[int, int, int, int]]:
    """R_L, R_R, R_T, R_B in source pixels for tile ``rect`` (see engine.tiles.template)."""
    x, y, w, h = rect
    return {
        "R_L": (x, y, overlap, h + overlap),
        "R_R": (x + w, y, overlap, h + overlap),
        "R_T": (x, y, w, overlap),
        "R_B": (x, y + h, w, overlap),
    }


class WaypointItem(QGraphicsEllipseItem):
    """A ring of constant screen size (12 px) centred on a waypoint pixel, white on black so
    it shows at any zoom and on any colour."""

    RADIUS = 6.0

    def __init__(self, row: int, col: int) -> None:
        r = self.RADIUS
        super().__init__(QRectF(-r, -r, 2 * r, 2 * r))
        self.setFlag(QGraphicsItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
        self.setPos(col + 0.5, row + 0.5)
        self.setPen(QPen(QColor(WAYPOINT_COLOR), 2))
        self.setBrush(Qt.BrushStyle.NoBrush)
        self.setZValue(35)
        halo = QGraphicsEllipseItem(QRectF(-r - 1.5, -r - 1.5, 2 * r + 3, 2 * r + 3), self)
        halo.setPen(QPen(QColor(0, 0, 0, 200), 1.5))
        halo.setFlag(QGraphicsItem.GraphicsItemFlag.ItemStacksBehindParent, True)
        dot = QGraphicsEllipseItem(QRectF(-1.5, -1.5, 3, 3), self)
        dot.setPen(Qt.PenStyle.NoPen)
        dot.setBrush(QBrush(QColor(WAYPOINT_COLOR)))


class SourceView(ImageCanvas):
    """The source canvas of the tile-set workflow."""

    patch_moved = Signal(int, object)  # candidate index, new patch origin (row, col)

    def __init__(self, doc: Document, pipeline: Pipeline, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.pipeline = pipeline
        self.rect_item = EditableRect("#ffd23f")
        self.rect_item.hide()
        self.add_item(self.rect_item)
        self.shades = {k: ShadeItem(c) for k, c in REGION_COLORS.items()}
        self.heat = {"horizontal": HeatItem(), "vertical": HeatItem()}
        self.seams = {k: PixelSetItem(c) for k, c in SEAM_COLORS.items()}
        for item in (*self.shades.values(), *self.heat.values(), *self.seams.values()):
            item.hide()
            self.add_item(item)
        self.patch_item = EditableRect("#ff8c3f", resizable=False)
        self.patch_item.hide()
        self.add_item(self.patch_item)
        self.patch_index: int | None = None
        self.sweep = SweepItem()  # the template search's sweep while it runs
        self.add_item(self.sweep)
        self.painter = ExclusionPainter(doc, self)  # excluded pixels: Shift+drag, Ctrl+Shift+click
        self._waypoint_items: list[WaypointItem] = []
        self.heat_visible = True
        self._nudge_merge: int | None = None
        self._drawing: tuple | None = None  # (first pixel, merge id) while a drag draws
        self.setDragMode(self.DragMode.NoDrag)  # a plain drag draws; Space/middle-drag pans
        self.rect_item.edited.connect(self._on_rect_edited)
        self.patch_item.drag_finished.connect(self._on_patch_dropped)
        self.zoom_changed.connect(self._on_zoom)
        doc.source_changed.connect(self._on_source_changed)
        doc.pixels_changed.connect(self._on_pixels_changed)
        doc.tileset.template_changed.connect(self._on_template_changed)
        doc.params_changed.connect(self._on_params_changed)
        doc.tileset.seamless_changed.connect(self._on_seamless_changed)
        doc.tileset.waypoints_changed.connect(self._on_waypoints_changed)
        doc.tileset.candidate_changed.connect(self._on_candidate_changed)
        doc.tileset.candidates_reset.connect(self._on_candidates_reset)
        pipeline.seam_updated.connect(self._on_seam_updated)
        pipeline.candidate_failed.connect(self._on_candidate_changed)  # the patch snaps back
        pipeline.template_searching.connect(self._on_searching)
        pipeline.template_swept.connect(self.sweep.add_event)

    # ------------------------------------------------------------------ document -> view
    @Slot()
    def _on_source_changed(self) -> None:
        src = self.doc.source
        self.set_image(None if src is None else src.main, fit=True)
        if src is not None:
            self.rect_item.bounds = src.shape
            self.patch_item.bounds = src.shape
        self.show_patch(None)
        self._on_template_changed()

    @Slot()
    def _on_pixels_changed(self) -> None:
        """New pixels (healed), same size: redraw, keep the zoom and the overlays."""
        self.set_image(self.doc.source.main)

    @Slot(bool)
    def _on_searching(self, searching: bool) -> None:
        """The rectangle animates while the search runs, its sweep drawn faintly; it is not
        draggable meanwhile."""
        self.rect_item.setEnabled(not searching)
        (self.sweep.start if searching else self.sweep.stop)()

    @Slot(object)
    def _on_zoom(self, zoom: float) -> None:
        self.rect_item.set_view_scale(zoom)
        self.patch_item.set_view_scale(zoom)

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        if "overlap" in keys:
            self._on_template_changed()

    @Slot()
    def _on_template_changed(self) -> None:
        rect = self.doc.tileset.template_rect
        overlap = self.doc.tileset.overlap()
        if rect is None:
            for item in (self.rect_item, *self.shades.values()):
                item.hide()
            self._hide_results()
            return
        self.rect_item.extra = overlap
        self.rect_item.set_rect(rect)
        self.rect_item.show()
        for k, r in region_rects(rect, overlap).items():
            self.shades[k].set_rect(*r)
            self.shades[k].show()
        self._on_seamless_changed()

    def _hide_results(self) -> None:
        for item in (*self.heat.values(), *self.seams.values()):
            item.hide()

    def seamless_is_current(self) -> bool:
        s = self.doc.tileset.seamless
        return (
            s is not None
            and tuple(s.rect) == self.doc.tileset.template_rect
            and s.overlap == self.doc.tileset.overlap()
        )

    @Slot()
    def _on_seamless_changed(self) -> None:
        s = self.doc.tileset.seamless
        if not self.seamless_is_current():
            self._hide_results()
            self._on_waypoints_changed()
            return
        x, y, _, _ = s.rect
        for which in ("horizontal", "vertical"):
            self.heat[which].set_error(np.asarray(s.errors[which]), (x, y))
            self.heat[which].setVisible(self.heat_visible)
            self.seams[which].set_points(s.paths_source[which])
            self.seams[which].show()
        self._on_waypoints_changed()

    @Slot(object)
    def _on_seam_updated(self, update) -> None:
        """A live seam improvement of the running seamless job (current inputs only)."""
        item = self.seams.get(update.which)
        if item is None:
            return
        item.set_points(update.path_source)
        item.show()

    @Slot()
    def _on_waypoints_changed(self) -> None:
        for it in self._waypoint_items:
            self.scene().removeItem(it)
        self._waypoint_items = []
        rect = self.doc.tileset.template_rect
        if rect is None:
            return
        x, y = rect[0], rect[1]
        for pts in self.doc.tileset.waypoints_in_use().values():
            for r, c in pts:
                it = WaypointItem(y + r, x + c)
                self.scene().addItem(it)
                self._waypoint_items.append(it)

    def set_heat_visible(self, on: bool) -> None:
        self.heat_visible = bool(on)
        current = self.seamless_is_current()
        for item in self.heat.values():
            item.setVisible(self.heat_visible and current)

    # ------------------------------------------------------------------ patch source
    def show_patch(self, index: int | None) -> None:
        """Show the patch source rectangle of candidate ``index`` (None hides it)."""
        entry = None
        if index is not None and 0 <= index < len(self.doc.tileset.candidates):
            entry = self.doc.tileset.candidates[index]
        if entry is None or entry.patch_rect is None:
            self.patch_index = None
            self.patch_item.hide()
            return
        self.patch_index = index
        self.patch_item.set_rect(entry.patch_rect)
        self.patch_item.show()

    @Slot(int)
    def _on_candidate_changed(self, index: int) -> None:
        if index == self.patch_index:
            self.show_patch(index)

    @Slot()
    def _on_candidates_reset(self) -> None:
        self.show_patch(self.patch_index)

    @Slot()
    def _on_patch_dropped(self) -> None:
        if self.patch_index is None:
            return
        x, y, _, _ = self.patch_item.rect
        self.patch_moved.emit(self.patch_index, (y, x))

    # ------------------------------------------------------------------ user edits
    @Slot(object, int)
    def _on_rect_edited(self, rect, merge_id: int) -> None:
        self.doc.tileset.set_template_rect(rect, merge_id=merge_id)

    def nudge(self, dx: int, dy: int, *, merge_id: int | None = None) -> None:
        rect = self.doc.tileset.template_rect
        if rect is None:
            return
        x, y, w, h = rect
        self.doc.tileset.set_template_rect(
            (x + dx, y + dy, w, h), merge_id=merge_id, text="Nudge tile rectangle"
        )

    def keyPressEvent(self, event) -> None:  # noqa: N802 - Qt API
        steps = {
            Qt.Key.Key_Left: (-1, 0),
            Qt.Key.Key_Right: (1, 0),
            Qt.Key.Key_Up: (0, -1),
            Qt.Key.Key_Down: (0, 1),
        }
        if event.key() in steps and self.doc.tileset.template_rect is not None:
            dx, dy = steps[event.key()]
            n = 10 if event.modifiers() & Qt.KeyboardModifier.ShiftModifier else 1
            if not event.isAutoRepeat() or self._nudge_merge is None:
                self._nudge_merge = new_merge_id()  # a held key is one undo step
            self.nudge(dx * n, dy * n, merge_id=self._nudge_merge)
            event.accept()
            return
        super().keyPressEvent(event)

    def waypoint_target(self, row: int, col: int) -> tuple[str, tuple[int, int]] | None:
        """Which overlap a source pixel lies in, and its (row, col) in that overlap's frame."""
        rect = self.doc.tileset.template_rect
        if rect is None:
            return None
        overlap = self.doc.tileset.overlap()
        regions = region_rects(rect, overlap)
        x, y = rect[0], rect[1]
        for which, key in (("horizontal", "R_L"), ("vertical", "R_T")):
            rx, ry, rw, rh = regions[key]
            if rx <= col < rx + rw and ry <= row < ry + rh:
                return which, (row - y, col - x)
        return None

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        """Ctrl+click in an overlap adds a waypoint; right-click on one removes it."""
        px = self.pixel_at(event.position())
        ctrl = event.modifiers() & Qt.KeyboardModifier.ControlModifier
        if px is not None and (ctrl or event.button() == Qt.MouseButton.RightButton):
            target = self.waypoint_target(*px)
            if target is not None:
                which, pt = target
                if event.button() == Qt.MouseButton.RightButton:
                    near = nearest_waypoint(self.doc.tileset.waypoints[which], pt)
                    if near is not None:
                        self.doc.tileset.remove_waypoint(which, near)
                else:
                    self.doc.tileset.add_waypoint(which, pt)
                event.accept()
                return
        if self._starts_drawing(event, px):
            self._drawing = (px, new_merge_id())
            event.accept()
            return
        super().mousePressEvent(event)

    def _starts_drawing(self, event, px) -> bool:
        """A plain left press on the image, not on a rectangle: draw the tile rectangle."""
        if (
            px is None
            or event.button() != Qt.MouseButton.LeftButton
            or event.modifiers() != Qt.KeyboardModifier.NoModifier
            or self.space_down
        ):
            return False
        item = self.itemAt(event.position().toPoint())
        while item is not None and not isinstance(item, EditableRect):
            item = item.parentItem()
        return item is None or not (item.isVisible() and item.isEnabled())

    def mouseMoveEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drawing is None:
            super().mouseMoveEvent(event)
            return
        (r0, c0), merge_id = self._drawing
        p = self.mapToScene(event.position().toPoint())
        H, W = self.doc.source.shape
        r1 = min(max(int(np.floor(p.y())), 0), H - 1)
        c1 = min(max(int(np.floor(p.x())), 0), W - 1)
        w, h = abs(c1 - c0) + 1, abs(r1 - r0) + 1
        if self.doc.params["tile_size"] != params.ANY:  # square tiles unless Any size
            w = h = max(w, h)
        x = c0 if c1 >= c0 else c0 - w + 1
        y = r0 if r1 >= r0 else r0 - h + 1
        if max(w, h) >= MIN_DRAWN:
            text = "Draw tile rectangle"
            self.doc.tileset.set_template_rect((x, y, w, h), merge_id=merge_id, text=text)
        self.hovered.emit((r1, c1))
        event.accept()

    def mouseReleaseEvent(self, event) -> None:  # noqa: N802 - Qt API
        if self._drawing is not None and event.button() == Qt.MouseButton.LeftButton:
            self._drawing = None
            event.accept()
            return
        super().mouseReleaseEvent(event)


def nearest_waypoint(points, pt, radius: float = 3.0):
    """The waypoint within ``radius`` pixels of ``pt`` (row, col), or None."""
    best, dist = None, radius
    for p in points:
        d = float(np.hypot(p[0] - pt[0], p[1] - pt[1]))
        if d <= dist:
            best, dist = p, d
    return best
