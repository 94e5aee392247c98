"""The document: one QObject holding everything the user works on, and its signals.

Views subscribe to the signals; every user edit goes through a method that pushes a
:mod:`quilt_gui.commands` QUndoCommand, whose ``redo``/``undo`` call the ``apply_*``
methods here. Results streamed by background jobs (the template search's moving
rectangle, candidates arriving one by one) are applied directly and are not undo steps;
a finished job pushes one command for its final result.

The document holds no widgets and builds no QImages. Its serialization is
:class:`engine.project.Project` (:meth:`to_project` / :meth:`from_project`).
"""

from __future__ import annotations

import base64
import re
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal, Slot
from PySide6.QtGui import QUndoStack

from engine.project import Candidate, Project
from quilt_gui import commands, params

WAYPOINT_KEYS = ("horizontal", "vertical")


@dataclass(frozen=True)
class CandidateEntry:
    """One candidate tile as the editor shows it.

    ``maps`` holds the tile per material map (main map first); ``patch_rect`` is the
    patch source in source pixels (x, y, w, h) and ``patch_origin`` its (row, col);
    ``target_rect`` where that window lies in the tile (x, y, w, h); ``loop`` the closed
    seam pixels (row, col) in tile coordinates.
    """

    maps: dict[str, np.ndarray]
    patch_origin: tuple[int, int] | None = None
    patch_rect: tuple[int, int, int, int] | None = None
    seed: int | None = None
    score: float | None = None
    scores: dict = field(default_factory=dict)
    locked: bool = False
    weight: float = 1.0
    loop: np.ndarray | None = None
    target_rect: tuple[int, int, int, int] | None = None

    @property
    def tile(self) -> np.ndarray:
        return next(iter(self.maps.values()))


@dataclass(frozen=True)
class Source:
    """The opened source: material maps (main first), where they came from, bit depth."""

    maps: dict[str, np.ndarray]
    paths: dict[str, str]
    bit_depth: int = 8
    kinds: dict[str, str] = field(default_factory=dict)

    @property
    def main(self) -> np.ndarray:
        return next(iter(self.maps.values()))

    @property
    def main_name(self) -> str:
        return next(iter(self.maps))

    @property
    def extra_maps(self) -> dict[str, np.ndarray]:
        """The material maps other than the main one."""
        return {k: v for k, v in self.maps.items() if k != self.main_name}

    @property
    def path(self) -> str:
        return next(iter(self.paths.values()), "")

    @property
    def shape(self) -> tuple[int, int]:
        return self.main.shape[:2]


def safe_name(text: str) -> str:
    """A project / file-name part made of letters, digits, ``. _ -`` (export names)."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._-")
    return (s or "tileset")[:100]


class Document(QObject):
    """Source, parameters, template, seamless tile, candidates, picks, layout, waypoints."""

    source_changed = Signal()
    maps_changed = Signal()
    map_weights_changed = Signal()
    params_changed = Signal(object)  # frozenset of changed keys
    template_changed = Signal()  # template rectangle
    waypoints_changed = Signal()
    seamless_changed = Signal()
    candidates_reset = Signal()
    candidate_inserted = Signal(int)  # row
    candidate_changed = Signal(int)  # row
    picks_changed = Signal()
    layout_changed = Signal()
    preview_changed = Signal()
    modified_changed = Signal(bool)
    path_changed = Signal()
    quilt_reset = Signal()  # a synthesis started (or was cleared)
    block_placed = Signal(int)  # index into quilt_blocks
    quilt_finished = Signal()
    quilt_iteration = Signal(int)  # a texture-transfer pass finished (its number)
    target_changed = Signal()
    exclusion_changed = Signal()  # the painted exclusion mask

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.source: Source | None = None
        self.name = "tileset"
        self.params: dict[str, Any] = dict(params.DEFAULTS)
        self.template_rect: tuple[int, int, int, int] | None = None
        self.waypoints: dict[str, list[tuple[int, int]]] = {k: [] for k in WAYPOINT_KEYS}
        self.map_weights: dict[str, float] = {}  # seam-error weight per map; {} = main only
        self.seamless = None  # engine SeamlessTile (derived)
        self.candidates: list[CandidateEntry] = []
        self.picks: list[int] = []
        self.layout: np.ndarray | None = None
        self.preview: np.ndarray | None = None  # derived
        self.grid_score: float | None = None
        self.project_path: str | None = None
        self.quilt_output: np.ndarray | None = None  # being synthesized, (H, W, C)
        self.quilt_blocks: list = []  # engine BlockRecord per placed block
        self.quilt_result = None  # engine QuiltResult / TransferResult when finished
        self.transfer_target: np.ndarray | None = None  # the image a transfer imitates
        # (H, W) bool: source pixels the template search, the candidates and quilting never
        # use (with the exclude_color range); saved in the project's extra["exclude_painted"]
        self.exclude_painted: np.ndarray | None = None
        self._dirty = False  # changes that are not undo steps (streamed results)
        self._was_modified = False
        self.undo_stack.cleanChanged.connect(self._on_clean_changed)

    # ------------------------------------------------------------------ state
    @property
    def has_source(self) -> bool:
        return self.source is not None

    @property
    def modified(self) -> bool:
        return self._dirty or not self.undo_stack.isClean()

    def mark_dirty(self) -> None:
        self._dirty = True
        self._emit_modified()

    def mark_saved(self, path: str | None = None) -> None:
        self._dirty = False
        self.undo_stack.setClean()
        if path is not None and path != self.project_path:
            self.project_path = path
            self.path_changed.emit()
        self._emit_modified()

    @Slot(bool)
    def _on_clean_changed(self, _clean: bool) -> None:
        self._emit_modified()

    def _emit_modified(self) -> None:
        m = self.modified
        if m != self._was_modified:
            self._was_modified = m
            self.modified_changed.emit(m)

    def picked_entries(self) -> list[CandidateEntry]:
        return [self.candidates[i] for i in self.picks]

    def connects_to_template(self, entry: CandidateEntry) -> bool:
        """True when ``entry`` was made from the current seamless template (same size and
        outer margin), i.e. it connects to tiles made from it."""
        if self.seamless is None:
            return False
        template = np.asarray(self.seamless.tile)
        tile, m = np.asarray(entry.tile), max(1, int(self.params["margin"]))
        return tile.shape == template.shape and bool(
            np.array_equal(tile[:m], template[:m])
            and np.array_equal(tile[-m:], template[-m:])
            and np.array_equal(tile[:, :m], template[:, :m])
            and np.array_equal(tile[:, -m:], template[:, -m:])
        )

    @property
    def candidates_outdated(self) -> bool:
        """The candidates were made from an earlier template (they still connect to each
        other, not to tiles of the current one)."""
        return (
            bool(self.candidates)
            and self.seamless is not None
            and not (self.connects_to_template(self.candidates[0]))
        )

    # ------------------------------------------------------------------ user edits (undoable)
    def set_param(
        self, key: str, value: Any, *, merge_id: int | None = None, text: str | None = None
    ) -> None:
        """Change one parameter; consecutive changes with the same ``merge_id`` are one step.

        The undo step is named after the parameter's label ("Change Seam method")."""
        p = params.BY_KEY[key]
        value = p.coerce(value)
        if self.params.get(key) == value:
            return
        text = text or f"Change {p.label}"
        self.undo_stack.push(commands.SetParams(self, {key: value}, merge_id=merge_id, text=text))

    def set_params(self, values: dict, *, text: str = "Change parameters") -> None:
        values = {k: params.BY_KEY[k].coerce(v) for k, v in values.items()}
        values = {k: v for k, v in values.items() if self.params.get(k) != v}
        if values:
            self.undo_stack.push(commands.SetParams(self, values, text=text))

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
        entries: list[CandidateEntry],
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

    def replace_candidate(self, index: int, entry: CandidateEntry, *, text: str) -> None:
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
        if self.source is None or name not in self.source.maps:
            raise ValueError(f"no material map named {name!r}")
        weight = max(0.0, float(weight))
        if self.map_weight(name) == weight:
            return
        new = {**self.map_weights, name: weight}
        self.undo_stack.push(commands.SetMapWeights(self, new, f"Seam weight of {name}"))

    def map_weight(self, name: str) -> float:
        default = 1.0 if self.source is not None and name == self.source.main_name else 0.0
        return float(self.map_weights.get(name, default))

    def engine_weights(self) -> dict[str, float] | None:
        """The ``weights`` of the engine's seam calls ("main" is the source), None when only
        the main map counts (the engine's default)."""
        if self.source is None:
            return None
        names = list(self.source.maps)
        w = {("main" if n == names[0] else n): self.map_weight(n) for n in names}
        if w["main"] == 1.0 and not any(v for k, v in w.items() if k != "main"):
            return None
        return w

    # ------------------------------------------------------------------ apply (commands, jobs)
    def apply_params(self, values: dict) -> None:
        self.params.update(values)
        self.params_changed.emit(frozenset(values))

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
        self, entries: list[CandidateEntry], picks: list[int] | None = None
    ) -> None:
        self.candidates = list(entries)
        self.picks = [i for i in (picks if picks is not None else []) if i < len(entries)]
        self.candidates_reset.emit()
        self.picks_changed.emit()

    def append_candidate(self, entry: CandidateEntry) -> int:
        """Add a streamed candidate (not an undo step; the finished job pushes one)."""
        self.candidates.append(entry)
        row = len(self.candidates) - 1
        self.candidate_inserted.emit(row)
        self.mark_dirty()
        return row

    def apply_candidate(self, index: int, entry: CandidateEntry) -> None:
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

    # ------------------------------------------------------------------ quilting (streamed)
    def start_quilt(self, shape: tuple[int, int] | None) -> None:
        """Clear the quilting output (None) or start a new one of ``shape`` (H, W)."""
        if shape is None or self.source is None:
            self.quilt_output = None
        else:
            c = self.source.main.shape[2]
            self.quilt_output = np.zeros((*shape, c), dtype=np.float32)
        self.quilt_blocks = []
        self.quilt_result = None
        self.quilt_reset.emit()

    def place_block(self, record, pixels: np.ndarray) -> int:
        """Paste a placed block into the output (wrapping on a torus) and keep its record."""
        H, W = self.quilt_output.shape[:2]
        r, c = record.position
        h, w = pixels.shape[:2]
        rows, cols = (r + np.arange(h)) % H, (c + np.arange(w)) % W
        self.quilt_output[np.ix_(rows, cols)] = pixels
        self.quilt_blocks.append(record)
        self.block_placed.emit(len(self.quilt_blocks) - 1)
        return len(self.quilt_blocks) - 1

    def finish_iteration(self, event) -> None:
        """A transfer pass ended: the output is its image; the next pass places new blocks."""
        self.quilt_output = np.array(event.image, dtype=np.float32)
        self.quilt_blocks = []
        self.quilt_iteration.emit(int(event.iteration))

    def set_painted(self, mask: np.ndarray | None, *, text: str = "Paint exclusion") -> None:
        """Replace the painted exclusion mask (one undo step)."""
        self.undo_stack.push(commands.SetPainted(self, mask, text))

    def apply_painted(self, mask: np.ndarray | None) -> None:
        self.exclude_painted = mask
        self.exclusion_changed.emit()

    def set_transfer_target(self, pixels: np.ndarray | None) -> None:
        self.transfer_target = pixels
        self.target_changed.emit()

    def finish_quilt(self, result) -> None:
        self.quilt_result = result
        self.quilt_output = np.asarray(result.image, dtype=np.float32)  # the worker's display
        # copy of this very array is cached (imaging.prepare_display): no copy here
        self.quilt_blocks = list(result.blocks)
        self.quilt_finished.emit()

    def block_at(self, row: int, col: int) -> int | None:
        """Index of the last placed block covering output pixel (row, col), or None."""
        if self.quilt_output is None:
            return None
        H, W = self.quilt_output.shape[:2]
        for i in range(len(self.quilt_blocks) - 1, -1, -1):
            rec = self.quilt_blocks[i]
            (r, c), (h, w) = rec.position, rec.size
            if (row - r) % H < h and (col - c) % W < w:
                return i
        return None

    # ------------------------------------------------------------------ whole-document changes
    def clamp_rect(self, rect) -> tuple[int, int, int, int]:
        """``rect`` (x, y, w, h) moved and shrunk so its footprint (the rectangle plus the
        overlap to the right and below) lies inside the source."""
        x, y, w, h = (int(round(v)) for v in rect)
        if self.source is None:
            return x, y, max(1, w), max(1, h)
        H, W = self.source.shape
        e = min(int(self.params["overlap"]), max(0, min(H, W) - 1))
        w, h = max(1, min(w, W - e)), max(1, min(h, H - e))
        x, y = min(max(0, x), W - e - w), min(max(0, y), H - e - h)
        return x, y, w, h

    def set_source(self, source: Source, *, name: str | None = None) -> None:
        """Start over on a new source (clears results and the undo history)."""
        self.source = source
        self.name = safe_name(name or Path(source.path).stem or "tileset")
        self.template_rect = None
        self.waypoints = {k: [] for k in WAYPOINT_KEYS}
        self.map_weights = {}
        self.seamless = None
        self.candidates, self.picks, self.layout = [], [], None
        self.preview, self.grid_score = None, None
        self.project_path = None
        self.undo_stack.clear()
        self._dirty = False
        self.source_changed.emit()
        self.maps_changed.emit()
        self.template_changed.emit()
        self.waypoints_changed.emit()
        self.map_weights_changed.emit()
        self.seamless_changed.emit()
        self.candidates_reset.emit()
        self.picks_changed.emit()
        self.layout_changed.emit()
        self.preview_changed.emit()
        self.path_changed.emit()
        self.apply_painted(None)
        self.start_quilt(None)
        self._emit_modified()

    def attach_map(self, name: str, pixels: np.ndarray, path: str, kind: str) -> None:
        """Add a co-registered material map (same height and width as the main map)."""
        if self.source is None:
            raise ValueError("open a source image before attaching material maps")
        if pixels.shape[:2] != self.source.shape:
            h, w = self.source.shape
            raise ValueError(
                f"{path}: the map is {pixels.shape[1]}x{pixels.shape[0]} but the source is {w}x{h};"
                " material maps must have the source's size"
            )
        maps = {**self.source.maps, name: pixels}
        self.source = replace(
            self.source,
            maps=maps,
            paths={**self.source.paths, name: path},
            kinds={**self.source.kinds, name: kind},
        )
        self.mark_dirty()
        self.maps_changed.emit()

    # ------------------------------------------------------------------ serialization
    def to_project(self) -> Project:
        """The document as an :class:`engine.project.Project`."""
        if self.source is None:
            raise ValueError("nothing to save: no source image is open")
        names = list(self.source.maps)
        template = None
        if self.seamless is not None:
            template = _tile_maps(self.seamless, names)
        cands = [
            Candidate(
                maps={m: e.maps[m] for m in names},
                patch_origin=e.patch_origin,
                seed=e.seed,
                locked=e.locked,
                score=e.score,
                params={
                    "weight": e.weight,
                    "scores": dict(e.scores),
                    "patch_rect": list(e.patch_rect) if e.patch_rect else None,
                    "target_rect": list(e.target_rect) if e.target_rect else None,
                    "loop": None if e.loop is None else np.asarray(e.loop).tolist(),
                },
            )
            for e in self.candidates
            if all(m in e.maps for m in names)
        ]
        layout = self.layout
        if layout is not None and (not self.picks or layout.max(initial=-1) >= len(self.picks)):
            layout = None
        preview = None
        if self.preview is not None and layout is not None:
            preview = {names[0]: self.preview}
        return Project(
            sources=dict(self.source.maps),
            name=self.name,
            source_paths=dict(self.source.paths),
            map_kinds=dict(self.source.kinds),
            map_weights={k: v for k, v in self.map_weights.items() if k in self.source.maps},
            bit_depth=self.source.bit_depth,
            parameters=dict(self.params),
            seeds={"candidates": self.params["seed"], "layout": self.params["layout_seed"]},
            template_rect=self.template_rect,
            template=template,
            candidates=cands,
            picks=list(self.picks),
            layout=layout,
            waypoints={k: [tuple(p) for p in v] for k, v in self.waypoints.items()},
            preview=preview,
            extra={"editor": "quilt-studio", **_painted_extra(self.exclude_painted)},
        )

    def from_project(self, project: Project, path: str | None) -> None:
        """Replace the whole document by ``project`` (clears the undo history)."""
        source = Source(
            maps=dict(project.sources),
            paths=dict(project.source_paths),
            bit_depth=project.bit_depth,
            kinds=dict(project.map_kinds),
        )
        self.set_source(source, name=project.name)
        self.params = params.coerce_all(project.parameters)
        self.template_rect = (
            None if project.template_rect is None else tuple(int(v) for v in project.template_rect)
        )
        self.waypoints = {
            k: [tuple(p) for p in project.waypoints.get(k, [])] for k in WAYPOINT_KEYS
        }
        self.map_weights = {k: float(v) for k, v in project.map_weights.items()}
        entries = []
        for c in project.candidates:
            entries.append(
                CandidateEntry(
                    maps=dict(c.maps),
                    patch_origin=c.patch_origin,
                    patch_rect=_rect(c.params.get("patch_rect")),
                    target_rect=_rect(c.params.get("target_rect")),
                    loop=_points(c.params.get("loop")),
                    seed=c.seed,
                    score=c.score,
                    scores=dict(c.params.get("scores") or {}),
                    locked=c.locked,
                    weight=float(c.params.get("weight", 1.0)),
                )
            )
        self.candidates = entries
        self.picks = list(project.picks)
        self.layout = None if project.layout is None else np.asarray(project.layout)
        if project.preview is not None:
            self.preview = next(iter(project.preview.values()))
        self.project_path = path
        self.apply_painted(_painted_from_extra(project.extra, source.shape))
        self.params_changed.emit(frozenset(self.params))
        self.template_changed.emit()
        self.waypoints_changed.emit()
        self.map_weights_changed.emit()
        self.candidates_reset.emit()
        self.picks_changed.emit()
        self.layout_changed.emit()
        self.preview_changed.emit()
        self.path_changed.emit()
        self.mark_saved()


PAINTED_KEY = "exclude_painted"


def _painted_extra(mask: np.ndarray | None) -> dict:
    """The painted exclusion as JSON for ``Project.extra`` (the project format has no field
    for it): shape and the bit-packed, zlib-compressed mask in base64."""
    if mask is None or not mask.any():
        return {}
    packed = zlib.compress(np.packbits(np.asarray(mask, bool)).tobytes(), 9)
    return {
        PAINTED_KEY: {
            "shape": list(mask.shape),
            "packbits_zlib_base64": base64.b64encode(packed).decode("ascii"),
        }
    }


def _painted_from_extra(extra: dict, shape: tuple[int, int]) -> np.ndarray | None:
    """The painted exclusion saved by :func:`_painted_extra`; None if absent or not a mask of
    the source's ``shape`` (a damaged entry is dropped, the rest of the project opens)."""
    entry = extra.get(PAINTED_KEY) if isinstance(extra, dict) else None
    if not isinstance(entry, dict) or entry.get("shape") != list(shape):
        return None
    n = int(shape[0]) * int(shape[1])
    try:
        raw = base64.b64decode(entry["packbits_zlib_base64"], validate=True)
        bits = zlib.decompressobj().decompress(raw, (n + 7) // 8 + 1)
    except (KeyError, TypeError, ValueError, zlib.error):
        return None
    if len(bits) != (n + 7) // 8:
        return None
    mask = np.unpackbits(np.frombuffer(bits, np.uint8), count=n).astype(bool).reshape(shape)
    return mask if mask.any() else None


def _rect(value) -> tuple[int, int, int, int] | None:
    """An (x, y, w, h) rectangle read from a project's JSON, None if it is not one."""
    if isinstance(value, list) and len(value) == 4 and all(isinstance(v, int) for v in value):
        return tuple(value)
    return None


def _points(value) -> np.ndarray | None:
    """(N, 2) int (row, col) points read from a project's JSON, None if they are not."""
    try:
        a = np.asarray(value, dtype=np.int64)
    except (TypeError, ValueError):
        return None
    return a if a.ndim == 2 and a.shape[1] == 2 and len(a) else None


def _tile_maps(seamless, names: list[str]) -> dict[str, np.ndarray] | None:
    """Per-map template tiles of an engine SeamlessTile: the main map is ``tile``, the
    material maps are in ``maps``; None if a map is missing (a result from before it was
    attached)."""
    maps = {names[0]: seamless.tile, **dict(seamless.maps or {})}
    if not all(m in maps for m in names):
        return None
    return {m: maps[m] for m in names}
