"""Seam search: the validation of a call and the dispatch to the methods' solvers
(the method tables and the options' checks live in :mod:`engine.seams.spec`)."""

from __future__ import annotations

import functools
import numbers
from dataclasses import dataclass

import numpy as np

from engine._validate import as_error_map
from engine.cancel import check
from engine.events import Snapshot, drain
from engine.seams._result import Seam, make_seam
from engine.seams.dp import dp_seam
from engine.seams.graph import shortest_path
from engine.seams.oscillating import controls_seam, iter_oscillating, optimal_controls
from engine.seams.resistance import resistance_path
from engine.seams.spec import (
    CYCLIC_METHODS,
    INITS,
    METHODS,
    MINIMAX_VARIANTS,
    RESISTANCE_VARIANTS,
    SeamSpec,
    as_seam_spec,
)

#: path metric of the graph search for each minimax variant
MINIMAX_METRIC = {"exact": "minimax", "lm": "lm", "sorted": "sorted"}

__all__ = [
    "MINIMAX_METRIC",
    "SeamUpdate",
    "find_seam",
    "iter_find_seam",
    "warmup",
]


@dataclass(frozen=True, slots=True)
class SeamUpdate(Snapshot):
    """The best seam found so far (anytime methods stream every improvement)."""

    seam: Seam
    final: bool = False


# ----------------------------------------------------------------------------- validation
def _column(value, name: str, w: int) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer column or None, got {value!r}")
    if not 0 <= value < w:
        raise ValueError(f"{name} must be a column in [0, {w - 1}], got {value}")
    return int(value)


def _waypoints(waypoints, h: int, w: int) -> list[tuple[int, int]]:
    try:
        pts = list(waypoints)
    except TypeError:
        raise TypeError(
            f"waypoints must be an iterable of (row, col) pairs, got {waypoints!r}"
        ) from None
    out = set()
    for p in pts:
        try:
            r, c = p
        except (TypeError, ValueError):
            raise ValueError(f"waypoints must be (row, col) pairs, got {p!r}") from None
        for v in (r, c):
            if isinstance(v, bool) or not isinstance(v, numbers.Integral):
                raise TypeError(f"waypoints must hold integer (row, col) pairs, got {p!r}")
        if not (0 <= r < h and 0 <= c < w):
            raise ValueError(
                f"waypoint {(int(r), int(c))} lies outside the error map ({h} rows x {w} columns)"
            )
        out.add((int(r), int(c)))
    pts = sorted(out)
    for a, b in zip(pts, pts[1:], strict=False):
        if a[0] == b[0]:
            raise ValueError(f"waypoints must lie in distinct rows, got {a} and {b}")
    return pts


def _pins(shape, start, end, waypoints) -> np.ndarray:
    """Pinned column of every row (-1: free) from start, end and waypoints."""
    h, w = shape
    pins = np.full(h, -1, dtype=np.int64)
    for r, c in _waypoints(waypoints, h, w):
        pins[r] = c
    by = {r: f"waypoint {(r, int(pins[r]))}" for r in np.flatnonzero(pins >= 0)}
    for name, row, col in (
        ("start", 0, _column(start, "start", w)),
        ("end", h - 1, _column(end, "end", w)),
    ):
        if col is None:
            continue
        if pins[row] >= 0 and pins[row] != col:
            raise ValueError(f"{name}={col} conflicts with {by[row]} in row {row}")
        pins[row] = col
        by[row] = f"{name}={col}"
    return pins


def _step_image(image, shape) -> np.ndarray:
    a = np.asarray(image)
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == bool):
        raise TypeError(f"image must be a numeric array, got dtype {a.dtype}")
    a = a.astype(np.float64)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[:2] != tuple(shape):
        raise ValueError(
            f"image must be shaped {tuple(shape)} or {tuple(shape)} + (C,), got {np.shape(image)}"
        )
    if not np.all(np.isfinite(a)):
        raise ValueError("image must be finite")
    return np.ascontiguousarray(a)


# ----------------------------------------------------------------------------- solvers
def _intervals(pins: np.ndarray, w: int):
    return np.where(pins >= 0, pins, 0), np.where(pins >= 0, pins, w - 1)


def _segmented(e: np.ndarray, pins: np.ndarray, solve, cancel) -> np.ndarray:
    """Join the best paths between consecutive anchors (top row or start, waypoints, bottom
    row or end); each segment stays inside its band of rows and off earlier segments."""
    h, w = e.shape
    anchors = [(int(r), int(pins[r])) for r in np.flatnonzero(pins >= 0) if 0 < r < h - 1]
    top = (0, int(pins[0]) if pins[0] >= 0 else None)
    bottom = (h - 1, int(pins[h - 1]) if pins[h - 1] >= 0 else None)
    anchors = [top, *anchors, bottom]
    used = np.zeros(e.shape, dtype=bool)
    parts = []
    for (ra, ca), (rb, cb) in zip(anchors, anchors[1:], strict=False):
        check(cancel)
        dom = np.zeros(e.shape, dtype=bool)
        dom[ra : rb + 1] = True
        dom &= ~used
        src = np.zeros(e.shape, dtype=bool)
        tgt = np.zeros(e.shape, dtype=bool)
        if ca is None:
            src[ra] = True
        else:
            src[ra, ca] = dom[ra, ca] = True
        if cb is None:
            tgt[rb] = True
        else:
            tgt[rb, cb] = True
        path = solve(src, tgt, dom)
        if path is None:  # cannot happen for a band (a straight detour always exists)
            raise ValueError(f"no path from {(ra, ca)} to {(rb, cb)}")
        used[path[:, 0], path[:, 1]] = True
        parts.append(path if not parts else path[1:])
    return np.concatenate(parts)


def _graph_seam(e, pins, method, opts, cancel) -> Seam:
    metric = MINIMAX_METRIC[opts["variant"]] if method == "minimax" else "sum"

    def solve(src, tgt, dom):
        return shortest_path(
            e,
            src,
            tgt,
            dom,
            metric=metric,
            levels=opts.get("levels", 32),
            connectivity=opts["connectivity"],
            cancel=cancel,
        )

    return make_seam(e, _segmented(e, pins, solve, cancel), method)


def _solve(e, method, pins, cyclic, opts, image, cancel) -> Seam:
    h, w = e.shape
    check(cancel)
    if method == "dp":
        return dp_seam(e, *_intervals(pins, w), cyclic=cyclic)
    if method == "oscillating-optimal":
        c = optimal_controls(e, *_intervals(pins, w), cyclic=cyclic, cancel=cancel)
        return controls_seam(e, c, cyclic, method, lazy=False)
    if method == "resistance":
        path = resistance_path(
            e, pins, max_run=opts["max_run"], image=image, variant=opts["variant"]
        )
        return make_seam(e, path, method)
    return _graph_seam(e, pins, method, opts, cancel)


def _iter_single(e, method, pins, cyclic, opts, image, cancel):
    seam = _solve(e, method, pins, cyclic, opts, image, cancel)
    check(cancel)
    yield SeamUpdate(seam, final=True)
    return seam


def _iter_anytime(e, pins, cyclic, opts, cancel):
    best = None
    for best in iter_oscillating(
        e,
        pins,
        o_max=opts["o_max"],
        variant=opts["variant"],
        init=opts["init"],
        cyclic=cyclic,
        cancel=cancel,
    ):
        yield SeamUpdate(best, final=False)
    yield SeamUpdate(best, final=True)  # the search ended (converged or cancelled)
    return best


@functools.cache
def _default_spec(method: str) -> SeamSpec:
    """``SeamSpec(method)``, built once per method: a spec is immutable, and validating it
    again on every call cost about 20 µs of a 70 µs cut on a 32×6 overlap."""
    return SeamSpec(method)


# ----------------------------------------------------------------------------- public API
def iter_find_seam(
    error,
    *,
    seam: SeamSpec | None = None,
    method: str | None = None,
    start: int | None = None,
    end: int | None = None,
    waypoints=(),
    cyclic: bool = False,
    image=None,
    cancel=None,
    **options,
):
    """Validate the call eagerly, then return a generator of :class:`SeamUpdate` returning the
    :class:`Seam`.

    Parameters
    ----------
    error : (h, w) array_like
        Non-negative, finite error map (R1 left, R2 right; the path runs top to bottom).
    seam : SeamSpec, optional
        The method and its options (its metric and blend concern the caller)...
    method, **options
        ... or the method by name (default ``"dp"``) and its options as keywords
        (:data:`engine.seams.OPTIONS`; unknown ones raise TypeError), not both.
    start, end : int, optional
        Fixed column of the path in row 0 / row h-1.
    waypoints : iterable of (row, col)
        Pixels the path must pass through (at most one per row).
    cyclic : bool
        Rows 0 and h-1 are neighbours (toroidal wrap, ALGORITHMS §1.7); ``dp``, ``oscillating``
        and ``oscillating-optimal`` only.
    image : (h, w[, C]) array, optional
        ``resistance`` only: the image whose colour steps the walk's run cost reads (default:
        the error map).
    cancel : CancelToken, optional
        ``oscillating`` returns its best path so far when cancelled, the others raise
        :class:`engine.Cancelled`.

    Yields
    ------
    SeamUpdate
        ``oscillating``: the initial path (``init``) and every improvement as they come,
        then the best one again with ``final=True``; other methods: one final update.
    """
    if seam is not None:
        if method is not None or options:
            raise TypeError("give either seam=SeamSpec(...) or method= and its options, not both")
        seam = as_seam_spec(seam)
    else:
        method = "dp" if method is None else method
        if not isinstance(method, str) or method not in METHODS:
            raise ValueError(
                f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}"
            )
        seam = SeamSpec(method, options) if options else _default_spec(method)
    method = seam.method
    e = np.ascontiguousarray(as_error_map(error))
    if not e.flags.writeable:  # numba compiles read-only arrays separately: avoid a recompile
        e = e.copy()
    pins = _pins(e.shape, start, end, waypoints)
    if not isinstance(cyclic, bool | np.bool_):
        raise TypeError(f"cyclic must be a bool, got {cyclic!r}")
    cyclic = bool(cyclic)
    if cyclic and method not in CYCLIC_METHODS:
        raise ValueError(
            f"cyclic=True is not supported by method {method!r} "
            f"(use one of {', '.join(CYCLIC_METHODS)})"
        )
    if image is not None:
        if method != "resistance":
            raise TypeError(
                f"unexpected option(s) for method {method!r}: image (only 'resistance' reads it)"
            )
        image = _step_image(image, e.shape)
    opts = seam.options
    if method == "oscillating":
        # streamed seams are built lazily from the map: keep a private copy
        return _iter_anytime(e.copy(), pins, cyclic, opts, cancel)
    return _iter_single(e, method, pins, cyclic, opts, image, cancel)


def find_seam(error, **kwargs) -> Seam:
    """Find a top-to-bottom seam through ``error``: ``find_seam(e, seam=spec, start=...)`` or
    ``find_seam(e, method="oscillating", o_max=5)`` (see :func:`iter_find_seam`)."""
    return drain(iter_find_seam(error, **kwargs))


def warmup() -> None:
    """Compile (or load from the numba cache) every seam kernel on a tiny input.

    About 0.2 s with a warm cache (a first compile takes seconds). Call it in a worker thread at
    start-up so that the first seam a person asks for is not delayed by it.
    """
    rng = np.random.default_rng(0)
    e = rng.random((4, 3))
    image = rng.random((4, 3, 3))
    runs = [dict(method=m) for m in METHODS]
    runs += [dict(method=m, start=1, end=1, waypoints=[(2, 2)]) for m in METHODS]
    runs += [dict(method=m, cyclic=True) for m in CYCLIC_METHODS]
    runs += [dict(method="minimax", variant=v, connectivity=4) for v in MINIMAX_VARIANTS]
    runs += [dict(method="oscillating", variant="faithful", init=i) for i in INITS]
    runs += [dict(method="oscillating", init=i, cyclic=True) for i in INITS]
    runs += [dict(method="resistance", variant=v, image=image) for v in RESISTANCE_VARIANTS]
    runs += [dict(method="resistance", variant="walk", start=1, end=1, waypoints=[(2, 2)])]
    for kw in runs:
        for update in iter_find_seam(e, **kw):
            update.seam.mask  # noqa: B018 (lazily built seams: compile their builder too)
