"""The document as a project file's :class:`engine.project.Project`, and back.

:func:`to_project` reads every part of the document (the source, the parameters, the tile
set's template, candidates, picks and layout, the Wang set, the painted exclusion, the
finished quilting output and the transfer target); :func:`apply_project` replaces the whole
document by a project (the undo history starts empty). :func:`template_maps` is the seamless
tile per material map (what File ▸ Export seamless tile writes).
"""

from __future__ import annotations

import numpy as np

from engine.exclusion import mask_from_json, mask_to_json
from engine.project import Project
from quilt_gui import params
from quilt_gui.model import WAYPOINT_KEYS, Source

__all__ = ["apply_project", "template_maps", "to_project"]


def to_project(doc) -> Project:
    """``doc`` (a :class:`quilt_gui.document.Document`) as an engine Project."""
    if doc.source is None:
        raise ValueError("nothing to save: no source image is open")
    ts = doc.tileset
    names = list(doc.source.maps)
    template = None
    if ts.seamless is not None:
        template = _tile_maps(ts.seamless, names)
    cands = [  # the source's maps in its order; made before a map was attached: left out
        e.replace(maps={m: e.maps[m] for m in names[1:]})
        for e in ts.candidates
        if all(m in e.maps for m in names[1:])
    ]
    layout = ts.layout
    if layout is not None and (not ts.picks or layout.max(initial=-1) >= len(ts.picks)):
        layout = None
    preview = None
    if ts.preview is not None and layout is not None:
        preview = {names[0]: ts.preview}
    wang, wang_tiles = doc.wang.to_project(names)
    return Project(
        sources=dict(doc.source.maps),
        name=doc.name,
        source_paths=dict(doc.source.paths),
        map_kinds=dict(doc.source.kinds),
        map_weights={k: v for k, v in ts.map_weights.items() if k in doc.source.maps},
        bit_depth=doc.source.bit_depth,
        parameters=params.project_parameters(
            doc.params, doc.source.shape, doc.tileset.source_scale()
        ),
        seeds={"candidates": doc.params["seed"], "layout": doc.params["layout_seed"]},
        template_rect=ts.template_rect,
        template=template,
        candidates=cands,
        picks=list(ts.picks),
        layout=layout,
        waypoints={k: [tuple(p) for p in v] for k, v in ts.waypoints.items()},
        preview=preview,
        extra={"editor": "quilt-studio", **mask_to_json(doc.exclude_painted)},
        outputs=_outputs(doc.quilting),
        wang=wang,
        wang_tiles=wang_tiles,
    )


def apply_project(doc, project: Project, path: str | None) -> None:
    """Replace the whole of ``doc`` by ``project`` (clears the undo history)."""
    source = Source(
        maps=dict(project.sources),
        paths=dict(project.source_paths),
        bit_depth=project.bit_depth,
        kinds=dict(project.map_kinds),
    )
    doc.set_source(source, name=project.name)
    doc.params = params.from_project_parameters(project.parameters, project.seeds)
    ts = doc.tileset
    ts.template_rect = (
        None if project.template_rect is None else tuple(int(v) for v in project.template_rect)
    )
    ts.waypoints = {k: [tuple(p) for p in project.waypoints.get(k, [])] for k in WAYPOINT_KEYS}
    ts.map_weights = {k: float(v) for k, v in project.map_weights.items()}
    ts.candidates = list(project.candidates)
    ts.picks = list(project.picks)
    ts.layout = None if project.layout is None else np.asarray(project.layout)
    if project.preview is not None:
        ts.preview = next(iter(project.preview.values()))
    doc.project_path = path
    doc.quilting.restore(project.outputs.get(QUILT), project.outputs.get(TARGET))
    doc.apply_painted(mask_from_json(project.extra, source.shape))
    doc.params_changed.emit(frozenset(doc.params))
    ts.emit_all()
    doc.wang.apply_project(project.wang, project.wang_tiles)
    doc.path_changed.emit()
    doc.mark_saved()


QUILT, TARGET = "quilt", "transfer_target"  # names in Project.outputs


def _outputs(quilting) -> dict:
    """The finished quilting / transfer output and the transfer target, for the project."""
    out = {QUILT: quilting.finished_output, TARGET: quilting.target}
    return {k: np.asarray(v, dtype=np.float32) for k, v in out.items() if v is not None}


def template_maps(doc) -> dict[str, np.ndarray] | None:
    """The seamless tile of every material map (main first), None without one."""
    seamless = doc.tileset.seamless
    if seamless is None or doc.source is None:
        return None
    return _tile_maps(seamless, list(doc.source.maps))


def _tile_maps(seamless, names: list[str]) -> dict[str, np.ndarray] | None:
    """Per-map template tiles of an engine SeamlessTile: the main map is ``tile``, the
    material maps are in ``maps``; None if a map is missing (a result from before it was
    attached)."""
    maps = {names[0]: seamless.tile, **dict(seamless.maps or {})}
    if not all(m in maps for m in names):
        return None
    return {m: maps[m] for m in names}
