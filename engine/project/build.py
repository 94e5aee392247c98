"""A project from plain arrays: what the ``tileset`` CLI and the tests save."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from engine._validate import as_image
from engine.bitdepth import to_float
from engine.candidate import CandidateTile
from engine.materials import resolve_kinds
from engine.project.checks import check_project
from engine.project.model import Project

__all__ = ["as_float", "project_from_tileset"]


def project_from_tileset(
    *,
    sources,
    tiles: Sequence,
    name: str = "tileset",
    template=None,
    template_rect=None,
    patch_origins=None,
    seeds=None,
    scores=None,
    locked=None,
    picks=None,
    layout=None,
    parameters=None,
    project_seeds=None,
    bit_depth: int = 8,
    source_paths=None,
    map_kinds=None,
    map_weights=None,
    normal_convention: str = "opengl",
    waypoints=None,
    preview=None,
    extra=None,
    wang=None,
    tile_params=None,
    wang_tiles=None,
) -> Project:
    """Build a validated :class:`Project` from plain arrays (for the ``tileset`` CLI and tests).

    ``sources`` is an image or {map: image}; ``tiles`` a list of images, of
    {map: image} (same maps as ``sources``) or of :class:`engine.candidate.CandidateTile`
    (kept as they are, re-indexed; the per-tile lists below are then ignored); ``template``
    likewise. ``patch_origins``, ``seeds``, ``scores``, ``locked``, ``tile_params`` (each
    tile's ``CandidateTile.params``) are per-tile lists (or None); ``wang`` a Wang set's
    record (:attr:`Project.wang`) and ``wang_tiles`` its tiles (``CandidateTile``, whose maps
    are floats in [0, 1], re-indexed).
    """

    def as_maps(v, what):
        if isinstance(v, Mapping):
            return {str(k): as_float(a, f"{what}[{k!r}]") for k, a in v.items()}
        return {"albedo": as_float(v, what)}

    srcs = as_maps(sources, "sources")
    tiles = list(tiles)
    n = len(tiles)

    def per_tile(v, what):
        if v is None:
            return [None] * n
        v = list(v)
        if len(v) != n:
            raise ValueError(f"{what} must have one entry per tile ({n}), got {len(v)}")
        return v

    po, sd, sc, lk, pp = (
        per_tile(patch_origins, "patch_origins"),
        per_tile(seeds, "seeds"),
        per_tile(scores, "scores"),
        per_tile(locked, "locked"),
        per_tile(tile_params, "tile_params"),
    )
    cands = []
    for i, t in enumerate(tiles):
        if isinstance(t, CandidateTile):
            cands.append(t.replace(index=i, mask=None, alpha=None))
            continue
        maps = as_maps(t, f"tiles[{i}]")
        if not isinstance(t, Mapping) and len(srcs) == 1:
            maps = {next(iter(srcs)): maps["albedo"]}
        main = next(iter(srcs))
        cands.append(
            CandidateTile(
                index=i,
                tile=maps.get(main),
                maps={m: a for m, a in maps.items() if m != main},
                patch_origin=None if po[i] is None else (int(po[i][0]), int(po[i][1])),
                seed=None if sd[i] is None else int(sd[i]),
                locked=bool(lk[i]) if lk[i] is not None else False,
                scores={} if sc[i] is None else {"score": float(sc[i])},
                params=dict(pp[i] or {}),
            )
        )
    tmpl = None
    if template is not None:
        tmpl = as_maps(template, "template")
        if not isinstance(template, Mapping) and len(srcs) == 1:
            tmpl = {next(iter(srcs)): tmpl["albedo"]}
    prev = None
    if preview is not None:
        prev = as_maps(preview, "preview")
        if not isinstance(preview, Mapping) and len(srcs) == 1:
            prev = {next(iter(srcs)): prev["albedo"]}
    p = Project(
        sources=srcs,
        name=name,
        source_paths=dict(source_paths or {}),
        map_kinds=resolve_kinds(srcs, map_kinds),
        map_weights=dict(map_weights or {}),
        normal_convention=normal_convention,
        bit_depth=bit_depth,
        parameters=dict(parameters or {}),
        seeds=dict(project_seeds or {}),
        template_rect=None if template_rect is None else tuple(int(v) for v in template_rect),
        template=tmpl,
        candidates=cands,
        picks=[int(i) for i in (picks or [])],
        layout=None if layout is None else np.asarray(layout, dtype=np.int64),
        waypoints={
            str(k): [(int(r), int(c)) for r, c in v] for k, v in dict(waypoints or {}).items()
        },
        preview=prev,
        extra=dict(extra or {}),
        wang=None if wang is None else dict(wang),
        wang_tiles=[t.replace(index=i) for i, t in enumerate(wang_tiles or [])],
    )
    check_project(p, "project")
    return p


def as_float(a, what: str) -> np.ndarray:
    """Like ``as_image`` but uint8/uint16 are divided exactly as ``engine.io.load_image`` does,
    so a project built from integer arrays holds the same floats as one built from loaded files."""
    arr = np.asarray(a)
    if arr.dtype in (np.uint8, np.uint16):
        arr = arr[:, :, None] if arr.ndim == 2 else arr
        if arr.ndim != 3:
            raise ValueError(f"{what} must be shaped (H, W) or (H, W, C), got {np.shape(a)}")
        return to_float(arr)
    return as_image(a, what)
