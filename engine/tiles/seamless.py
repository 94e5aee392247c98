"""Seamless tile from a template rectangle (ALGORITHMS.md §1.7).

R_R is stitched over R_L (the tile's left edge then continues its own last column) and R_B
over R_T (its top edge continues its last row). The second path is cyclic: its first and last
control points (tile columns 0 and w-1, neighbours across the wrap) are equal, so the wrap
has no corner seam. Every cut keeps the tile's own outer column/row from R1 (R_R, R_B) and the
innermost overlap column/row from R2 (R_L, R_T), so the tile wraps and the stitched strips
join the interior without a step.

Material maps (normal, roughness...) follow the same cuts: the seam is searched on
:func:`engine.materials.material_error` and applied with :func:`engine.materials.apply_cut`.

With ``blend="poisson"`` both cuts are hard and the tile is then solved in the gradient domain
on the torus (:func:`engine.poisson.solve_torus_maps`): every pixel is traced to its source
position, and the edges whose two pixels are not neighbours in the source (the cuts) take the
source's natural gradient, so a tone step along a cut is spread over the whole tile.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from engine._validate import as_image, choice
from engine.blend import blend_weights
from engine.cancel import check
from engine.events import Progress, Snapshot, drain, frozen_array
from engine.materials import apply_cut, material_error
from engine.seams._result import Seam
from engine.seams.search import SeamUpdate, iter_find_seam
from engine.seams.spec import CYCLIC_METHODS, POISSON, SeamSpec, as_seam_spec
from engine.tiles.template import Template, check_rect, flat_warning

__all__ = [
    "MAIN",
    "SeamlessTile",
    "SeamlessUpdate",
    "iter_make_seamless",
    "make_seamless",
]

MAIN = "main"  # the key of the source itself in ``weights``
OVERLAPS = ("horizontal", "vertical")


@dataclass(frozen=True, slots=True)
class SeamlessUpdate(Snapshot):
    """The best seam so far in one overlap (``which``: "horizontal" or "vertical").

    ``seam`` is canonical (rows run along the seam); ``path`` is (row, col) in the overlap
    region as drawn (R_L frame: (h + w_T) x w_T; R_T frame: w_T x w); ``path_source`` in
    source pixels. ``final`` marks the last update of that overlap.

    ``regions`` (``R_R`` and ``R_L``, or ``R_B`` and ``R_T``: the main map's pixels) and
    ``error`` (the error map as drawn, float32) let a viewer draw the overlap before the
    result exists; the vertical overlap's regions are cut from the horizontal stitch, so
    nothing else could show them live. They are read-only arrays made once per overlap:
    every update of that overlap carries the same objects (no copy per update, and a
    consumer that keeps only the newest snapshot still has them), and the final
    :class:`SeamlessTile` holds them too.
    """

    which: str
    seam: Seam
    path: np.ndarray
    path_source: np.ndarray
    final: bool = False
    regions: dict | None = None
    error: np.ndarray | None = None

    @property
    def slot(self) -> str:
        """Each overlap keeps its own newest seam."""
        return self.which


@dataclass(frozen=True)
class SeamlessTile:
    """A seamless tile and everything the editor draws about it.

    Attributes
    ----------
    tile : (h, w, C) float32
        The seamless tile (wraps left-right and top-bottom).
    rect : (x, y, w, h)
        Tile rectangle in the source; ``overlap`` is w_T.
    regions : dict
        ``R_L``, ``R_R`` ((h + w_T) x w_T, from the source) and ``R_T``, ``R_B``
        (w_T x w, taken after the horizontal stitch).
    region_rects : dict
        Their rectangles (x, y, w, h) in source pixels.
    errors : dict
        ``"horizontal"``: error map of R_R vs R_L, ``"vertical"``: R_B vs R_T (as drawn).
    seams : dict
        The canonical :class:`engine.seams.Seam` of each overlap.
    paths, paths_tile, paths_source : dict
        Seam pixels (row, col) in the region as drawn, in the tile, and in the source.
    alphas : dict
        Weight of R1 (R_R, R_B) over each overlap region as drawn.
    maps : dict
        The same tile for every material map (same cuts).
    criterion, peak : dict
        Per overlap: sum and maximum of the error along the seam.
    seam : SeamSpec
        How the cuts were made (method, options, metric, blending).
    warnings : tuple of str
    """

    tile: np.ndarray
    rect: tuple[int, int, int, int]
    overlap: int
    regions: dict
    region_rects: dict
    errors: dict
    seams: dict
    paths: dict
    paths_tile: dict
    paths_source: dict
    alphas: dict
    maps: dict = field(default_factory=dict)
    criterion: dict = field(default_factory=dict)
    peak: dict = field(default_factory=dict)
    seam: SeamSpec = field(default_factory=SeamSpec)
    warnings: tuple[str, ...] = ()

    @property
    def shape(self) -> tuple[int, int]:
        return self.tile.shape[:2]


# --------------------------------------------------------------------------- helpers
def as_maps(maps, shape: tuple[int, int], name: str = "maps") -> dict[str, np.ndarray]:
    """Validate extra material maps: {name: image of the source's height and width}."""
    if maps is None:
        return {}
    if not isinstance(maps, Mapping):
        raise TypeError(f"{name} must be a mapping of map name -> image, got {type(maps).__name__}")
    out = {}
    for key, img in maps.items():
        if not isinstance(key, str) or not key or key == MAIN:
            raise ValueError(f"{name}: bad map name {key!r} ({MAIN!r} is the source itself)")
        a = as_image(img, f"{name}[{key!r}]")
        if a.shape[:2] != tuple(shape):
            raise ValueError(
                f"{name}[{key!r}] is {a.shape[1]}x{a.shape[0]}, the source is "
                f"{shape[1]}x{shape[0]}; material maps must be co-registered (same size)"
            )
        out[key] = a
    return out


def check_weights(weights, names) -> dict | None:
    if weights is None:
        return None
    if not isinstance(weights, Mapping):
        raise TypeError(f"weights must be a mapping of map name -> weight, got {weights!r}")
    for k in weights:
        if k != MAIN and k not in names:
            raise ValueError(f"weights names an unknown map {k!r} (use {MAIN!r} for the source)")
    return dict(weights)


def seam_error(stack_r1: dict, stack_r2: dict, weights, metric: str) -> np.ndarray:
    """Error map of a (weighted) material; the source alone when ``weights`` is None."""
    return np.asarray(
        material_error(stack_r1, stack_r2, weights=weights, main=MAIN, metric=metric),
        dtype=np.float64,
    )


def iter_seam(error, spec: SeamSpec, *, cyclic=False, waypoints=(), cancel=None):
    """Stream the :class:`SeamUpdate` events of ``spec.iter_find``.

    ``cyclic`` with a method that has no cyclic mode (the graph methods, the walk) pins the
    first and last rows to one common column instead: the best column of ``E[0] + E[-1]``
    (ALGORITHMS §1.7, DP-mode fallback).
    """
    if cyclic and spec.method not in CYCLIC_METHODS:
        e = np.asarray(error, dtype=np.float64)
        pinned = {int(r) for r, _ in waypoints}
        v = int(np.argmin(e[0] + e[-1]))
        kw = {}
        if 0 not in pinned:
            kw["start"] = v
        if e.shape[0] - 1 not in pinned:
            kw["end"] = v
        return (
            yield from iter_find_seam(
                error, seam=spec, waypoints=tuple(waypoints), cancel=cancel, **kw
            )
        )
    return (
        yield from iter_find_seam(
            error, seam=spec, waypoints=tuple(waypoints), cyclic=bool(cyclic), cancel=cancel
        )
    )


def _restrict(error: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """Make columns outside [lo, hi] prohibitively expensive (finite, for every method)."""
    out = error.copy()
    big = float(error.sum()) + 1.0
    out[:, :lo] = big
    out[:, hi + 1 :] = big
    return out


def _allowed(width: int, spec: SeamSpec) -> tuple[int, int]:
    """Control-point range that keeps column 0 from R1 and column width-1 from R2."""
    pad = math.ceil(spec.width / 2) if spec.blend == "feather" else 0
    lo, hi = pad, width - 2 - pad
    return (lo, hi) if lo <= hi else (0, width - 2)


def _check_waypoints(waypoints) -> dict:
    if waypoints is None:
        return {}
    if not isinstance(waypoints, Mapping):
        raise TypeError("waypoints must be a mapping {'horizontal': [(r, c)...], 'vertical': ...}")
    out = {}
    for k, pts in waypoints.items():
        choice(k, "waypoints key", OVERLAPS)
        arr = np.asarray(list(pts), dtype=np.int64).reshape(-1, 2)
        out[k] = [(int(r), int(c)) for r, c in arr]
    return out


# --------------------------------------------------------------------------- API
def iter_make_seamless(
    source,
    rect,
    *,
    overlap=None,
    seam: SeamSpec | None = None,
    waypoints=None,
    maps=None,
    weights=None,
    cancel=None,
):
    """Make the tile of ``rect`` seamless; returns a generator whose value is a SeamlessTile.

    Parameters
    ----------
    source : (H, W[, C]) array
    rect : (x, y, w, h) or Template
        The tile rectangle (see :mod:`engine.tiles.template`); a :class:`Template` also
        gives ``overlap``.
    overlap : int
        w_T (required with a plain rectangle).
    seam : SeamSpec, optional
        Seam method and options, error metric and blending of both cuts (default
        ``SeamSpec()``: dp, euclid, hard cut).
    waypoints : {"horizontal": [(r, c), ...], "vertical": [...]} or None
        Points the seams must pass, in each overlap region's coordinates as drawn.
    maps : {name: (H, W[, C]) image} or None
        Extra co-registered material maps; they get the same cuts.
    weights : {name: float} or None
        Seam error weights per map (``"main"`` is the source); default: the source only.
    cancel : CancelToken or None
        Raises :class:`engine.cancel.Cancelled` (anytime seam methods stop early first).

    Yields :class:`SeamlessUpdate` snapshots (every seam improvement) and :class:`Progress`.
    """
    S = as_image(source, "source")
    H, W = S.shape[:2]
    if isinstance(rect, Template):
        overlap = rect.overlap if overlap is None else overlap
        rect = rect.rect
    if overlap is None:
        raise TypeError("overlap is required when rect is a plain (x, y, w, h) rectangle")
    x, y, a, b = check_rect(rect, overlap, (H, W))
    spec = as_seam_spec(seam)
    extra = as_maps(maps, (H, W))
    wts = check_weights(weights, extra)
    wps = _check_waypoints(waypoints)
    notes = []
    flat = flat_warning(S)
    if flat:
        notes.append(flat)
        warnings.warn(flat, stacklevel=2)
    return _iter_make_seamless(
        S, extra, (x, y, a, b), int(overlap), spec, wps, wts, cancel, tuple(notes)
    )


def _iter_make_seamless(S, extra, rect, wT, spec: SeamSpec, wps, wts, cancel, notes):
    x, y, a, b = rect
    stack = {MAIN: S, **extra}
    F = {k: v[y : y + b + wT, x : x + a + wT] for k, v in stack.items()}
    R_L = {k: v[:, :wT] for k, v in F.items()}
    R_R = {k: v[:, a : a + wT] for k, v in F.items()}
    yield Progress(0, 2, "seamless: horizontal stitch")

    # ---- horizontal: R1 = R_R kept on the left (the tile's left edge), R2 = R_L; canonical
    E_h = seam_error(R_R, R_L, wts, spec.metric)
    drawn_h = _drawn({"R_R": R_R[MAIN], "R_L": R_L[MAIN]}, E_h)
    lo, hi = _allowed(wT, spec)
    seam_h = yield from _stream(
        iter_seam(_restrict(E_h, lo, hi), spec, waypoints=wps.get("horizontal", ()), cancel=cancel),
        "horizontal",
        (y, x),
        drawn_h,
    )
    check(cancel)
    alpha_h = _alpha(seam_h, E_h, spec)
    strip = apply_cut(R_R, R_L, alpha_h)
    inner = {k: v[:, :a].copy() for k, v in F.items()}  # I of §1.7
    for k in inner:
        inner[k][:, :wT] = strip[k]
    yield _update("horizontal", seam_h, True, (y, x), drawn_h)
    yield Progress(1, 2, "seamless: vertical stitch")

    # ---- vertical: R1 = R_B kept on top; canonical = transpose (rows = tile columns), cyclic
    R_T = {k: v[:wT] for k, v in inner.items()}
    R_B = {k: v[b : b + wT] for k, v in inner.items()}
    E_v = seam_error(R_B, R_T, wts, spec.metric)
    drawn_v = _drawn({"R_B": R_B[MAIN], "R_T": R_T[MAIN]}, E_v)
    Ec = np.ascontiguousarray(E_v.T)
    wv = tuple((c, r) for r, c in wps.get("vertical", ()))
    seam_v = yield from _stream(
        iter_seam(_restrict(Ec, lo, hi), spec, cyclic=True, waypoints=wv, cancel=cancel),
        "vertical",
        (y, x),
        drawn_v,
        transpose=True,
    )
    check(cancel)
    alpha_v = np.ascontiguousarray(_alpha(seam_v, Ec, spec, cyclic=True).T)
    band = apply_cut(R_B, R_T, alpha_v)
    tiles = {k: v[:b].copy() for k, v in inner.items()}
    for k in tiles:
        tiles[k][:wT] = band[k]
    if spec.blend == POISSON:  # the hard cuts, then the gradient-domain solve on the torus
        from engine.poisson import solve_torus_maps

        coords = _traced(rect, wT, alpha_h, alpha_v)
        tiles = solve_torus_maps(tiles, coords, stack)
    up_v = _update("vertical", seam_v, True, (y, x), drawn_v, transpose=True)
    yield up_v
    yield Progress(2, 2, "seamless: done")

    path_h = np.asarray(seam_h.path, dtype=np.intp)
    path_v = np.asarray(up_v.path, dtype=np.intp)
    errors = {"horizontal": drawn_h["error"], "vertical": drawn_v["error"]}
    regions = {**drawn_h["regions"], **drawn_v["regions"]}
    region_rects = {
        "R_L": (x, y, wT, b + wT),
        "R_R": (x + a, y, wT, b + wT),
        "R_T": (x, y, a, wT),
        "R_B": (x, y + b, a, wT),
    }
    drawn = (("horizontal", E_h, path_h), ("vertical", E_v, path_v))
    fr = frozen_array
    return SeamlessTile(
        tile=fr(tiles[MAIN]),
        rect=(x, y, a, b),
        overlap=wT,
        regions={k: regions[k] for k in ("R_L", "R_R", "R_T", "R_B")},
        region_rects=region_rects,
        errors=errors,
        seams={"horizontal": seam_h, "vertical": seam_v},
        paths={"horizontal": fr(path_h), "vertical": fr(path_v)},
        paths_tile={"horizontal": fr(path_h[path_h[:, 0] < b]), "vertical": fr(path_v)},
        paths_source={"horizontal": fr(path_h + (y, x)), "vertical": fr(path_v + (y, x))},
        alphas={"horizontal": fr(alpha_h), "vertical": fr(alpha_v)},
        maps={k: fr(v) for k, v in tiles.items() if k != MAIN},
        criterion={k: float(v[p[:, 0], p[:, 1]].sum()) for k, v, p in drawn},
        peak={k: float(v[p[:, 0], p[:, 1]].max()) for k, v, p in drawn},
        seam=spec,
        warnings=notes,
    )


def _traced(rect, wT: int, alpha_h: np.ndarray, alpha_v: np.ndarray) -> np.ndarray:
    """(h, w, 2) source (row, col) of every pixel of the tile the two hard cuts made."""
    x, y, a, b = rect
    F = np.stack(np.mgrid[y : y + b + wT, x : x + a + wT], axis=2)
    inner = F[:, :a].copy()
    inner[:, :wT] = np.where(alpha_h[..., None] >= 1, F[:, a : a + wT], F[:, :wT])
    tile = inner[:b].copy()
    tile[:wT] = np.where(alpha_v[..., None] >= 1, inner[b : b + wT], inner[:wT])
    return tile


def _alpha(seam: Seam, error: np.ndarray, spec: SeamSpec, cyclic: bool = False) -> np.ndarray:
    """Canonical weight of R1 with the outer column pinned to R1 and the inner one to R2."""
    alpha = np.array(blend_weights(seam, error, spec=spec, cyclic=cyclic), dtype=np.float32)
    alpha[:, 0] = 1.0
    alpha[:, -1] = 0.0
    return alpha


def _drawn(regions: dict, error: np.ndarray) -> dict:
    """The read-only region and error arrays of one overlap (made once, shared by its
    updates and the result)."""
    return {
        "regions": {k: frozen_array(v) for k, v in regions.items()},
        "error": frozen_array(error.astype(np.float32)),
    }


def _stream(gen, which: str, origin, drawn: dict, *, transpose: bool = False):
    """Re-yield a seam search's improvements as :class:`SeamlessUpdate`; return its seam.

    The final update is sent by the caller once the cut is applied.
    """
    while True:
        try:
            ev = next(gen)
        except StopIteration as stop:
            return stop.value
        if isinstance(ev, SeamUpdate):
            if not ev.final:
                yield _update(which, ev.seam, False, origin, drawn, transpose=transpose)
        else:
            yield ev


def _update(which: str, seam: Seam, final: bool, origin, drawn: dict, *, transpose=False):
    path = np.asarray(seam.path, dtype=np.intp)
    if transpose:
        path = path[:, ::-1]
    return SeamlessUpdate(
        which=which,
        seam=seam,
        path=frozen_array(path),
        path_source=frozen_array(path + np.asarray(origin)),
        final=final,
        **drawn,
    )


def make_seamless(source, rect, **options) -> SeamlessTile:
    """Drain :func:`iter_make_seamless` and return the :class:`SeamlessTile`."""
    return drain(iter_make_seamless(source, rect, **options))
