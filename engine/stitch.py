"""Stitching along minimum-error seams: oriented stitches, the L-shaped quilting cut, patching.

ALGORITHMS.md §0 (canonical stitch and orientations), §1.4 (stitch), §1.5 (closed-path
patching), §1.7 (cyclic template stitch), §2.3 (minimum error boundary cut, L-shaped overlap).

The canonical stitch keeps R1 on the left and R2 on the right of an (h, w) overlap; the seam
runs top to bottom. ``orientation`` names where R2 lies relative to R1:

* ``"right"``  – R2 right of R1, R1 kept on the left (canonical),
* ``"left"``   – R2 left of R1, R1 kept on the right (``fliplr``),
* ``"bottom"`` – R2 below R1, R1 kept on top (transpose),
* ``"top"``    – R2 above R1, R1 kept at the bottom (``flipud`` then transpose).

Every result keeps the cut (``mask``, ``alpha`` = weight of R1) apart from the pixels, so the
same cut can be applied to other co-registered maps (normal, height, ...) with ``.apply``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from engine import _jit as jit
from engine import stitch_numpy
from engine._jit import njit
from engine._validate import as_error_map, as_image, choice, positive_int
from engine.blend import (
    adaptive_half_widths,
    blend_weights,
    clamped_half_widths,
    composite,
    cut_columns,
    ramp_from_mask,
)
from engine.cancel import check
from engine.errormap import error_map
from engine.l_cut_side import old_side_of_l_cut, spread
from engine.seams._result import Seam
from engine.seams.graph import graph_path
from engine.seams.search import MINIMAX_METRIC, find_seam
from engine.seams.spec import POISSON, SeamSpec, as_seam_spec

ORIENTATIONS = ("right", "left", "bottom", "top")
GRAPH_METHODS = ("dijkstra", "minimax")
#: the default cut of :func:`patch_cut`: dp with adaptive blending (Somol & Haindl)
PATCH_SEAM = SeamSpec(blend="adaptive")

__all__ = [
    "GRAPH_METHODS",
    "LCut",
    "ORIENTATIONS",
    "PATCH_SEAM",
    "PatchCut",
    "PatchResult",
    "StitchResult",
    "dp_arm_cut_kernel",
    "dp_l_cut_kernel",
    "l_cut",
    "map_points",
    "patch",
    "patch_cut",
    "stitch",
]


# ----------------------------------------------------------------------------- orientation
def to_canonical(a: np.ndarray, orientation: str) -> np.ndarray:
    """View of an (H, W[, C]) array in the canonical orientation (R1 left, R2 right)."""
    if orientation == "right":
        return a
    if orientation == "left":
        return a[:, ::-1]
    if orientation == "bottom":
        return np.swapaxes(a, 0, 1)
    return np.swapaxes(a[::-1], 0, 1)


def from_canonical(a: np.ndarray, orientation: str) -> np.ndarray:
    """Inverse of :func:`to_canonical`."""
    if orientation in ("right", "left", "bottom"):
        return to_canonical(a, orientation)  # these transforms are their own inverse
    return np.swapaxes(a, 0, 1)[::-1]


def map_points(pts: np.ndarray, orientation: str, shape, *, inverse: bool = False) -> np.ndarray:
    """Map (N, 2) (row, col) points of an (h, w) = ``shape`` map in ``orientation`` to its
    canonical view (:func:`to_canonical`), or canonical points back with ``inverse`` (``shape``
    is the map's own shape both ways). Returns (N, 2) intp."""
    h, w = shape
    r, c = pts[:, 0], pts[:, 1]
    if orientation == "left":
        out = (r, w - 1 - c)
    elif orientation == "bottom":
        out = (c, r)
    elif orientation == "top":
        out = (h - 1 - c, r) if inverse else (c, h - 1 - r)
    else:
        out = (r, c)
    return np.column_stack(out).astype(np.intp)


def _frozen(*arrays: np.ndarray) -> None:
    for a in arrays:
        a.setflags(write=False)


def _pair(r1, r2, names=("r1", "r2")) -> tuple[np.ndarray, np.ndarray]:
    a = as_image(r1, names[0])
    b = as_image(r2, names[1])
    if a.shape != b.shape:
        raise ValueError(
            f"{names[0]} and {names[1]} must have the same shape, got {a.shape} and {b.shape}"
        )
    return a, b


def _given_error(error, shape, name: str = "error") -> np.ndarray:
    e = as_error_map(error, name)
    if e.shape != tuple(shape):
        raise ValueError(f"{name} must be shaped {tuple(shape)}, got {e.shape}")
    return e.astype(np.float32)


# ----------------------------------------------------------------------------- stitch
@dataclass(frozen=True)
class StitchResult:
    """A stitch of two co-registered regions.

    Attributes
    ----------
    image : (h, w, C) float32
        The stitched overlap, ``alpha * r1 + (1 - alpha) * r2``.
    error : (h, w) float32
        The error map the seam was searched on (caller orientation).
    seam : Seam
        The seam in the canonical orientation (its ``criterion`` and ``peak`` do not depend
        on the orientation).
    path : (N, 2) intp
        The seam pixels (row, col) in the caller's orientation.
    mask : (h, w) bool
        True where the hard cut keeps R1 (path included).
    alpha : (h, w) float32
        Weight of R1 after blending.
    orientation : str
        Where R2 lies relative to R1.
    """

    image: np.ndarray
    error: np.ndarray
    seam: Seam
    path: np.ndarray
    mask: np.ndarray
    alpha: np.ndarray
    orientation: str

    @property
    def criterion(self) -> float:
        return self.seam.criterion

    @property
    def peak(self) -> float:
        return self.seam.peak

    def apply(self, r1, r2) -> np.ndarray:
        """The same cut and blend applied to other co-registered maps (material maps)."""
        return composite(self.alpha, r1, r2)


def stitch(
    r1,
    r2,
    *,
    orientation: str = "right",
    seam: SeamSpec | None = None,
    start: int | None = None,
    end: int | None = None,
    waypoints=(),
    cyclic: bool = False,
    error=None,
    cancel=None,
) -> StitchResult:
    """Stitch two equally sized overlap regions along a minimum-error seam (§1.4).

    Parameters
    ----------
    r1, r2 : (h, w[, C]) array
        R1 (kept on its side, see the module docstring) and R2.
    orientation : {"right", "left", "bottom", "top"}
        Where R2 lies relative to R1.
    seam : SeamSpec, optional
        Seam method and options, the error metric (ignored when ``error`` is given) and the
        blending after the cut; default ``SeamSpec()`` (dp, euclid, hard cut).
    start, end : int, optional
        Column of the first / last row of the path in the canonical orientation.
    waypoints : iterable of (row, col)
        Pixels the path must pass, in the caller's orientation.
    cyclic : bool
        The canonical rows form a ring (the cyclic template stitch, §1.7): the path closes on
        itself and the blend ramp wraps instead of ending at the ring's cut.
    error : (h, w) array, optional
        A precomputed error map (e.g. a weighted multi-map error of a material).
    cancel : CancelToken, optional
    """
    a, b = _pair(r1, r2)
    choice(orientation, "orientation", ORIENTATIONS)
    spec = as_seam_spec(seam)
    err = error_map(a, b, metric=spec.metric) if error is None else _given_error(error, a.shape[:2])
    ce = np.ascontiguousarray(to_canonical(err, orientation))
    wps = ()
    if len(waypoints):
        try:
            wp = np.asarray(waypoints, dtype=np.intp).reshape(-1, 2)
        except (TypeError, ValueError):
            raise ValueError(f"waypoints must be (row, col) pairs, got {waypoints!r}") from None
        wps = [tuple(p) for p in map_points(wp, orientation, err.shape).tolist()]
    found = find_seam(
        ce, seam=spec, start=start, end=end, waypoints=wps, cyclic=cyclic, cancel=cancel
    )
    alpha_c = blend_weights(found, ce, spec=spec, cyclic=bool(cyclic))
    alpha = np.ascontiguousarray(from_canonical(alpha_c, orientation))
    mask = np.ascontiguousarray(from_canonical(np.asarray(found.mask), orientation))
    path = map_points(np.asarray(found.path), orientation, err.shape, inverse=True)
    image = composite(alpha, a, b)
    _frozen(image, err, path, mask, alpha)
    return StitchResult(image, err, found, path, mask, alpha, orientation)


# ----------------------------------------------------------------------------- L-shaped cut
@njit(cache=True, nogil=True)
def _dp_to_bottom(e):  # pragma: no cover - compiled
    """cost[j, i] = cheapest one-pixel-per-row 8-connected path from (j, i) to the last row."""
    h, w = e.shape
    cost = np.empty((h, w))
    step = np.zeros((h, w), np.int8)
    cost[h - 1] = e[h - 1]
    for j in range(h - 2, -1, -1):
        for i in range(w):
            best = cost[j + 1, i]
            k = 0
            if i > 0 and cost[j + 1, i - 1] < best:
                best = cost[j + 1, i - 1]
                k = -1
            if i < w - 1 and cost[j + 1, i + 1] < best:
                best = cost[j + 1, i + 1]
                k = 1
            cost[j, i] = e[j, i] + best
            step[j, i] = k
    return cost, step


@njit(cache=True, nogil=True)
def _trace_down(step, r, c):  # pragma: no cover - compiled
    h = step.shape[0]
    cols = np.empty(h - r, np.intp)
    cols[0] = c
    for j in range(r, h - 1):
        c += step[j, c]
        cols[j - r + 1] = c
    return cols


@dataclass(frozen=True)
class LCut:
    """Efros & Freeman's cut of a quilting block against its left and top overlaps.

    Attributes
    ----------
    mask : (bh, bw) bool
        True where the old (already placed) content is kept; the cut's pixels are old.
    path : (N, 2) intp
        The cut (row, col), from the bottom end of the left arm to the right end of the top
        arm (a single strip: bottom to top, or left to right).
    criterion, peak : float
        Sum and maximum of the error over ``path``.
    meeting : tuple[int, int] | None
        Where the two arms join (None for a single strip or a graph path over the L).
    """

    mask: np.ndarray
    path: np.ndarray
    criterion: float
    peak: float
    meeting: tuple[int, int] | None = None

    def apply(self, old, new) -> np.ndarray:
        """Hard composite: ``old`` where ``mask``, else ``new``."""
        return composite(self.mask, old, new)


@njit(cache=True, nogil=True)
def _old_side_of_barrier(barrier, seed_left, seed_top):  # pragma: no cover - compiled
    """Old region of a cut given as a barrier (h, w) bool: the barrier, every pixel 4-connected
    to the left (``seed_left``) or top (``seed_top``) edge without crossing it, and every pocket
    of the rest not 4-connected to the block's border (holes filled).

    The same as labelling ``~barrier`` (4-connectivity), keeping the labels met on the seed
    edges, adding the barrier and ``ndimage.binary_fill_holes``; two flood fills of one stack.
    """
    h, w = barrier.shape
    state = np.zeros((h, w), np.uint8)  # 0 unvisited, 1 barrier, 2 old side, 3 new side
    for r in range(h):
        for c in range(w):
            if barrier[r, c]:
                state[r, c] = 1
    stack = np.empty(h * w, np.int64)
    for fill in (2, 3):
        n = 0
        for r in range(h):
            for c in range(w):
                if state[r, c] != 0:
                    continue
                if fill == 2:
                    seed = (seed_left and c == 0) or (seed_top and r == 0)
                else:  # what the old side left and touches the border is new
                    seed = r == 0 or c == 0 or r == h - 1 or c == w - 1
                if seed:
                    state[r, c] = fill
                    stack[n] = r * w + c
                    n += 1
        spread(state, stack, n, fill)
    return state != 3


def _old_side(path: np.ndarray, shape, seed_left: bool, seed_top: bool) -> np.ndarray:
    """Old region of a cut: the cut plus everything 4-connected to the block's left (top) edge
    without crossing it; pockets of the new side enclosed by it become old (holes filled)."""
    barrier = np.zeros(shape, dtype=bool)
    barrier[path[:, 0], path[:, 1]] = True
    if _numpy_cut(barrier):
        return stitch_numpy.old_side_of_barrier(barrier, seed_left, seed_top)
    return _old_side_of_barrier(barrier, seed_left, seed_top)


@njit(cache=True, nogil=True)
def _dp_meeting(e, ovl, ovt):  # pragma: no cover - compiled
    """Where the dp arms of an L-cut join: the first (row-major) corner pixel q of least
    ``E_v(q) + E_h(q) - e(q)``, with the step tables of the left strip (bottom-up) and of the
    transposed top strip (right-to-left)."""
    v_cost, v_step = _dp_to_bottom(np.ascontiguousarray(e[:, :ovl]))
    h_cost, h_step = _dp_to_bottom(np.ascontiguousarray(e[:ovt].T))
    qr = qc = 0
    best = v_cost[0, 0] + h_cost[0, 0] - e[0, 0]
    for r in range(ovt):
        for c in range(ovl):
            joint = v_cost[r, c] + h_cost[c, r] - e[r, c]
            if joint < best:
                best, qr, qc = joint, r, c
    return qr, qc, v_step, h_step


@njit(cache=True, nogil=True)
def _dp_l_cut(e, ovl, ovt):  # pragma: no cover - compiled
    """The dp L-cut of an (bh, bw) error map with both arms: path, old side and meeting point.

    The arms join at :func:`_dp_meeting`'s q; the path runs from the bottom row up the left
    arm to q, then along the top arm to the right column, each pixel once (first visit kept).
    """
    bh, bw = e.shape
    qr, qc, v_step, h_step = _dp_meeting(e, ovl, ovt)
    down = _trace_down(v_step, qr, qc)  # columns of rows qr .. bh - 1
    right = _trace_down(h_step, qc, qr)  # rows of columns qc .. bw - 1
    barrier = np.zeros((bh, bw), np.bool_)
    path = np.empty((down.size + right.size, 2), np.intp)
    n = 0
    for k in range(down.size + right.size):
        if k < down.size:
            r, c = qr + down.size - 1 - k, down[down.size - 1 - k]
        else:
            r, c = right[k - down.size], qc + k - down.size
        if not barrier[r, c]:
            barrier[r, c] = True
            path[n, 0], path[n, 1] = r, c
            n += 1
    return path[:n].copy(), old_side_of_l_cut(barrier, ovl, ovt), qr, qc


dp_l_cut_kernel = _dp_l_cut
"""The compiled dp L-cut (path, old side, meeting row, meeting col) of a float64 error map with
both arms, for other kernels to call without the checks of :func:`l_cut` (quilting's)."""


@njit(cache=True, nogil=True)
def dp_arm_cut_kernel(e, ovl, ovt):  # pragma: no cover - compiled
    """:func:`l_cut`'s dp cut (path, old side) of a float64 error map with one arm (``ovt``
    or ``ovl`` 0: the first row or column of blocks): the same pixels, for other kernels."""
    bh, bw = e.shape
    strip = np.ascontiguousarray(e[:, :ovl] if ovt == 0 else e[:ovt].T)
    cost, step = _dp_to_bottom(strip)
    cols = _trace_down(step, 0, np.argmin(cost[0]))
    n = len(cols)
    path = np.empty((n, 2), np.intp)
    barrier = np.zeros((bh, bw), np.bool_)
    for i in range(n):
        j = n - 1 - i if ovt == 0 else i  # the left arm bottom to top; the top one rightwards
        r, c = (j, cols[j]) if ovt == 0 else (cols[j], j)
        path[i, 0], path[i, 1] = r, c
        barrier[r, c] = True
    return path, _old_side_of_barrier(barrier, ovl > 0, ovt > 0)


def _numpy_cut(e: np.ndarray) -> bool:
    """Whether to cut ``e`` with :mod:`engine.stitch_numpy` (same results): a small block while
    numba is not loaded (a small job then never starts it)."""
    return e.size <= stitch_numpy.SMALL_CUT_PIXELS and not jit.loaded()


def _strip_path(strip: np.ndarray, spec: SeamSpec, start, cancel) -> np.ndarray:
    """Top-to-bottom path through a vertical strip with ``spec`` (dp inline for speed)."""
    strip = np.ascontiguousarray(strip)
    if spec.method == "dp":
        small = _numpy_cut(strip)
        cost, step = (stitch_numpy.dp_to_bottom if small else _dp_to_bottom)(strip)
        c0 = int(np.argmin(cost[0])) if start is None else start
        cols = (stitch_numpy.trace_down if small else _trace_down)(step, 0, c0)
        return np.column_stack([np.arange(strip.shape[0]), cols])
    return np.asarray(find_seam(strip, seam=spec, start=start, cancel=cancel).path)


def l_cut(
    error,
    *,
    overlap_left: int,
    overlap_top: int,
    seam: SeamSpec | None = None,
    cancel=None,
) -> LCut:
    """Minimum error boundary cut of a block against its left and top overlaps (§2.3).

    Parameters
    ----------
    error : (bh, bw) array
        Error of the new block against the existing content over the block's footprint; only
        the left strip (``overlap_left`` columns) and the top strip (``overlap_top`` rows) are
        read.
    overlap_left, overlap_top : int
        Overlap widths; one of them may be 0 (a single strip: first row / column of blocks).
    seam : SeamSpec, optional
        The seam method and its options (default dp; metric and blend are the caller's).

        * ``dp``: the vertical strip is solved bottom-up and the horizontal strip right-to-left;
          the arms join at the corner pixel q of lowest combined cost
          ``E_v(q) + E_h(q) - e(q)`` (exact for this path model).
        * ``dijkstra`` / ``minimax``: one :func:`engine.seams.graph_path` over the L-shaped
          domain from the bottom row of the left arm to the right column of the top arm
          (options ``connectivity``, and ``variant`` / ``levels`` for minimax).
        * ``oscillating``, ``oscillating-optimal``, ``resistance``: the meeting point q is the
          one of lowest combined dp cost; then each arm is searched with ``method`` from q,
          pinned there (``start``): down the left strip and right along the top strip.
    cancel : CancelToken, optional

    The old region is the cut plus everything on its outer (top-left) side; new pockets the
    cut encloses join the old side, so old and new are each one 4-connected region when the
    block has an interior outside the overlaps. The cut's own pixels are old, as R1 keeps the
    path in every :class:`engine.seams.Seam` mask (ALGORITHMS §2.3 gives them to the new block,
    §0 to R1: one pixel of difference along the cut).
    """
    e = np.ascontiguousarray(as_error_map(error))
    bh, bw = e.shape
    ovl = positive_int(overlap_left, "overlap_left", minimum=0)
    ovt = positive_int(overlap_top, "overlap_top", minimum=0)
    if ovl == 0 and ovt == 0:
        raise ValueError("overlap_left and overlap_top must not both be 0")
    if ovl > bw:
        raise ValueError(f"overlap_left must be <= the block width {bw}, got {ovl}")
    if ovt > bh:
        raise ValueError(f"overlap_top must be <= the block height {bh}, got {ovt}")
    spec = as_seam_spec(seam)
    method = spec.method
    check(cancel)
    meeting = mask = None
    if ovt == 0:
        path = _strip_path(e[:, :ovl], spec, None, cancel)[::-1]
    elif ovl == 0:
        path = _strip_path(e[:ovt].T, spec, None, cancel)[:, ::-1]
    elif method in GRAPH_METHODS:
        path = _graph_l_path(e, ovl, ovt, spec, cancel)
    elif method == "dp":
        path, mask, qr, qc = (stitch_numpy.dp_l_cut if _numpy_cut(e) else _dp_l_cut)(e, ovl, ovt)
        meeting = (int(qr), int(qc))
    else:
        qr, qc, _, _ = _dp_meeting(e, ovl, ovt)
        meeting = (int(qr), int(qc))
        down = _strip_path(e[qr:, :ovl], spec, qc, cancel) + (qr, 0)
        right = _strip_path(e[:ovt, qc:].T, spec, qr, cancel)
        path = _unique_in_order(np.concatenate([down[::-1], right[:, ::-1] + (0, qc)]))
    if mask is None:
        path = np.ascontiguousarray(path, dtype=np.intp)
        mask = _old_side(path, e.shape, ovl > 0, ovt > 0)
    values = e[path[:, 0], path[:, 1]]
    _frozen(mask, path)
    return LCut(mask, path, float(values.sum()), float(values.max()), meeting)


def _graph_l_path(e, ovl, ovt, spec: SeamSpec, cancel) -> np.ndarray:
    opts = dict(spec.options)
    metric = "sum"
    if spec.method == "minimax":
        metric = MINIMAX_METRIC[opts.pop("variant")]
    bh, bw = e.shape
    domain = np.zeros(e.shape, dtype=bool)
    domain[:, :ovl] = True
    domain[:ovt] = True
    sources = np.zeros(e.shape, dtype=bool)
    sources[bh - 1, :ovl] = True
    targets = np.zeros(e.shape, dtype=bool)
    targets[:ovt, bw - 1] = True
    return graph_path(e, sources, targets, domain=domain, metric=metric, cancel=cancel, **opts)


# ----------------------------------------------------------------------------- patching
@dataclass(frozen=True)
class PatchCut:
    """Closed-path cut transferring a window Q (source) onto U (target), §1.5.

    Attributes
    ----------
    alpha : (ph, pw) float32
        Weight of Q; exactly 0 on the outer ``margin`` ring.
    mask : (ph, pw) bool
        True inside the closed loop (loop included): the hard cut's Q pixels.
    loop : (N, 2) intp
        The closed 8-connected loop (row, col) in window coordinates: top side (TL→TR), right
        (TR→BR), bottom (BR→BL), left (BL→TL), each corner once.
    corners : tuple of four (row, col)
        The pinned corner points TL, TR, BR, BL.
    sides : dict[str, Seam]
        The four side seams in their canonical orientation (R1 = Q inside, R2 = U outside).
    criterion, peak : float
        Sum and maximum of the error over the loop's pixels (each counted once).
    error : (ph, pw) float32
        The error map D(Q, U).
    """

    alpha: np.ndarray
    mask: np.ndarray
    loop: np.ndarray
    corners: tuple
    sides: dict
    criterion: float
    peak: float
    error: np.ndarray

    def apply(self, q, u) -> np.ndarray:
        """Composite ``q`` over ``u`` with this cut (also for co-registered material maps)."""
        return composite(self.alpha, q, u)


class PatchResult(NamedTuple):
    """The patched target image and the cut that made it."""

    image: np.ndarray
    cut: PatchCut


def _corner(d: np.ndarray, r0: int, c0: int, n: int, anti: bool) -> tuple[int, int]:
    """argmin of ``d`` in the n×n square at (r0, c0); ties go to the pixel nearest the square's
    diagonal through the window corner (main diagonal, or the anti-diagonal when ``anti``)."""
    sub = d[r0 : r0 + n, c0 : c0 + n]
    rr, cc = np.mgrid[0:n, 0:n]
    off = np.abs(rr - (n - 1 - cc)) if anti else np.abs(rr - cc)
    k = np.lexsort((off.ravel(), sub.ravel()))[0]
    return r0 + int(rr.ravel()[k]), c0 + int(cc.ravel()[k])


def patch_cut(
    q,
    u,
    *,
    ring: int,
    margin: int = 2,
    seam: SeamSpec | None = None,
    error=None,
    bias=None,
    cancel=None,
) -> PatchCut:
    """Closed-path cut for moving window ``q`` onto ``u`` (ALGORITHMS §1.5).

    ``bias`` (ph, pw), optional, is added to the error for the choice of the corner points
    and the paths only (e.g. to draw the cut toward the outer margin); the blend widths and
    the reported criterion and peak use the error itself.

    Four oriented stitches (left, top, right, bottom) run in the outer ring of width ``ring``
    (w_P), at ring offsets ``margin .. ring - 1``, with R1 = Q (inside) and R2 = U (outside).
    Their end control points are pinned to four corner points (the lowest-error pixel of each
    corner square, ties nearest the square's diagonal), so they form one closed 8-connected
    loop. The mask is everything not 4-connected to the window border (loop included); the
    blend is the EDT ramp with each side's half-widths (adaptive: §1.3 per side; feather:
    ``width / 2``); the outer ``margin`` pixels keep alpha exactly 0 (U untouched).

    ``seam`` gives the method, its options, the metric (unless ``error`` is given) and the
    blending; default :data:`PATCH_SEAM` (dp, adaptive blending).
    """
    qq, uu = _pair(q, u, ("q", "u"))
    wp = positive_int(ring, "ring", minimum=1)
    m = positive_int(margin, "margin", minimum=0)
    if m >= wp:
        raise ValueError(f"margin must be smaller than ring, got margin={m}, ring={wp}")
    spec = as_seam_spec(seam, default=PATCH_SEAM)
    ph, pw = qq.shape[:2]
    if min(ph, pw) < 2 * wp:
        raise ValueError(
            f"the window ({pw}x{ph}) must be at least 2 * ring = {2 * wp} pixels on each side"
        )
    d = error_map(qq, uu, metric=spec.metric) if error is None else _given_error(error, (ph, pw))
    d64 = d.astype(np.float64)
    s64 = d64 if bias is None else d64 + _given_error(bias, (ph, pw), "bias")
    n = wp - m
    tl = _corner(s64, m, m, n, False)
    tr = _corner(s64, m, pw - wp, n, True)
    br = _corner(s64, ph - wp, pw - wp, n, False)
    bl = _corner(s64, ph - wp, m, n, True)

    # each side: (canonical error map, start, end, canonical (row, col) -> window (row, col))
    def side_maps(x):
        return {
            "top": (
                x[m:wp, tl[1] : tr[1] + 1][::-1].T,
                wp - 1 - tl[0],
                wp - 1 - tr[0],
                lambda p: (wp - 1 - p[:, 1], p[:, 0] + tl[1]),
            ),
            "right": (
                x[tr[0] : br[0] + 1, pw - wp : pw - m],
                tr[1] - (pw - wp),
                br[1] - (pw - wp),
                lambda p: (p[:, 0] + tr[0], p[:, 1] + pw - wp),
            ),
            "bottom": (
                x[ph - wp : ph - m, bl[1] : br[1] + 1].T,
                bl[0] - (ph - wp),
                br[0] - (ph - wp),
                lambda p: (p[:, 1] + ph - wp, p[:, 0] + bl[1]),
            ),
            "left": (
                x[tl[0] : bl[0] + 1, m:wp][:, ::-1],
                wp - 1 - tl[1],
                wp - 1 - bl[1],
                lambda p: (p[:, 0] + tl[0], wp - 1 - p[:, 1]),
            ),
        }

    specs = side_maps(d64)
    search = specs if bias is None else side_maps(s64)
    sides, pieces = {}, {}
    b_at = np.zeros((ph, pw))
    for name, (ce, start, end, to_window) in specs.items():
        check(cancel)
        ce = np.ascontiguousarray(ce)
        # the path on the (biased) search map; the blend widths from the error itself
        side = find_seam(
            np.ascontiguousarray(search[name][0]), seam=spec, start=start, end=end, cancel=cancel
        )
        sides[name] = side
        p = np.asarray(side.path)
        rows, cols = to_window(p)
        pieces[name] = np.column_stack([rows, cols]).astype(np.intp)
        b_rows = _side_half_widths(side, ce, spec)
        np.maximum.at(b_at, (rows, cols), b_rows[p[:, 0]])
    from scipy import ndimage

    loop = _ordered_loop(pieces)
    barrier = np.zeros((ph, pw), dtype=bool)
    barrier[loop[:, 0], loop[:, 1]] = True
    labels, _ = ndimage.label(~barrier)
    border = np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])
    mask = ~np.isin(labels, np.unique(border[border > 0]))
    hard = spec.blend in ("none", POISSON)
    alpha = mask.astype(np.float32) if hard else _ring_ramp(mask, barrier, b_at, wp)
    if m:
        alpha[:m] = 0
        alpha[-m:] = 0
        alpha[:, :m] = 0
        alpha[:, -m:] = 0
    values = d64[loop[:, 0], loop[:, 1]]
    _frozen(alpha, mask, loop, d)
    return PatchCut(
        alpha, mask, loop, (tl, tr, br, bl), sides, float(values.sum()), float(values.max()), d
    )


def _loop_ramp(mask: np.ndarray, barrier: np.ndarray, b_at: np.ndarray) -> np.ndarray:
    """EDT ramp of ``mask`` whose half-width is read at the loop pixel nearest to each pixel."""
    from scipy import ndimage

    _, idx = ndimage.distance_transform_edt(~barrier, return_indices=True)
    return ramp_from_mask(mask, b_at[idx[0], idx[1]])


def _ring_ramp(mask: np.ndarray, barrier: np.ndarray, b_at: np.ndarray, ring: int) -> np.ndarray:
    """:func:`_loop_ramp` computed only where it can differ from the hard mask.

    The loop lies in the outer ``ring`` pixels and a pixel is blended only within ``b`` of the
    mask's boundary, so everything further than ``ring + r`` from the window border (``r``:
    the largest half-width plus a few pixels of slack for the nearest-pixel look-ups) is hard.
    The ramp is computed on four border strips of width ``ring + 2 r``, each kept where every
    pixel within ``r`` of it lies in the strip (what the distance transforms see there is what
    they see in the whole window); windows too small for that get the whole-window ramp.
    """
    ph, pw = mask.shape
    r = math.ceil(float(b_at.max())) + 3
    d = ring + 2 * r
    if 4 * d * max(ph, pw) >= ph * pw:
        return _loop_ramp(mask, barrier, b_at)
    alpha = mask.astype(np.float32)
    k = d - r  # rows (columns) of a strip whose r-neighbourhood lies inside it
    every = slice(None)
    for src, dst, part in (
        ((slice(0, d), every), (slice(0, k), every), (slice(0, k), every)),
        ((slice(ph - d, ph), every), (slice(ph - k, ph), every), (slice(d - k, d), every)),
        ((every, slice(0, d)), (every, slice(0, k)), (every, slice(0, k))),
        ((every, slice(pw - d, pw)), (every, slice(pw - k, pw)), (every, slice(d - k, d))),
    ):
        alpha[dst] = _loop_ramp(mask[src], barrier[src], b_at[src])[part]
    return alpha


def _side_half_widths(seam: Seam, ce: np.ndarray, spec: SeamSpec):
    """Per canonical row half-widths of one side (§1.3 per side, clamped inside the ring)."""
    h = ce.shape[0]
    if spec.blend in ("none", POISSON):
        return np.zeros(h)
    b = (
        np.full(h, spec.width / 2.0)
        if spec.blend == "feather"
        else adaptive_half_widths(seam, ce, rho=spec.rho)
    )
    cols = cut_columns(seam.mask)
    return clamped_half_widths(cols, b, ce.shape[1]) if cols is not None else b


def _ordered_loop(pieces: dict) -> np.ndarray:
    """Top (TL→TR), right (TR→BR), bottom (BR→BL), left (BL→TL); each corner once."""
    parts = [pieces["top"], pieces["right"], pieces["bottom"][::-1], pieces["left"][::-1]]
    return _unique_in_order(np.concatenate(parts))


def _unique_in_order(path: np.ndarray) -> np.ndarray:
    """``path`` without repeated pixels (first occurrence kept, order preserved)."""
    _, first = np.unique(path, axis=0, return_index=True)
    return np.ascontiguousarray(path[np.sort(first)], dtype=np.intp)


def patch(
    target,
    source,
    *,
    target_origin=(0, 0),
    source_origin=(0, 0),
    size=None,
    ring: int,
    margin: int = 2,
    **options,
) -> PatchResult:
    """Patch the window of ``source`` at ``source_origin`` into a copy of ``target``.

    ``target_origin`` and ``source_origin`` are the windows' top-left (row, col); ``size`` is
    (height, width), default the whole target. ``options`` go to :func:`patch_cut`. Pixels
    outside the target window, and its outer ``margin`` ring, are copied from ``target``
    exactly.
    """
    t = as_image(target, "target")
    s = as_image(source, "source")
    if t.shape[2] != s.shape[2]:
        raise ValueError(
            f"target and source must have the same channels, got {t.shape[2]} and {s.shape[2]}"
        )
    ph, pw = (t.shape[0], t.shape[1]) if size is None else (int(size[0]), int(size[1]))
    ty, tx = (int(v) for v in target_origin)
    sy, sx = (int(v) for v in source_origin)
    for name, (y, x), img in (("target", (ty, tx), t), ("source", (sy, sx), s)):
        if not (0 <= y <= img.shape[0] - ph and 0 <= x <= img.shape[1] - pw):
            raise ValueError(
                f"{name}_origin {(y, x)} with size {(ph, pw)} puts the window outside the "
                f"{img.shape[1]}x{img.shape[0]} {name}"
            )
    qq = s[sy : sy + ph, sx : sx + pw]
    uu = t[ty : ty + ph, tx : tx + pw]
    cut = patch_cut(qq, uu, ring=ring, margin=margin, **options)
    out = t.copy()
    out[ty : ty + ph, tx : tx + pw] = cut.apply(qq, uu)
    return PatchResult(out, cut)
