"""Export a project's picked tiles as a bundle (:func:`engine.export.export_bundle`)."""

from __future__ import annotations

from engine.export import export_bundle
from engine.project.checks import check_project
from engine.project.model import Project

__all__ = ["export_project"]


def export_project(project: Project, out_dir, **options) -> dict:
    """Export the picked tiles with :func:`engine.export.export_bundle`; returns the manifest.

    ``options`` are passed on (columns, spacing, margin, extrude, bit_depth,
    dither, overwrite ...); bit depth defaults to the project's.
    """
    check_project(project, "project")
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
    options.setdefault("source_bit_depth", project.bit_depth)
    if options.get("bit_depth") is None:
        options["bit_depth"] = project.bit_depth
    if options.get("normal_convention") is None:
        options["normal_convention"] = project.normal_convention
    if project.wang is not None:  # edge signatures for Tiled's Wang set and Godot's terrains
        k = project.wang["colours"]
        options.setdefault("wang", {"colours": k, "tiles": [c.params["wang"] for c in cands]})
        if options.get("columns") is None and len(cands) % (k * k) == 0:
            options["columns"] = k * k  # the atlas shows the set's canonical arrangement
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
