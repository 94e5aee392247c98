"""Template tile search: position and size of the tile rectangle (ALGORITHMS.md §1.6).

The tile rectangle ``rect = (x, y, w, h)`` is the tile's *period*: the finished tile is
``w`` x ``h`` pixels. Its *footprint* in the source extends ``overlap`` (w_T) pixels further
right and down, ``(x, y, w + overlap, h + overlap)``: the left border region R_L is columns
``[x, x + w_T)`` and R_R columns ``[x + w, x + w + w_T)`` (both over the footprint's rows);
R_T / R_B are rows ``[y, y + w_T)`` / ``[y + h, y + h + w_T)``.

The search minimises the mean RGB Euclidean distance between R_L and R_R and between R_T and
R_B, in the paper's two phases (horizontal: every x and width at once, vertical: every y and
height with the columns fixed), optionally refined by redoing the horizontal phase on the
chosen rows until the rectangle is stable (at most three times).

**Calm wrap joints** [REC, beyond the paper]: after the stitch (:mod:`engine.tiles.seamless`)
the tile's left edge is source column ``x + w`` and its right edge column ``x + w - 1`` (the
cuts keep both), so the tile's left-right wrap joint *is* the natural column pair
``(x + w - 1, x + w)``; likewise its top-bottom joint is the row pair ``(y + h - 1, y + h)``.
Minimising the strip mismatch alone may put that pair on an edge of the texture (a mortar
line of a brick wall: 2.6x the mean column step), which no cut can repair. The phases
therefore minimise ``D_h(x, w) + λ·G_h(x + w)`` and ``D_v(y, h) + λ·G_v(y + h)`` where
``G_h(c)`` is the mean distance between columns ``c - 1`` and ``c`` over the rows in use (the
units of D) and λ is ``joint_weight`` (default :data:`JOINT_WEIGHT`, chosen on the bundled
samples by ``benchmarks/tileset.py --joint-weights``; 0 gives the paper's criterion).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import time
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from engine import _jit as jit
from engine._checks import as_size
from engine._validate import as_image, positive_int
from engine.cancel import Cancelled, is_cancelled
from engine.errormap import colour_channels
from engine.events import Item, Progress, Snapshot, drain, frozen_array
from engine.tiles.detail import DETAIL_WEIGHT, DetailTerm, check_detail_weight
from engine.tiles.scale import Scale, structure_scale, whole_structure_range
from engine.tiles.stationarity import stationarity_of
from engine.tiles.template_scan import (
    SMALL_SCAN_PAIRS,
    Scan,
    argmin_cost,
    rect_costs,
    runs_1d,
    runs_right,
)

__all__ = [
    "Template",
    "TemplateSweep",
    "TemplateUpdate",
    "default_overlap",
    "find_template",
    "iter_find_template",
    "template_cost",
]

SWEEP_INTERVAL = 1 / 30  # seconds between sweep events at least (no display redraws faster)
JOINT_WEIGHT = 0.5  # λ: weight of the natural wrap joint's step G next to the strip mismatch D


@dataclass(frozen=True, slots=True)
class TemplateUpdate(Snapshot):
    """The best tile rectangle so far: ``rect = (x, y, w, h)``, its ``cost`` and phase."""

    rect: tuple[int, int, int, int]
    cost: float
    overlap: int
    phase: str = ""


@dataclass(frozen=True, slots=True)
class TemplateSweep(Item):
    """A sample of the rectangles the search has just scored (``sweep`` > 0), to draw the sweep.

    ``rects`` (n, 4) holds (x, y, w, h) tile rectangles in source pixels (as
    :attr:`Template.rect`; a phase scores them all at once over its rows or columns), ``costs``
    their criterion; ``best`` / ``best_cost`` the best of the phase's sampled rectangles so far,
    and in the phase's last event (whose one rectangle it is) the phase's own best, which the
    search goes on with. ``phase`` is
    ``"horizontal"`` or ``"vertical"``, ``round`` 0 for the search and 1.. for the refinement
    rounds, ``coarse`` True on the reduced image of a large source (coordinates scaled back).
    """

    phase: str
    round: int
    coarse: bool
    rects: np.ndarray
    costs: np.ndarray
    best: tuple[int, int, int, int]
    best_cost: float
    overlap: int


@dataclass(frozen=True, slots=True)
class Template:
    """Result of the template search.

    Attributes
    ----------
    rect : (x, y, w, h)
        The tile rectangle in source pixels; the tile is ``w`` x ``h``.
    overlap : int
        w_T, the width of the border regions R_L/R_R/R_T/R_B.
    cost : float
        The searched criterion: ``(cost_horizontal + cost_vertical) / 2 + joint_weight *
        (joint_horizontal + joint_vertical) / 2`` plus the detail term ``κ·C·max(0, 1 −
        detail)`` (:mod:`engine.tiles.detail`; :func:`template_cost` gives the same).
    cost_horizontal, cost_vertical : float
        Mean RGB Euclidean distance R_L vs R_R and R_T vs R_B (the strip mismatch).
    warnings : tuple of str
        Anything the caller should show the user (clamped range, flat source...).
    joint_horizontal, joint_vertical : float
        Mean distance between the natural columns ``x + w - 1`` and ``x + w`` (rows
        ``y + h - 1`` and ``y + h``) over the footprint: the step across the tile's wrap.
    joint_weight : float
        λ used by the search.
    detail : float
        q of the footprint: its mean high-frequency energy over the mean of every window of
        its size in the source (:mod:`engine.tiles.detail`; 1 = as detailed as the average;
        NaN when the search ran without the detail term).
    detail_weight : float
        κ used by the search (0: no detail term).
    scale : Scale or None
        The texture's structure scale (:mod:`engine.tiles.scale`) the search measured (None:
        not measured, ``whole_structures=False``).
    """

    rect: tuple[int, int, int, int]
    overlap: int
    cost: float
    cost_horizontal: float = 0.0
    cost_vertical: float = 0.0
    warnings: tuple[str, ...] = ()
    joint_horizontal: float = 0.0
    joint_vertical: float = 0.0
    joint_weight: float = 0.0
    detail: float = math.nan
    detail_weight: float = 0.0
    scale: Scale | None = None

    @property
    def footprint(self) -> tuple[int, int, int, int]:
        """Source rectangle (x, y, w, h) the seamless tile is made from (rect + overlap)."""
        x, y, w, h = self.rect
        return (x, y, w + self.overlap, h + self.overlap)


# --------------------------------------------------------------------------- validation
def default_overlap(tile_min, tile_max=None) -> int:
    """w_T ≈ 1/10 of the expected tile size (the mean of the range), at least 2 and at most
    half the smallest tile side (a wide range such as 40..400 would otherwise get a w_T
    that ``tile_min`` cannot hold)."""
    lo = as_size(tile_min, "tile_min")
    hi = as_size(tile_max if tile_max is not None else tile_min, "tile_max")
    expected = (lo[0] + lo[1] + hi[0] + hi[1]) / 4.0
    return max(2, min(int(round(expected / 10.0)), min(lo) // 2))


def excluded_mask(excluded, shape: tuple[int, int]) -> np.ndarray | None:
    if excluded is None:
        return None
    m = np.asarray(excluded)
    if m.ndim == 3 and m.shape[2] == 1:
        m = m[:, :, 0]
    if m.shape != tuple(shape):
        raise ValueError(
            f"excluded must be a (H, W) mask of the source's size {tuple(shape)}, got {m.shape}"
        )
    m = m.astype(bool)
    if m.all():
        raise ValueError("excluded covers the whole source: no tile can be taken from it")
    return m if m.any() else None


def _resolve_range(shape, tile_min, tile_max, overlap):
    """Validated ((hmin, wmin), (hmax, wmax), overlap, warnings) for a source of ``shape``."""
    H, W = shape
    lo = as_size(tile_min, "tile_min")
    hi = as_size(tile_max if tile_max is not None else tile_min, "tile_max")
    if lo[0] > hi[0] or lo[1] > hi[1]:
        raise ValueError(f"tile_min {lo} must not exceed tile_max {hi} (as (h, w))")
    if overlap is None:
        overlap = default_overlap(lo, hi)
    if isinstance(overlap, bool) or not isinstance(overlap, numbers.Integral):
        raise TypeError(f"overlap must be an integer, got {overlap!r}")
    overlap = int(overlap)
    if overlap < 2:
        raise ValueError(f"overlap must be >= 2, got {overlap}")
    if 2 * overlap > min(lo):
        raise ValueError(
            f"overlap {overlap} is too wide for tile_min {lo}: it must be at most half the "
            "smallest tile side"
        )
    if lo[0] + overlap > H or lo[1] + overlap > W:
        raise ValueError(
            f"the source ({W}x{H}) is smaller than the minimum tile {lo[1]}x{lo[0]} plus the "
            f"overlap {overlap}: choose a smaller tile_min or a larger source"
        )
    notes = []
    fit = (min(hi[0], H - overlap), min(hi[1], W - overlap))
    if fit != hi:
        notes.append(
            f"tile_max {hi[1]}x{hi[0]} plus overlap {overlap} does not fit the {W}x{H} source; "
            f"using tile_max {fit[1]}x{fit[0]}"
        )
    return lo, fit, overlap, notes


def flat_warning(source: np.ndarray) -> str | None:
    """A warning text when ``source`` is (nearly) a single colour, else None."""
    ref = source[0, 0]
    for step in (8, 1):  # a sparse look first: large sources are rarely flat
        if float(np.abs(source[::step, ::step] - ref).max()) >= 1e-6:
            return None
    return "the source is a single flat colour: every tile (and every candidate) will be identical"


def _make_template(S, valid, rect, overlap, joint_weight, notes=(), detail=None) -> Template:
    ch, cv, gh, gv = rect_costs(S, valid, rect, overlap)
    q, pen = (math.nan, 0.0) if detail is None else detail.rect_detail(rect, overlap)
    return Template(
        rect=rect,
        overlap=overlap,
        cost=(ch + cv) / 2.0 + joint_weight * (gh + gv) / 2.0 + pen,
        cost_horizontal=ch,
        cost_vertical=cv,
        warnings=tuple(notes),
        joint_horizontal=gh,
        joint_vertical=gv,
        joint_weight=joint_weight,
        detail=q,
        detail_weight=0.0 if detail is None else detail.weight,
    )


def _joint_weight(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"joint_weight must be a number, got {value!r}")
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"joint_weight must be finite and >= 0, got {value!r}")
    return float(value)


# --------------------------------------------------------------------------- API
def template_cost(
    source,
    rect,
    *,
    overlap: int,
    excluded=None,
    joint_weight: float = JOINT_WEIGHT,
    detail_weight: float = DETAIL_WEIGHT,
) -> tuple[float, float, float]:
    """Cost of a given (e.g. user-dragged) rectangle: ``(cost, cost_horizontal, cost_vertical)``.

    ``rect = (x, y, w, h)``; its footprint ``(x, y, w + overlap, h + overlap)`` must lie in
    the source. Excluded pixels are left out of the means. ``cost`` is the search's criterion
    (strip mismatches plus ``joint_weight`` times the wrap-joint steps plus the detail term
    of ``detail_weight``, as :attr:`Template.cost`); ``cost_horizontal`` / ``cost_vertical``
    are the strip mismatches.
    """
    t = rect_template(
        source,
        rect,
        overlap=overlap,
        excluded=excluded,
        joint_weight=joint_weight,
        detail_weight=detail_weight,
    )
    return t.cost, t.cost_horizontal, t.cost_vertical


def rect_template(
    source,
    rect,
    *,
    overlap: int,
    excluded=None,
    joint_weight: float = JOINT_WEIGHT,
    detail_weight: float = DETAIL_WEIGHT,
) -> Template:
    """The :class:`Template` of a given rectangle: every figure the search would report for it
    (costs, joint steps, detail)."""
    S = colour_channels(as_image(source, "source"))
    H, W = S.shape[:2]
    x, y, a, b = check_rect(rect, overlap, (H, W))
    ex = excluded_mask(excluded, (H, W))
    lam = _joint_weight(joint_weight)
    term = DetailTerm.of(S, check_detail_weight(detail_weight))
    return _make_template(
        S, None if ex is None else ~ex, (x, y, a, b), int(overlap), lam, detail=term
    )


def check_rect(rect, overlap, shape) -> tuple[int, int, int, int]:
    H, W = shape
    if isinstance(overlap, bool) or not isinstance(overlap, numbers.Integral) or overlap < 1:
        raise ValueError(f"overlap must be a positive integer, got {overlap!r}")
    try:
        x, y, a, b = (int(v) for v in rect)
    except (TypeError, ValueError):
        raise TypeError(f"rect must be (x, y, w, h) integers, got {rect!r}") from None
    if a < 2 * overlap or b < 2 * overlap:
        raise ValueError(f"rect {rect!r} must be at least 2*overlap = {2 * overlap} px per side")
    if x < 0 or y < 0 or x + a + overlap > W or y + b + overlap > H:
        raise ValueError(
            f"rect {rect!r} plus overlap {overlap} reaches outside the {W}x{H} source "
            f"(the footprint is (x, y, w + overlap, h + overlap))"
        )
    return x, y, a, b


def iter_find_template(
    source,
    *,
    tile_min,
    tile_max=None,
    overlap=None,
    excluded=None,
    refine: bool = True,
    coarse: int | None = None,
    joint_weight: float = JOINT_WEIGHT,
    detail_weight: float = DETAIL_WEIGHT,
    sweep: int = 0,
    whole_structures: bool = True,
    cancel=None,
):
    """Search the tile rectangle; returns a generator of events whose value is a Template.

    Parameters
    ----------
    source : (H, W[, C]) array
        The source image (any dtype; converted to float32 in [0, 1]).
    tile_min, tile_max : int or (h, w)
        Smallest and largest tile size (the tile period, without the overlap). A
        ``tile_max`` that does not fit the source is clamped with a warning.
    overlap : int or None
        w_T; default ≈ 1/10 of the expected tile size (:func:`default_overlap`).
    excluded : (H, W) bool array or None
        Source pixels the tile footprint must not contain.
    refine : bool
        Redo the horizontal phase on the chosen rows until stable (≤ 3 rounds).
    coarse : int or None
        Search first on an image ``coarse`` times smaller (with the same refinement), then
        at full resolution only around that result (shifts ±coarse, positions ±2·coarse).
        None (default): chosen from the work (1 = off for a 512 px source, 4 for 4096 px
        with a ±12 % size range).
    joint_weight : float
        λ >= 0: weight of the step across the tile's wrap joints (the natural column pair
        ``x + w - 1, x + w`` and row pair ``y + h - 1, y + h``) added to the strip mismatch,
        so the wrap does not fall on an edge of the texture (module docstring). 0 searches
        the strip mismatch alone (the paper's criterion).
    detail_weight : float
        κ >= 0: weight of the detail term (:mod:`engine.tiles.detail`), which keeps the
        search out of flat or blurred regions, where a low strip mismatch is easy. 0: off.
    sweep : int
        0 (default): no sweep events. n > 0: a :class:`TemplateSweep` with about n of the
        rectangles scored since the last one (spread evenly over the widths or heights and their
        positions, their costs computed for the sample alone) and the best shown so far, at most
        every :data:`SWEEP_INTERVAL` seconds (no display redraws faster, and the sampling costs
        the search little); at the end of each phase one more with the phase's own best. For
        drawing the search (the editor draws them faintly); how many arrive depends on timing.
    whole_structures : bool
        Measure the texture's structure scale (:func:`engine.tiles.scale.structure_scale`) and
        search only tiles that hold :data:`~engine.tiles.scale.STRUCTURES_PER_TILE` structures
        per side where the range allows (its smallest tile raised per axis), warning in words
        when the largest tile cannot (issue 10, item 6). False: the range as given.
    cancel : CancelToken or None
        Once a first rectangle exists the search returns the best so far; before that it
        raises :class:`engine.cancel.Cancelled`.

    Yields :class:`TemplateUpdate` for every better rectangle, :class:`TemplateSweep` (with
    ``sweep``) and :class:`Progress`. When lighting or sharpness varies across the source
    (:func:`engine.tiles.stationarity.check_stationarity`), the search warns and the
    Template's ``warnings`` say so, with what to do.
    """
    S = np.ascontiguousarray(colour_channels(as_image(source, "source")))
    H, W = S.shape[:2]
    lo, hi, overlap, notes = _resolve_range((H, W), tile_min, tile_max, overlap)
    ex = excluded_mask(excluded, (H, W))
    valid = None if ex is None else ~ex
    run0 = None
    if valid is not None:
        run0 = _feasible_run0(valid, lo[0] + overlap)
        if run0.max(initial=0) < lo[1] + overlap:
            raise ValueError(
                f"no {lo[1]}x{lo[0]} tile (plus overlap {overlap}) fits outside the excluded "
                "region; paint a smaller exclusion or lower tile_min"
            )
    flat = flat_warning(S)
    if flat:
        notes.append(flat)
    scale = None
    if whole_structures and not flat:
        scale = structure_scale(S)
        whole, hi, too_small = whole_structure_range(scale, lo, hi)
        notes += too_small
        if valid is None:
            lo = whole
        elif whole != lo:  # with an exclusion, only when such a tile still fits outside it
            run_w = _feasible_run0(valid, whole[0] + overlap)
            if run_w.max(initial=0) >= whole[1] + overlap:
                lo, run0 = whole, run_w
    for n in notes:
        warnings.warn(n, stacklevel=2)
    if coarse is not None:
        positive_int(coarse, "coarse")
    lam = _joint_weight(joint_weight)
    kappa = check_detail_weight(detail_weight)
    sweep = positive_int(sweep, "sweep", minimum=0)
    return _iter_find_template(
        S,
        valid,
        run0,
        lo,
        hi,
        overlap,
        bool(refine),
        cancel,
        tuple(notes),
        coarse,
        lam,
        sweep,
        kappa,
        scale,
    )


_BUDGET = 1.5e8  # pixel pairs of a full-resolution horizontal phase before going coarse


def _feasible_run0(valid: np.ndarray, h0: int) -> np.ndarray:
    """Widest exclusion-free footprint starting at column x over some ``h0`` rows."""
    H = valid.shape[0]
    runs = runs_right(valid)
    mins = ndimage.minimum_filter1d(runs, size=h0, axis=0, mode="constant", cval=0)
    return mins[h0 // 2 : h0 // 2 + H - h0 + 1].max(axis=0)


def _window(feasible: np.ndarray | None, n: int, win) -> np.ndarray | None:
    """``feasible`` (or "no limit") with every position outside ``win = (lo, hi)`` disabled."""
    if win is None:
        return feasible
    out = np.full(n, n, dtype=np.int64) if feasible is None else feasible.copy()
    lo, hi = max(0, win[0]), min(n - 1, win[1])
    out[:lo] = 0
    out[hi + 1 :] = 0
    return out


def _coarse_factor(shape, n_shifts: int) -> int:
    f = 1
    while n_shifts * shape[0] * shape[1] / f**3 > _BUDGET:
        f += 1
    return f


def _iter_find_template(
    S,
    valid,
    run0,
    lo,
    hi,
    overlap,
    refine,
    cancel,
    notes,
    coarse=None,
    lam=JOINT_WEIGHT,
    sweep=0,
    kappa=DETAIL_WEIGHT,
    scale=None,
):
    H, W = S.shape[:2]
    term = DetailTerm.of(S, kappa)
    uneven = stationarity_of(S, energy=None if term is None else term.E).warnings
    for n in uneven:
        warnings.warn(n, stacklevel=3)
    notes = (*notes, *uneven)
    n_a = hi[1] - lo[1] + 1
    f = _coarse_factor((H, W), n_a) if coarse is None else int(coarse)
    rounds = 4 if refine else 1
    prog = {"done": 0, "total": rounds * (n_a + hi[0] - lo[0] + 1)}
    xwin = ywin = None
    a_rng, b_rng = (lo[1], hi[1]), (lo[0], hi[0])
    if f > 1:
        # coarse-to-fine: the same search on an f-times smaller image, then full resolution
        # only around it (shifts +-f, positions +-2f)
        Hc, Wc = H // f, W // f
        Sc = S[: Hc * f, : Wc * f].reshape(Hc, f, Wc, f, -1).mean(axis=(1, 3))
        Sc = np.ascontiguousarray(Sc, dtype=np.float32)
        vc = None if valid is None else valid[: Hc * f, : Wc * f].reshape(Hc, f, Wc, f).all((1, 3))
        term_c = None
        if term is not None:  # the full resolution's energy, pooled: still *high* frequencies
            Ec = term.E[: Hc * f, : Wc * f].reshape(Hc, f, Wc, f).mean(axis=(1, 3))
            term_c = DetailTerm.of(Sc, kappa, E=Ec)
        loc = (-(-lo[0] // f), -(-lo[1] // f))
        hic = (max(loc[0], hi[0] // f), max(loc[1], hi[1] // f))
        ovc = max(2, round(overlap / f))
        if loc[0] + ovc <= Hc and loc[1] + ovc <= Wc:
            prog["total"] += rounds * (hic[1] - loc[1] + hic[0] - loc[0] + 2)
            run0c = None if vc is None else _feasible_run0(vc, loc[0] + ovc)
            if run0c is None or run0c.max(initial=0) >= loc[1] + ovc:
                c, stopped = yield from _phases(
                    *(Sc, vc, run0c, loc, hic, ovc, refine, cancel, notes, prog, "coarse ", lam),
                    sweep=sweep,
                    scale=f,
                    detail=term_c,
                )
                if stopped:
                    raise Cancelled("cancelled before the first tile rectangle was found")
                if c is not None:
                    xc, yc, ac, bc = c.rect
                    a_rng = (max(lo[1], f * ac - f), min(hi[1], f * ac + f))
                    b_rng = (max(lo[0], f * bc - f), min(hi[0], f * bc + f))
                    xwin = (f * xc - 2 * f, f * xc + 2 * f)
                    ywin = (f * yc - 2 * f, f * yc + 2 * f)
    best, stopped = yield from _phases(
        S,
        valid,
        run0,
        (b_rng[0], a_rng[0]),
        (b_rng[1], a_rng[1]),
        overlap,
        refine,
        cancel,
        notes,
        prog,
        "",
        lam,
        xwin,
        ywin,
        sweep=sweep,
        detail=term,
    )
    if best is None and not stopped and xwin is not None:  # the windows missed: search it all
        best, stopped = yield from _phases(
            *(S, valid, run0, lo, hi, overlap, refine, cancel, notes, prog, "", lam),
            sweep=sweep,
            detail=term,
        )
    if best is None:
        if stopped:
            raise Cancelled("cancelled before the first tile rectangle was found")
        raise ValueError(
            "no tile rectangle fits the source outside the excluded region for this tile range"
        )
    yield Progress(prog["total"], prog["total"], "template: done")
    return best if scale is None else dataclasses.replace(best, scale=scale)


def _phases(
    S,
    valid,
    run0,
    lo,
    hi,
    overlap,
    refine,
    cancel,
    notes,
    prog,
    label,
    lam,
    xwin=None,
    ywin=None,
    sweep=0,
    scale=1,
    detail=None,
):
    """The two phases (+ refinement rounds); returns (best Template or None, cancelled).

    ``sweep`` > 0 streams :class:`TemplateSweep` items of about that many scored rectangles
    (coordinates times ``scale``)."""
    H, W = S.shape[:2]
    a_shifts = np.arange(lo[1], hi[1] + 1)
    b_shifts = np.arange(lo[0], hi[0] + 1)
    rounds = 4 if refine else 1
    if H * W * (a_shifts.size + b_shifts.size) * rounds >= SMALL_SCAN_PAIRS:
        # the whole search's pixel pairs decide whether numba's start-up pays: a search over a
        # range of tile sizes runs several scans of many shifts, each small on its own (512²,
        # 224..288: 3.2 s on the numpy twins, 0.49 s with the kernels, their loading included)
        jit.load()
    best: Template | None = None

    def scan(St, vt, rows, shifts, feasible, what, to_rect, footprint=None):
        """``to_rect(positions, shifts)`` -> (n, 4) rects of a phase's scored pairs;
        ``footprint`` = (line energy, depth, reference per shift) of the detail term."""
        sc = Scan(St, vt, rows, shifts, overlap, lam, footprint and (detail, *footprint))
        top = [np.inf, None]  # the best rectangle the sweep has shown in this phase

        def swept(pos, kk, cost, final=False):
            rects = to_rect(pos, shifts[kk]) * scale
            i = int(np.argmin(cost))
            if cost[i] < top[0] or final:
                top[:] = [float(cost[i]), tuple(int(v) for v in rects[i])]
            return TemplateSweep(
                phase=what,
                round=_round,
                coarse=bool(label),
                rects=frozen_array(rects),
                costs=frozen_array(cost),
                best=top[1],
                best_cost=top[0],
                overlap=overlap * scale,
            )

        shown = [-np.inf, 0]  # time of the last sweep event, the shifts it covered
        for _k0, k1 in sc.chunks():
            if sweep and time.perf_counter() - shown[0] >= SWEEP_INTERVAL:
                kk, pos, cost = sc.sampled(feasible, shown[1], k1, sweep)
                shown[:] = [time.perf_counter(), k1]
                if cost.size:
                    yield swept(pos, kk, cost)
            yield Progress(
                min(prog["done"] + k1, prog["total"]),
                prog["total"],
                f"template: {label}{what} phase",
            )
            if is_cancelled(cancel):
                return None
        prog["done"] += shifts.size
        found = argmin_cost(sc.costs(feasible), shifts)
        if sweep and found is not None:  # the phase's own best, what the search goes on with
            x, a, c = found
            k = int(np.flatnonzero(shifts == a)[0])
            yield swept(np.array([x]), np.array([k]), np.array([c]), final=True)
        return found

    def horizontal_rects(r0, r1):
        return lambda x, a: np.stack(
            [x, np.full_like(x, r0), a, np.full_like(x, r1 - r0 - overlap)], 1
        )

    rows = (0, H)
    feasible_h = _window(run0, W, xwin)
    current = None
    _round = 0
    for _round in range(rounds):
        fp = None
        if detail is not None:
            depth = rows[1] - rows[0]
            fp = (detail.line_energy(rows), depth, detail.reference(depth, a_shifts + overlap))
        hx = yield from scan(
            S, valid, rows, a_shifts, feasible_h, "horizontal", horizontal_rects(*rows), fp
        )
        if is_cancelled(cancel):
            return best, True
        if hx is None:
            break
        x, a, _ = hx
        band = slice(x, x + a + overlap)
        St = np.ascontiguousarray(S[:, band].transpose(1, 0, 2))
        vt = None
        feasible_v = None
        if valid is not None:
            vt = np.ascontiguousarray(valid[:, band].T)
            feasible_v = runs_1d(valid[:, band].all(axis=1))
        feasible_v = _window(feasible_v, H, ywin)
        fp = None
        if detail is not None:
            line = detail.line_energy(None, (x, x + a + overlap), transposed=True)
            fp = (line, a + overlap, detail.reference(b_shifts + overlap, a + overlap))
        vy = yield from scan(
            St,
            vt,
            (0, a + overlap),
            b_shifts,
            feasible_v,
            "vertical",
            lambda y, b, x=x, a=a: np.stack([np.full_like(y, x), y, np.full_like(y, a), b], 1),
            fp,
        )
        if is_cancelled(cancel):
            return best, True
        if vy is None:
            break
        y, b, _ = vy
        rect = (x, y, a, b)
        if rect == current:
            break
        current = rect
        t = _make_template(S, valid, rect, overlap, lam, notes, detail)
        if best is None or t.cost < best.cost - 1e-12:
            best = t
            if not label:
                yield TemplateUpdate(
                    rect=rect,
                    cost=t.cost,
                    overlap=overlap,
                    phase="search" if _round == 0 else "refine",
                )
        elif _round > 0:
            break
        # refinement: the horizontal phase again on the chosen rows
        rows = (y, y + b + overlap)
        if valid is not None:
            feasible_h = _window(runs_1d(valid[rows[0] : rows[1]].all(axis=0)), W, xwin)
    return best, False


def find_template(source, **options) -> Template:
    """Drain :func:`iter_find_template` and return the :class:`Template`."""
    return drain(iter_find_template(source, **options))
