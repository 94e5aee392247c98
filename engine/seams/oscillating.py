"""Somol & Haindl's control-point path model: oscillating search and its exact optimum.

Path model (ALGORITHMS §1.1): one control point ``c_j`` per row; row j covers the columns
``mu_j..c_j`` with ``mu_j = min(c_j, c_{j-1} + 1, c_{j+1} + 1)`` (a missing neighbour is omitted;
with ``cyclic`` rows 0 and h-1 are neighbours). Criterion
``eps(c) = sum_j P[j, c_j + 1] - P[j, mu_j]`` with row prefix sums ``P``.

* :func:`iter_oscillating` — the anytime oscillating search (§1.2): block moves of up to
  ``o_max`` consecutive control points, first improvement in loop order, incremental
  evaluation (O(1) per candidate column: only rows j-1..j+o change), ``faithful`` (restart at
  o = 1, j = 0) or ``resume`` (o = 1 at the current j, stop after a full cycle without
  improvement) variants, frozen control points, and a choice of starting path ``init``:

  - ``"argmin"``: c_j = per-row argmin of E, the paper's start. **The published algorithm is
    ``variant="faithful", init="argmin"``.**
  - ``"dp"`` (default of :func:`engine.seams.find_seam`): the exact one-pixel-per-row
    8-connected cut (``dp``). Such a path is a point of this model (|c_j - c_{j-1}| <= 1 gives
    mu_j = c_j) with the DP cost as criterion, so the moves can only lower it further. O(3wh),
    0.05 ms at 512x64; on a cyclic map the open cut comes first and the closed cyclic cut
    (0.4 ms at 512x64, see :mod:`engine.seams.dp`) follows as the first improvement when better.
  - ``"smoothed"``: per-row argmin of E smoothed along the path direction (Gaussian,
    :data:`SMOOTH_SIGMA` rows).

  Why the start matters (``python -m benchmarks.seams --quality --diagnose``, on the samples'
  random strip pairs and on the template, patch-ring and quilting overlaps the product cuts):
  the per-row argmins scatter across the overlap (40-60 % of the rows jump by more than one
  column; the start is 7-9x the optimum), and the moves — vertical runs of at most ``o_max``
  rows — tidy that into a thin path lying in a poor valley: at o_max = 3 the paper's setting
  ends 31-65 % above the optimum on average (the paper reports ~10 %; larger o_max helps:
  10-34 % at 8). τ plays no part (no move gains more than 1e-9 relative from the final paths even
  at τ = 0); steepest descent instead of first improvement roughly halves the excess but stays
  above 15 % on most sets; a lightly smoothed start barely helps (16-50 %). From the DP cut
  (first path 2-9 % above the optimum) the same moves end 0.7-2.3 % above it, several times
  faster.

* :func:`optimal_controls` — the exact optimum of the same model. Row j's cost depends on its
  neighbours only through ``m = min(c_{j-1}, c_{j+1})``: ``r_j = R_{j,b}(m) = P[j,b+1] -
  P[j, min(b, m+1)]`` with ``b = c_j``. The second-order DP over pairs (c_j, c_{j+1}) therefore
  needs only a prefix minimum and a suffix minimum per (row, b): O(h w²) instead of O(h w³).
  Cyclic maps fix c_0 = s and bound ``min(c_{h-1}, c_1) >= L`` (charging row 0 ``R_{0,s}(L)``,
  exact at the optimal L), pruned by a lower bound: O(h w^4) worst case, ~1 s at 512x64.
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit
from engine.cancel import check, is_cancelled
from engine.seams._result import Seam
from engine.seams.dp import dp_columns
from engine.seams.spec import INITS

#: Gaussian sigma (rows) of the ``smoothed`` start: light, averages pixel noise over a few rows
SMOOTH_SIGMA = 2.0

# kernel status codes
_BUDGET, _CONVERGED = 0, 2


def prefix_sums(error: np.ndarray) -> np.ndarray:
    """``P[j, k] = sum_{i<k} E[j, i]`` shaped (h, w + 1)."""
    h, w = error.shape
    p = np.zeros((h, w + 1))
    np.cumsum(error, axis=1, out=p[:, 1:])
    return p


# ----------------------------------------------------------------------------- criterion
@njit(cache=True, nogil=True, inline="always")
def _mu(ck, prev, nxt):
    m = ck
    if prev >= 0 and prev + 1 < m:
        m = prev + 1
    if nxt >= 0 and nxt + 1 < m:
        m = nxt + 1
    return m


@njit(cache=True, nogil=True)
def _mus(c, cyclic):
    """Complementary point mu_j of every row."""
    h = c.shape[0]
    mu = np.empty(h, dtype=np.int64)
    for k in range(h):
        if cyclic:
            prev, nxt = c[(k - 1) % h], c[(k + 1) % h]
        else:
            prev = c[k - 1] if k > 0 else -1
            nxt = c[k + 1] if k + 1 < h else -1
        mu[k] = _mu(c[k], prev, nxt)
    return mu


@njit(cache=True, nogil=True)
def _criterion(p, c, cyclic):
    mu = _mus(c, cyclic)
    total = 0.0
    for k in range(c.shape[0]):
        total += p[k, c[k] + 1] - p[k, mu[k]]
    return total


@njit(cache=True, nogil=True)
def _seam_arrays(error, c, cyclic):
    """Path pixels (row by row, columns ascending), R1 mask, criterion and peak of ``c``."""
    h, w = error.shape
    mu = _mus(c, cyclic)
    n = 0
    for k in range(h):
        n += c[k] - mu[k] + 1
    path = np.empty((n, 2), dtype=np.int64)
    mask = np.zeros((h, w), dtype=np.bool_)
    t = 0
    total = 0.0
    peak = 0.0
    for k in range(h):
        for i in range(mu[k], c[k] + 1):
            path[t, 0] = k
            path[t, 1] = i
            v = error[k, i]
            total += v
            if v > peak:
                peak = v
            t += 1
        for i in range(c[k] + 1):
            mask[k, i] = True
    return path, mask, total, peak


def controls_seam(
    error: np.ndarray, c: np.ndarray, cyclic: bool, method: str, *, lazy: bool = True
) -> Seam:
    """The :class:`Seam` of control points ``c`` (complementary points included); a lazy one
    is built on first use from a private copy of ``c`` (``error`` must then stay unchanged)."""
    c = np.array(c, dtype=np.int64)
    seam = Seam.lazy(lambda: _seam_arrays(error, c, cyclic), method)
    if not lazy:
        seam.path  # noqa: B018 (build now)
    return seam


def _replayed_seam(error, base, moves, k, cyclic, method) -> Seam:
    """Lazy seam of ``base`` after the block moves ``moves[:k + 1]`` (rows j, block size o,
    column i); ``base`` and ``moves`` are private and never changed afterwards."""

    def build():
        c = base.copy()
        h = c.shape[0]
        for j, o, i in moves[: k + 1]:
            c[(j + np.arange(o)) % h] = i
        return _seam_arrays(error, c, cyclic)

    return Seam.lazy(build, method)


def criterion(error: np.ndarray, c: np.ndarray, *, cyclic: bool = False) -> float:
    """eps(c) of the control-point model (prefix sums; used by tests and benchmarks)."""
    return float(_criterion(prefix_sums(error), np.asarray(c, dtype=np.int64), bool(cyclic)))


# ----------------------------------------------------------------------------- search
@njit(cache=True, nogil=True)
def _affected_cost(p, c, j, o, i, cyclic):
    """Criterion of ``c`` with the block j..j+o-1 set to column i (``i < 0``: unchanged).
    O(h); used only for tiny cyclic maps where the O(1) update does not apply."""
    h = c.shape[0]
    total = 0.0
    for k in range(h):
        kp, kn = (k - 1) % h, (k + 1) % h
        ck = i if i >= 0 and (k - j) % h < o else c[k]
        prev = i if i >= 0 and (kp - j) % h < o else c[kp]
        nxt = i if i >= 0 and (kn - j) % h < o else c[kn]
        if not cyclic:
            prev = prev if k > 0 else -1
            nxt = nxt if k + 1 < h else -1
        total += p[k, ck + 1] - p[k, _mu(ck, prev, nxt)]
    return total


@njit(cache=True, nogil=True, inline="always")
def _add_outer(acc, prow, cval, m):
    """acc[i] += cost of an outer row (control point cval, mu without the block = m) when its
    block-side neighbour moves to column i: P[cval+1] - P[min(m, i+1)]."""
    w = acc.shape[0]
    top = prow[cval + 1]
    k = min(max(m - 1, 0), w)
    for i in range(k):
        acc[i] += top - prow[i + 1]
    const = top - prow[m]
    for i in range(k, w):
        acc[i] += const


@njit(cache=True, nogil=True, inline="always")
def _set_block_row(acc, prow, m):
    """acc[i] = cost of a block row at column i whose other neighbours give mu bound m:
    P[i+1] - P[min(i, m)]."""
    w = acc.shape[0]
    k = min(max(m, 0), w - 1)
    for i in range(k + 1):
        acc[i] = prow[i + 1] - prow[i]
    for i in range(k + 1, w):
        acc[i] = prow[i + 1] - prow[m]


@njit(cache=True, nogil=True)
def _first_improving(p, q, c, j, o, cyclic, eps, limit, acc, tmp):
    """First column i (in loop order) for which moving the block j..j+o-1 to i gives a
    criterion below ``limit``; returns (i, new criterion) or (-1, eps).

    Only rows j-1 .. j+o change: the block's inner rows cost E[k, i] (column prefix sums
    ``q``), its end rows and the two outer rows get new complementary points. Each term is a
    contiguous slice of a prefix-sum row or a constant over a range of i, so the whole vector
    of candidate criteria costs a few simple passes over w values (``acc``, ``tmp`` scratch).
    """
    h = c.shape[0]
    w = p.shape[1] - 1
    big = w + 2  # a missing neighbour never lowers mu
    if cyclic and o + 2 > h:
        old = _affected_cost(p, c, j, o, -1, cyclic)
        for i in range(w):
            new = eps - old + _affected_cost(p, c, j, o, i, cyclic)
            if new < limit:
                return i, new
        return -1, eps
    last = (j + o - 1) % h
    # outer rows a = j-1 and z = j+o with their own outer neighbours' bounds
    if cyclic:
        a, z = (j - 1) % h, (j + o) % h
        has_a = has_z = True
        ma = min(c[a], c[(j - 2) % h] + 1)
        mz = min(c[z], c[(j + o + 1) % h] + 1)
    else:
        a, z = j - 1, j + o
        has_a, has_z = a >= 0, z < h
        ma = min(c[a], c[j - 2] + 1 if j >= 2 else big) if has_a else big
        mz = min(c[z], c[z + 1] + 1 if z + 1 < h else big) if has_z else big
    ca = c[a] + 1 if has_a else big
    cz = c[z] + 1 if has_z else big
    old = 0.0
    if has_a:
        old += p[a, c[a] + 1] - p[a, min(ma, c[j] + 1)]
    if has_z:
        old += p[z, c[z] + 1] - p[z, min(mz, c[last] + 1)]
    for t in range(o):
        k = (j + t) % h
        prev = c[(k - 1) % h] + 1 if cyclic or k > 0 else big
        nxt = c[(k + 1) % h] + 1 if cyclic or k + 1 < h else big
        old += p[k, c[k] + 1] - p[k, min(c[k], prev, nxt)]
    # a block already uniform at column v cannot improve by moving to v
    v = c[j]
    for t in range(1, o):
        if c[(j + t) % h] != v:
            v = -1
            break
    if o == 1:
        _set_block_row(acc, p[j], min(ca, cz))
    else:
        _set_block_row(acc, p[j], ca)
        _set_block_row(tmp, p[last], cz)
        for i in range(w):
            acc[i] += tmp[i]
        n_in = o - 2
        if n_in > 0:
            s0 = (j + 1) % h
            if s0 + n_in <= h:
                for i in range(w):
                    acc[i] += q[s0 + n_in, i] - q[s0, i]
            else:
                for i in range(w):
                    acc[i] += q[h, i] - q[s0, i] + q[s0 + n_in - h, i]
    if has_a:
        _add_outer(acc, p[a], c[a], ma)
    if has_z:
        _add_outer(acc, p[z], c[z], mz)
    base = eps - old
    bound = limit - base
    for i in range(w):
        if acc[i] < bound and i != v:
            return i, base + acc[i]
    return -1, eps


# state slots of _osc_run
_POS, _IDLE, _COUNT, _CYCLIC, _RESUME, _BUDGET_SLOT, _NMOVES = range(7)


@njit(cache=True, nogil=True)
def _osc_run(p, q, c, seq, state, fstate, moves):
    """Run the oscillating search from ``state`` for at most ``state[_BUDGET_SLOT]`` trials,
    until ``moves`` is full or the search converges; ``c`` is updated in place.

    ``seq`` rows: block size o, first row j, skip (block holds a frozen point) of every move
    in loop order. Each accepted move (j, o, i) is appended to ``moves``; its count goes to
    ``state[_NMOVES]``. ``fstate[0]`` is the current criterion. Returns 2 when converged.
    """
    h = c.shape[0]
    w = p.shape[1] - 1
    n = seq.shape[1]
    cyclic = state[_CYCLIC] != 0
    resume = state[_RESUME] != 0
    acc = np.empty(w)
    tmp = np.empty(w)
    pos = state[_POS]
    idle = state[_IDLE]
    eps = fstate[0]
    nm = 0
    status = _BUDGET
    for _ in range(state[_BUDGET_SLOT]):
        if idle >= n:
            eps = _criterion(p, c, cyclic)
            status = _CONVERGED
            break
        o = seq[0, pos]
        j = seq[1, pos]
        if seq[2, pos] == 0:
            i, new = _first_improving(p, q, c, j, o, cyclic, eps, eps - 1e-9 * eps, acc, tmp)
            if i >= 0:
                for t in range(o):
                    c[(j + t) % h] = i
                moves[nm, 0] = j
                moves[nm, 1] = o
                moves[nm, 2] = i
                nm += 1
                state[_COUNT] += 1
                # incremental value; refreshed exactly now and then against drift
                eps = _criterion(p, c, cyclic) if state[_COUNT] % 256 == 0 else new
                pos = j if resume else 0
                idle = 0
                if nm == moves.shape[0]:
                    break
                continue
        idle += 1
        pos += 1
        if pos == n:
            pos = 0
    state[_POS] = pos
    state[_IDLE] = idle
    state[_NMOVES] = nm
    fstate[0] = eps
    return status


def _move_sequence(h: int, o_max: int, cyclic: bool, frozen: np.ndarray) -> np.ndarray:
    """All block moves in loop order as rows (o, j, skip); skip marks blocks holding a frozen
    control point."""
    seq_o, seq_j = [], []
    for o in range(1, o_max + 1):
        nj = (h if o < h else 1) if cyclic else h - o + 1
        seq_o.append(np.full(nj, o, dtype=np.int64))
        seq_j.append(np.arange(nj, dtype=np.int64))
    seq_o = np.concatenate(seq_o)
    seq_j = np.concatenate(seq_j)
    # block rows (j + t) % h for t < o contain a frozen index?
    fz = np.concatenate([frozen, frozen]) if cyclic else np.concatenate([frozen, [False]])
    csum = np.concatenate([[0], np.cumsum(fz)])
    skip = (csum[seq_j + seq_o] - csum[seq_j] > 0).astype(np.int64)
    return np.stack([seq_o, seq_j, skip])


def _intervals(pins: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Allowed column range lo..hi of every row: the pinned column, else all."""
    return np.where(pins >= 0, pins, 0), np.where(pins >= 0, pins, w - 1)


def initial_controls(
    error: np.ndarray, pins: np.ndarray, init: str = "argmin", *, cyclic: bool = False
) -> np.ndarray:
    """Starting control points; pinned rows (pins >= 0) take their pinned column.

    ``argmin``: per-row argmin of the error (the paper's start). ``smoothed``: per-row argmin
    of the error smoothed along the path direction (Gaussian, :data:`SMOOTH_SIGMA` rows).
    ``dp``: the exact one-pixel-per-row 8-connected cut, ignoring the wrap even when
    ``cyclic`` (O(3wh); :func:`iter_oscillating` streams the closed cyclic cut next when that is
    better); per-row argmin when the pins admit no such path.
    """
    from scipy import ndimage

    if init not in INITS:
        raise ValueError(f"init must be one of {', '.join(map(repr, INITS))}, got {init!r}")
    if init == "dp":
        c = dp_columns(error, *_intervals(pins, error.shape[1]))
        if c is not None:
            return c
    elif init == "smoothed":
        mode = "wrap" if cyclic else "nearest"
        error = ndimage.gaussian_filter1d(error, SMOOTH_SIGMA, axis=0, mode=mode, truncate=3.0)
    c = np.argmin(error, axis=1).astype(np.int64)
    return np.where(pins >= 0, pins, c)


def iter_oscillating(
    error,
    pins,
    *,
    o_max: int,
    variant: str,
    cyclic: bool,
    cancel,
    init: str = "argmin",
    method: str = "oscillating",
):
    """Generator: yields a Seam for the initial path (``init``, see :func:`initial_controls`)
    and for every improvement (in order, each strictly better than the one before). Stops
    early, keeping the best path so far, when ``cancel`` is set. ``error`` must stay unchanged
    while the seams are in use."""
    h, w = error.shape
    c = initial_controls(error, pins, init, cyclic=cyclic)
    yield controls_seam(error, c, cyclic, method)
    p = prefix_sums(error)
    eps = _criterion(p, c, cyclic)
    if init == "dp" and cyclic and not is_cancelled(cancel):
        # the closed cut (|c_0 - c_{h-1}| <= 1) costs more (several starts): streamed next
        closed = dp_columns(error, *_intervals(pins, w), cyclic=True)
        if closed is not None and _criterion(p, closed, cyclic) < eps - 1e-9 * eps:
            c = closed
            eps = _criterion(p, c, cyclic)
            yield controls_seam(error, c, cyclic, method)
    o_max = min(o_max, h)
    q = np.zeros((h + 1, w))
    np.cumsum(error, axis=0, out=q[1:])
    seq = _move_sequence(h, o_max, cyclic, pins >= 0)
    state = np.zeros(7, dtype=np.int64)
    state[_CYCLIC] = cyclic
    state[_RESUME] = variant == "resume"
    # ~1e5 column evaluations per kernel call: the cancel token is polled every ~0.1 ms
    state[_BUDGET_SLOT] = max(1, 100_000 // w)
    fstate = np.array([eps])
    moves = np.empty((64, 3), dtype=np.int64)
    while not is_cancelled(cancel):
        base = c.copy()
        status = _osc_run(p, q, c, seq, state, fstate, moves)
        n = int(state[_NMOVES])
        if n:
            log = moves[:n].copy()
            for k in range(n):
                yield _replayed_seam(error, base, log, k, cyclic, method)
        if status == _CONVERGED:
            break


# ----------------------------------------------------------------------------- optimum
@njit(cache=True, nogil=True, inline="always")
def _r(p, j, b, m):
    """Cost of row j with c_j = b when min(c_{j-1}, c_{j+1}) = m (m >= w: no neighbour)."""
    mu = b if m + 1 > b else m + 1
    return p[j, b + 1] - p[j, mu]


@njit(cache=True, nogil=True)
def _chain(p, lo, hi, first_cost, last_nb, back, backf, cols, want_path):
    """Exact minimum of the control-point criterion with c_j limited to lo[j]..hi[j].

    ``first_cost >= 0`` replaces row 0's cost by that constant (cyclic closure: row 0's
    neighbour terms are charged by the caller); ``last_nb >= 0`` is an extra neighbour of the
    last row (c_h := c_0 when cyclic). Needs h >= 2. With ``want_path`` the argmin pointers are
    stored in ``back`` (h, w, w) / ``backf`` (w) and the path written to ``cols``.
    Returns the minimum (inf when infeasible).
    """
    h = p.shape[0]
    w = p.shape[1] - 1
    inf = np.inf
    d = np.full((w, w), inf)  # d[a, b]: best cost of rows < j given c_{j-1} = a, c_j = b
    for a in range(lo[0], hi[0] + 1):
        for b in range(lo[1], hi[1] + 1):
            d[a, b] = first_cost if first_cost >= 0 else _r(p, 0, a, b)
    nd = np.empty((w, w))
    pre = np.empty(w)
    pre_arg = np.empty(w, dtype=np.int64)
    suf = np.empty(w)
    suf_arg = np.empty(w, dtype=np.int64)
    for j in range(1, h - 1):
        nd[:, :] = inf
        for b in range(lo[j], hi[j] + 1):
            # pre[c] = min_{a<=c} d[a,b] + r(a);  suf[c] = min_{a>=c} d[a,b]
            run = inf
            arg = -1
            for a in range(w):
                v = d[a, b] + _r(p, j, b, a)
                if v < run:
                    run = v
                    arg = a
                pre[a] = run
                pre_arg[a] = arg
            run = inf
            arg = -1
            for a in range(w - 1, -1, -1):
                if d[a, b] < run:
                    run = d[a, b]
                    arg = a
                suf[a] = run
                suf_arg[a] = arg
            for cn in range(lo[j + 1], hi[j + 1] + 1):
                v1 = pre[cn]
                v2 = suf[cn] + _r(p, j, b, cn)
                if v1 <= v2:
                    nd[b, cn] = v1
                    if want_path:
                        back[j, b, cn] = pre_arg[cn]
                else:
                    nd[b, cn] = v2
                    if want_path:
                        back[j, b, cn] = suf_arg[cn]
        d, nd = nd, d
    # last row: F[b] = min_a d[a, b] + r(min(a, last_nb))
    best = inf
    best_b = -1
    for b in range(lo[h - 1], hi[h - 1] + 1):
        fb = inf
        fa = -1
        for a in range(w):
            if d[a, b] == inf:
                continue
            m = a if last_nb < 0 or a < last_nb else last_nb
            v = d[a, b] + _r(p, h - 1, b, m)
            if v < fb:
                fb = v
                fa = a
        if want_path:
            backf[b] = fa
        if fb < best:
            best = fb
            best_b = b
    if want_path and best_b >= 0:
        cols[h - 1] = best_b
        cols[h - 2] = backf[best_b]
        for j in range(h - 2, 0, -1):
            cols[j - 1] = back[j, cols[j], cols[j + 1]]
    return best


def optimal_controls(
    error: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, cyclic: bool, cancel=None
):
    """Control points of the exact optimum (row j limited to lo[j]..hi[j]).

    Cyclic maps: for every allowed c_0 = s, the chain is solved with the bound
    ``min(c_{h-1}, c_1) >= L`` for L = s-1, s-2, ... (row 0 charged ``R_{0,s}(L)``, exact at
    the optimal L); an s or L whose lower bound cannot beat the best so far is skipped. The
    cancel token is checked between chains.
    """
    h, w = error.shape
    if w >= 32768:
        raise ValueError(f"method 'oscillating-optimal' needs fewer than 32768 columns, got {w}")
    p = prefix_sums(error)
    cols = np.zeros(h, dtype=np.int64)
    if h == 1:
        cols[0] = lo[0] + int(np.argmin(error[0, lo[0] : hi[0] + 1]))
        return cols
    back = np.zeros((h, w, w), dtype=np.int16)
    backf = np.zeros(w, dtype=np.int64)
    if not cyclic:
        _chain(p, lo, hi, -1.0, -1, back, backf, cols, True)
        return cols
    no_back = np.zeros((1, 1, 1), dtype=np.int16)
    best, best_s, best_l = np.inf, -1, -1

    def bounded(s, low):
        lo2, hi2 = lo.copy(), hi.copy()
        lo2[0] = hi2[0] = s
        if low >= 0:
            lo2[1] = max(lo[1], low)
            lo2[h - 1] = max(lo[h - 1], low)
        return lo2, hi2

    for s in range(lo[0], hi[0] + 1):
        check(cancel)
        # lower bound: row 0 at its cheapest (E[0, s]) and no bound on c_1, c_{h-1}
        base = _chain(p, *bounded(s, -1), 0.0, s, no_back, backf, cols, False)
        for low in range(max(s - 1, 0), -1, -1):
            r0 = p[0, s + 1] - p[0, min(s, low + 1)]
            if r0 + base >= best:
                break  # r0 only grows as the bound decreases
            v = r0 + _chain(p, *bounded(s, low), 0.0, s, no_back, backf, cols, False)
            if v < best:
                best, best_s, best_l = v, s, low
    _chain(p, *bounded(best_s, best_l), 0.0, best_s, back, backf, cols, True)
    return cols
