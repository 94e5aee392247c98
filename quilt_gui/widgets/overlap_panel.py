"""Side panel: each overlap's two regions and its error map, with the seam and waypoints.

Click on any of the three panels to add a waypoint the seam must pass through;
right-click near a waypoint to remove it. The same view shows a quilting block's
overlap in quilting mode (:meth:`OverlapView.show_overlap`).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from quilt_gui.document import Document
from quilt_gui.imaging import heat_rgba, pixel_text, to_uint8
from quilt_gui.pipeline import Pipeline
from quilt_gui.widgets.canvas import ImageCanvas, PixelSetItem
from quilt_gui.widgets.source_view import (
    SEAM_COLORS,
    WaypointItem,
    nearest_waypoint,
)
from quilt_gui.widgets.watch_search import WatchSearch

GAP = 3  # pixels between the three panels
#: The two regions of each overlap, in panel order (R1 kept on the outside, then R2).
LIVE_REGIONS = {"horizontal": ("R_R", "R_L"), "vertical": ("R_B", "R_T")}


def _rgba(a: np.ndarray) -> np.ndarray:
    u = to_uint8(a)
    if u.shape[2] == 1:
        u = np.repeat(u, 3, axis=2)
    if u.shape[2] == 3:
        u = np.concatenate([u, np.full(u.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return u


class OverlapView(ImageCanvas):
    """R1, R2 and the error map of one overlap side by side (or stacked), seam on each."""

    waypoint_added = Signal(object)  # (row, col) in the overlap frame
    waypoint_removed = Signal(object)

    def __init__(self, color="#7dff5f", parent=None, *, names=("R_R", "R_L", "error")) -> None:
        super().__init__(parent)
        self.names = names  # of the three panels, for the status bar
        self.panels: list[np.ndarray] = []  # r1, r2 and the error map as given
        self.setDragMode(ImageCanvas.DragMode.NoDrag)
        self.hide_scrollbars()
        self.frame_shape: tuple[int, int] | None = None
        self.offsets: list[tuple[int, int]] = []  # (x, y) of each panel
        self.paths = [PixelSetItem(color) for _ in range(3)]
        for p in self.paths:
            self.add_item(p)
        self.waypoints: list[tuple[int, int]] = []
        self._wp_items: list[WaypointItem] = []
        self.setToolTip(
            "Click: add a waypoint the seam must pass through\n"
            "Right-click: remove the nearest waypoint"
        )

    def show_overlap(self, r1, r2, error, *, stacked: bool) -> None:
        """Show the regions and the error map; ``stacked`` puts them one above the other."""
        error = np.asarray(error)
        h, w = error.shape
        self.panels = [np.asarray(r1), np.asarray(r2), error]
        panels = [_rgba(r1), _rgba(r2), heat_rgba(error)]
        if stacked:
            canvas = np.zeros((3 * h + 2 * GAP, w, 4), np.uint8)
            self.offsets = [(0, i * (h + GAP)) for i in range(3)]
        else:
            canvas = np.zeros((h, 3 * w + 2 * GAP, 4), np.uint8)
            self.offsets = [(i * (w + GAP), 0) for i in range(3)]
        for (ox, oy), p in zip(self.offsets, panels, strict=True):
            canvas[oy : oy + h, ox : ox + w] = p
        refit = self.frame_shape != (h, w)
        self.frame_shape = (h, w)
        self.set_image(canvas, fit=refit)

    def hover_text(self, px, bit_depth: int = 8) -> str:
        """The overlap pixel under the mouse: which panel, its row and column in the overlap
        and its value (the regions' colour, the error map's error), not the composite's
        display colours."""
        if px is None or self.frame_shape is None or len(self.panels) != 3:
            return ""
        h, w = self.frame_shape
        for name, a, (ox, oy) in zip(self.names, self.panels, self.offsets, strict=True):
            r, c = px[0] - oy, px[1] - ox
            if 0 <= r < h and 0 <= c < w:
                if a.ndim == 2:
                    return f"{name} x {c}, y {r}: {float(a[r, c]):.4g}"
                return f"{name} x {c}, y {r} = ({pixel_text(a, r, c, bit_depth)})"
        return ""  # the gap between two panels

    def clear(self) -> None:
        self.frame_shape = None
        self.panels = []
        self.set_image(None)
        for p in self.paths:
            p.hide()
        self.set_waypoints([])

    def set_path(self, path) -> None:
        if self.frame_shape is None or path is None:
            for p in self.paths:
                p.hide()
            return
        for item, (ox, oy) in zip(self.paths, self.offsets, strict=True):
            item.set_points(path, (ox, oy))
            item.show()

    def set_waypoints(self, points) -> None:
        for it in self._wp_items:
            self.scene().removeItem(it)
        self._wp_items = []
        self.waypoints = [tuple(p) for p in points]
        if self.frame_shape is None:
            return
        for r, c in self.waypoints:
            for ox, oy in self.offsets:
                it = WaypointItem(r + oy, c + ox)
                self.scene().addItem(it)
                self._wp_items.append(it)

    def frame_point(self, view_pos) -> tuple[int, int] | None:
        """(row, col) in the overlap frame under a view position (any of the panels)."""
        px = self.pixel_at(view_pos)
        if px is None or self.frame_shape is None:
            return None
        r, c = px
        h, w = self.frame_shape
        for ox, oy in self.offsets:
            if ox <= c < ox + w and oy <= r < oy + h:
                return r - oy, c - ox
        return None

    def mousePressEvent(self, event) -> None:  # noqa: N802 - Qt API
        pt = self.frame_point(event.position())
        if pt is None:
            super().mousePressEvent(event)
            return
        if event.button() == Qt.MouseButton.RightButton:
            near = nearest_waypoint(self.waypoints, pt)
            if near is not None:
                self.waypoint_removed.emit(near)
        elif event.button() == Qt.MouseButton.LeftButton:
            self.waypoint_added.emit(pt)
        event.accept()


class OverlapPanel(QWidget):
    """The two overlaps of the template (horizontal: R_R | R_L, vertical: R_B / R_T)."""

    def __init__(self, doc: Document, pipeline: Pipeline, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.views = {
            "horizontal": OverlapView(SEAM_COLORS["horizontal"]),
            "vertical": OverlapView(SEAM_COLORS["vertical"], names=("R_B", "R_T", "error")),
        }
        self.labels = {k: QLabel() for k in self.views}
        for label in self.labels.values():
            label.setWordWrap(True)  # long texts must not widen the window
        lay = QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        split = QSplitter(Qt.Orientation.Vertical)
        for which, title in (
            ("horizontal", "Left / right overlap</b> — R_R | R_L | error map<b>"),
            ("vertical", "Top / bottom overlap</b> — R_B / R_T / error map<b>"),
        ):
            box = QWidget()
            bl = QVBoxLayout(box)
            bl.setContentsMargins(0, 0, 0, 0)
            head = QLabel(f"<b>{title}</b>")
            head.setWordWrap(True)
            bl.addWidget(head)
            bl.addWidget(self.views[which], 1)
            bl.addWidget(self.labels[which])
            split.addWidget(box)
            self.views[which].waypoint_added.connect(getattr(self, f"_add_{which}"))
            self.views[which].waypoint_removed.connect(getattr(self, f"_remove_{which}"))
        split.setStretchFactor(0, 3)  # the left/right overlap is tall and narrow
        split.setStretchFactor(1, 2)
        lay.addWidget(split, 1)
        self.watch = WatchSearch(doc, pipeline)
        lay.addWidget(self.watch)
        row = QHBoxLayout()
        self.clear_button = QPushButton("Clear waypoints")
        self.clear_button.setToolTip("Remove every waypoint of both seams")
        self.clear_button.clicked.connect(doc.tileset.clear_waypoints)
        row.addStretch(1)
        row.addWidget(self.clear_button)
        lay.addLayout(row)
        self.frames: dict[str, tuple | None] = {k: None for k in self.views}  # (rect, w_T) shown
        self._shown: dict[str, object] = {k: None for k in self.views}  # error map shown
        doc.tileset.seamless_changed.connect(self._on_seamless_changed)
        doc.tileset.waypoints_changed.connect(self._on_waypoints_changed)
        pipeline.seam_updated.connect(self._on_seam_updated)
        self._on_seamless_changed()

    @Slot(object)
    def _add_horizontal(self, pt) -> None:
        self.doc.tileset.add_waypoint("horizontal", pt)

    @Slot(object)
    def _add_vertical(self, pt) -> None:
        self.doc.tileset.add_waypoint("vertical", pt)

    @Slot(object)
    def _remove_horizontal(self, pt) -> None:
        self.doc.tileset.remove_waypoint("horizontal", pt)

    @Slot(object)
    def _remove_vertical(self, pt) -> None:
        self.doc.tileset.remove_waypoint("vertical", pt)

    @Slot()
    def _on_seamless_changed(self) -> None:
        s = self.doc.tileset.seamless
        if s is None:
            for which, v in self.views.items():
                v.clear()
                self.frames[which] = None
                self._shown[which] = None
                self.labels[which].setText("No tile yet: draw a rectangle or Find best tile.")
            return
        self.frames = {k: (tuple(s.rect), int(s.overlap)) for k in self.views}
        for which, v in self.views.items():
            r1, r2 = (s.regions[k] for k in LIVE_REGIONS[which])
            v.show_overlap(r1, r2, s.errors[which], stacked=which == "vertical")
            self._shown[which] = s.errors[which]
            v.set_path(s.paths[which])
            self.labels[which].setText(
                f"seam criterion {s.criterion[which]:.3f}   peak {s.peak[which]:.3f}   "
                f"({s.seams[which].method})"
            )
        self._on_waypoints_changed()

    def current_frame(self) -> tuple | None:
        """(rect, w_T) of the document's tile rectangle: what live seams belong to."""
        rect = self.doc.tileset.template_rect
        return None if rect is None else (tuple(rect), self.doc.tileset.overlap())

    def _show_live_frame(self, update, frame) -> None:
        """Show the overlap a running job's update belongs to, from the regions and error
        map the update carries (a new rectangle's overlaps are drawn before its result)."""
        which = update.which
        view = self.views[which]
        r1, r2 = (update.regions[k] for k in LIVE_REGIONS[which])
        view.show_overlap(r1, r2, update.error, stacked=which == "vertical")
        view.set_waypoints(self.doc.tileset.waypoints_in_use()[which])
        self.frames[which] = frame
        self._shown[which] = update.error
        other = "vertical"
        if which == "horizontal" and self.frames[other] != frame:
            self.views[other].clear()  # the old rectangle's overlap must not stay up
            self.frames[other] = None
            self.labels[other].setText(
                "waiting for the left/right stitch (this overlap is cut from it)..."
            )

    @Slot(object)
    def _on_seam_updated(self, update) -> None:
        """A live seam of the running job: drawn on its own rectangle's overlap only."""
        v = self.views.get(update.which)
        frame = self.current_frame()
        if v is None or frame is None:
            return
        new = self.frames[update.which] != frame or self._shown[update.which] is not update.error
        if update.regions is not None and update.error is not None and new:
            self._show_live_frame(update, frame)
        elif self.frames[update.which] != frame or v.frame_shape is None:
            return  # an update without its overlap's pixels, for a frame not shown
        v.set_path(np.asarray(update.path))
        self.labels[update.which].setText(
            f"searching... criterion {update.seam.criterion:.3f}   peak {update.seam.peak:.3f}"
        )

    @Slot()
    def _on_waypoints_changed(self) -> None:
        for which, v in self.views.items():
            v.set_waypoints(self.doc.tileset.waypoints_in_use()[which])
