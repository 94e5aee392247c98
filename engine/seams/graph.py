"""Shortest paths on the pixel graph with node costs (ALGORITHMS §3): Dijkstra and minimax.

Nodes are the pixels of ``domain``; a step to a 4- or 8-neighbour q adds ``cost[q]``; start
nodes pay their own cost. Labels and their order, by metric:

* ``sum``      — cumulative cost (plain Dijkstra, exact);
* ``lm``       — Long & Mould's partial non-scalar label (max, sum) compared by max, ties by
  sum; exact for the max, not always for the sum (the order is not kept by extension, §3);
* ``minimax``  — exact two-phase version: the minimal peak m* (the ``lm`` run's max is exact),
  then the minimal sum over the nodes with cost <= m*;
* ``sorted``   — the full Pai–Reissell metric on costs quantised to ``levels`` levels: the
  count vector of path nodes per level compared from the top level down, ties by sum. The
  order is invariant under adding the same node to both paths, so Dijkstra is exact.

Two numba kernels: the scalar labels (sum; lm, whose max also gives minimax's m*) with keys
inline in a lazy-deletion heap, the sorted label in an indexed heap with decrease-key.
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit
from engine._validate import as_error_map, choice, positive_int
from engine.cancel import check
from engine.seams.spec import check_connectivity

GRAPH_METRICS = ("sum", "minimax", "lm", "sorted")
_SUM, _LM, _SORTED = 0, 1, 2


@njit(cache=True, nogil=True)
def _less(u, v, cnt, total):
    """Sorted-vector label of node u strictly smaller than that of node v."""
    for lv in range(cnt.shape[1] - 1, -1, -1):
        if cnt[u, lv] != cnt[v, lv]:
            return cnt[u, lv] < cnt[v, lv]
    return total[u] < total[v]


@njit(cache=True, nogil=True)
def _sift_up(heap, pos, t, cnt, total):
    node = heap[t]
    while t > 0:
        parent = (t - 1) >> 1
        q = heap[parent]
        if not _less(node, q, cnt, total):
            break
        heap[t] = q
        pos[q] = t
        t = parent
    heap[t] = node
    pos[node] = t


@njit(cache=True, nogil=True)
def _sift_down(heap, pos, size, t, cnt, total):
    node = heap[t]
    while True:
        left = 2 * t + 1
        if left >= size:
            break
        child = left
        right = left + 1
        if right < size and _less(heap[right], heap[left], cnt, total):
            child = right
        q = heap[child]
        if not _less(q, node, cnt, total):
            break
        heap[t] = q
        pos[q] = t
        t = child
    heap[t] = node
    pos[node] = t


@njit(cache=True, nogil=True)
def _dijkstra_sorted(cost, domain, sources, targets, lev, nlev, conn, pred):
    """Dijkstra with the quantised sorted-vector label (per-level node counts, compared from
    the top level down, ties by sum) in an indexed heap with decrease-key. Returns the flat
    index of the first target settled (-1: none reachable); ``pred`` gets the predecessors."""
    h, w = cost.shape
    n = h * w
    total = np.zeros(n)
    cnt = np.zeros((n, nlev), dtype=np.int32)
    heap = np.empty(n, dtype=np.int64)
    pos = np.full(n, -1, dtype=np.int64)  # -1: never queued, -2: settled
    dr, dc = _steps(conn)
    size = 0
    for r in range(h):
        for c in range(w):
            if sources[r, c] and domain[r, c]:
                u = r * w + c
                total[u] = cost[r, c]
                cnt[u, lev[r, c]] = 1
                pred[u] = -1
                heap[size] = u
                pos[u] = size
                size += 1
                _sift_up(heap, pos, size - 1, cnt, total)
    while size > 0:
        u = heap[0]
        size -= 1
        pos[u] = -2
        if size > 0:
            heap[0] = heap[size]
            pos[heap[0]] = 0
            _sift_down(heap, pos, size, 0, cnt, total)
        ur, uc = u // w, u % w
        if targets[ur, uc]:
            return u
        for t in range(dr.shape[0]):
            vr, vc = ur + dr[t], uc + dc[t]
            if vr < 0 or vr >= h or vc < 0 or vc >= w or not domain[vr, vc]:
                continue
            v = vr * w + vc
            if pos[v] == -2:
                continue
            lv = lev[vr, vc]
            new_total = total[u] + cost[vr, vc]
            better = pos[v] == -1
            if not better:
                decided = False
                for m in range(nlev - 1, -1, -1):
                    a = cnt[u, m] + (1 if m == lv else 0)
                    if a != cnt[v, m]:
                        better = a < cnt[v, m]
                        decided = True
                        break
                if not decided:
                    better = new_total < total[v]
            if better:
                total[v] = new_total
                for m in range(nlev):
                    cnt[v, m] = cnt[u, m]
                cnt[v, lv] += 1
                pred[v] = u
                if pos[v] == -1:
                    heap[size] = v
                    pos[v] = size
                    size += 1
                _sift_up(heap, pos, pos[v], cnt, total)
    return -1


@njit(cache=True, nogil=True)
def _steps(conn):
    if conn == 8:
        return (np.array([-1, -1, -1, 0, 0, 1, 1, 1]), np.array([-1, 0, 1, -1, 1, -1, 0, 1]))
    return np.array([-1, 0, 0, 1]), np.array([0, -1, 1, 0])


@njit(cache=True, nogil=True)
def _heap_push(hk1, hk2, hn, size, a, b, node):
    t = size
    while t > 0:
        parent = (t - 1) >> 1
        if hk1[parent] < a or (hk1[parent] == a and hk2[parent] <= b):
            break
        hk1[t] = hk1[parent]
        hk2[t] = hk2[parent]
        hn[t] = hn[parent]
        t = parent
    hk1[t] = a
    hk2[t] = b
    hn[t] = node
    return size + 1


@njit(cache=True, nogil=True)
def _heap_pop(hk1, hk2, hn, size):
    """Remove the root (the caller read it); returns the new size."""
    size -= 1
    if size == 0:
        return 0
    a, b, node = hk1[size], hk2[size], hn[size]
    t = 0
    while True:
        child = 2 * t + 1
        if child >= size:
            break
        r = child + 1
        if r < size and (hk1[r] < hk1[child] or (hk1[r] == hk1[child] and hk2[r] < hk2[child])):
            child = r
        if a < hk1[child] or (a == hk1[child] and b <= hk2[child]):
            break
        hk1[t] = hk1[child]
        hk2[t] = hk2[child]
        hn[t] = hn[child]
        t = child
    hk1[t] = a
    hk2[t] = b
    hn[t] = node
    return size


@njit(cache=True, nogil=True)
def _dijkstra_scalar(cost, domain, sources, targets, lm, conn, pred):
    """Dijkstra for the scalar labels: sum, or (with ``lm``) Long & Mould's (max, sum), keys
    inline in a lazy-deletion heap. Returns the flat index of the first target settled
    (-1: none reachable); ``pred`` gets the predecessors."""
    h, w = cost.shape
    n = h * w
    d1 = np.full(n, np.inf)
    d2 = np.zeros(n)
    done = np.zeros(n, dtype=np.bool_)
    cap = n * (conn + 1) + 1  # every push is a strict improvement of some node
    hk1 = np.empty(cap)
    hk2 = np.empty(cap)
    hn = np.empty(cap, dtype=np.int64)
    dr, dc = _steps(conn)
    size = 0
    for r in range(h):
        for c in range(w):
            if sources[r, c] and domain[r, c]:
                u = r * w + c
                d1[u] = cost[r, c]
                d2[u] = cost[r, c] if lm else 0.0
                pred[u] = -1
                size = _heap_push(hk1, hk2, hn, size, d1[u], d2[u], u)
    while size > 0:
        u = hn[0]
        a, b = hk1[0], hk2[0]
        size = _heap_pop(hk1, hk2, hn, size)
        if done[u] or a != d1[u] or b != d2[u]:
            continue
        done[u] = True
        ur, uc = u // w, u % w
        if targets[ur, uc]:
            return u
        for t in range(dr.shape[0]):
            vr, vc = ur + dr[t], uc + dc[t]
            if vr < 0 or vr >= h or vc < 0 or vc >= w or not domain[vr, vc]:
                continue
            v = vr * w + vc
            if done[v]:
                continue
            e = cost[vr, vc]
            if lm:
                n1, n2 = max(a, e), b + e
            else:
                n1, n2 = a + e, 0.0
            if n1 < d1[v] or (n1 == d1[v] and n2 < d2[v]):
                d1[v] = n1
                d2[v] = n2
                pred[v] = u
                size = _heap_push(hk1, hk2, hn, size, n1, n2, v)
    return -1


def _run(cost, domain, sources, targets, mode, conn, levels=0):
    pred = np.full(cost.size, -1, dtype=np.int64)
    if mode == _SORTED:
        lev = quantise(cost, domain, levels)
        t = _dijkstra_sorted(cost, domain, sources, targets, lev, levels, conn, pred)
    else:
        t = _dijkstra_scalar(cost, domain, sources, targets, mode == _LM, conn, pred)
    if t < 0:
        return None
    nodes = [t]
    while pred[nodes[-1]] >= 0:
        nodes.append(pred[nodes[-1]])
    nodes = np.array(nodes[::-1], dtype=np.intp)
    return np.column_stack(np.divmod(nodes, cost.shape[1]))


def quantise(cost: np.ndarray, domain: np.ndarray, levels: int) -> np.ndarray:
    """Level 0..levels-1 of every pixel, uniform between 0 and the largest cost in ``domain``."""
    top = float(cost[domain].max()) if domain.any() else 0.0
    if top <= 0:
        return np.zeros(cost.shape, dtype=np.int64)
    return np.minimum((cost * (levels / top)).astype(np.int64), levels - 1)


def shortest_path(
    cost,
    sources,
    targets,
    domain,
    *,
    metric: str,
    levels: int = 32,
    connectivity: int = 8,
    cancel=None,
):
    """Path ((N, 2) intp, source to target) on validated C-contiguous inputs, or None."""
    check(cancel)
    if metric == "sum":
        path = _run(cost, domain, sources, targets, _SUM, connectivity)
    elif metric == "sorted":
        path = _run(cost, domain, sources, targets, _SORTED, connectivity, levels)
    else:
        path = _run(cost, domain, sources, targets, _LM, connectivity)
        if metric == "minimax" and path is not None:
            check(cancel)
            peak = cost[path[:, 0], path[:, 1]].max()
            low = domain & (cost <= peak)
            path = _run(cost, low, sources, targets, _SUM, connectivity)
    check(cancel)
    return path


def _bool_mask(a, name: str, shape) -> np.ndarray:
    m = np.asarray(a)
    if m.dtype != bool:
        raise TypeError(f"{name} must be a bool array, got dtype {m.dtype}")
    if m.shape != shape:
        raise ValueError(f"{name} must have the shape of cost {shape}, got {m.shape}")
    return np.ascontiguousarray(m)


def graph_path(
    cost,
    sources,
    targets,
    *,
    domain=None,
    metric: str = "sum",
    levels: int = 32,
    connectivity: int = 8,
    cancel=None,
) -> np.ndarray:
    """Best path on the pixel graph from any pixel of ``sources`` to the first reached target.

    Parameters
    ----------
    cost : (h, w) array_like
        Non-negative, finite node costs; every node on the path pays its own cost (the start
        node included).
    sources, targets : (h, w) bool ndarray
        Start and goal pixels (only those inside ``domain`` count).
    domain : (h, w) bool ndarray, optional
        Pixels the path may use (default: all), e.g. the L-shaped quilting overlap.
    metric : {'sum', 'minimax', 'lm', 'sorted'}
        Path order (module docstring): cumulative cost, exact (peak, sum), Long & Mould's
        comparator, or the quantised sorted-vector metric with ``levels`` levels.
    connectivity : {8, 4}
        Pixel neighbourhood.
    cancel : CancelToken, optional
        Raises :class:`engine.Cancelled` when set.

    Returns
    -------
    (N, 2) intp ndarray
        (row, col) pixels from the source to the target.

    Raises
    ------
    ValueError
        When no target can be reached from a source within the domain.
    """
    c = np.ascontiguousarray(as_error_map(cost, "cost"))
    choice(metric, "metric", GRAPH_METRICS)
    levels = positive_int(levels, "levels")
    connectivity = check_connectivity(connectivity)
    src = _bool_mask(sources, "sources", c.shape)
    tgt = _bool_mask(targets, "targets", c.shape)
    dom = np.ones(c.shape, bool) if domain is None else _bool_mask(domain, "domain", c.shape)
    if not (src & dom).any():
        raise ValueError("sources has no pixel inside domain")
    if not (tgt & dom).any():
        raise ValueError("targets has no pixel inside domain")
    path = shortest_path(
        c, src, tgt, dom, metric=metric, levels=levels, connectivity=connectivity, cancel=cancel
    )
    if path is None:
        raise ValueError("no path from sources to targets within domain")
    return path
