"""``project.json``: the project as a JSON document whose images are archive entry names.

:func:`to_doc` writes it; :func:`from_doc` reads it strictly (every key typed, every list
checked, paths to the offending key in the messages). Neither touches the archive: the caller
stores or loads the images (:mod:`engine.project.archive`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from engine.candidate import CandidateTile
from engine.project.checks import finite_number
from engine.project.model import PROJECT_FORMAT, PROJECT_VERSION, SAFE_NAME, Project

__all__ = ["from_doc", "to_doc"]


def to_doc(project: Project, put: Callable[[np.ndarray, str], str]) -> dict:
    """The ``project.json`` document of ``project``; ``put(image, entry)`` stores every image
    under its archive entry name and returns that name."""
    return {
        "format": PROJECT_FORMAT,
        "version": PROJECT_VERSION,
        "name": project.name,
        "bit_depth": project.bit_depth,
        "normal_convention": project.normal_convention,
        "maps": list(project.sources),
        "sources": {m: put(a, f"images/source_{m}.png") for m, a in project.sources.items()},
        "source_paths": {str(k): str(v) for k, v in project.source_paths.items()},
        "map_kinds": dict(project.map_kinds),
        "map_weights": {k: float(v) for k, v in project.map_weights.items()},
        "parameters": project.parameters,
        "seeds": project.seeds,
        "template_rect": None
        if project.template_rect is None
        else [int(v) for v in project.template_rect],
        "template": None
        if project.template is None
        else {m: put(a, f"images/template_{m}.png") for m, a in project.template.items()},
        "candidates": [
            _candidate_doc(c, i, project.main_map, put) for i, c in enumerate(project.candidates)
        ],
        "picks": [int(k) for k in project.picks],
        "layout": None
        if project.layout is None
        else np.asarray(project.layout).astype(int).tolist(),
        "waypoints": {
            str(k): [[int(r), int(c)] for r, c in v] for k, v in project.waypoints.items()
        },
        "preview": None
        if project.preview is None
        else {m: put(a, f"images/preview_{m}.png") for m, a in project.preview.items()},
        "extra": project.extra,
        "outputs": {k: put(a, f"images/output_{k}.png") for k, a in project.outputs.items()},
        "wang": project.wang,
        "wang_tiles": [
            _candidate_doc(c, i, project.main_map, put, "wang")
            for i, c in enumerate(project.wang_tiles)
        ],
    }


def _candidate_doc(c: CandidateTile, i: int, main: str, put, kind: str = "candidate") -> dict:
    """One candidate's entry (its images by map, how it was made, the user's choices)."""
    images = {m: put(a, f"images/{kind}_{i:04}_{m}.png") for m, a in c.images(main).items()}

    def ints(v):
        return None if v is None else [int(x) for x in v]

    return {
        "images": images,
        "patch_origin": ints(c.patch_origin),
        "seed": None if c.seed is None else int(c.seed),
        "locked": bool(c.locked),
        "score": c.score,
        "params": {
            **c.params,
            "weight": float(c.weight),
            "scores": {k: float(v) for k, v in c.scores.items()},
            "patch_rect": ints(c.patch_rect),
            "target_rect": ints(c.target_rect),
            "loop": None if c.loop is None else np.asarray(c.loop).tolist(),
        },
    }


def _candidate(i: int, c: dict, images: dict, main: str, s, key="candidates") -> CandidateTile:
    """The candidate of entry ``c`` (what :func:`_candidate_doc` wrote; files of version 1
    without ``params`` keep only their score); malformed optional details are dropped."""
    where = f"{key}[{i}]"
    po = s.get(c, "patch_origin", list, where, optional=True)
    params = s.get(c, "params", dict, where, optional=True, default={})
    scores = params.get("scores") if isinstance(params.get("scores"), dict) else {}
    scores = {k: v for k, v in scores.items() if isinstance(v, (int, float))}
    score = s.get(c, "score", (int, float), where, optional=True)
    if "criterion" not in scores and score is not None:
        scores["score"] = score
    weight = params.get("weight", 1.0)
    if isinstance(weight, (int, float)) and not (finite_number(weight) and weight >= 0):
        s.fail(
            f"project.json: {where}.params.weight must be a finite number >= 0, got {weight!r:.40}"
        )
    own = {"weight", "scores", "patch_rect", "target_rect", "loop"}
    return CandidateTile(
        index=i,
        tile=images[main],
        maps={m: a for m, a in images.items() if m != main},
        patch_rect=_rect(params.get("patch_rect")),
        patch_origin=None if po is None else tuple(_int_list(s, po, 2, f"{where}.patch_origin")),
        target_rect=_rect(params.get("target_rect")),
        loop=_points(params.get("loop")),
        scores=scores,
        seed=s.get(c, "seed", int, where, optional=True),
        locked=s.get(c, "locked", bool, where),
        weight=float(weight) if isinstance(weight, (int, float)) else 1.0,
        params={k: v for k, v in params.items() if k not in own},
    )


def _rect(value) -> tuple[int, int, int, int] | None:
    """An (x, y, w, h) rectangle read from JSON, None if it is not one."""
    if isinstance(value, list) and len(value) == 4 and all(isinstance(v, int) for v in value):
        return tuple(value)
    return None


def _points(value) -> np.ndarray | None:
    """(N, 2) int (row, col) points read from JSON, None if they are not."""
    try:
        a = np.asarray(value, dtype=np.int64)
    except (TypeError, ValueError, OverflowError):
        return None
    return a if a.ndim == 2 and a.shape[1] == 2 and len(a) else None


class _Spec:
    """Tiny typed accessor over the parsed JSON that reports the key path on errors."""

    def __init__(self, fail):
        self.fail = fail

    def get(self, d, key, types, where, *, optional=False, default=None):
        if not isinstance(d, dict):
            self.fail(f"project.json: {where} must be an object")
        if key not in d:
            if optional:
                return default
            self.fail(
                f"project.json: missing key {where}.{key}"
                if where
                else f"project.json: missing key {key!r}"
            )
        v = d[key]
        if v is None and optional:
            return default
        if isinstance(v, bool) and bool not in (types if isinstance(types, tuple) else (types,)):
            self.fail(
                f"project.json: {where + '.' if where else ''}{key} has the wrong type (bool)"
            )
        if not isinstance(v, types):
            names = "/".join(t.__name__ for t in (types if isinstance(types, tuple) else (types,)))
            self.fail(
                f"project.json: {where + '.' if where else ''}{key} must be {names}, got "
                f"{type(v).__name__}"
            )
        return v


def _int_list(s: _Spec, v, n, what):
    if (
        not isinstance(v, list)
        or (n is not None and len(v) != n)
        or any(isinstance(x, bool) or not isinstance(x, int) for x in v)
    ):
        s.fail(
            f"project.json: {what} must be a list of {n if n else ''} integers".replace("  ", " ")
        )
    return v


def from_doc(doc, fail: Callable[[str], None], image: Callable[[object], object]) -> Project:
    """The :class:`Project` a parsed ``project.json`` describes, every image replaced by
    ``image(reference)``; ``fail(message)`` raises on the first problem (with the key path)."""
    s = _Spec(fail)
    if not isinstance(doc, dict):
        fail("project.json: the document must be a JSON object")
    fmt = s.get(doc, "format", str, "")
    if fmt != PROJECT_FORMAT:
        fail(f"project.json: format is {fmt!r}, expected {PROJECT_FORMAT!r}")
    version = s.get(doc, "version", int, "")
    if version > PROJECT_VERSION:
        fail(
            f"project.json: version {version} was written by a newer Quilt Studio (this one reads "
            f"{PROJECT_VERSION})"
        )
    if version < 1:
        fail(f"project.json: bad version {version}")
    maps = s.get(doc, "maps", list, "")
    if (
        not maps
        or not all(isinstance(m, str) and SAFE_NAME.match(m) for m in maps)
        or len(set(maps)) != len(maps)
    ):
        fail("project.json: maps must be a non-empty list of distinct simple names")

    def map_images(d, where):
        if not isinstance(d, dict) or list(d) != maps:
            fail(f"project.json: {where} must map exactly the maps {maps} to image entries")
        return {m: image(d[m]) for m in maps}

    sources = map_images(s.get(doc, "sources", dict, ""), "sources")
    tmpl_d = s.get(doc, "template", dict, "", optional=True)
    prev_d = s.get(doc, "preview", dict, "", optional=True)
    preview = None
    if prev_d is not None:
        if set(prev_d) - set(maps):
            fail("project.json: preview keys must be map names")
        preview = {m: image(v) for m, v in prev_d.items()}
    outputs_d = s.get(doc, "outputs", dict, "", optional=True, default={})
    if not all(isinstance(k, str) and SAFE_NAME.match(k) for k in outputs_d):
        fail("project.json: outputs keys must be simple names")
    outputs = {k: image(v) for k, v in outputs_d.items()}

    def candidates(key, entries):
        out = []
        for i, c in enumerate(entries):
            where = f"{key}[{i}]"
            imgs = map_images(s.get(c, "images", dict, where), f"{where}.images")
            out.append(_candidate(i, c, imgs, maps[0], s, key))
        return out

    cands = candidates("candidates", s.get(doc, "candidates", list, ""))
    wang_tiles = candidates(
        "wang_tiles", s.get(doc, "wang_tiles", list, "", optional=True, default=[])
    )
    rect = s.get(doc, "template_rect", list, "", optional=True)
    layout = s.get(doc, "layout", list, "", optional=True)
    if layout is not None:
        if not layout or not all(isinstance(r, list) and len(r) == len(layout[0]) for r in layout):
            fail("project.json: layout must be a non-empty rectangular list of lists")
        for r in layout:
            _int_list(s, r, None, "layout rows")
            if any(not -1 <= x < 2**31 for x in r):
                fail("project.json: layout cells must be exported tile ids or -1")
        layout = np.asarray(layout, dtype=np.int64)
    wps = s.get(doc, "waypoints", dict, "", optional=True, default={})
    waypoints = {}
    for k, v in wps.items():
        if not isinstance(v, list):
            fail(f"project.json: waypoints[{k!r}] must be a list of [row, col]")
        waypoints[k] = [tuple(_int_list(s, pt, 2, f"waypoints[{k!r}] entries")) for pt in v]
    kinds = s.get(doc, "map_kinds", dict, "", optional=True, default={})
    weights = s.get(doc, "map_weights", dict, "", optional=True, default={})
    paths = s.get(doc, "source_paths", dict, "", optional=True, default={})
    if not all(isinstance(v, str) for v in paths.values()):
        fail("project.json: source_paths values must be strings")
    return Project(
        sources=sources,
        name=s.get(doc, "name", str, ""),
        version=PROJECT_VERSION,
        source_paths=paths,
        map_kinds=kinds,
        map_weights=weights,
        normal_convention=s.get(doc, "normal_convention", str, ""),
        bit_depth=s.get(doc, "bit_depth", int, ""),
        parameters=s.get(doc, "parameters", dict, ""),
        seeds=s.get(doc, "seeds", dict, ""),
        template_rect=None if rect is None else tuple(_int_list(s, rect, 4, "template_rect")),
        template=None if tmpl_d is None else map_images(tmpl_d, "template"),
        candidates=cands,
        picks=_int_list(s, s.get(doc, "picks", list, ""), None, "picks"),
        layout=layout,
        waypoints=waypoints,
        preview=preview,
        extra=s.get(doc, "extra", dict, "", optional=True, default={}),
        outputs=outputs,
        wang=s.get(doc, "wang", dict, "", optional=True),
        wang_tiles=wang_tiles,
    )
