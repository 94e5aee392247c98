"""The engine runs for the document: background jobs started on edits, results written back.

:class:`Pipeline` listens to the document; when an input of a derived result changes
(the template rectangle, a seam parameter, a waypoint) it restarts the matching job,
which supersedes the running one, so results of stale inputs are never applied.
Long user actions (find template, generate candidates, quilting) are methods here.
Messages for the user go out through :attr:`Pipeline.message` (level, text).
"""

from __future__ import annotations

import logging
from functools import partial

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal, Slot

from engine.cancel import Cancelled
from engine.candidate import CandidateTile
from quilt_gui import jobs, params
from quilt_gui.document import Document
from quilt_gui.job_bodies import (
    excluding,
    flattening,
    make_preview,
    quilt_job,
    quilt_options,
    transfer_job,
)
from quilt_gui.jobs import error_text

log = logging.getLogger(__name__)

__all__ = ["SWEEP_SAMPLES", "Pipeline"]

#: rectangles the template search streams per chunk of widths (drawn as its sweep)
SWEEP_SAMPLES = 24


def _soon(parent: QObject, slot) -> QTimer:
    """A single-shot 0 ms timer: several triggers in one event-loop cycle run ``slot`` once."""
    timer = QTimer(parent)
    timer.setSingleShot(True)
    timer.setInterval(0)
    timer.timeout.connect(slot)
    return timer


class Pipeline(QObject):
    """Runs the engine for ``doc`` in the background."""

    message = Signal(str, str)  # level ("info" | "warning" | "error"), text
    seam_updated = Signal(object)  # engine.tiles.seamless.SeamlessUpdate, live
    template_searching = Signal(bool)
    template_swept = Signal(object)  # engine.tiles.TemplateSweep: rectangles being scored
    candidate_failed = Signal(int)  # a re-roll / patch move of this candidate failed

    def __init__(self, doc: Document, manager: jobs.JobManager | None = None, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.jobs = manager or jobs.manager()
        self.seamless_inputs = None  # the inputs doc.tileset.seamless was computed from
        self._seamless_pending = None
        self._template_old_rect = None
        self._auto_size: int | None = None  # the Auto tile size being searched
        self._auto_note: tuple | None = None  # (size, why Auto chose it) when it moved it
        self._seamless_timer = _soon(self, self._start_seamless)
        doc.source_changed.connect(self._on_source_changed)
        doc.maps_changed.connect(self.schedule_seamless)
        doc.tileset.map_weights_changed.connect(self.schedule_seamless)
        doc.tileset.template_changed.connect(self.schedule_seamless)
        doc.tileset.template_changed.connect(self._drop_generation)
        doc.tileset.waypoints_changed.connect(self.schedule_seamless)
        doc.params_changed.connect(self._on_params_changed)
        self._preview_timer = _soon(self, self._start_preview)
        doc.tileset.picks_changed.connect(self.schedule_preview)
        doc.tileset.candidates_reset.connect(self.schedule_preview)
        doc.tileset.candidates_reset.connect(self._drop_remakes)
        doc.tileset.candidate_changed.connect(self._on_candidate_changed)
        doc.exclusion_changed.connect(self.restart_quilt_if_shown)
        self._quilt_timer = _soon(self, self._restart_quilt)
        self._gen_old = ([], [])
        self._gen_wanted, self._gen_next = 0, 0  # candidates asked for / shown in index order
        self._gen_waiting: dict[int, CandidateTile] = {}  # finished before their turn
        self._gen_notice = ""  # the engine's reason when it makes fewer candidates than asked
        self._gen_job: jobs.Job | None = None
        self._gen_rect = None  # the tile rectangle of the running Generate
        self._quilt_mode = "quilt"  # what a parameter change restarts: "quilt" or "transfer"
        self.sweep_samples = SWEEP_SAMPLES  # 0: the template search streams no sweep

    # ------------------------------------------------------------------ helpers
    def _error(self, exc: BaseException) -> None:
        self.message.emit("error", params.ui_words(error_text(exc)))

    @Slot()
    def _on_source_changed(self) -> None:
        for key in ("template", "seamless", "candidates", "preview", "tile_metrics", "quilt"):
            self.jobs.abort(key)
        self.jobs.abort_matching("candidate:")
        self.seamless_inputs = None
        self.template_searching.emit(False)

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        if keys & params.SEAMLESS_KEYS:
            if "overlap" in keys and self.doc.tileset.template_rect is not None:
                clamped = self.doc.tileset.clamp_rect(self.doc.tileset.template_rect)
                if clamped != self.doc.tileset.template_rect:
                    self.doc.tileset.apply_template_rect(clamped)
                    return  # template_changed schedules the seamless job
            self.schedule_seamless()
        if keys & params.PREVIEW_KEYS:
            self.schedule_preview()
        if keys & params.QUILT_KEYS:
            self.restart_quilt_if_shown()

    @Slot()
    def restart_quilt_if_shown(self) -> None:
        """Re-run quilting / transfer after an input changed, if a result is shown or running."""
        if self.jobs.get("quilt") is not None or self.doc.quilting.result is not None:
            self.jobs.abort("quilt")  # its blocks are stale now
            self._quilt_timer.start()

    @Slot(int)
    def _on_candidate_changed(self, index: int) -> None:
        if index in self.doc.tileset.picks:
            self.schedule_preview()

    def stop(self, key: str) -> None:
        self.jobs.stop(key)

    def shutdown(self) -> None:
        """No new jobs from now on (the window closes); running ones are the manager's."""
        for timer in (self._seamless_timer, self._preview_timer, self._quilt_timer):
            timer.stop()
            timer.timeout.disconnect()

    def busy(self) -> bool:
        """True while a job runs or a recompute is scheduled (tests wait for False)."""
        timers = (self._seamless_timer, self._preview_timer, self._quilt_timer)
        return bool(self.jobs.running() or any(t.isActive() for t in timers))

    # ------------------------------------------------------------------ template search
    def find_template(self, *, size: int | None = None) -> jobs.Job | None:
        """Search the best tile rectangle; the rectangle animates as the search improves.

        ``size``: a square tile side instead of the parameters' (the Auto size retries with
        half the side when no tile of its size fits outside the excluded pixels)."""
        from engine.tiles import iter_find_template
        from engine.tiles.template import default_overlap

        doc = self.doc
        if doc.source is None:
            self.message.emit("warning", "Open a source image first.")
            return None
        s = self.settings()
        if size is not None:
            s = s.replace(tile_size=size)
        if doc.params["tile_size"] == params.AUTO and s.tile_size is None:  # under 10 px
            H, W = doc.source.shape[:2]
            n = params.MIN_AUTO_TILE
            self.message.emit(
                "warning",
                f"No square tile fits this {W}×{H} image: “Tile size” Auto (square) needs "
                f"{n + default_overlap(n)} px each way (the smallest tile, {n} px, and its "
                "overlap). Open a larger image.",
            )
            return None
        auto = doc.params["tile_size"] == params.AUTO and s.tile_size is not None
        self._auto_size = s.tile_size[0] if auto else None
        if size is None:  # a retry at half the side keeps the first search's rect and word
            scale = doc.tileset.source_scale() if auto else None
            note = params.auto_size_note(doc.source.shape, scale, self._auto_size)
            self._auto_note = (self._auto_size, note) if note else None
            self._template_old_rect = doc.tileset.template_rect
        lo, hi = s.tile_range(doc.source.shape)
        self.template_searching.emit(True)
        return self.jobs.start(
            "template",
            excluding(iter_find_template),
            doc.source.main,
            label="Finding the best tile",
            exclusion=self.exclusion(),
            flatten=self.flatten_scale(),
            tile_min=lo,
            tile_max=hi,
            overlap=s.overlap or doc.tileset.overlap(),
            joint_weight=s.joint_weight,
            detail_weight=s.detail_weight,
            whole_structures=s.whole_structures,
            sweep=self.sweep_samples,
            on_event=self._on_template_event,
            on_done=self._on_template_done,
            on_error=self._on_template_error,
            on_cancel=self._on_template_cancel,
        )

    def _on_template_event(self, event) -> None:
        from engine.tiles.template import TemplateSweep, TemplateUpdate

        if isinstance(event, TemplateUpdate):
            self.doc.tileset.apply_template_rect(event.rect)
        elif isinstance(event, TemplateSweep):
            self.template_swept.emit(event)

    def _on_template_done(self, template) -> None:
        self.doc.tileset.apply_template_rect(template.rect)
        self.doc.tileset.commit_template_rect(self._template_old_rect)
        x, y, w, h = template.rect
        line = f"Best tile: {w}x{h} at ({x}, {y}), border cost {template.cost:.4f}"
        auto = self._auto_note[1] if self._auto_note and (w, h) == (self._auto_note[0],) * 2 else ""
        self.message.emit("info", f"{line}. {auto}." if auto else line)  # status and banner
        self.settings()  # the source's Auto tone note, said with the search's warnings
        notes = [self.doc.tileset.tone_note, *template.warnings]
        if any(notes) and auto:  # the warning replaces the line on the banner: keep the word
            notes.insert(0, auto)
        if any(notes):  # after the info line, so the banner keeps them, all at once
            self.message.emit("warning", "\n".join(params.sentence(n) for n in notes if n))
        self.template_searching.emit(False)

    def _on_template_error(self, exc) -> None:
        size = self._auto_size
        if size is not None and size > 64 and isinstance(exc.__cause__ or exc, ValueError):
            self.find_template(size=size // 2)  # Auto: the next smaller square that fits
            return
        self._restore_template_rect()
        self._error(exc)

    def _on_template_cancel(self) -> None:
        self._restore_template_rect()
        self.message.emit("info", "Template search cancelled.")

    def _restore_template_rect(self) -> None:
        if self.doc.tileset.template_rect != self._template_old_rect:
            self.doc.tileset.apply_template_rect(self._template_old_rect)
        self.template_searching.emit(False)

    # ------------------------------------------------------------------ seamless tile
    def seamless_request(self) -> tuple | None:
        """(args, kwargs, inputs) of the seamless job for the current document, or None."""
        doc = self.doc
        if doc.source is None or doc.tileset.template_rect is None:
            return None
        wps = {k: v for k, v in doc.tileset.waypoints_in_use().items() if v}
        kwargs = dict(
            overlap=doc.tileset.overlap(),
            waypoints=wps or None,
            seam=self.seam_spec(),
            **self._maps(),
        )
        inputs = (
            doc.tileset.template_rect,
            tuple(sorted((k, repr(v)) for k, v in kwargs.items() if k != "maps")),
            tuple(doc.source.extra_maps),
            self.flatten_scale(),
        )
        return (doc.source.main, doc.tileset.template_rect), kwargs, inputs

    @Slot()
    def schedule_seamless(self) -> None:
        """Recompute the seamless tile soon (coalesces several edits in one event cycle).

        The running job is aborted now: its inputs are stale, so none of its events may
        reach the views any more."""
        self.jobs.abort("seamless")
        self._seamless_timer.start()

    @Slot()
    def _start_seamless(self) -> None:
        from engine.tiles import iter_make_seamless

        req = self.seamless_request()
        if req is None:
            self.jobs.abort("seamless")
            if self.doc.tileset.seamless is not None:
                self.doc.tileset.apply_seamless(None)
            self.seamless_inputs = None
            return
        args, kwargs, inputs = req
        if inputs == self.seamless_inputs and self.jobs.get("seamless") is None:
            return
        self._seamless_pending = inputs
        self.jobs.start(
            "seamless",
            flattening(iter_make_seamless),
            *args,
            flatten=inputs[-1],
            label="Stitching the tile",
            on_event=self._on_seamless_event,
            on_done=self._on_seamless_done,
            on_error=self._on_seamless_error,
            **kwargs,
        )

    def _on_seamless_event(self, event) -> None:
        from engine.tiles.seamless import SeamlessUpdate

        if isinstance(event, SeamlessUpdate):
            self.seam_updated.emit(event)

    def _on_seamless_done(self, result) -> None:
        self.seamless_inputs = self._seamless_pending
        self.doc.tileset.apply_seamless(result)
        for note in result.warnings:
            self.message.emit("warning", params.sentence(note))

    def _on_seamless_error(self, exc) -> None:
        self.seamless_inputs = None
        if self.doc.tileset.seamless is not None:
            self.doc.tileset.apply_seamless(None)
        if not isinstance(exc, Cancelled):
            self._error(exc)

    def settings(self):
        """The tile set's :class:`engine.tiles.TilesetSettings`, from the parameters (Flatten
        lighting's Auto decided for the source: ``doc.tileset.working_settings()``)."""
        return self.doc.tileset.working_settings()

    def flatten_scale(self) -> int | None:
        """The scale the tiles' source is flattened at (TilesetSettings.flatten), or None."""
        from engine.tiles.pipeline import flatten_scale_for

        if self.doc.source is None:
            return None
        return flatten_scale_for(self.settings(), self.doc.source.shape)

    def seam_spec(self):
        """The seamless tile's cut (the candidates' is ``settings().seam``)."""
        return self.settings().template_seam

    def _maps(self) -> dict:
        """The material maps and their seam-error weights."""
        return dict(
            maps=self.doc.source.extra_maps or None,
            weights=self.doc.tileset.engine_weights(),
        )

    # ------------------------------------------------------------------ candidates
    def _tile_options(self) -> dict:
        """Seam and patch options of the candidate calls (from the parameters), with the
        ``exclusion`` that :func:`excluding` turns into their ``excluded`` mask."""
        s = self.settings()
        return dict(
            exclusion=self.exclusion(),
            flatten=self.flatten_scale(),
            patch_size=s.patch_size,
            patch_overlap=s.patch_overlap,
            margin=s.margin,
            patch_search=s.patch_search,
            min_distance=s.min_distance,
            seam=s.seam,
            **self._maps(),
        )

    def _template_ready(self) -> bool:
        doc = self.doc
        if doc.source is None:
            self.message.emit("warning", "Open a source image first.")
            return False
        if doc.tileset.seamless is None or self.seamless_inputs is None:
            self.message.emit(
                "warning",
                "Make the seamless tile first: draw the tile rectangle or use Find best tile.",
            )
            return False
        return True

    @staticmethod
    def kept(c: CandidateTile) -> CandidateTile:
        """What the document keeps of a new candidate: all of it but the tile-sized mask and
        alpha (nothing shows them; 300 large tiles would hold gigabytes of them)."""
        return c.replace(mask=None, alpha=None)

    def generate_candidates(self) -> jobs.Job | None:
        """Stream ``n_candidates`` new variants into the document (locked ones are kept)."""
        from engine.tiles import iter_candidates

        if not self._template_ready():
            return None
        doc = self.doc
        keep, keep_picks, dropped = [], [], 0
        for i, e in enumerate(doc.tileset.candidates):
            if not e.locked:
                continue
            if not doc.tileset.connects_to_template(e):
                dropped += 1
                continue
            if i in doc.tileset.picks:
                keep_picks.append((doc.tileset.picks.index(i), len(keep)))
            keep.append(e)
        if dropped:
            self.message.emit(
                "warning",
                f"{dropped} locked candidate(s) were made from another "
                "template and do not connect to this one; dropped.",
            )
        self.jobs.abort_matching("candidate:")
        self._gen_old = (list(doc.tileset.candidates), list(doc.tileset.picks))
        doc.tileset.apply_candidates(keep, [k for _, k in sorted(keep_picks)])
        s = self.settings()
        n = s.candidates - len(keep)
        self._gen_wanted, self._gen_next, self._gen_waiting = max(0, n), 0, {}
        self._gen_notice = ""
        self._gen_job = None
        self._gen_rect = doc.tileset.template_rect  # the rectangle the candidates connect to
        if n <= 0:
            self._on_candidates_done([])
            return None
        self._gen_job = self.jobs.start(
            "candidates",
            excluding(iter_candidates),
            doc.source.main,
            doc.tileset.seamless,
            n,
            label=f"Generating {n} candidates",
            rng=s.seed,
            neighbourhood=s.neighbourhood,
            workers=2,
            on_event=self._on_candidate_event,
            on_done=self._on_candidates_done,
            on_error=self._on_candidates_error,
            **self._tile_options(),
        )
        return self._gen_job

    @Slot()
    def _drop_remakes(self) -> None:
        """Another set of candidates (Generate, its Undo or Redo): a re-roll or patch move
        still running for the last set's candidate #k would land in this set's #k (ux13)."""
        self.jobs.abort_matching("candidate:")

    @Slot()
    def _drop_generation(self) -> None:
        """The tile rectangle changed (moved, or Undo took back the template) while Generate
        ran: its candidates would not connect to the new one. The run stops and the gallery
        goes back to what it held before Generate, which pushed no undo step yet (it ran on
        and pushed one at the end, over the undone template's redo, with candidates of a
        template no longer there: ux13)."""
        job = self._gen_job
        if job is None or not job.alive or self.doc.tileset.template_rect == self._gen_rect:
            return
        self.jobs.abort("candidates")
        self._gen_job, self._gen_waiting = None, {}
        self.doc.tileset.apply_candidates(*self._gen_old)
        text = (
            "Generation stopped: the tile rectangle changed, and candidates made for the old "
            "one would not connect to it. Generate candidates (Ctrl+G) makes them again."
        )
        if self.doc.tileset.template_rect is None:  # Undo took the template away: Ctrl+G is
            # disabled until there is a tile rectangle again (the banner offered it: ux13)
            text = (
                "Generation stopped: the tile rectangle was taken away. Find best tile (Ctrl+T)"
                " or draw the tile rectangle, then Generate candidates (Ctrl+G)."
            )
        self.message.emit("warning", text)

    def _on_candidate_event(self, event) -> None:
        """Candidates finish in any order; they are shown in the order of their index, so
        candidate #k is the same tile for the same seed (each waits for the ones before it,
        at most a worker's head start)."""
        from engine.tiles.candidates import CandidatesNotice

        if isinstance(event, CandidatesNotice):  # fewer than asked, and why: said at the end
            self._gen_notice = event.message
        elif isinstance(event, CandidateTile):
            self._gen_waiting[int(event.index)] = self.kept(event)
            while self._gen_next in self._gen_waiting:
                self.doc.tileset.append_candidate(self._gen_waiting.pop(self._gen_next))
                self._gen_next += 1

    def _on_candidates_done(self, _result) -> None:
        doc = self.doc
        made = self._gen_next
        for k in sorted(self._gen_waiting):  # after a cancel: the ones that did finish
            doc.tileset.append_candidate(self._gen_waiting.pop(k))
            made += 1
        doc.tileset.set_candidates(
            list(doc.tileset.candidates),
            list(doc.tileset.picks),
            text="Generate candidates",
            old=self._gen_old,
            already_applied=True,
        )
        what = f"{len(doc.tileset.candidates)} candidates"
        level, notice = "info", self._gen_notice
        stopped = self._gen_job is not None and self._gen_job.token.cancelled
        if notice and not stopped:  # the source gave no more: the engine's reason, kept
            level, what = "warning", f"{params.sentence(notice)}. {what}"
        elif made < self._gen_wanted:
            what = f"Generation stopped: {made} of {self._gen_wanted} new candidates made, {what}"
        nxt = (
            "Click to pick the tiles to keep; double-click to open one"
            if doc.tileset.candidates
            else "Generate candidates (Ctrl+G) makes them"  # nothing to click (ux13)
        )
        self.message.emit(level, f"{what}. {nxt}.")

    def _on_candidates_error(self, exc) -> None:
        self._on_candidates_done(None)
        self._error(exc)

    def remake_candidate(self, index: int, *, origin=None) -> jobs.Job | None:
        """Re-roll candidate ``index`` (new random patch) or rebuild it from ``origin``."""
        from engine.tiles import make_candidate

        if not self._template_ready() or not 0 <= index < len(self.doc.tileset.candidates):
            return None
        doc = self.doc
        kw = self._tile_options()
        if origin is None:
            kw.update(
                rng=int(np.random.default_rng().integers(2**31)),
                neighbourhood=self.settings().neighbourhood,
            )
            text = f"Re-roll candidate #{index + 1}"
        else:
            kw.update(patch_origin=(int(origin[0]), int(origin[1])))
            text = f"Move patch of candidate #{index + 1}"
        return self.jobs.start(
            f"candidate:{index}",
            excluding(make_candidate),
            doc.source.main,
            doc.tileset.seamless,
            index=index,
            label=text,
            on_done=partial(self._on_remade, text),
            on_error=partial(self._on_remake_error, index),
            **kw,
        )

    def _on_remade(self, text: str, c) -> None:
        index = int(c.index)
        if index >= len(self.doc.tileset.candidates):
            return
        entry = self.kept(c).replace(weight=self.doc.tileset.candidates[index].weight)
        self.doc.tileset.replace_candidate(index, entry, text=text)

    def _on_remake_error(self, index: int, exc) -> None:
        self._error(exc)
        self.candidate_failed.emit(index)

    # ------------------------------------------------------------------ preview
    @Slot()
    def schedule_preview(self) -> None:
        self.jobs.abort("preview")
        self._preview_timer.start()

    @Slot()
    def _start_preview(self) -> None:
        doc = self.doc
        tiles = [e.tile for e in doc.tileset.picked_entries()]
        if not tiles or doc.source is None:
            self.jobs.abort("preview")
            if doc.tileset.preview is not None or doc.tileset.layout is not None:
                doc.tileset.apply_layout(None)
                doc.tileset.apply_preview(None, None)
            return
        s = self.settings()
        weights = [e.weight for e in doc.tileset.picked_entries()]
        self.jobs.start(
            "preview",
            make_preview,
            tiles,
            doc.source.main,
            label="Preview",
            rows=s.preview[0],
            cols=s.preview[1],
            seed=s.layout_seed,
            no_equal_neighbours=s.no_equal_neighbours,
            weights=weights,
            on_done=self._on_preview_done,
            on_error=self._error,
        )

    def _on_preview_done(self, result) -> None:
        layout, image, score = result
        self.doc.tileset.apply_layout(layout)
        self.doc.tileset.apply_preview(image, score)

    # ------------------------------------------------------------------ quilting
    def run_quilt(self, may_replace=None) -> jobs.Job | None:
        """Synthesize ``out_height`` x ``out_width`` from the source; blocks stream in.

        The options are checked first: a run that cannot start leaves the shown output as
        it is, and ``may_replace()`` (asks before an unsaved output goes) is asked only then."""
        doc = self.doc
        if doc.source is None:
            self.message.emit("warning", "Open a sample image first.")
            return None
        problem = self.quilt_problem()
        if problem is not None:
            self.message.emit("error", problem)
            return None
        if may_replace is not None and not may_replace():
            return None
        self._quilt_mode = "quilt"
        p = doc.params
        shape = params.output_shape(p, doc.source.shape)
        doc.quilting.start(shape)
        return self.jobs.start(
            "quilt",
            quilt_job,
            doc.source.main,
            shape,
            label="Quilting",
            exclusion=self.exclusion(),
            on_event=self._on_quilt_event,
            on_done=self._on_quilt_done,
            on_error=self._on_quilt_error,
            on_cancel=self._on_quilt_cancel,
            **quilt_options(p),
        )

    def quilt_problem(self) -> str | None:
        """Why quilting cannot run with the parameters on this source (the editor's words),
        or None. The engine's own check of the options, on the source's shape only (the
        excluded pixels are checked in the job)."""
        from engine.quilting.options import check_options

        p, shape = self.doc.params, self.doc.source.main.shape
        opts = quilt_options(p)
        opts.pop("rng")
        stand_in = np.broadcast_to(np.float32(0), shape)  # no copy of a large source
        try:
            check_options(stand_in, params.output_shape(p, shape), excluded=None, **opts)
        except (ValueError, TypeError) as exc:
            return params.quilt_words(str(exc))
        return None

    def transfer_options(self) -> dict:
        """Keyword options of :func:`engine.transfer.iter_transfer` from the parameters."""
        p = self.doc.params
        opts = quilt_options(p)
        for key in ("select", "candidates", "tileable", "adaptive_threshold", "min_block"):
            opts.pop(key)
        alpha = None if p["alpha_ramp"] else p["alpha"]
        keys = ("iterations", "correspondence", "sigma")
        return opts | {"alpha": alpha} | {k: p[k] for k in keys}

    def transfer_problem(self, opts: dict) -> str | None:
        """Why the transfer cannot run with ``opts`` on this source and target (the editor's
        words), or None: the engine's check on the source's shape (as :meth:`quilt_problem`)."""
        from engine.transfer import transfer_plans

        opts = {k: v for k, v in opts.items() if k != "rng"}
        stand_in = np.broadcast_to(np.float32(0), self.doc.source.main.shape)
        try:
            transfer_plans(stand_in, self.doc.quilting.target.shape[:2], excluded=None, **opts)
        except (ValueError, TypeError) as exc:
            return params.quilt_words(str(exc))
        return None

    def exclusion(self) -> tuple:
        """(colour, tolerance, painted mask): the arguments of :func:`excluded_mask` (the
        source pixels the template search, the candidates and quilting never use)."""
        p = self.doc.params
        return p["exclude_color"], p["exclude_tolerance"], self.doc.exclude_painted

    def run_transfer(self, may_replace=None) -> jobs.Job | None:
        """Texture transfer of the source onto the target's layout; passes stream in. The
        options are checked before the shown output is cleared (as :meth:`run_quilt`)."""
        doc = self.doc
        if doc.source is None:
            self.message.emit("warning", "Open a sample image first.")
            return None
        if doc.quilting.target is None:
            self.message.emit("warning", "Load a target image first (Quilting ▸ Load target).")
            return None
        opts = self.transfer_options()
        problem = self.transfer_problem(opts)
        if problem is not None:
            self.message.emit("error", problem)
            return None
        if may_replace is not None and not may_replace():
            return None
        self._quilt_mode = "transfer"
        doc.quilting.start(doc.quilting.target.shape[:2])
        return self.jobs.start(
            "quilt",
            transfer_job,
            doc.source.main,
            doc.quilting.target,
            label="Texture transfer",
            exclusion=self.exclusion(),
            on_event=self._on_quilt_event,
            on_done=self._on_quilt_done,
            on_error=self._on_quilt_error,
            on_cancel=self._on_quilt_cancel,
            **opts,
        )

    def _on_quilt_event(self, event) -> None:
        from engine.quilting import BlockPlaced, Estimated
        from engine.transfer import IterationDone

        if self.doc.quilting.output is None:
            return
        if isinstance(event, BlockPlaced):
            self.doc.quilting.place_block(event.record, np.asarray(event.pixels))
        elif isinstance(event, IterationDone):
            self.doc.quilting.finish_iteration(event)
        elif isinstance(event, Estimated) and (job := self.jobs.get("quilt")) is not None:
            job.estimate = f"estimate: {event.plan.describe()}"  # the status bar shows it
            self.jobs.progress.emit(job)

    def _on_quilt_done(self, result) -> None:
        self.doc.quilting.finish(result)
        h, w = result.image.shape[:2]
        from engine.transfer import TransferResult

        if isinstance(result, TransferResult):
            what = f"in {len(result.iterations)} transfer passes"
        else:
            what = f"from {len(result.blocks)} blocks"
        self.message.emit(
            "info",
            f"Synthesized {w}×{h} {what}{self.doc.quilting.colour_only()}. Click a block to see "
            "its overlap, error map and seam.",
        )

    def _on_quilt_error(self, exc: BaseException) -> None:
        """A run that failed in its job (e.g. every block position excluded): its empty
        output goes (the view does not say "quilting…" for ever), the message says why."""
        self.doc.quilting.start(None)
        self.message.emit("error", params.quilt_words(params.ui_words(error_text(exc))))

    def _on_quilt_cancel(self) -> None:
        what = "Texture transfer" if self._quilt_mode == "transfer" else "Quilting"
        n = len(self.doc.quilting.blocks)
        where = " of this pass" if self._quilt_mode == "transfer" else ""
        self.message.emit("info", f"{what} cancelled after {n} blocks{where}.")

    @Slot()
    def _restart_quilt(self) -> None:
        if self._quilt_mode == "transfer":
            self.run_transfer()
        else:
            self.run_quilt()

    def reroll_layout(self) -> None:
        """A new random layout for the preview (one undo step: the layout seed changes)."""
        seed = int(np.random.default_rng().integers(2**31 - 1))
        self.doc.set_param("layout_seed", seed, text="Re-roll layout")
