"""Brute-force oracles for the seam methods (imported by test_seams.py), and their self-checks.

Everything here enumerates: all one-pixel-per-row paths, all control-point vectors, all simple
paths of the pixel graph. Use them on tiny maps only.
"""

import itertools

import numpy as np


def one_per_row_paths(h: int, w: int) -> np.ndarray:
    """Every monotone 8-connected one-pixel-per-row path as an (N, h) array of columns."""
    cols = np.array(list(itertools.product(range(w), repeat=h)), dtype=int).reshape(-1, h)
    ok = np.all(np.abs(np.diff(cols, axis=1)) <= 1, axis=1)
    return cols[ok]


def _pinned(cols: np.ndarray, pins: dict) -> np.ndarray:
    ok = np.ones(len(cols), dtype=bool)
    for r, c in pins.items():
        ok &= cols[:, r] == c
    return ok


def brute_dp(error, pins=None, cyclic=False) -> float:
    """Minimal sum of E over one-per-row paths honouring ``pins`` {row: col} (inf if none)."""
    h, w = error.shape
    cols = one_per_row_paths(h, w)
    ok = _pinned(cols, pins or {})
    if cyclic:
        ok &= np.abs(cols[:, 0] - cols[:, -1]) <= 1
    if not ok.any():
        return np.inf
    sums = error[np.arange(h), cols[ok]].sum(axis=1)
    return float(sums.min())


def osc_eps(error, c, cyclic=False) -> float:
    """Somol & Haindl's criterion straight from its definition (ALGORITHMS §1.1)."""
    h = error.shape[0]
    total = 0.0
    for j in range(h):
        nbrs = []
        if cyclic:
            nbrs = [c[(j - 1) % h], c[(j + 1) % h]]
        else:
            if j > 0:
                nbrs.append(c[j - 1])
            if j + 1 < h:
                nbrs.append(c[j + 1])
        mu = min([c[j]] + [n + 1 for n in nbrs])
        total += error[j, mu : c[j] + 1].sum()
    return float(total)


def brute_osc(error, pins=None, cyclic=False) -> float:
    """Minimal criterion over all control-point vectors honouring ``pins``."""
    h, w = error.shape
    best = np.inf
    for c in itertools.product(range(w), repeat=h):
        if any(c[r] != v for r, v in (pins or {}).items()):
            continue
        best = min(best, osc_eps(error, c, cyclic))
    return best


def simple_paths(h: int, w: int, connectivity: int = 8):
    """Every simple path from a top-row pixel to its first bottom-row pixel that never returns
    to the top row (restricting to these loses no optimum: dropping nodes never hurts)."""
    if connectivity == 8:
        steps = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]
    else:
        steps = [(-1, 0), (1, 0), (0, -1), (0, 1)]

    def extend(path, seen):
        r, c = path[-1]
        if r == h - 1:
            yield list(path)
            return
        for dr, dc in steps:
            q = (r + dr, c + dc)
            if 0 < q[0] < h and 0 <= q[1] < w and q not in seen:
                seen.add(q)
                path.append(q)
                yield from extend(path, seen)
                path.pop()
                seen.discard(q)

    for c0 in range(w):
        if h == 1:
            yield [(0, c0)]
        else:
            yield from extend([(0, c0)], {(0, c0)})


def path_key(error, path, metric, levels=32):
    """Order key of a path under a graph metric (smaller is better)."""
    v = np.array([error[r, c] for r, c in path])
    if metric == "sum":
        return (v.sum(),)
    if metric == "minimax":
        return (v.max(), v.sum())
    top = error.max()
    lev = (
        np.zeros(len(v), int)
        if top <= 0
        else np.minimum((v * (levels / top)).astype(int), levels - 1)
    )
    return (tuple(sorted(lev.tolist(), reverse=True)), v.sum())


def brute_graph(error, metric, connectivity=8, levels=32):
    """Best key over all simple top-to-bottom paths."""
    h, w = error.shape
    return min(path_key(error, p, metric, levels) for p in simple_paths(h, w, connectivity))


# ----------------------------------------------------------------------------- self-checks
def test_one_per_row_count():
    # w=3, h=3: 3 starts, each row step has 2 or 3 choices -> 17 paths
    assert len(one_per_row_paths(3, 3)) == 17
    assert len(one_per_row_paths(1, 5)) == 5


def test_osc_eps_examples():
    e = np.arange(12, dtype=float).reshape(3, 4)
    # c = (3, 0, 3): row 0 spans 1..3, row 1 spans 0, row 2 spans 1..3
    assert osc_eps(e, (3, 0, 3)) == (1 + 2 + 3) + 4 + (9 + 10 + 11)
    # cyclic: row 0 also neighbours row 2 (c=3), no change; row 2's mu from row 0 (3) + row 1
    assert osc_eps(e, (0, 0, 3), cyclic=True) == 0 + 4 + (9 + 10 + 11)


def test_simple_paths_small():
    paths = list(simple_paths(2, 2))
    assert sorted(map(tuple, paths)) == sorted(
        [((0, 0), (1, 0)), ((0, 0), (1, 1)), ((0, 1), (1, 0)), ((0, 1), (1, 1))]
    )
    assert all(p[-1][0] == 2 for p in simple_paths(3, 3))
