"""The engine runs of the Wang workflow: make a set, rebuild the tiles of a moved sample,
re-roll a sample or the preview's layout. Jobs stream into :attr:`Document.wang`."""

from __future__ import annotations

from functools import partial

import numpy as np
from PySide6.QtCore import QObject, Signal, Slot

from engine.tiles.wang import WangSample, WangSamples, WangTile, choose_sample, iter_wang_set
from engine.tiles.wang_layout import wang_layout
from quilt_gui import jobs, params
from quilt_gui.jobs import error_text
from quilt_gui.pipeline import excluding
from quilt_gui.wang_doc import NewWangSet

__all__ = ["WangRunner"]

PREVIEW = (8, 8)  # the preview layout's cells (rows, cols)
MIN_TILE = 8  # the smallest Wang tile the engine makes (a 2 px band on each side)
STOPPED = "Wang set stopped"  # the start of the message of a cancelled set


class WangRunner(QObject):
    """Starts the Wang jobs for ``doc`` (a :class:`quilt_gui.document.Document`)."""

    message = Signal(str, str)  # level, text
    #: level, text, actions ((label, callable) buttons): a message the banner offers a fix for
    advice = Signal(str, str, object)
    #: the start of a message no longer true (the set it spoke of is not the one shown)
    retracted = Signal(str)

    def __init__(self, doc, pipeline, manager: jobs.JobManager | None = None, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.pipeline = pipeline
        self.jobs = manager or jobs.manager()
        self._reroll_seed = 1000
        self._job: jobs.Job | None = None  # the last Generate's
        self._version = 0  # of the edge samples: one more at every move
        self._outdated: dict[int, int] = {}  # tile -> the version its sample last moved at
        doc.wang.sample_moved.connect(self._on_sample_moved)
        doc.wang.superseded.connect(self._drop_jobs)
        doc.wang.restored.connect(self._on_restored)
        self._stopped_due = False  # a restored stopped set, said once the undo step is taken
        doc.wang.undo_stack.indexChanged.connect(self._after_step)
        doc.source_changed.connect(self._on_source_changed)
        doc.pixels_changed.connect(self._on_pixels_changed)

    @property
    def stale(self) -> set[int]:
        """The tiles waiting for a rebuild (:attr:`WangDocument.stale`)."""
        return self.doc.wang.stale

    @stale.setter
    def stale(self, tiles) -> None:
        self.doc.wang.stale = set(tiles)

    # ------------------------------------------------------------------ options
    def engine_options(self) -> dict:
        """Keyword options of :func:`engine.tiles.wang.iter_wang_set` (with ``exclusion``
        for :func:`quilt_gui.pipeline.excluding`): the set's own options, the cut of the
        Parameters panel, the material maps and their weights, the exclusion."""
        o = self.doc.wang.options
        src = self.doc.source
        return dict(
            tile_size=int(o["tile_size"]),
            colours=int(o["colours"]),
            variants=int(o["variants"]),
            interior=o["interior"],
            seam=params.tileset_settings(self.doc.params).seam,
            maps=src.extra_maps or None,
            weights=self.doc.tileset.engine_weights(),
            exclusion=self.pipeline.exclusion(),
        )

    def _ready(self) -> bool:
        if self.doc.source is None:
            self.message.emit("warning", "Open a source image first.")
            return False
        return True

    def largest_tile(self, limit: int = 1024) -> int | None:
        """The largest Wang tile size (at most ``limit``) the source takes with the
        Parameters panel's cut (each edge sample needs about twice the tile), or None."""
        from engine.tiles.wang_size import source_fits

        if self.doc.source is None:
            return None
        shape = self.doc.source.main.shape
        seam = params.tileset_settings(self.doc.params).seam
        top = min(limit, *shape[:2])
        return next(
            (T for T in range(top, MIN_TILE - 1, -1) if source_fits(shape, T, seam=seam)), None
        )

    def _fits(self, size: int) -> bool:
        """Whether the source takes ``size`` px tiles; else say which size it does take."""
        from engine.tiles.wang_size import source_fits

        src = self.doc.source.main
        seam = params.tileset_settings(self.doc.params).seam
        if size >= MIN_TILE and source_fits(src.shape, size, seam=seam):
            return True
        top = self.largest_tile()
        H, W = src.shape[:2]
        text = f"The {W}x{H} source is too small for {size} px Wang tiles"
        if top is None:
            text += f" (each edge sample needs twice the tile; {MIN_TILE} px is the smallest)"
        else:
            text += f": each edge sample needs about twice the tile; {top} px tiles fit (Tile size)"
        self.message.emit("warning", text + ".")
        return False

    # ------------------------------------------------------------------ the whole set
    def generate(self, options: dict | None = None) -> jobs.Job | None:
        """Make a new set with ``options`` (colours, tile_size, variants, interior, seed)."""
        if not self._ready():
            return None
        w = self.doc.wang
        if not self._fits(int({**w.options, **(options or {})}["tile_size"])):
            return None
        w.new_set({**w.options, **(options or {})})  # first: its undo keeps the waiting tiles
        return self._start_set()

    def _start_set(self) -> jobs.Job | None:
        """Start the job making the whole set of the document's options."""
        w = self.doc.wang
        self._drop_jobs()
        try:
            opts = self.engine_options()
        except (TypeError, ValueError) as exc:
            self.message.emit("error", f"Wang set: {exc}")
            return None
        self._job = self.jobs.start(
            "wang",
            excluding(iter_wang_set),
            self.doc.source.main,
            label=f"Making {w.count} Wang tiles",
            rng=int(w.options["seed"]),
            workers=2,
            on_event=partial(self._on_event, self._version),
            on_done=self._on_done,
            on_error=self._on_error,
            **opts,
        )
        return self._job

    def _on_event(self, version: int, event) -> None:
        """An event of a job started at samples ``version``: a tile made with a sample moved
        since is dropped (the rebuild started by the move makes it again)."""
        if isinstance(event, WangSamples):
            if version == self._version:
                self.doc.wang.apply_samples(event.samples)
        elif isinstance(event, WangTile):
            k = int(event.index)
            if version < self._outdated.get(k, 0):
                return
            self.stale.discard(k)
            self.doc.wang.set_tile(event)
            self._first_layout()

    def _first_layout(self) -> None:
        w = self.doc.wang
        if w.complete and w.layout is None and not self.stale:
            seed = int(w.options["seed"])
            w.apply_layout(self._layout(seed), seed)

    def _on_done(self, result) -> None:
        w = self.doc.wang
        w.notes = tuple(result.notes)
        w.parameters = dict(result.parameters)
        size = getattr(result, "suggested_size", None)
        advice = getattr(result, "suggested_note", None) if size else None
        for note in result.notes:
            if note != advice:  # that one last, with its button (a later message replaces it)
                self.message.emit("warning", f"Wang set: {note}")
        if advice in result.notes:
            use = lambda: self.generate({"tile_size": size})  # noqa: E731
            self.advice.emit("warning", f"Wang set: {advice}", [(f"Use {size} px tiles", use)])
        self._first_layout()
        if self._job is not None and self._job.token.cancelled and not w.complete:
            self._say_stopped()  # cancelled: the part made stays on screen, said in words

    def _say_stopped(self) -> None:
        w = self.doc.wang
        text = f"{STOPPED}: {len(w.tiles)} of {w.count} tiles made; Generate makes it"
        if w.undo_stack.undoText() == NewWangSet.TEXT:
            text += " (Edit ▸ Undo, Ctrl+Z, brings back the set before)"
        self.message.emit("warning", text + ".")

    def _on_error(self, exc) -> None:
        self.message.emit("error", f"Wang set failed: {error_text(exc)}")

    # ------------------------------------------------------------------ samples
    def move_sample(self, axis: str, colour: int, origin) -> bool:
        """Put sample (axis, colour) at ``origin`` (row, col); False when it does not fit."""
        from engine.tiles.wang import WangSetup

        w = self.doc.wang
        size = int(w.options["tile_size"])
        try:
            setup = WangSetup(
                self.doc.source.main,
                tile_size=size,
                seam=params.tileset_settings(self.doc.params).seam,
            )
            try:
                origin = setup.check_origin(axis, origin)
            except ValueError:  # dragged past the border: the nearest place it fits
                origin = setup.check_origin(axis, setup.nearest_origin(axis, origin))
        except (TypeError, ValueError) as exc:
            self.message.emit("warning", f"The edge sample cannot go there: {exc}")
            return False
        if tuple(origin) != tuple(w.sample(axis, colour).origin):
            w.set_sample(WangSample(axis, int(colour), tuple(origin)))
        return True

    def reroll_sample(self, axis: str, colour: int) -> jobs.Job | None:
        """Choose sample (axis, colour) again (a new draw among the best matches)."""
        w = self.doc.wang
        if not self._ready() or w.samples is None:
            return None
        self._reroll_seed += 1
        opts = self.engine_options()
        keep = ("tile_size", "colours", "seam", "maps", "weights", "exclusion")
        return self.jobs.start(
            "wang-sample",
            excluding(choose_sample),
            self.doc.source.main,
            list(w.samples),
            axis,
            int(colour),
            label="Choosing an edge sample",
            rng=self._reroll_seed,
            pass_cancel=False,
            on_done=lambda s: w.set_sample(s, text="Re-roll edge sample"),
            on_error=self._on_error,
            **{k: v for k, v in opts.items() if k in keep},
        )

    @Slot(str, int)
    def _on_sample_moved(self, axis: str, colour: int) -> None:
        self._version += 1  # tiles of the jobs running now that show the sample are outdated
        users = set(self.doc.wang.users(axis, colour))
        self._outdated.update(dict.fromkeys(users, self._version))
        self.stale |= users
        self.rebuild()

    def rebuild(self) -> jobs.Job | None:
        """Make the stale tiles again with the current samples (supersedes a running
        rebuild: its tiles stay stale until this one delivers them)."""
        w = self.doc.wang
        if not self.stale or w.samples is None or self.doc.source is None:
            return None
        todo = sorted(self.stale)
        avoid = [t.patch_origin for k, t in w.tiles.items() if k not in self.stale]
        return self.jobs.start(
            "wang-rebuild",
            excluding(iter_wang_set),
            self.doc.source.main,
            label=f"Rebuilding {len(todo)} Wang tiles",
            samples=list(w.samples),
            tiles=todo,
            avoid=[a for a in avoid if a is not None],
            rng=int(w.options["seed"]),
            workers=2,
            on_event=partial(self._on_event, self._version),
            on_error=self._on_error,
            **self.engine_options(),
        )

    # ------------------------------------------------------------------ preview layout
    def _layout(self, seed: int) -> np.ndarray:
        sigs = [self.doc.wang.tiles[k].signature for k in sorted(self.doc.wang.tiles)]
        return wang_layout(sigs, *PREVIEW, rng=seed, no_equal_neighbours=True)

    def reroll_layout(self) -> None:
        w = self.doc.wang
        if not w.complete:
            self.message.emit("warning", "Make the Wang set first (Generate).")
            return
        seed = w.layout_seed + 1
        w.set_layout(self._layout(seed), seed)

    @Slot()
    def _drop_jobs(self) -> None:
        """The running set's jobs end unheard (another set replaces it): a stop said of the
        set before is no longer true."""
        self.jobs.abort_matching("wang")
        self.retracted.emit(STOPPED)
        self._stopped_due = False
        self.stale = set()
        self._outdated = {}

    @Slot(object)
    def _on_restored(self, pending) -> None:
        """A set put back by undo / redo (or opened) with tiles whose sample had moved or
        whose pixels changed: rebuild them; a set stopped before its end says so again."""
        self.stale = set(pending)
        self.rebuild()
        # said after the undo stack's index moves: inside QUndoCommand.redo() / undo() its
        # undo text is still the step before (or the one being undone), not this set's
        self._stopped_due = not self.stale and not self.doc.wang.complete

    @Slot()
    def _after_step(self) -> None:
        if self._stopped_due:
            self._stopped_due = False
            self._say_stopped()

    @Slot()
    def _on_pixels_changed(self) -> None:
        """The source healed (or its heal undone): every tile made again from the new pixels
        with the same edge samples (a tile left from the old pixels would not match a rebuilt
        neighbour where the heal touched a sample); a set still choosing its samples starts
        again (same options, no undo step)."""
        w = self.doc.wang
        if w.samples is None:
            if self._job is not None and self._job.alive and self._job.running:
                self._start_set()  # still choosing samples: again from the new pixels
            return
        self._version += 1
        self._outdated = dict.fromkeys(range(w.count), self._version)
        self.stale = set(range(w.count))
        self.message.emit("info", "Wang set: made again from the healed source, same edge samples.")
        self.rebuild()

    @Slot()
    def _on_source_changed(self) -> None:
        self._drop_jobs()
        self.doc.wang.clear()
