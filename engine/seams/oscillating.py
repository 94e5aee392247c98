"""Somol & Haindl's control-point path model: oscillating search and its exact optimum.

Path model (ALGORITHMS §1.1): one control point ``c_j`` per row; row j covers the columns
``mu_j..c_j`` with ``mu_j = min(c_j, c_{j-1} + 1, c_{j+1} + 1)`` (a missing neighbour is omitted;
with ``cyclic`` rows 0 and h-1 are neighbours). Criterion
``eps(c) = sum_j P[j, c_j + 1] - P[j, mu_j]`` with row prefix sums ``P``.

* :func:`iter_oscillating` — the anytime oscillating search (§1.2): block moves of up to
  ``o_max`` consecutive control points, first improvement in loop order, incremental O(o)
  evaluation per trial, ``faithful`` (restart at o = 1, j = 0) or ``resume`` (o = 1 at the current
  j, stop after a full cycle without improvement) variants, frozen control points.
* :func:`optimal_controls` — the exact optimum of the same model. Row j's cost depends on its
  neighbours only through ``m = min(c_{j-1}, c_{j+1})``: ``r_j = R_{j,b}(m) = P[j,b+1] -
  P[j, min(b, m+1)]`` with ``b = c_j``. The second-order DP over pairs (c_j, c_{j+1}) therefore
  needs only a prefix minimum and a suffix minimum per (row, b): O(h w²) instead of O(h w³).
  Cyclic maps fix c_0 = s and bound ``min(c_{h-1}, c_1) >= L`` (charging row 0 ``R_{0,s}(L)``,
  exact at the optimal L), pruned by a lower bound.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from engine.cancel import is_cancelled
from engine.seams._result import Seam

# kernel status codes
_IMPROVED, _BUDGET, _CONVERGED = 1, 0, 2


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


def controls_seam(error: np.ndarray, c: np.ndarray, cyclic: bool, method: str) -> Seam:
    """The :class:`Seam` of control points ``c`` (complementary points included), built lazily
    from a private copy of ``c`` (``error`` must stay unchanged, as engine inputs do)."""
    c = np.array(c, dtype=np.int64)
    return Seam.lazy(lambda: _seam_arrays(error, c, cyclic), method)


def criterion(error: np.ndarray, c: np.ndarray, *, cyclic: bool = False) -> float:
    """eps(c) of the control-point model (prefix sums; used by tests and benchmarks)."""
    return float(_criterion(prefix_sums(error), np.asarray(c, dtype=np.int64), bool(cyclic)))


# ----------------------------------------------------------------------------- search
@njit(cache=True, nogil=True)
def _affected_cost(p, c, rows, nrows, j, o, i, cyclic):
    """Sum of the row costs of ``rows[:nrows]`` with the block j..j+o-1 set to column i.

    ``i < 0`` keeps the current columns.
    """
    h = c.shape[0]
    total = 0.0
    for t in range(nrows):
        k = rows[t]
        if cyclic:
            kp, kn = (k - 1) % h, (k + 1) % h
            ck = i if i >= 0 and (k - j) % h < o else c[k]
            prev = i if i >= 0 and (kp - j) % h < o else c[kp]
            nxt = i if i >= 0 and (kn - j) % h < o else c[kn]
        else:
            ck = i if i >= 0 and j <= k < j + o else c[k]
            prev = -1
            nxt = -1
            if k > 0:
                prev = i if i >= 0 and j <= k - 1 < j + o else c[k - 1]
            if k + 1 < h:
                nxt = i if i >= 0 and j <= k + 1 < j + o else c[k + 1]
        total += p[k, ck + 1] - p[k, _mu(ck, prev, nxt)]
    return total


@njit(cache=True, nogil=True)
def _first_improving(p, q, c, j, o, cyclic, eps, limit):
    """First column i (in loop order) for which moving the block j..j+o-1 to i gives a
    criterion below ``limit``; returns (i, new criterion) or (-1, eps).

    O(1) per i: only rows j-1 .. j+o change; the block's inner rows cost E[k, i] (column
    prefix sums ``q``), its end rows and the two outer rows get new complementary points.
    """
    h = c.shape[0]
    w = p.shape[1] - 1
    big = w + 2  # a missing neighbour never lowers mu
    if cyclic and o + 2 > h:
        return _first_improving_generic(p, c, j, o, cyclic, eps, limit)
    # outer rows a = j-1 and z = j+o, their outer neighbours aa = j-2 and zz = j+o+1
    if cyclic:
        a, z = (j - 1) % h, (j + o) % h
        has_a = has_z = True
        ca_prev = c[(j - 2) % h] + 1
        cz_next = c[(j + o + 1) % h] + 1
    else:
        a, z = j - 1, j + o
        has_a, has_z = a >= 0, z < h
        ca_prev = c[j - 2] + 1 if j >= 2 else big
        cz_next = c[j + o + 1] + 1 if j + o + 1 < h else big
    ca = c[a] + 1 if has_a else big
    cz = c[z] + 1 if has_z else big
    old = 0.0
    if has_a:
        old += p[a, c[a] + 1] - p[a, min(c[a], ca_prev, c[j] + 1)]
    if has_z:
        old += p[z, c[z] + 1] - p[z, min(c[z], cz_next, c[(j + o - 1) % h] + 1)]
    last = (j + o - 1) % h
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
    base = eps - old
    s0 = (j + 1) % h  # first inner row
    n_in = o - 2
    for i in range(w):
        if i == v:
            continue
        new = base
        if has_a:
            new += p[a, c[a] + 1] - p[a, min(c[a], ca_prev, i + 1)]
        if has_z:
            new += p[z, c[z] + 1] - p[z, min(c[z], cz_next, i + 1)]
        if o == 1:
            new += p[j, i + 1] - p[j, min(i, ca, cz)]
        else:
            new += p[j, i + 1] - p[j, min(i, ca)]
            new += p[last, i + 1] - p[last, min(i, cz)]
            if n_in > 0:
                if s0 + n_in <= h:
                    new += q[s0 + n_in, i] - q[s0, i]
                else:
                    new += q[h, i] - q[s0, i] + q[s0 + n_in - h, i]
        if new < limit:
            return i, new
    return -1, eps


@njit(cache=True, nogil=True)
def _first_improving_generic(p, c, j, o, cyclic, eps, limit):
    """Same as :func:`_first_improving` for tiny cyclic maps (o + 2 > h): O(h) per i."""
    h = c.shape[0]
    w = p.shape[1] - 1
    rows = np.arange(h)
    old = _affected_cost(p, c, rows, h, j, o, -1, cyclic)
    for i in range(w):
        new = eps - old + _affected_cost(p, c, rows, h, j, o, i, cyclic)
        if new < limit:
            return i, new
    return -1, eps


@njit(cache=True, nogil=True)
def _osc_run(p, q, c, seq_o, seq_j, skip, cyclic, resume, state, fstate, budget):
    """Run the oscillating search from ``state`` until an improvement, ``budget`` trials or
    convergence. ``c`` is updated in place.

    state = [position in the (o, j) sequence, trials since the last improvement,
    improvements]; fstate = [current criterion]. Returns 1 (improved), 0 (budget used up),
    2 (converged).
    """
    h = c.shape[0]
    n = seq_o.shape[0]
    pos = state[0]
    idle = state[1]
    eps = fstate[0]
    for _ in range(budget):
        if idle >= n:
            state[0] = pos
            state[1] = idle
            fstate[0] = _criterion(p, c, cyclic)
            return _CONVERGED
        o = seq_o[pos]
        j = seq_j[pos]
        if not skip[pos]:
            i, new = _first_improving(p, q, c, j, o, cyclic, eps, eps - 1e-9 * eps)
            if i >= 0:
                for t in range(o):
                    c[(j + t) % h] = i
                state[2] += 1
                # incremental value; refreshed exactly now and then against drift
                eps = _criterion(p, c, cyclic) if state[2] % 256 == 0 else new
                state[0] = j if resume else 0
                state[1] = 0
                fstate[0] = eps
                return _IMPROVED
        idle += 1
        pos += 1
        if pos == n:
            pos = 0
    state[0] = pos
    state[1] = idle
    return _BUDGET


def _move_sequence(h: int, o_max: int, cyclic: bool, frozen: np.ndarray):
    """All block moves (o, j) in loop order, and which of them touch a frozen control point."""
    seq_o, seq_j = [], []
    for o in range(1, o_max + 1):
        nj = (h if o < h else 1) if cyclic else h - o + 1
        seq_o.append(np.full(nj, o, dtype=np.int64))
        seq_j.append(np.arange(nj, dtype=np.int64))
    seq_o = np.concatenate(seq_o)
    seq_j = np.concatenate(seq_j)
    if frozen.any():
        # block rows (j + t) % h for t < o contain a frozen index?
        fz = np.concatenate([frozen, frozen]) if cyclic else np.concatenate([frozen, [False]])
        csum = np.concatenate([[0], np.cumsum(fz)])
        skip = csum[seq_j + seq_o] - csum[seq_j] > 0
    else:
        skip = np.zeros(seq_o.shape, dtype=bool)
    return seq_o, seq_j, skip


def initial_controls(error: np.ndarray, pins: np.ndarray) -> np.ndarray:
    """Per-row argmin of the error; pinned rows (pins >= 0) take their pinned column."""
    c = np.argmin(error, axis=1).astype(np.int64)
    return np.where(pins >= 0, pins, c)


def iter_oscillating(error, pins, *, o_max: int, variant: str, cyclic: bool, cancel,
                     method: str = "oscillating"):
    """Generator: yields a Seam for the initial path and for every improvement; returns the
    final control points (the last Seam yielded is the best). Stops early, keeping the best
    path so far, when ``cancel`` is set."""
    h, w = error.shape
    c = initial_controls(error, pins)
    yield controls_seam(error, c, cyclic, method)
    p = prefix_sums(error)
    frozen = pins >= 0
    seq_o, seq_j, skip = _move_sequence(h, min(o_max, h), cyclic, frozen)
    q = np.zeros((h + 1, w))
    np.cumsum(error, axis=0, out=q[1:])
    state = np.zeros(3, dtype=np.int64)
    fstate = np.array([_criterion(p, c, cyclic)])
    # about 1e5 row evaluations per kernel call: the cancel token is polled every ~0.1 ms
    budget = max(1, 100_000 // (w * (min(o_max, h) + 2)))
    resume = variant == "resume"
    while not is_cancelled(cancel):
        status = _osc_run(p, q, c, seq_o, seq_j, skip, cyclic, resume, state, fstate, budget)
        if status == _IMPROVED:
            yield controls_seam(error, c, cyclic, method)
        elif status == _CONVERGED:
            break
    return c


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


@njit(cache=True, nogil=True)
def _optimal_kernel(p, lo, hi, cyclic, cols):
    """Exact optimum (see module docstring); writes ``cols``, returns the criterion."""
    h = p.shape[0]
    w = p.shape[1] - 1
    if h == 1:
        best = np.inf
        for b in range(lo[0], hi[0] + 1):
            v = p[0, b + 1] - p[0, b]
            if v < best:
                best = v
                cols[0] = b
        return best
    back = np.zeros((h, w, w), dtype=np.int16)  # w < 32768 (checked by the caller)
    backf = np.zeros(w, dtype=np.int64)
    dummy = np.zeros((1, 1, 1), dtype=back.dtype)
    if not cyclic:
        return _chain(p, lo, hi, -1.0, -1, back, backf, cols, True)
    lo2 = lo.copy()
    best = np.inf
    best_s = -1
    best_l = -1
    for s in range(lo[0], hi[0] + 1):
        lo2[0] = s
        hi_s = hi.copy()
        hi_s[0] = s
        # lower bound for this s: row 0 at its cheapest (E[0, s]) and no bound on c_1, c_{h-1}
        lo2[1] = lo[1]
        lo2[h - 1] = lo[h - 1]
        e0 = p[0, s + 1] - p[0, s]
        base = _chain(p, lo2, hi_s, 0.0, s, dummy, backf, cols, False)
        if e0 + base >= best:
            continue
        for L in range(max(s - 1, 0), -1, -1):
            r0 = p[0, s + 1] - p[0, min(s, L + 1)]
            if r0 + base >= best:
                break  # r0 only grows as L decreases
            lo2[1] = max(lo[1], L)
            lo2[h - 1] = max(lo[h - 1], L)
            v = r0 + _chain(p, lo2, hi_s, 0.0, s, dummy, backf, cols, False)
            if v < best:
                best = v
                best_s = s
                best_l = L
    if best_s < 0:
        return np.inf
    lo2[0] = best_s
    hi_s = hi.copy()
    hi_s[0] = best_s
    lo2[1] = max(lo[1], best_l)
    lo2[h - 1] = max(lo[h - 1], best_l)
    r0 = p[0, best_s + 1] - p[0, min(best_s, best_l + 1)]
    return r0 + _chain(p, lo2, hi_s, 0.0, best_s, back, backf, cols, True)


def optimal_controls(error: np.ndarray, lo: np.ndarray, hi: np.ndarray, *, cyclic: bool):
    """Control points of the exact optimum (row j limited to lo[j]..hi[j])."""
    if error.shape[1] >= 32768:
        raise ValueError(f"method 'oscillating-optimal' needs fewer than 32768 columns, got {error.shape[1]}")
    cols = np.zeros(error.shape[0], dtype=np.int64)
    _optimal_kernel(prefix_sums(error), lo, hi, bool(cyclic), cols)
    return cols
