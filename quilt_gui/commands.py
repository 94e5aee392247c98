"""Undo commands: each changes the document (never a widget) through its ``apply_*`` methods.

A drag (slider, rectangle) is one undo step: the view gives every change of one drag the
same ``merge_id`` and :meth:`QUndoCommand.mergeWith` folds them together.

``doc`` is the part of the document a command changes (:class:`quilt_gui.document.Document`
for parameters and the painted exclusion, :class:`quilt_gui.tileset_doc.TileSetDocument`
for the rest); this module does not import them, they import it.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

from PySide6.QtGui import QUndoCommand

if TYPE_CHECKING:
    from engine.candidate import CandidateTile

_merge_ids = itertools.count(1)


def new_merge_id() -> int:
    """A fresh id for one drag gesture (every change of the gesture shares it)."""
    return next(_merge_ids)


class _Mergeable(QUndoCommand):
    ID = -1

    def __init__(self, text: str, merge_id: int | None) -> None:
        super().__init__(text)
        self.merge_id = merge_id

    def id(self) -> int:  # noqa: A003 - Qt API
        return self.ID if self.merge_id is not None else -1

    def _can_merge(self, other: QUndoCommand) -> bool:
        return (
            type(other) is type(self)
            and self.merge_id is not None
            and other.merge_id == self.merge_id
        )


class SetParams(_Mergeable):
    ID = 1

    def __init__(
        self, doc, values: dict, *, merge_id: int | None = None, text: str | None = None
    ) -> None:
        if text is None:
            text = "Change " + ", ".join(values)
        super().__init__(text, merge_id)
        self.doc = doc
        self.new = dict(values)
        self.old = {k: doc.params[k] for k in values}

    def redo(self) -> None:
        self.doc.apply_params(self.new)

    def undo(self) -> None:
        self.doc.apply_params(self.old)

    def mergeWith(self, other: QUndoCommand) -> bool:  # noqa: N802 - Qt API
        if not self._can_merge(other) or set(other.new) != set(self.new):
            return False
        self.new = dict(other.new)
        if self.new == self.old:
            self.setObsolete(True)
        return True


class SetTemplateRect(_Mergeable):
    ID = 2

    def __init__(
        self,
        doc,
        rect,
        *,
        merge_id: int | None = None,
        text: str = "Move tile rectangle",
        old=None,
        already_applied: bool = False,
    ) -> None:
        super().__init__(text, merge_id)
        self.doc = doc
        self.new = rect
        self.old = old if already_applied else doc.template_rect
        self._skip = already_applied

    def redo(self) -> None:
        if self._skip:  # streamed in already (the template search animates the rectangle)
            self._skip = False
            return
        self.doc.apply_template_rect(self.new)

    def undo(self) -> None:
        self.doc.apply_template_rect(self.old)

    def mergeWith(self, other: QUndoCommand) -> bool:  # noqa: N802 - Qt API
        if not self._can_merge(other):
            return False
        self.new = other.new
        if self.new == self.old:
            self.setObsolete(True)
        return True


class _Swap(QUndoCommand):
    """Redo gives the document ``new``, undo gives it back ``old``, both through its method
    named ``APPLY``."""

    APPLY = ""

    def __init__(self, doc, new, old, text: str) -> None:
        super().__init__(text)
        self.doc = doc
        self.new = new
        self.old = old

    def redo(self) -> None:
        getattr(self.doc, self.APPLY)(self.new)

    def undo(self) -> None:
        getattr(self.doc, self.APPLY)(self.old)


class SetWaypoints(_Swap):
    APPLY = "apply_waypoints"

    def __init__(self, doc, waypoints: dict, text: str) -> None:
        new = {k: list(v) for k, v in waypoints.items()}
        super().__init__(doc, new, {k: list(v) for k, v in doc.waypoints.items()}, text)


class SetPicks(_Swap):
    APPLY = "apply_picks"

    def __init__(self, doc, picks: list[int], text: str) -> None:
        super().__init__(doc, list(picks), list(doc.picks), text)


class SetCandidates(QUndoCommand):
    """All candidates and picks at once (a finished generation).

    ``old`` is the (candidates, picks) before the generation started streamed its
    entries in; ``already_applied`` skips the first ``redo`` for that case.
    """

    def __init__(
        self,
        doc,
        entries: list[CandidateTile],
        picks: list[int],
        text: str,
        *,
        old=None,
        already_applied: bool = False,
    ) -> None:
        super().__init__(text)
        self.doc = doc
        self.new, self.new_picks = list(entries), list(picks)
        self.old, self.old_picks = (list(doc.candidates), list(doc.picks)) if old is None else old
        self._skip = already_applied

    def redo(self) -> None:
        if self._skip:
            self._skip = False
            if self.doc.picks != self.new_picks:
                self.doc.apply_picks(self.new_picks)
            return
        self.doc.apply_candidates(self.new, self.new_picks)

    def undo(self) -> None:
        self.doc.apply_candidates(self.old, self.old_picks)


class ReplaceCandidate(QUndoCommand):
    def __init__(self, doc, index: int, entry: CandidateTile, text: str) -> None:
        super().__init__(text)
        self.doc = doc
        self.index = index
        self.new = entry
        self.old = doc.candidates[index]

    def redo(self) -> None:
        self.doc.apply_candidate(self.index, self.new)

    def undo(self) -> None:
        self.doc.apply_candidate(self.index, self.old)


class SetPainted(_Swap):
    """The painted exclusion mask of the source (one brush stroke = one step)."""

    APPLY = "apply_painted"

    def __init__(self, doc, mask, text: str) -> None:
        super().__init__(doc, mask, doc.exclude_painted, text)


class SetHealMask(_Swap):
    """The region of the source painted to heal."""

    APPLY = "apply_heal_mask"

    def __init__(self, doc, mask, text: str) -> None:
        super().__init__(doc, mask, doc.heal_mask, text)


class SetSourceMaps(_Swap):
    """The source's pixels (every material map), e.g. healed, with their generation (undo
    gives the old one back: a Wang set made from them is not made again)."""

    def __init__(self, doc, maps: dict, text: str) -> None:
        new, old = (dict(maps), doc.new_pixels()), (dict(doc.source.maps), doc.pixels)
        super().__init__(doc, new, old, text)

    def redo(self) -> None:
        self.doc.apply_source_maps(*self.new)

    def undo(self) -> None:
        self.doc.apply_source_maps(*self.old)


class SetMapWeights(_Swap):
    """The seam-error weights of the material maps (one step per change)."""

    APPLY = "apply_map_weights"

    def __init__(self, doc, weights: dict, text: str) -> None:
        super().__init__(doc, dict(weights), dict(doc.map_weights), text)
