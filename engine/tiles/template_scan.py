"""The template search's scans (ALGORITHMS.md §1.6): for every position and shift of one
phase at once, the strip mismatch D, the natural wrap joint's step G and the detail term
(:mod:`engine.tiles.detail`) — numba kernels over the shifts, cumulative sums over positions.
A small scan while numba is not loaded takes the kernel's numpy twin (the same sums in the same
order: identical values) and so does not start numba (:func:`engine.tiles.detail.kernel_pays`).
"""

from __future__ import annotations

import math

import numpy as np

from engine import _jit as jit
from engine._jit import njit
from engine.tiles.detail import kernel_pays

__all__ = [
    "CHUNK",
    "Scan",
    "argmin_cost",
    "pair_cost",
    "rect_costs",
    "runs_1d",
    "runs_right",
]

CHUNK = 8  # shifts per kernel call between cancel checks / progress events
#: A scan of fewer pixel pairs (rows x columns x shifts) than this, while numba is not loaded,
#: takes :func:`_shift_sums_numpy` (~10 ns a pair here against the kernel's ~3 ns: numba's
#: start-up, ~0.3-0.6 s, buys ~50-100 M pairs).
SMALL_SCAN_PAIRS = 1 << 24


@njit(cache=True, nogil=True)
def _shift_sums(S, valid, use_valid, r0, r1, shifts, out_sum, out_cnt):  # pragma: no cover
    """out_sum[k, x] = Σ_y d(S[y, x], S[y, x + shifts[k]]) over rows r0..r1-1 (valid pairs)."""
    W = S.shape[1]
    C = S.shape[2]
    for k in range(shifts.shape[0]):
        a = shifts[k]
        for y in range(r0, r1):
            for x in range(W - a):
                if use_valid and not (valid[y, x] and valid[y, x + a]):
                    continue
                s = 0.0
                for c in range(C):
                    d = S[y, x, c] - S[y, x + a, c]
                    s += d * d
                out_sum[k, x] += math.sqrt(s)
                out_cnt[k, x] += 1.0


@njit(cache=True, nogil=True)
def runs_right(free):  # pragma: no cover
    """Length of the run of True starting at every pixel and going right."""
    H, W = free.shape
    out = np.zeros((H, W), dtype=np.int64)
    for y in range(H):
        run = 0
        for x in range(W - 1, -1, -1):
            run = run + 1 if free[y, x] else 0
            out[y, x] = run
    return out


def _shift_sums_numpy(S, valid, use_valid, r0, r1, shifts, out_sum, out_cnt) -> None:
    """:func:`_shift_sums` in numpy: the same float32 differences and squares, float64 channel
    sums, square roots and row-by-row sums (down the rows, from ``out_sum``)."""
    W, C = S.shape[1], S.shape[2]
    if r1 <= r0:
        return
    rows = S[r0:r1]
    for k in range(shifts.shape[0]):
        a = int(shifts[k])
        n = W - a
        if n <= 0:
            continue
        sq = rows[:, :n] - rows[:, a:]
        sq *= sq
        s = sq[..., 0].astype(np.float64)
        for c in range(1, C):
            s += sq[..., c]
        seq = np.empty((r1 - r0 + 1, n))
        seq[0] = out_sum[k, :n]
        np.sqrt(s, out=seq[1:])
        ok = valid[r0:r1, :n] & valid[r0:r1, a:] if use_valid else None
        if ok is not None:
            seq[1:][~ok] = 0.0  # x + 0.0 == x: a skipped pair
        cnt = out_cnt[k, :n]
        if np.array_equal(cnt, np.trunc(cnt)):  # whole counts (always here): any order is exact
            cnt += float(r1 - r0) if ok is None else ok.sum(axis=0)
        else:
            ones = np.ones((r1 - r0, n)) if ok is None else ok
            out_cnt[k, :n] = _down_rows(np.concatenate([cnt[None], ones]))
        out_sum[k, :n] = _down_rows(seq)


def _down_rows(a: np.ndarray) -> np.ndarray:
    """The sum of each column of ``a`` (rows, n), added row by row from the first."""
    # down the rows of a C-ordered (rows, n >= 2) array numpy adds row by row (pairwise
    # summation is only along the contiguous axis: a single column would take it)
    return np.add.reduce(a, axis=0) if a.shape[1] > 1 else np.cumsum(a, axis=0)[-1]


def runs_1d(free: np.ndarray) -> np.ndarray:
    return runs_right(np.ascontiguousarray(free[None, :]))[0]


# --------------------------------------------------------------------------- phases
def scan_kernel_pays(S, rows, shifts: int) -> bool:
    """Whether a scan of ``shifts`` shifts over ``rows`` of ``S`` takes the numba kernel."""
    return kernel_pays((rows[1] - rows[0]) * S.shape[1] * shifts, SMALL_SCAN_PAIRS)


def _sums(S, valid, rows, shifts, out_sum, out_cnt, kernel=True) -> None:
    use_valid = valid is not None
    (_shift_sums if kernel or jit.loaded() else _shift_sums_numpy)(
        S,
        valid if use_valid else np.ones((1, 1), dtype=np.bool_),
        use_valid,
        rows[0],
        rows[1],
        shifts,
        out_sum,
        out_cnt,
    )


def _joint_steps(S, valid, rows) -> np.ndarray:
    """G[c] = mean distance between columns c - 1 and c over ``rows`` (valid pairs); G[0] = 0."""
    W = S.shape[1]
    s = np.zeros((1, W))
    c = np.zeros((1, W))
    _sums(S, valid, rows, np.ones(1, dtype=np.int64), s, c, scan_kernel_pays(S, rows, 1))
    G = np.zeros(W)
    G[1:] = s[0, : W - 1] / np.maximum(c[0, : W - 1], 1.0)
    return G


class Scan:
    """One phase over shifts: the cost D(x, a) + λ·G(x + a) (+ the detail term of the
    footprint) of every position and shift.

    ``detail`` = (term, line, depth, reference): the :class:`DetailTerm`, the energy summed
    over the footprint's other extent per column of ``S`` (``line``, length W), that extent
    (``depth`` px) and the reference ē per shift; None: no detail term."""

    def __init__(self, S, valid, rows, shifts, overlap, joint_weight=0.0, detail=None):
        self.S = S
        self.detail = detail
        self.valid = valid
        self.rows = rows
        self.shifts = np.asarray(shifts, dtype=np.int64)
        self.overlap = overlap
        self.joint_weight = float(joint_weight)
        W = S.shape[1]
        self.sum = np.zeros((self.shifts.size, W), dtype=np.float64)
        self.cnt = np.zeros((self.shifts.size, W), dtype=np.float64)
        self._G = None
        self.kernel = scan_kernel_pays(S, rows, self.shifts.size)

    def chunks(self):
        """Run the kernel chunk by chunk; yields the (start, end) shifts done."""
        for k0 in range(0, self.shifts.size, CHUNK):
            k1 = min(k0 + CHUNK, self.shifts.size)
            _sums(
                *(self.S, self.valid, self.rows, self.shifts[k0:k1]),
                *(self.sum[k0:k1], self.cnt[k0:k1], self.kernel),
            )
            yield k0, k1

    def costs(self, feasible_run: np.ndarray | None, k0: int = 0, k1: int | None = None):
        """(k1 - k0, W) cost of the border pair at x with shift shifts[k]; inf where invalid.

        ``feasible_run[x]`` is the widest footprint allowed to start at column x.
        """
        k1 = self.shifts.size if k1 is None else k1
        K, W = k1 - k0, self.sum.shape[1]
        w = self.overlap
        if self._G is None:
            self._G = self.joint_weight * _joint_steps(self.S, self.valid, self.rows)
        out = np.full((K, W), np.inf)
        n = W - w + 1  # positions of the overlap strip
        if K == 0 or n <= 0:
            return out
        cs = np.zeros((K, W + 1))
        cc = np.zeros((K, W + 1))
        np.cumsum(self.sum[k0:k1], axis=1, out=cs[:, 1:])
        np.cumsum(self.cnt[k0:k1], axis=1, out=cc[:, 1:])
        s = cs[:, w : w + n] - cs[:, :n]
        c = cc[:, w : w + n] - cc[:, :n]
        x = np.arange(n)[None, :]
        a = self.shifts[k0:k1, None]
        ok = (c > 0) & (x + a + w <= W)  # the whole footprint inside
        if feasible_run is not None:
            ok &= feasible_run[:n][None, :] >= a + w
        with np.errstate(invalid="ignore", divide="ignore"):
            d = s / np.maximum(c, 1) + self._G[np.minimum(x + a, W - 1)]
        if self.detail is not None:
            term, line, depth, ref = self.detail
            cl = np.concatenate([[0.0], np.cumsum(line)])
            end = np.minimum(x + a + w, W)
            mean = (cl[end] - cl[x]) / (depth * (a + w))
            d = d + term.penalty(mean, ref[k0:k1, None])
        out[:, :n] = np.where(ok, d, np.inf)
        return out

    def sampled(self, feasible_run, k0: int, k1: int, n: int):
        """About ``n`` scored pairs of shifts k0..k1 for the sweep: (shift indices, positions,
        costs), spread evenly over the shifts and over each shift's positions (offset from call
        to call), invalid ones left out. Costs as :meth:`costs`, for these pairs alone."""
        W = self.sum.shape[1]
        w = self.overlap
        if self._G is None:
            self._G = self.joint_weight * _joint_steps(self.S, self.valid, self.rows)
        ks = np.linspace(k0, k1 - 1, n).astype(np.int64)
        out = []
        for j, k in enumerate(ks.tolist()):
            a = int(self.shifts[k])
            m = W - a - w + 1  # positions with the whole footprint inside
            if m <= 0:
                continue
            x = int(((j + k0) * 0.618034 % 1.0) * m)
            c = self.cnt[k, x : x + w].sum()
            if c > 0 and (feasible_run is None or feasible_run[x] >= a + w):
                cost = self.sum[k, x : x + w].sum() / c + self._G[x + a]
                if self.detail is not None:
                    term, line, depth, ref = self.detail
                    mean = line[x : x + a + w].sum() / (depth * (a + w))
                    cost += float(term.penalty(np.asarray(mean), ref[k]))
                out.append((k, x, cost))
        if not out:
            return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
        k, x, cost = zip(*out, strict=True)
        return np.array(k, np.int64), np.array(x, np.int64), np.array(cost, np.float64)


def argmin_cost(costs: np.ndarray, shifts: np.ndarray) -> tuple[int, int, float] | None:
    k = int(np.argmin(costs))
    kk, x = np.unravel_index(k, costs.shape)
    c = float(costs[kk, x])
    if not np.isfinite(c):
        return None
    return int(x), int(shifts[kk]), c


def pair_cost(S, valid, rows, x, a, overlap) -> tuple[float, float]:
    """Mean distance of columns [x, x+w_T) and [x+a, x+a+w_T) over ``rows``, and the joint
    G: mean distance of columns x+a-1 and x+a (valid pairs only)."""
    r0, r1 = rows
    F = S[r0:r1, x : x + a + overlap].astype(np.float64)
    d = np.sqrt(((F[:, :overlap] - F[:, a:]) ** 2).sum(axis=2))
    g = np.sqrt(((F[:, a - 1] - F[:, a]) ** 2).sum(axis=1))
    if valid is None:
        return float(d.mean()), float(g.mean())
    v = valid[r0:r1, x : x + a + overlap]
    ok = v[:, :overlap] & v[:, a:]
    gk = v[:, a - 1] & v[:, a]
    return (
        float(d[ok].mean()) if ok.any() else math.inf,
        float(g[gk].mean()) if gk.any() else 0.0,
    )


def rect_costs(S, valid, rect, overlap) -> tuple[float, float, float, float]:
    """(D_h, D_v, G_h, G_v) of ``rect``: strip mismatches and wrap-joint steps."""
    x, y, a, b = rect
    St = np.ascontiguousarray(S[:, x : x + a + overlap].transpose(1, 0, 2))
    vt = None if valid is None else np.ascontiguousarray(valid[:, x : x + a + overlap].T)
    ch, gh = pair_cost(S, valid, (y, y + b + overlap), x, a, overlap)
    cv, gv = pair_cost(St, vt, (0, a + overlap), y, b, overlap)
    return ch, cv, gh, gv
