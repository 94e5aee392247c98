"""Cross-field checks of a :class:`~engine.project.model.Project`, shared by building, saving
and loading: names, versions, shapes of every map and tile, indices, rectangles, numbers."""

from __future__ import annotations

import math
import numbers

import numpy as np

from engine.candidate import CandidateTile
from engine.materials import MAP_KINDS, NORMAL_CONVENTIONS
from engine.project.model import PROJECT_VERSION, SAFE_NAME, Project

__all__ = ["check_project", "finite_number"]


def finite_number(v) -> bool:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:  # an int beyond the float range
        return False


def check_project(p: Project, where: str) -> None:
    """Cross-field checks shared by building, saving and loading; raises ValueError."""
    if not isinstance(p, Project):
        raise TypeError(f"{where} must be a Project, got {type(p).__name__}")
    if not isinstance(p.name, str) or not SAFE_NAME.match(p.name) or len(p.name) > 100:
        raise ValueError(
            f"{where}: name must be a simple file-name part (letters, digits, . _ -), got "
            f"{p.name!r}"
        )
    if p.version != PROJECT_VERSION:
        raise ValueError(
            f"{where}: version {p.version!r} is not supported (this build reads version "
            f"{PROJECT_VERSION})"
        )
    if not isinstance(p.sources, dict) or not p.sources:
        raise ValueError(f"{where}: sources must be a non-empty dict of map name -> image")
    for m in p.sources:
        if not isinstance(m, str) or not SAFE_NAME.match(m) or len(m) > 64:
            raise ValueError(f"{where}: bad map name {m!r} (letters, digits, . _ - only)")
    shapes = {m: np.shape(a) for m, a in p.sources.items()}
    hw = shapes[p.main_map][:2]
    for m, s in shapes.items():
        if len(s) != 3 or s[:2] != hw:
            raise ValueError(
                f"{where}: source map {m!r} is shaped {s}; all maps must be (H, W, C) of the main "
                f"map's size {hw}"
            )
    if p.normal_convention not in NORMAL_CONVENTIONS:
        raise ValueError(
            f"{where}: normal_convention must be one of {NORMAL_CONVENTIONS}, got "
            f"{p.normal_convention!r}"
        )
    if p.bit_depth not in (8, 16) or isinstance(p.bit_depth, bool):
        raise ValueError(f"{where}: bit_depth must be 8 or 16, got {p.bit_depth!r}")
    for m, k in p.map_kinds.items():
        if m not in p.sources or k not in MAP_KINDS:
            raise ValueError(f"{where}: map_kinds has a bad entry {m!r}: {k!r}")
    for m, w in p.map_weights.items():
        if m not in p.sources or not finite_number(w) or w < 0:
            raise ValueError(f"{where}: map_weights has a bad entry {m!r}: {w!r:.40}")
    if p.template_rect is not None:
        r = p.template_rect
        if (
            len(r) != 4
            or any(isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in r)
            or r[2] < 1
            or r[3] < 1
            or r[0] < 0
            or r[1] < 0
        ):
            raise ValueError(
                f"{where}: template_rect must be 4 integers (x, y, w, h) with w, h >= 1, got {r!r}"
            )
    first = [("template", p.template)] if p.template is not None else []
    _check_tiles(p, where, shapes, first, "candidates", p.candidates)
    n = len(p.candidates)
    for k in p.picks:
        if isinstance(k, bool) or not isinstance(k, numbers.Integral) or not 0 <= k < n:
            raise ValueError(f"{where}: picks must be candidate indices in [0, {n - 1}], got {k!r}")
    if len(set(p.picks)) != len(p.picks):
        raise ValueError(f"{where}: picks must not repeat a candidate")
    if p.layout is not None:
        lay = np.asarray(p.layout)
        count = len(p.picks) if p.picks else n
        if lay.ndim != 2 or lay.size == 0 or not np.issubdtype(lay.dtype, np.integer):
            raise ValueError(
                f"{where}: layout must be a non-empty 2-D integer matrix, got shape {lay.shape} "
                f"{lay.dtype}"
            )
        if lay.min() < -1 or lay.max() >= count:
            raise ValueError(
                f"{where}: layout cells must be exported tile ids in [0, {count - 1}] or -1"
            )
    if not isinstance(p.waypoints, dict):
        raise ValueError(f"{where}: waypoints must be a dict of seam key -> [(row, col), ...]")
    for key, pts in p.waypoints.items():
        for pt in pts:
            if len(pt) != 2 or any(
                isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in pt
            ):
                raise ValueError(
                    f"{where}: waypoints[{key!r}] must be (row, col) integer pairs, got {pt!r}"
                )
    if p.preview is not None:
        if not isinstance(p.preview, dict) or set(p.preview) - set(p.sources):
            raise ValueError(f"{where}: preview keys must be map names")
        for m, a in p.preview.items():
            if len(np.shape(a)) != 3 or np.shape(a)[2] != shapes[m][2]:
                raise ValueError(f"{where}: preview[{m!r}] is shaped {np.shape(a)}")
    for key in ("parameters", "seeds", "extra", "outputs"):
        if not isinstance(getattr(p, key), dict):
            raise ValueError(f"{where}: {key} must be a dict")
    for k, a in p.outputs.items():
        if not isinstance(k, str) or not SAFE_NAME.match(k):
            raise ValueError(f"{where}: outputs keys must be simple names, got {k!r}")
        if len(np.shape(a)) != 3 or not 1 <= np.shape(a)[2] <= 4 or 0 in np.shape(a):
            raise ValueError(f"{where}: outputs[{k!r}] is shaped {np.shape(a)}")
    if p.wang is not None or p.wang_tiles:
        check_project_wang(p, where, shapes)


def _check_tiles(p: Project, where: str, shapes, first, key: str, candidates) -> None:
    """Tiles of one size with every map (``first``: (name, maps) checked before them), and
    each candidate's fields."""
    tile_shape = None

    def check_tile(maps, what):
        nonlocal tile_shape
        if not isinstance(maps, dict) or list(maps) != list(p.sources):
            raise ValueError(
                f"{where}: {what} must have the maps {list(p.sources)}, got "
                f"{list(maps) if isinstance(maps, dict) else type(maps).__name__}"
            )
        for m, a in maps.items():
            s = np.shape(a)
            if len(s) != 3 or s[2] != shapes[m][2]:
                raise ValueError(
                    f"{where}: {what}[{m!r}] is shaped {s}, expected (h, w, {shapes[m][2]})"
                )
            if tile_shape is None:
                tile_shape = s[:2]
            if s[:2] != tile_shape:
                raise ValueError(
                    f"{where}: {what}[{m!r}] is {s[1]}x{s[0]}, other tiles are "
                    f"{tile_shape[1]}x{tile_shape[0]}"
                )

    for what, maps in first:
        check_tile(maps, what)
    for i, c in enumerate(candidates):
        if not isinstance(c, CandidateTile):
            raise TypeError(f"{where}: {key}[{i}] must be a CandidateTile")
        check_tile(c.images(p.main_map), f"{key}[{i}]")
        if c.patch_origin is not None and (
            len(c.patch_origin) != 2
            or any(
                isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in c.patch_origin
            )
        ):
            raise ValueError(
                f"{where}: {key}[{i}].patch_origin must be (row, col) integers or None"
            )
        if c.seed is not None and (
            isinstance(c.seed, bool)
            or not isinstance(c.seed, numbers.Integral)
            or not 0 <= c.seed < 2**64
        ):
            raise ValueError(f"{where}: {key}[{i}].seed must be an integer in [0, 2**64) or None")
        if not all(finite_number(v) for v in c.scores.values()):
            raise ValueError(f"{where}: {key}[{i}].scores (and score) must be finite numbers")
        if not isinstance(c.locked, bool) or not finite_number(c.weight) or c.weight < 0:
            raise ValueError(f"{where}: {key}[{i}].locked must be a bool and weight a number >= 0")


def check_project_wang(p: Project, where: str, shapes) -> None:
    """A Wang set's record (K colours, 2 K samples, a valid layout) and its tiles, each with
    an edge signature."""
    from engine.export.wang import check_wang, layout_mismatches

    w = p.wang
    if not isinstance(w, dict):
        raise ValueError(f"{where}: wang_tiles need the Wang set's record (wang)")
    k = w.get("colours")
    samples = w.get("samples")
    if not isinstance(samples, list) or isinstance(k, bool) or not isinstance(k, int):
        raise ValueError(f"{where}: wang must hold 'colours' (int) and 'samples' (list)")
    want = [(a, c) for a in ("h", "v") for c in range(k)]
    for i, smp in enumerate(samples):
        ok = (
            isinstance(smp, dict)
            and i < len(want)
            and (smp.get("axis"), smp.get("colour")) == want[i]
        )
        origin = smp.get("origin") if isinstance(smp, dict) else None
        if not ok or not isinstance(origin, list) or len(origin) != 2:
            raise ValueError(f"{where}: wang.samples[{i}] must be {{'axis', 'colour', 'origin'}}")
    if len(samples) != 2 * k:
        raise ValueError(f"{where}: wang.samples must list {2 * k} samples (h, then v colours)")
    _check_tiles(p, where, shapes, [], "wang_tiles", p.wang_tiles)
    try:
        sigs = check_wang(
            {"colours": k, "tiles": [c.params.get("wang") for c in p.wang_tiles]},
            len(p.wang_tiles),
        )["tiles"]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: the Wang tiles' signatures: {exc}") from None
    lay = w.get("layout")
    if lay is not None:
        try:
            bad = layout_mismatches([tuple(s[x] for x in "nesw") for s in sigs], lay)
        except (TypeError, ValueError):
            bad = -1
        if bad:
            raise ValueError(f"{where}: wang.layout must be a valid layout of the Wang tiles")
