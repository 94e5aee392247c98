"""Flatten lighting, before / after: the Source canvas shows the photo or the source as the
tile set's tiles are made from it (its lighting flattened, :func:`engine.tone.flatten_lighting`
at the scale the tile set uses; a Wang set is made from the photo as it is). View ▸ *Flattened
lighting* (key F) switches; the overlays stay."""

from __future__ import annotations

from PySide6.QtCore import QObject, Qt, Slot
from PySide6.QtGui import QAction

__all__ = ["FlattenCompare"]

#: parameters that change the flattened source (whether it is flattened, and its scale)
KEYS = frozenset({"flatten", "tile_size", "tile_min", "tile_max"})


def _flattened(source, *, scale: int):
    from engine.tone import flatten_lighting

    return flatten_lighting(source, scale=scale)


class FlattenCompare(QObject):
    """Owns the checkable :attr:`action`; draws on ``view`` (the Source canvas)."""

    def __init__(self, doc, pipeline, view, parent=None) -> None:
        super().__init__(parent)
        self.doc, self.pipeline, self.view = doc, pipeline, view
        self.action = QAction("Flattened &lighting (before / after)", self)
        self.action.setCheckable(True)
        self.action.setShortcut("F")
        self.action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        self.action.setToolTip(
            "Show the source as the tile set's tiles are made from it, its lighting flattened "
            "(Flatten lighting: On, or Auto where the lighting varies; a Wang set uses the photo "
            "as it is); again: the photo as it is (F)"
        )
        self.action.toggled.connect(self._refresh)
        self.shown: int | None = None  # the scale of the flattened source on screen
        self._asked = (None, None, None)  # (job, photo, scale) of the flatten job last started
        doc.source_changed.connect(self._new_pixels)
        doc.pixels_changed.connect(self._new_pixels)
        doc.tileset.tone_changed.connect(self._refresh)
        doc.params_changed.connect(self._on_params_changed)

    @Slot()
    def _new_pixels(self) -> None:
        """The Source canvas shows the new photo: flatten it again if asked."""
        self.shown = None
        self._refresh()

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        if self.action.isChecked() and KEYS & set(keys):
            self._refresh()

    @Slot()
    def _refresh(self, *_args) -> None:
        src = self.doc.source
        scale = None if src is None else self.pipeline.flatten_scale()
        if not self.action.isChecked() or scale is None:
            self.pipeline.jobs.abort_matching("flatten-view")
            if self.shown is not None and src is not None:
                self.view.set_image(src.main)  # the photo again, zoom and overlays kept
            self.shown = None
            if self.action.isChecked():  # nothing to compare: say why, and switch back
                self.action.setChecked(False)
                if src is not None:
                    self.pipeline.message.emit(
                        "info",
                        "Flatten lighting is off for this photo: the tiles are made from it "
                        "as it is (Flatten lighting: On, Parameters ▸ Advanced ▸ Tile, "
                        "flattens it).",
                    )
            return
        if scale == self.shown:  # asked back: a job of another scale under way is not
            self.pipeline.jobs.abort_matching("flatten-view")  # (its image would replace it)
            return
        job, photo, asked = self._asked
        under_way = job is not None and job is self.pipeline.jobs.get("flatten-view")
        if under_way and photo is src.main and asked == scale:
            return  # under way (asked again by flatten_scale's own tone_changed)
        job = self.pipeline.jobs.start(
            "flatten-view",
            _flattened,
            src.main,
            scale=scale,
            label="Flattening the lighting",
            pass_cancel=False,
            on_done=lambda img, s=scale: self._show(img, s),
        )
        self._asked = (job, src.main, scale)

    def _show(self, image, scale: int) -> None:
        if not self.action.isChecked():
            return
        self.view.set_image(image)
        self.shown = scale
        self.pipeline.message.emit(
            "info",
            f"The source with its lighting flattened (at {scale:g} px), as the tile set's tiles "
            "are made from it (a Wang set uses the photo as it is); F shows the photo as it is.",
        )
