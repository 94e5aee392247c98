"""The document: what the user works on, one part per workflow, and its signals.

:class:`Document` holds what both workflows share: the source and its material maps,
the parameters, the painted exclusion, the project path and the modified state. The
tile-set workflow's state is :attr:`Document.tileset` (:mod:`quilt_gui.tileset_doc`), the
quilting / transfer workflow's :attr:`Document.quilting` (:mod:`quilt_gui.quilting_doc`);
each has its own signals. Views subscribe to the signals of the part they show.

Every user edit goes through a method that pushes a :mod:`quilt_gui.commands`
QUndoCommand, whose ``redo``/``undo`` call the ``apply_*`` methods. Each workflow has its own
history (``tileset.undo_stack``, ``quilting.undo_stack``, in :attr:`Document.undo_group`):
Undo on one tab never changes the other's parameters; an edit both share (the painted
exclusion, a seam option) goes to the history of the tab in front. The document holds no
widgets and builds no QImages. Its serialization is :mod:`quilt_gui.project_io`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal, Slot
from PySide6.QtGui import QUndoGroup, QUndoStack

from quilt_gui import commands, params
from quilt_gui.model import Source, safe_name
from quilt_gui.param_table import QUILTING_GROUPS, TILESET_GROUPS
from quilt_gui.quilting_doc import QuiltingDocument
from quilt_gui.tileset_doc import TileSetDocument
from quilt_gui.wang_doc import WangDocument


class Document(QObject):
    """Source, parameters, exclusion, path; :attr:`tileset` and :attr:`quilting`."""

    source_changed = Signal()
    maps_changed = Signal()
    params_changed = Signal(object)  # frozenset of changed keys
    exclusion_changed = Signal()  # the painted exclusion mask
    heal_mask_changed = Signal()  # the region painted to heal
    pixels_changed = Signal()  # the source's pixels changed (healed), not its size or maps
    modified_changed = Signal(bool)
    path_changed = Signal()

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.undo_group = QUndoGroup(self)
        self.source: Source | None = None
        self.name = "tileset"
        self.params: dict[str, Any] = dict(params.DEFAULTS)
        self.project_path: str | None = None
        # (H, W) bool: source pixels the template search, the candidates and quilting never
        # use (with the exclude_color range); saved in the project's extra["exclude_painted"]
        self.exclude_painted: np.ndarray | None = None
        self.heal_mask: np.ndarray | None = None  # (H, W) bool: the region to heal (not saved)
        #: the source's pixels generation: a new one at every heal, the old one back at its undo
        self.pixels = 0
        self._generations = 0  # the generations handed out
        self._dirty = False  # changes that are not undo steps (streamed results)
        self._was_modified = False
        self.tileset = TileSetDocument(self, QUndoStack(self))
        self.quilting = QuiltingDocument(self, QUndoStack(self))
        self.wang = WangDocument(self, QUndoStack(self))
        for stack in self.stacks:
            self.undo_group.addStack(stack)
            stack.cleanChanged.connect(self._on_clean_changed)
        self.undo_group.setActiveStack(self.tileset.undo_stack)

    # ------------------------------------------------------------------ state
    @property
    def has_source(self) -> bool:
        return self.source is not None

    @property
    def stacks(self) -> tuple[QUndoStack, ...]:
        """The histories of the tile set, quilting and the Wang tiles."""
        return self.tileset.undo_stack, self.quilting.undo_stack, self.wang.undo_stack

    @property
    def undo_stack(self) -> QUndoStack:
        """The history Undo acts on: the workflow in front."""
        return self.undo_group.activeStack()

    def set_workflow(self, name: str) -> None:
        """``"tileset"``, ``"quilting"`` or ``"wang"`` is in front (its history is the active
        one)."""
        part = {"quilting": self.quilting, "wang": self.wang}.get(name, self.tileset)
        self.undo_group.setActiveStack(part.undo_stack)

    def _stack_for(self, keys) -> QUndoStack:
        """The history of an edit of parameters ``keys``: their workflow's, or the active one
        for parameters both workflows use."""
        groups = {params.BY_KEY[k].group for k in keys}
        if groups <= set(QUILTING_GROUPS):
            return self.quilting.undo_stack
        if groups <= set(TILESET_GROUPS):
            return self.tileset.undo_stack
        return self.undo_stack

    @property
    def modified(self) -> bool:
        return self._dirty or not all(s.isClean() for s in self.stacks)

    def mark_dirty(self) -> None:
        self._dirty = True
        self._emit_modified()

    def mark_saved(self, path: str | None = None) -> None:
        self._dirty = False
        self.quilting.unsaved = False  # a finished output is kept in the project
        for stack in self.stacks:
            stack.setClean()
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
        command = commands.SetParams(self, {key: value}, merge_id=merge_id, text=text)
        self._stack_for([key]).push(command)

    def set_params(self, values: dict, *, text: str = "Change parameters") -> None:
        values = {k: params.BY_KEY[k].coerce(v) for k, v in values.items()}
        values = {k: v for k, v in values.items() if self.params.get(k) != v}
        if values:
            self._stack_for(values).push(commands.SetParams(self, values, text=text))

    def apply_params(self, values: dict) -> None:
        self.params.update(values)
        self.params_changed.emit(frozenset(values))

    def set_painted(self, mask: np.ndarray | None, *, text: str = "Paint exclusion") -> None:
        """Replace the painted exclusion mask (one undo step)."""
        self.undo_stack.push(commands.SetPainted(self, mask, text))

    def apply_painted(self, mask: np.ndarray | None) -> None:
        self.exclude_painted = mask
        self.exclusion_changed.emit()

    def set_heal_mask(self, mask: np.ndarray | None, *, text: str = "Paint region to heal") -> None:
        """Replace the region to heal (one undo step)."""
        self.undo_stack.push(commands.SetHealMask(self, mask, text))

    def apply_heal_mask(self, mask: np.ndarray | None) -> None:
        self.heal_mask = mask
        self.heal_mask_changed.emit()

    def heal(self, maps: dict[str, np.ndarray]) -> None:
        """The source's maps replaced by their healed pixels and the region cleared: one undo
        step (the template search, the candidates and quilting use the healed source)."""
        st = self.undo_stack
        st.beginMacro("Heal")
        st.push(commands.SetSourceMaps(self, maps, "Heal"))
        st.push(commands.SetHealMask(self, None, "Heal"))
        st.endMacro()

    def new_pixels(self) -> int:
        """A pixels generation not given before (:attr:`pixels`)."""
        self._generations += 1
        return self._generations

    def apply_source_maps(self, maps: dict[str, np.ndarray], pixels: int | None = None) -> None:
        """New pixels for the source's maps (same names and size), of generation ``pixels``
        (a new one when None)."""
        self.pixels = self.new_pixels() if pixels is None else int(pixels)
        self.source = replace(self.source, maps=dict(maps))
        self.pixels_changed.emit()
        self.maps_changed.emit()

    # ------------------------------------------------------------------ whole-document changes
    def set_source(self, source: Source, *, name: str | None = None) -> None:
        """Start over on a new source (clears results and the undo history)."""
        self.source = source
        self.name = safe_name(name or Path(source.path).stem or "tileset")
        self.project_path = None
        for stack in self.stacks:
            stack.clear()
        self._dirty = False
        self.source_changed.emit()
        self.maps_changed.emit()
        self.tileset.clear()
        self.wang.clear()
        self.quilting.start(None)  # the last source's output: no re-run on this one (ux13)
        self.path_changed.emit()
        self.apply_painted(None)
        self.apply_heal_mask(None)
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
