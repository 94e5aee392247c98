"""Export a project's picked tiles as a bundle (:func:`engine.export.export_bundle`)."""

from __future__ import annotations

from engine.export import export_bundle
from engine.project.checks import check_project
from engine.project.model import Project

__all__ = ["export_project"]


def export_project(project: Project, out_dir, *, wang: bool | None = None, **options) -> dict:
    """Export the picked tiles with :func:`engine.export.export_bundle`; returns the manifest.

    ``options`` are passed on (columns, spacing, margin, extrude, bit_depth,
    dither, overwrite ...); bit depth defaults to the project's. ``wang``: export the
    project's Wang set (every Wang tile, its layout and edge signatures: Tiled's Wang set,
    Godot's terrain set) instead of the candidates; None: when it has no candidates.
    """
    check_project(project, "project")
    if wang is None:
        wang = bool(project.wang_tiles) and not project.candidates
    if wang:
        return _export_wang(project, out_dir, options)
    order = list(project.picks) if project.picks else list(range(len(project.candidates)))
    if not order:
        raise ValueError("the project has no candidate tiles to export")
    cands = [project.candidates[i] for i in order]
    origins = [None if c.patch_origin is None else list(c.patch_origin) for c in cands]
    extra = {
        "parameters": project.parameters,
        "seeds": {"project": project.seeds, "tiles": [c.seed for c in cands]},
        "scores": [c.score for c in cands],
        "source_rects": [
            {
                "template": list(project.template_rect) if project.template_rect else None,
                "patch_origin": o,
                "candidate": i,
            }
            for o, i in zip(origins, order, strict=True)
        ],
        "map_kinds": project.map_kinds,
        "map_weights": project.map_weights,
        "source_paths": project.source_paths,
    }
    _defaults(project, options)
    options.setdefault("weights", [c.weight for c in cands])  # -> Tiled tile probability
    return export_bundle(
        out_dir,
        name=project.name,
        tiles=[c.images(project.main_map) for c in cands],
        index_matrix=project.layout,
        preview=project.preview,
        manifest_extra=extra,
        **options,
    )


def _defaults(project: Project, options: dict) -> dict:
    options.setdefault("source_bit_depth", project.bit_depth)
    if options.get("bit_depth") is None:
        options["bit_depth"] = project.bit_depth
    if options.get("normal_convention") is None:
        options["normal_convention"] = project.normal_convention
    return options


def _export_wang(project: Project, out_dir, options: dict) -> dict:
    """The Wang set: every tile (in index order), its layout, its edge signatures."""
    import numpy as np

    if not project.wang_tiles:
        raise ValueError("the project has no Wang tiles to export")
    w = project.wang
    if w.get("pending"):  # the editor saved it while a sample move or a heal was rebuilt
        raise ValueError(
            f"{len(w['pending'])} of the project's Wang tiles were saved while they waited for "
            "a rebuild (their edges do not match their edge samples yet): open the project in "
            "the editor, let it rebuild them, save, and export again"
        )
    k = w["colours"]
    tiles = project.wang_tiles
    if options.get("columns") is None and len(tiles) % (k * k) == 0:
        options["columns"] = k * k  # the atlas shows the set's canonical arrangement
    layout = w.get("layout")
    extra = {
        "parameters": project.parameters,
        "seeds": {"project": project.seeds, "tiles": [t.seed for t in tiles]},
        "scores": [t.score for t in tiles],
        "source_rects": [
            {"patch_origin": None if t.patch_origin is None else list(t.patch_origin)}
            for t in tiles
        ],
        "wang": {key: v for key, v in w.items() if key != "layout"},
        "map_kinds": project.map_kinds,
        "map_weights": project.map_weights,
        "source_paths": project.source_paths,
    }
    options.setdefault("weights", [t.weight for t in tiles])
    return export_bundle(
        out_dir,
        name=project.name,
        tiles=[t.images(project.main_map) for t in tiles],
        index_matrix=None if layout is None else np.asarray(layout, dtype=np.int64),
        manifest_extra=extra,
        wang={"colours": k, "tiles": [t.params["wang"] for t in tiles]},
        **_defaults(project, options),
    )
