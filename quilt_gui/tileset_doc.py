"""The tile-set workflow's part of the document: template rectangle, waypoints, seamless
tile, candidates, picks, preview layout, and the material maps' seam weights.

User edits push :mod:`quilt_gui.commands` on :attr:`TileSetDocument.undo_stack`; their
``redo``/``undo`` call the ``apply_*`` methods. Results streamed by jobs (the template
search's moving rectangle, candidates arriving one by one) are applied directly and are not
undo steps; a finished job pushes one command for its final result.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from PySide6.QtCore import QObject, Signal

from engine.candidate import CandidateTile
from quilt_gui import commands, params
from quilt_gui.model import WAYPOINT_KEYS


class TileSetDocument(QObject):
    """Template, seamless tile, candidates, picks, layout, waypoints of ``root``'s source.

    ``root`` is the :class:`quilt_gui.document.Document` (source, parameters, undo).
    """

    map_weights_changed = Signal()
    template_changed = Signal()  # template rectangle
    waypoints_changed = Signal()
    seamless_changed = Signal()
    candidates_reset = Signal()
    candidate_inserted = Signal(int)  # row
    candidate_changed = Signal(int)  # row
    picks_changed = Signal()
    layout_changed = Signal()
    preview_changed = Signal()
    tone_changed = Signal()  # what Flatten lighting's Auto switched on (tone_note, auto_blend)

    def __init__(self, root, undo_stack) -> None:
        super().__init__(root)
        self.root = root
        self.undo_stack = undo_stack
        self.template_rect: tuple[int, int, int, int] | None = None
        self.waypoints: dict[str, list[tuple[int, int]]] = {k: [] for k in WAYPOINT_KEYS}
        self.map_weights: dict[str, float] = {}  # seam-error weight per map; {} = main only
        self.seamless = None  # engine SeamlessTile (derived)
        self.tone_note: str | None = None  # what Flatten lighting's Auto switched on
        self.auto_blend: str | None = None  # the seam blend Auto put in place of the chosen one
        self._tone = None  # (inputs, settings, note) of the last Auto decision
        self._scale = None  # (source pixels, their structure scale): the Auto tile size
        self.candidates: list[CandidateTile] = []
        self.picks: list[int] = []
        self.layout: np.ndarray | None = None
        self.preview: np.ndarray | None = None  # derived
        self.grid_score: float | None = None

    def clear(self) -> None:
        """Forget every result (a new source); emits every signal."""
        self.template_rect = None
        self.waypoints = {k: [] for k in WAYPOINT_KEYS}
        self.map_weights = {}
        self.seamless = None
        self.candidates, self.picks, self.layout = [], [], None
        self.preview, self.grid_score = None, None
        self.emit_all()

    def emit_all(self) -> None:
        """Every view redraws (after a whole-document change)."""
        for signal in (
            self.template_changed,
            self.waypoints_changed,
            self.map_weights_changed,
            self.seamless_changed,
            self.candidates_reset,
            self.picks_changed,
            self.layout_changed,
            self.preview_changed,
        ):
            signal.emit()

    # ------------------------------------------------------------------ state
    def picked_entries(self) -> list[CandidateTile]:
        return [self.candidates[i] for i in self.picks]

    def connects_to_template(self, entry: CandidateTile) -> bool:
        """True when ``entry`` was made from the current seamless template (same size and
        outer margin), i.e. it connects to tiles made from it.

        The borders are compared as saved: within one step of the source's bit depth, since a
        reopened project's candidates come back rounded to it while the template is
        recomputed exactly."""
        if self.seamless is None:
            return False
        template = np.asarray(self.seamless.tile)
        tile, m = np.asarray(entry.tile), max(1, int(self.root.params["margin"]))
        if tile.shape != template.shape:
            return False
        depth = self.root.source.bit_depth if self.root.source is not None else 8
        step = 1.0 / (2**depth - 1)
        sides = (np.s_[:m], np.s_[-m:], np.s_[:, :m], np.s_[:, -m:])
        return all(np.abs(tile[s] - template[s]).max() <= step for s in sides)

    @property
    def candidates_outdated(self) -> bool:
        """The candidates were made from an earlier template (they still connect to each
        other, not to tiles of the current one)."""
        return (
            bool(self.candidates)
            and self.seamless is not None
            and not (self.connects_to_template(self.candidates[0]))
        )

    def settings(self):
        """The tile set's :class:`engine.settings.TilesetSettings` for the source at hand."""
        source = self.root.source
        if source is None:
            return params.tileset_settings(self.root.params)
        return params.tileset_settings(self.root.params, source.shape, self.source_scale())

    def source_scale(self):
        """The source's structure scale (:func:`engine.tiles.scale.structure_scale`, measured
        once per image), which the Auto tile size keeps whole periods of; None without a
        source or when the tile size is not Auto."""
        source = self.root.source
        if source is None or self.root.params["tile_size"] != params.AUTO:
            return None
        if self._scale is None or self._scale[0] is not source.main:  # a new image
            from engine.tiles.scale import structure_scale

            self._scale = (source.main, structure_scale(source.main))
        return self._scale[1]

    def working_settings(self):
        """:meth:`settings` with Flatten lighting's Auto decided for the source at hand
        (:func:`engine.tiles.pipeline.auto_tone`: the settings every job runs with) and
        :attr:`tone_note`, the sentence saying what Auto switched on (None: nothing)."""
        from engine.tiles.pipeline import auto_tone

        s, source = self.settings(), self.root.source
        said = (self.tone_note, self.auto_blend)
        self.tone_note = self.auto_blend = None
        resolved = s
        if source is not None and s.flatten is None:
            key = (id(source.main), source.main.shape, s)
            cached = getattr(self, "_tone", None)
            if cached is None or cached[0] != key:
                self._tone = (key, *auto_tone(s, source.main))
            resolved, self.tone_note = self._tone[1], self._tone[2]
            if resolved.seam.blend != s.seam.blend:
                self.auto_blend = resolved.seam.blend
        if (self.tone_note, self.auto_blend) != said:
            self.tone_changed.emit()
        return resolved

    def overlap(self) -> int:
        """w_T, the Seam search width: the parameter, or (auto) about a tenth of the tile."""
        from engine.tiles.pipeline import resolve

        source = self.root.source
        if self.root.params["overlap"] or source is None:
            return int(self.root.params["overlap"]) or 16
        return int(resolve(self.settings(), source.shape).overlap)

    def clamp_rect(self, rect) -> tuple[int, int, int, int]:
        """``rect`` (x, y, w, h) moved and shrunk so its footprint (the rectangle plus the
        overlap to the right and below) lies inside the source."""
        x, y, w, h = (int(round(v)) for v in rect)
        source = self.root.source
        if source is None:
            return x, y, max(1, w), max(1, h)
        H, W = source.shape
        e = min(self.overlap(), max(0, min(H, W) - 1))
        w, h = max(1, min(w, W - e)), max(1, min(h, H - e))
        x, y = min(max(0, x), W - e - w), min(max(0, y), H - e - h)
        return x, y, w, h

    # ------------------------------------------------------------------ user edits (undoable)
    def set_template_rect(
        self, rect, *, merge_id: int | None = None, text: str = "Move tile rectangle"
    ) -> None:
        rect = self.clamp_rect(rect)
        if rect == self.template_rect:
            return
        self.undo_stack.push(commands.SetTemplateRect(self, rect, merge_id=merge_id, text=text))

    def commit_template_rect(self, old, *, text: str = "Find best tile") -> None:
        """One undo step for a rectangle the template search already streamed in."""
        if old != self.template_rect:
            self.undo_stack.push(
                commands.SetTemplateRect(
                    self, self.template_rect, text=text, old=old, already_applied=True
                )
            )

    def waypoints_in_use(self) -> dict[str, list[tuple[int, int]]]:
        """The waypoints inside the error maps of the current rectangle and Seam search width:
        a smaller rectangle leaves some outside (kept, for an undo or a larger one; the engine
        refuses them, so the seams and the views use these)."""
        if self.template_rect is None:
            return {k: [] for k in WAYPOINT_KEYS}
        _, _, a, b = self.template_rect
        ov = self.overlap()
        shape = {"horizontal": (b + ov, ov), "vertical": (ov, a)}  # error map (rows, cols)
        return {
            k: [(r, c) for r, c in self.waypoints[k] if r < shape[k][0] and c < shape[k][1]]
            for k in WAYPOINT_KEYS
        }

    def add_waypoint(self, key: str, point: tuple[int, int]) -> None:
        pt = (int(point[0]), int(point[1]))
        if pt in self.waypoints[key]:
            return
        new = {**self.waypoints, key: [*self.waypoints[key], pt]}
        self.undo_stack.push(commands.SetWaypoints(self, new, "Add waypoint"))

    def remove_waypoint(self, key: str, point: tuple[int, int]) -> None:
        new = {**self.waypoints, key: [p for p in self.waypoints[key] if p != tuple(point)]}
        if new[key] != self.waypoints[key]:
            self.undo_stack.push(commands.SetWaypoints(self, new, "Remove waypoint"))

    def clear_waypoints(self) -> None:
        if any(self.waypoints.values()):
            new = {k: [] for k in WAYPOINT_KEYS}
            self.undo_stack.push(commands.SetWaypoints(self, new, "Clear waypoints"))

    def set_picks(self, picks, *, text: str = "Pick tiles") -> commands.SetPicks | None:
        """Pick these candidates (in this order); returns the undo step, None if unchanged."""
        picks = [int(i) for i in dict.fromkeys(picks) if 0 <= int(i) < len(self.candidates)]
        if picks == self.picks:
            return None
        command = commands.SetPicks(self, picks, text)
        self.undo_stack.push(command)
        return command

    def toggle_pick(self, index: int) -> commands.SetPicks | None:
        if index in self.picks:
            return self.set_picks([i for i in self.picks if i != index], text="Unpick tile")
        return self.set_picks([*self.picks, index], text="Pick tile")

    def retract(self, command) -> bool:
        """Undo ``command`` and drop it from the history if it is the newest step.

        For a click that turns out to be the first half of a double-click: the double-click
        leaves neither the pick nor an undo (or redo) step behind.
        """
        st = self.undo_stack
        n = st.count()
        if command is None or not n or st.index() != n or st.command(n - 1) is not command:
            return False
        command.undo()
        command.setObsolete(True)  # QUndoStack.undo() deletes an obsolete command unapplied
        st.undo()
        return True

    def set_candidates(
        self,
        entries: list[CandidateTile],
        picks: list[int],
        *,
        text: str,
        old=None,
        already_applied: bool = False,
    ) -> None:
        """Replace all candidates and picks (one undo step); ``already_applied`` when the
        entries streamed in already and ``old`` is the (candidates, picks) before that."""
        self.undo_stack.push(
            commands.SetCandidates(
                self, entries, picks, text, old=old, already_applied=already_applied
            )
        )

    def replace_candidate(self, index: int, entry: CandidateTile, *, text: str) -> None:
        self.undo_stack.push(commands.ReplaceCandidate(self, index, entry, text))

    def set_locked(self, index: int, locked: bool) -> None:
        entry = self.candidates[index]
        if entry.locked != locked:
            self.replace_candidate(
                index, replace(entry, locked=locked), text="Lock tile" if locked else "Unlock tile"
            )

    def set_weight(self, index: int, weight: float) -> None:
        entry = self.candidates[index]
        if entry.weight != weight:
            self.replace_candidate(
                index, replace(entry, weight=float(weight)), text="Change tile weight"
            )

    def set_map_weight(self, name: str, weight: float) -> None:
        """How much map ``name`` counts in the seam error (main map 1, others 0 by default)."""
        source = self.root.source
        if source is None or name not in source.maps:
            raise ValueError(f"no material map named {name!r}")
        weight = max(0.0, float(weight))
        if self.map_weight(name) == weight:
            return
        new = {**self.map_weights, name: weight}
        self.undo_stack.push(commands.SetMapWeights(self, new, f"Seam weight of {name}"))

    def map_weight(self, name: str) -> float:
        source = self.root.source
        default = 1.0 if source is not None and name == source.main_name else 0.0
        return float(self.map_weights.get(name, default))

    def engine_weights(self) -> dict[str, float] | None:
        """The ``weights`` of the engine's seam calls ("main" is the source), None when only
        the main map counts (the engine's default)."""
        source = self.root.source
        if source is None:
            return None
        names = list(source.maps)
        w = {("main" if n == names[0] else n): self.map_weight(n) for n in names}
        if w["main"] == 1.0 and not any(v for k, v in w.items() if k != "main"):
            return None
        return w

    # ------------------------------------------------------------------ apply (commands, jobs)
    def apply_template_rect(self, rect) -> None:
        self.template_rect = None if rect is None else tuple(int(v) for v in rect)
        self.template_changed.emit()

    def apply_waypoints(self, waypoints: dict) -> None:
        self.waypoints = {k: list(waypoints.get(k, [])) for k in WAYPOINT_KEYS}
        self.waypoints_changed.emit()

    def apply_map_weights(self, weights: dict) -> None:
        self.map_weights = {k: float(v) for k, v in weights.items()}
        self.map_weights_changed.emit()

    def apply_picks(self, picks: list[int]) -> None:
        self.picks = list(picks)
        self.picks_changed.emit()

    def apply_candidates(
        self, entries: list[CandidateTile], picks: list[int] | None = None
    ) -> None:
        self.candidates = list(entries)
        self.picks = [i for i in (picks if picks is not None else []) if i < len(entries)]
        self.candidates_reset.emit()
        self.picks_changed.emit()

    def append_candidate(self, entry: CandidateTile) -> int:
        """Add a streamed candidate (not an undo step; the finished job pushes one)."""
        self.candidates.append(entry)
        row = len(self.candidates) - 1
        self.candidate_inserted.emit(row)
        self.root.mark_dirty()
        return row

    def apply_candidate(self, index: int, entry: CandidateTile) -> None:
        self.candidates[index] = entry
        self.candidate_changed.emit(index)

    def apply_layout(self, layout) -> None:
        self.layout = None if layout is None else np.asarray(layout, dtype=np.int64)
        self.layout_changed.emit()

    def apply_seamless(self, result) -> None:
        self.seamless = result
        self.seamless_changed.emit()

    def apply_preview(self, image: np.ndarray | None, grid_score: float | None) -> None:
        self.preview = image
        self.grid_score = grid_score
        self.preview_changed.emit()
