"""The Wang workflow's part of the document: the set's options, edge samples, tiles, layout.

A Wang set (:mod:`engine.tiles.wang`) is made by a job that streams its samples, then its
tiles; they are applied here directly (not undo steps), but *Generate* replacing a set is one
(:class:`NewWangSet`: undo puts the last set back whole). Moving or re-rolling an edge sample is
an undo step (:class:`SetWangSample`); the runner (:mod:`quilt_gui.wang_runner`) then rebuilds
the tiles that use it. Re-rolling the preview's layout is one too (:class:`SetWangLayout`).
"""

from __future__ import annotations

import numpy as np
import shiboken6
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoCommand

from engine.tiles.wang import (
    AXES,
    canonical_signatures,
    from_candidate,
    samples_from_record,
    wang_record,
)

__all__ = [
    "DEFAULT_OPTIONS",
    "KEPT_SETS",
    "NewWangSet",
    "SetWangLayout",
    "SetWangSample",
    "WangDocument",
]

#: Generate steps of the Wang history that keep their sets' tiles (a 4-colour set of 256 px
#: tiles is ~230 MB); an older one keeps options, samples and layout, its tiles made again
KEPT_SETS = 3

#: the editor's Wang options (engine.tiles.wang.iter_wang_set names) and their defaults
DEFAULT_OPTIONS = {"colours": 2, "tile_size": 128, "variants": 1, "interior": "patch", "seed": 0}


class WangDocument(QObject):
    """Options, samples, tiles and preview layout of a Wang set made from ``root``'s source."""

    reset = Signal()  # a new set is being made (or cleared): everything redraws
    samples_changed = Signal()
    sample_moved = Signal(str, int)  # axis, colour: a user edit, its tiles are stale
    tile_changed = Signal(int)  # tile index
    tiles_replaced = Signal()  # every tile at once (a set put back or opened): one redraw
    stale_changed = Signal()  # the tiles waiting for a rebuild (:attr:`stale`) replaced
    layout_changed = Signal()
    selection_changed = Signal()
    superseded = Signal()  # undo / redo put another set back: drop the jobs of this one
    restored = Signal(object)  # ...put back: these of its tiles wait for a rebuild (a set)

    def __init__(self, root, undo_stack) -> None:
        super().__init__(root)
        self.root = root
        self.undo_stack = undo_stack
        self.options = dict(DEFAULT_OPTIONS)
        self.samples: list | None = None  # engine WangSample, h colours then v colours
        self.tiles: dict[int, object] = {}  # index -> engine WangTile
        self.layout: np.ndarray | None = None
        self.layout_seed = 0
        self.selected: tuple[str, int] | None = None  # (axis, colour) of the chosen sample
        self.notes: tuple[str, ...] = ()
        self.parameters: dict = {}  # the engine's parameters of the last run
        self._stale: set[int] = set()
        undo_stack.indexChanged.connect(self._lighten_history)

    # ------------------------------------------------------------------ state
    @property
    def colours(self) -> int:
        return int(self.options["colours"])

    @property
    def count(self) -> int:
        return int(self.options["variants"]) * self.colours**4

    @property
    def complete(self) -> bool:
        return self.samples is not None and sorted(self.tiles) == list(range(self.count))

    def tile_list(self) -> list:
        return [self.tiles[k] for k in sorted(self.tiles)]

    def signature(self, index: int) -> tuple[int, int, int, int]:
        sigs = canonical_signatures(self.colours)
        return sigs[index % len(sigs)]

    def sample(self, axis: str, colour: int):
        return self.samples[AXES.index(axis) * self.colours + colour]

    def users(self, axis: str, colour: int) -> list[int]:
        """Indices of the tiles that show sample (axis, colour) on one of their edges."""
        sides = (0, 2) if axis == "h" else (1, 3)
        return [k for k in range(self.count) if any(self.signature(k)[s] == colour for s in sides)]

    # ------------------------------------------------------------------ results (not undo steps)
    def clear(self) -> None:
        self.start(self.options)

    def new_set(self, options: dict) -> None:
        """:meth:`start` as the user's *Generate*: one undo step when a set is replaced (undo
        brings it back as it was, with its own history below it; a cancel leaves a part)."""
        if self.samples is None and not self.tiles:
            self.start(options)
        else:
            self.undo_stack.push(NewWangSet(self, options))

    def _lighten_history(self) -> None:
        """Only the :data:`KEPT_SETS` Generate steps nearest the present keep the tiles of
        the set an undo (or redo) puts back; the others are made again when put back."""
        if not shiboken6.isValid(self.undo_stack):  # the stack clears as it is deleted
            return
        stack, now = self.undo_stack, self.undo_stack.index()
        steps = [(i, stack.command(i)) for i in range(stack.count())]
        steps = [(abs(now - 0.5 - i), i < now, c) for i, c in steps if isinstance(c, NewWangSet)]
        for rank, (_, done, c) in enumerate(sorted(steps, key=lambda s: s[0])):
            c.lighten(old=rank >= KEPT_SETS, new=rank >= KEPT_SETS or done)  # undo retakes new

    def start(self, options: dict) -> None:
        """A new set with ``options``: samples, tiles and layout forgotten."""
        self.options = {**DEFAULT_OPTIONS, **options}
        self.samples, self.tiles, self.layout = None, {}, None
        self.selected, self.notes = None, ()
        self.reset.emit()
        self.selection_changed.emit()

    def apply_samples(self, samples) -> None:
        self.samples = list(samples)
        self.samples_changed.emit()

    def set_tile(self, tile) -> None:
        self.tiles[int(tile.index)] = tile
        self.tile_changed.emit(int(tile.index))
        self.root.mark_dirty()

    @property
    def stale(self) -> set[int]:
        """The tiles waiting for a rebuild (their sample moved, or the pixels changed): the
        runner's work list (it discards each tile as it comes); a snapshot and a project keep
        them."""
        return self._stale

    @stale.setter
    def stale(self, tiles) -> None:
        self._stale = set(tiles)
        self.stale_changed.emit()

    def _replace_tiles(self, tiles: dict) -> None:
        """Every tile at once (one :attr:`tiles_replaced`, not one redraw per tile)."""
        self.tiles = dict(tiles)
        self.tiles_replaced.emit()

    @property
    def pixels(self) -> int:
        """The generation of the source's pixels (:attr:`Document.pixels`): a snapshot keeps
        the one its tiles were made from."""
        return self.root.pixels

    def select(self, key: tuple[str, int] | None) -> None:
        if key != self.selected:
            self.selected = key
            self.selection_changed.emit()

    def snapshot(self) -> tuple:
        """The whole set as it is (tiles are replaced, never changed in place), with the
        pixels generation its tiles were made from."""
        samples = None if self.samples is None else list(self.samples)
        return (dict(self.options), samples, dict(self.tiles), self.layout, self.layout_seed,
                self.notes, dict(self.parameters), set(self.stale), self.pixels)  # fmt: skip

    @staticmethod
    def light(state: tuple) -> tuple:
        """A :meth:`snapshot` without its tiles: every tile waits (made again on restore)."""
        options, samples, tiles, *rest, pending, pixels = state
        if samples is None:
            return state
        o = {**DEFAULT_OPTIONS, **options}
        every = set(range(int(o["variants"]) * int(o["colours"]) ** 4))
        return (options, samples, {}, *rest, every, pixels)

    def restore(self, state: tuple) -> None:
        """Back to a :meth:`snapshot`; the running jobs of the set it replaces are dropped
        first (:attr:`superseded`). Tiles made from pixels healed since wait, all of them."""
        self.superseded.emit()
        options, samples, tiles, layout, seed, notes, parameters, pending, pixels = state
        self.start(options)
        if pixels != self.pixels and samples is not None:  # healed since: all of them
            pending = set(range(self.count))
        self.notes, self.parameters = notes, dict(parameters)
        if samples is not None:
            self.apply_samples(samples)
        self._replace_tiles(tiles)
        self.apply_layout(layout, seed)
        self.root.mark_dirty()
        self.restored.emit(set(pending))

    # ------------------------------------------------------------------ project files
    def to_project(self, names: list[str]) -> tuple[dict | None, list]:
        """(record, tiles) of :attr:`engine.project.Project.wang` / ``wang_tiles``; nothing
        when there is no set, or when a tile lacks one of the source's maps ``names`` (made
        before the map was attached: generate again)."""
        tiles = self.tile_list()
        if self.samples is None or not tiles:
            return None, []
        if any(set(t.maps) != set(names[1:]) for t in tiles):
            return None, []
        params = {**self.parameters, **self.options}
        record = wang_record(self.samples, params)
        record.update(
            options=dict(self.options),
            layout=None if self.layout is None else self.layout.tolist(),
            layout_seed=self.layout_seed,
            pending=sorted(self.stale),  # tiles still to rebuild: made again on opening
        )
        return record, [t.to_candidate() for t in tiles]

    def apply_project(self, record: dict | None, tiles) -> None:
        """Take the Wang set a project kept (as :meth:`to_project` wrote it, or the CLI); the
        tiles it saved while they waited for a rebuild are made again (:attr:`restored`)."""
        if record is None:
            self.start(self.options)
            return
        params = record.get("parameters", {})
        opts = {k: params[k] for k in DEFAULT_OPTIONS if k in params}
        opts.update(record.get("options") or {})
        opts.setdefault("seed", params.get("seed", 0))
        self.start(opts)
        self.parameters = dict(params)
        self.apply_samples(samples_from_record(record))
        self._replace_tiles({t.index: t for t in map(from_candidate, tiles)})
        layout = record.get("layout")
        self.apply_layout(layout, int(record.get("layout_seed", 0)))
        pending = {int(k) for k in record.get("pending", ())}  # none in older projects
        if pending:
            self.restored.emit(pending)

    # ------------------------------------------------------------------ user edits (undoable)
    def set_sample(self, sample, *, text: str = "Move edge sample") -> None:
        """Replace one edge sample (its tiles are rebuilt); one undo step."""
        self.undo_stack.push(SetWangSample(self, sample, text))

    def apply_sample(self, sample) -> None:
        i = AXES.index(sample.axis) * self.colours + sample.colour
        self.samples[i] = sample
        self.samples_changed.emit()
        self.sample_moved.emit(sample.axis, int(sample.colour))

    def set_layout(self, layout, seed: int, *, text: str = "Re-roll Wang layout") -> None:
        self.undo_stack.push(SetWangLayout(self, layout, seed, text))

    def apply_layout(self, layout, seed: int) -> None:
        self.layout = None if layout is None else np.asarray(layout, dtype=np.int64)
        self.layout_seed = int(seed)
        self.layout_changed.emit()


class NewWangSet(QUndoCommand):
    """*Generate*: the set before it kept whole; the new one as it is when undone."""

    TEXT = "Generate Wang set"

    def __init__(self, doc: WangDocument, options: dict) -> None:
        super().__init__(self.TEXT)
        self.doc, self.options = doc, options
        self.old = doc.snapshot()
        self.new = None  # taken at the first undo (the job streams the set after the push)

    def redo(self) -> None:
        if self.new is None:
            self.doc.start(self.options)
        else:
            self.doc.restore(self.new)

    def undo(self) -> None:
        self.new = self.doc.snapshot()
        self.doc.restore(self.old)

    def lighten(self, *, old: bool, new: bool) -> None:
        """Forget the tiles of the set before (``old``) and / or after (``new``): they are
        made again when it is put back."""
        if old:
            self.old = WangDocument.light(self.old)
        if new and self.new is not None:
            self.new = WangDocument.light(self.new)


class SetWangSample(QUndoCommand):
    def __init__(self, doc: WangDocument, sample, text: str) -> None:
        super().__init__(text)
        self.doc = doc
        self.new = sample
        self.old = doc.sample(sample.axis, sample.colour)

    def redo(self) -> None:
        self.doc.apply_sample(self.new)

    def undo(self) -> None:
        self.doc.apply_sample(self.old)


class SetWangLayout(QUndoCommand):
    def __init__(self, doc: WangDocument, layout, seed: int, text: str) -> None:
        super().__init__(text)
        self.doc = doc
        self.new = (layout, seed)
        self.old = (doc.layout, doc.layout_seed)

    def redo(self) -> None:
        self.doc.apply_layout(*self.new)

    def undo(self) -> None:
        self.doc.apply_layout(*self.old)
