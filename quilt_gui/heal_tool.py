"""Heal on the Source tab: paint a region (a leaf, a logo, a blemish), then fill it from the rest
of the source by quilting (:func:`engine.heal.iter_heal`).

With the Heal brush on, a drag on the source paints the region (green), a right-drag erases it;
each stroke is an undo step. *Heal* runs in the background: the blocks appear on the source as
they are placed, and the finished result replaces the source's pixels (every material map,
with the same cuts) as one undo step. The template search, the candidates and quilting then
use the healed source. Source pixels the exclusion marks are never copied from.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QObject, Qt, Signal, Slot

from engine.heal import HealBlock
from quilt_gui import jobs
from quilt_gui.pipeline import Pipeline, excluding
from quilt_gui.widgets.exclusion import MaskBrush
from quilt_gui.widgets.quilt_view import RasterItem


class HealBrush(MaskBrush):
    """While :attr:`active`: a plain drag paints the region to heal, a right-drag erases."""

    COLOR = (60, 230, 120, 140)
    Z = 16

    def __init__(self, doc, canvas) -> None:
        super().__init__(doc, canvas)
        self.active = False
        doc.heal_mask_changed.connect(self.refresh)

    def wants(self, event) -> bool:
        plain = event.modifiers() == Qt.KeyboardModifier.NoModifier
        return self.active and plain and not self.canvas.space_down

    def current_mask(self):
        return self.doc.heal_mask

    def commit(self, mask, painting: bool) -> None:
        self.doc.set_heal_mask(mask, text="Paint region to heal" if painting else "Erase region")


class HealTool(QObject):
    """The brush, the job and its live display on ``view`` (the source view)."""

    message = Signal(str, str)  # level, text

    def __init__(self, doc, pipeline: Pipeline, view, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.pipeline = pipeline
        self.jobs = pipeline.jobs
        self.view = view
        self.brush = HealBrush(doc, view)
        self.live = RasterItem()
        self.live.setZValue(17)
        view.add_item(self.live)
        self._healing = None  # the region the running heal fills
        doc.source_changed.connect(self._on_source_changed)
        doc.heal_mask_changed.connect(self._on_region_changed)

    def set_brush(self, on: bool) -> None:
        """The Heal brush on (a drag paints the region) or off (a drag draws the tile)."""
        self.brush.active = bool(on)
        self.view.viewport().setCursor(
            Qt.CursorShape.CrossCursor if on else Qt.CursorShape.ArrowCursor
        )

    @Slot()
    def clear(self) -> None:
        if self.doc.heal_mask is not None:
            self.doc.set_heal_mask(None, text="Clear region to heal")

    @Slot()
    def run(self) -> jobs.Job | None:
        """Heal the painted region in the background."""
        from engine.heal import iter_heal

        doc = self.doc
        mask = doc.heal_mask
        if doc.source is None or mask is None or not mask.any():
            self.message.emit(
                "warning", "Paint the region to heal first: turn on the Heal brush and drag."
            )
            return None
        h, w = doc.source.shape
        self.live.reset(h, w)
        self._healing = mask
        return self.jobs.start(
            "heal",
            excluding(iter_heal),
            doc.source.main,
            mask,
            label=f"Healing {int(mask.sum())} pixels",
            exclusion=self.pipeline.exclusion(),
            maps=doc.source.extra_maps or None,
            seam=doc.tileset.settings().seam,  # the parameters' own (Auto tone is for tiles)
            rng=int(doc.params["seed"]),
            threads=2,
            on_event=self._on_event,
            on_done=self._on_done,
            on_error=self._on_error,
            on_cancel=self._on_cancel,
        )

    def _on_event(self, event) -> None:
        if isinstance(event, HealBlock):
            x, y, _, _ = event.rect
            self.live.paste(event.pixels, x, y)

    @Slot()
    def _on_region_changed(self) -> None:
        """The region changed while a heal of it ran (Undo took the stroke back, or another
        stroke): that heal stops; its result would replace pixels no longer painted (it was
        applied, "Healed 0 pixels", over the undone stroke's redo: ux13)."""
        if self._healing is None or self.doc.heal_mask is self._healing:
            return
        self._healing = None
        self.jobs.abort("heal")
        self.live.reset(0, 0)
        self.message.emit(
            "warning",
            "Heal stopped: the region to heal changed while it ran; the source is unchanged. "
            "Heal painted region heals the region as it is now.",
        )

    def _on_done(self, result) -> None:
        self._healing = None
        self.live.reset(0, 0)
        names = list(self.doc.source.maps)
        maps = {names[0]: result.image, **{k: result.maps[k] for k in names[1:]}}
        n = int(self.doc.heal_mask.sum()) if self.doc.heal_mask is not None else 0
        stale = unhealed_candidates(self.doc, result.image)
        self.doc.heal(maps)
        self.message.emit(
            "warning" if stale else "info",
            f"Healed {n} pixels with {len(result.blocks)} blocks of {result.block} px; the "
            f"template search and the candidates use the healed source (Undo restores it).{stale}",
        )

    def _on_error(self, exc) -> None:
        self._healing = None
        self.live.reset(0, 0)
        self.message.emit("error", f"Heal failed: {jobs.error_text(exc)}")

    def _on_cancel(self) -> None:
        self._healing = None
        self.live.reset(0, 0)
        self.message.emit("info", "Heal cancelled; the source is unchanged.")

    @Slot()
    def _on_source_changed(self) -> None:
        self._healing = None
        self.jobs.abort("heal")
        self.live.reset(0, 0)


def unhealed_candidates(doc, healed) -> str:
    """What of the tile set still shows the pixels a heal replaces by ``healed`` (the main
    map), in words ("" when nothing): the candidates whose patch was cut from them, or all
    when the tile rectangle holds some (its seamless tile is made again)."""
    ts = doc.tileset
    if not ts.candidates:
        return ""
    changed = np.any(np.asarray(healed) != doc.source.main, axis=2)

    def holds(rect) -> bool:
        x, y, w, h = (int(v) for v in rect)
        return bool(changed[max(y, 0) : y + h, max(x, 0) : x + w].any())

    if ts.template_rect is not None and holds(ts.template_rect):
        return (
            " The tile rectangle holds healed pixels: its seamless tile is made again and the "
            "candidates, made from the old one, show the unhealed pixels: Generate them again."
        )
    hit = [e.index for e in ts.candidates if e.patch_rect is not None and holds(e.patch_rect)]
    if not hit:
        return ""

    def names(indices) -> str:
        return ", ".join(f"#{i + 1}" for i in indices[:8]) + (", …" if len(indices) > 8 else "")

    picked = [i for i in hit if i in ts.picks]
    which = f"{names(hit)}; {len(picked)} of them picked" + (f": {names(picked)}" if picked else "")
    return (
        f" {len(hit)} candidate{'s' if len(hit) > 1 else ''} ({which}) still show"
        f"{'' if len(hit) > 1 else 's'} the unhealed pixels, their patches were cut from them: "
        "re-roll them (R in the gallery) or Generate again."
    )
