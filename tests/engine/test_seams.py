"""Seam engine: every method against its oracle, constraints, streaming and cancellation."""

import numpy as np
import pytest
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra as cs_dijkstra

from benchmarks.seams import sample_map
from engine import Cancelled, CancelToken
from engine.seams import (
    METHODS,
    Seam,
    SeamUpdate,
    find_seam,
    graph_path,
    iter_find_seam,
    warmup,
)
from engine.seams.oscillating import INITS, SMOOTH_SIGMA
from engine.seams.oscillating import criterion as osc_criterion
from tests.engine.helpers import events_and_result
from tests.engine.test_seams_oracles import (
    brute_dp,
    brute_graph,
    brute_osc,
    osc_eps,
    path_key,
)

SHAPES = [(1, 4), (2, 3), (3, 3), (4, 5), (5, 4), (6, 5)]


def rand_map(shape, seed, integer=False):
    rng = np.random.default_rng(seed)
    if integer:
        return rng.integers(0, 10, size=shape).astype(float)
    return rng.random(shape)


def smooth_map(shape, seed, sigma=2.0):
    rng = np.random.default_rng(seed)
    return ndimage.gaussian_filter(rng.random(shape), sigma) + 0.05 * rng.random(shape)


def controls_of(seam: Seam) -> np.ndarray:
    """Control points (rightmost path pixel of each row) of a control-point seam."""
    h = seam.mask.shape[0]
    c = np.full(h, -1)
    np.maximum.at(c, seam.path[:, 0], seam.path[:, 1])
    return c


def assert_valid(seam: Seam, error, *, one_per_row=False):
    """Path from row 0 to row h-1, 8-connected in order (or row-wise for control points),
    criterion/peak consistent, mask True on every path pixel and left of row-wise cuts."""
    h, w = error.shape
    p = seam.path
    assert p.ndim == 2 and p.shape[1] == 2 and len(p) >= h
    assert p[0, 0] == 0 and p[-1, 0] == h - 1
    assert np.all((p >= 0) & (p < [h, w]))
    vals = error[p[:, 0], p[:, 1]]
    assert seam.criterion == pytest.approx(vals.sum(), rel=1e-9, abs=1e-12)
    assert seam.peak == pytest.approx(vals.max())
    assert seam.mask.shape == (h, w) and seam.mask.dtype == bool
    assert seam.mask[p[:, 0], p[:, 1]].all()
    if one_per_row:
        assert np.array_equal(p[:, 0], np.arange(h))
        assert np.all(np.abs(np.diff(p[:, 1])) <= 1)
    else:
        assert len(np.unique(p, axis=0)) == len(p), "path repeats a pixel"
    assert not seam.path.flags.writeable and not seam.mask.flags.writeable


# ----------------------------------------------------------------------------- dp
@pytest.mark.parametrize("shape", SHAPES)
def test_dp_equals_brute_force(shape):
    h, w = shape
    for seed in range(5):
        e = rand_map(shape, seed)
        s = find_seam(e, method="dp")
        assert_valid(s, e, one_per_row=True)
        assert s.criterion == pytest.approx(brute_dp(e))
        assert np.array_equal(s.mask, np.arange(w)[None, :] <= s.path[:, 1][:, None])


@pytest.mark.parametrize("shape", [(3, 3), (5, 4), (6, 5)])
def test_dp_constraints_equal_brute_force(shape):
    h, w = shape
    rng = np.random.default_rng(1)
    for seed in range(6):
        e = rand_map(shape, seed)
        start, end = int(rng.integers(w)), int(rng.integers(w))
        wr = int(rng.integers(1, h - 1))
        wc = int(rng.integers(w))
        cases = [
            ({"start": start}, {0: start}, False),
            ({"end": end}, {h - 1: end}, False),
            ({"waypoints": [(wr, wc)]}, {wr: wc}, False),
            ({}, {}, True),
            ({"start": start}, {0: start}, True),
            ({"waypoints": [(wr, wc)]}, {wr: wc}, True),
        ]
        for kw, pins, cyclic in cases:
            want = brute_dp(e, pins, cyclic)
            if not np.isfinite(want):
                with pytest.raises(ValueError, match="dp"):
                    find_seam(e, method="dp", cyclic=cyclic, **kw)
                continue
            s = find_seam(e, method="dp", cyclic=cyclic, **kw)
            assert_valid(s, e, one_per_row=True)
            assert s.criterion == pytest.approx(want), (kw, cyclic)
            for r, c in pins.items():
                assert s.path[r, 1] == c
            if cyclic:
                assert abs(s.path[0, 1] - s.path[-1, 1]) <= 1


def test_dp_cyclic_pruned_starts_give_the_path_of_trying_every_start():
    """The cyclic DP tries start columns cheapest open bound first and stops early: the same
    path (ties included: the smallest start) as one constrained DP per start in turn."""
    from engine.seams.dp import _dp_pass

    rng = np.random.default_rng(4)
    for t in range(120):
        h, w = int(rng.integers(2, 25)), int(rng.integers(1, 10))
        e = [rng.random((h, w)), rng.integers(0, 3, (h, w)).astype(float), np.ones((h, w))][t % 3]
        lo, hi = np.zeros(h, np.int64), np.full(h, w - 1, np.int64)
        if t % 4 == 0:
            lo[0] = hi[0] = rng.integers(w)
        back, cols = np.zeros((h, w), np.int8), np.zeros(h, np.int64)
        costs = [_dp_pass(e, lo, hi, s, back, cols) for s in range(lo[0], hi[0] + 1)]
        _dp_pass(e, lo, hi, lo[0] + int(np.argmin(costs)), back, cols)
        kw = {"start": int(lo[0])} if t % 4 == 0 else {}
        np.testing.assert_array_equal(find_seam(e, cyclic=True, **kw).path[:, 1], cols)


def test_dp_start_end_waypoint_unreachable():
    e = np.ones((3, 6))
    with pytest.raises(ValueError, match="no one-pixel-per-row"):
        find_seam(e, method="dp", start=0, end=5)


# ----------------------------------------------------------------------------- oscillating-optimal
@pytest.mark.parametrize("shape", [(1, 4), (2, 3), (3, 4), (4, 4), (5, 4), (6, 3)])
@pytest.mark.parametrize("cyclic", [False, True])
def test_optimal_equals_brute_force(shape, cyclic):
    h, w = shape
    for seed in range(3):
        e = rand_map(shape, seed, integer=seed == 2)
        s = find_seam(e, method="oscillating-optimal", cyclic=cyclic)
        assert_valid(s, e)
        c = controls_of(s)
        assert s.criterion == pytest.approx(osc_eps(e, c, cyclic))
        assert s.criterion == pytest.approx(brute_osc(e, cyclic=cyclic))


@pytest.mark.parametrize("cyclic", [False, True])
def test_optimal_frozen_ends_equal_brute_force(cyclic):
    for seed in range(4):
        e = rand_map((5, 4), seed)
        start, end, wp = seed % 4, (seed * 3 + 1) % 4, (2, (seed + 2) % 4)
        s = find_seam(
            e, method="oscillating-optimal", start=start, end=end, waypoints=[wp], cyclic=cyclic
        )
        c = controls_of(s)
        assert (c[0], c[-1], c[2]) == (start, end, wp[1])
        want = brute_osc(e, {0: start, 4: end, 2: wp[1]}, cyclic)
        assert s.criterion == pytest.approx(want)


def test_optimal_larger_cyclic_matches_search_bound():
    # no brute force at this size: the optimum is never above any local search result
    e = smooth_map((40, 12), 3)
    for cyclic in (False, True):
        opt = find_seam(e, method="oscillating-optimal", cyclic=cyclic)
        osc = find_seam(e, method="oscillating", cyclic=cyclic, o_max=4)
        assert opt.criterion <= osc.criterion + 1e-9
        assert opt.criterion == pytest.approx(osc_eps(e, controls_of(opt), cyclic))


# ----------------------------------------------------------------------------- oscillating
def improves(e, c, o_max, cyclic, frozen=()):
    """Some block move of size <= o_max lowers eps(c) by more than the search's tolerance."""
    h, w = e.shape
    eps = osc_criterion(e, c, cyclic=cyclic)
    for o in range(1, min(o_max, h) + 1):
        starts = range(h if o < h else 1) if cyclic else range(h - o + 1)
        for j in starts:
            rows = [(j + t) % h for t in range(o)]
            if any(r in frozen for r in rows):
                continue
            for i in range(w):
                d = c.copy()
                d[rows] = i
                if osc_criterion(e, d, cyclic=cyclic) < eps - 1e-9 * eps:
                    return True
    return False


def expected_start(e, init, cyclic):
    """The first streamed control points of each ``init``, computed independently."""
    if init == "argmin":
        return np.argmin(e, axis=1)
    if init == "smoothed":
        mode = "wrap" if cyclic else "nearest"
        return np.argmin(ndimage.gaussian_filter1d(e, SMOOTH_SIGMA, 0, mode=mode, truncate=3), 1)
    return find_seam(e, method="dp").path[:, 1]  # the open cut, even on a cyclic map


@pytest.mark.parametrize("init", INITS)
@pytest.mark.parametrize("variant", ["resume", "faithful"])
@pytest.mark.parametrize("cyclic", [False, True])
@pytest.mark.parametrize("o_max", [1, 3])
def test_oscillating_monotone_and_locally_optimal(init, variant, cyclic, o_max):
    for seed in range(3):
        e = smooth_map((24, 7), seed, sigma=1.0)
        updates = list(
            iter_find_seam(
                e, method="oscillating", o_max=o_max, variant=variant, init=init, cyclic=cyclic
            )
        )
        crits = [u.seam.criterion for u in updates]
        assert all(b < a for a, b in zip(crits[:-1], crits[1:-1], strict=False))
        assert [u.final for u in updates] == [False] * (len(updates) - 1) + [True]
        assert updates[-1].seam is updates[-2].seam
        assert np.array_equal(controls_of(updates[0].seam), expected_start(e, init, cyclic))
        if init != "dp":
            assert len(updates) > 2, "the search never improved the initial path"
        final = updates[-1].seam
        assert_valid(final, e)
        c = controls_of(final)
        assert final.criterion == pytest.approx(osc_eps(e, c, cyclic))
        assert not improves(e, c, o_max, cyclic)
        opt = find_seam(e, method="oscillating-optimal", cyclic=cyclic).criterion
        assert opt <= final.criterion + 1e-9
        if init == "dp":  # the DP cut is a point of the model: never worse than dp itself
            assert final.criterion <= find_seam(e, cyclic=cyclic).criterion + 1e-9


def literal_oscillating(e, c, o_max, variant, cyclic, frozen=frozenset()):
    """ALGORITHMS §1.2's loop written out with the full criterion (no incremental update):
    block moves in loop order (o = 1..o_max, j ascending; cyclic blocks wrap), first
    improvement by more than tau = 1e-9 eps kept; then ``faithful`` restarts at o = 1, j = 0,
    ``resume`` at o = 1 and the current j; stop after a full cycle without improvement.
    Returns the control points after every accepted move."""
    h, w = e.shape
    o_max = min(o_max, h)
    seq = [
        (o, j)
        for o in range(1, o_max + 1)
        for j in (range(h if o < h else 1) if cyclic else range(h - o + 1))
    ]
    c = np.array(c)
    eps = osc_eps(e, c, cyclic)
    accepted, pos, idle = [], 0, 0
    while idle < len(seq):
        o, j = seq[pos]
        rows = [(j + t) % h for t in range(o)]
        moved = False
        if not frozen.intersection(rows):
            for i in range(w):
                d = c.copy()
                d[rows] = i
                v = osc_eps(e, d, cyclic)
                if v < eps - 1e-9 * eps:
                    c, eps, moved = d, v, True
                    accepted.append(c.copy())
                    break
        if moved:
            pos, idle = (j if variant == "resume" else 0), 0
        else:
            pos, idle = (pos + 1) % len(seq), idle + 1
    return accepted


@pytest.mark.parametrize("variant", ["faithful", "resume"])
@pytest.mark.parametrize("cyclic", [False, True])
def test_oscillating_replays_the_literal_loop_move_by_move(variant, cyclic):
    """Every streamed improvement is exactly the next move of the loop as printed (integer
    maps: exact sums; float maps too), from every start, with frozen points."""
    rng = np.random.default_rng(11)
    for trial in range(40):
        h, w = int(rng.integers(2, 12)), int(rng.integers(2, 8))
        e = rng.random((h, w)) if trial % 2 else rng.integers(0, 20, (h, w)).astype(float)
        o_max = int(rng.integers(1, 5))
        kw = {"start": int(rng.integers(w))} if trial % 3 == 0 else {}
        for init in INITS:
            ups = list(
                iter_find_seam(
                    e,
                    method="oscillating",
                    o_max=o_max,
                    variant=variant,
                    init=init,
                    cyclic=cyclic,
                    **kw,
                )
            )
            got = [controls_of(u.seam) for u in ups[:-1]]
            k0 = 1
            if init == "dp" and cyclic:  # the open cut, then the closed one when better
                closed = find_seam(e, method="dp", cyclic=True, **kw).path[:, 1]
                eps0 = osc_eps(e, got[0], True)
                if osc_eps(e, closed, True) < eps0 - 1e-9 * eps0:
                    np.testing.assert_array_equal(got[1], closed)
                    k0 = 2
            frozen = {0} if kw else set()
            want = literal_oscillating(e, got[k0 - 1], o_max, variant, cyclic, frozen)
            assert len(got) - k0 == len(want), (trial, init)
            for a, b in zip(got[k0:], want, strict=True):
                np.testing.assert_array_equal(a, b)


def test_oscillating_dp_start_streams_the_closed_cut_on_cyclic_maps():
    closed_better = 0
    for seed in range(12):
        e = smooth_map((20, 8), seed, sigma=1.0)
        updates = list(iter_find_seam(e, method="oscillating", init="dp", cyclic=True))
        open_cut = controls_of(updates[0].seam)
        closed = find_seam(e, method="dp", cyclic=True).path[:, 1]
        if osc_eps(e, closed, cyclic=True) < osc_eps(e, open_cut, cyclic=True) - 1e-9:
            closed_better += 1
            assert np.array_equal(controls_of(updates[1].seam), closed)
    assert closed_better >= 3


@pytest.mark.parametrize("init", INITS)
def test_oscillating_frozen_points_and_waypoints(init):
    e = smooth_map((20, 8), 5, sigma=1.0)
    s = find_seam(e, method="oscillating", start=7, end=0, waypoints=[(9, 3)], init=init)
    c = controls_of(s)
    assert (c[0], c[19], c[9]) == (7, 0, 3)
    assert not improves(e, c, 3, False, frozen={0, 9, 19})
    opt = find_seam(e, method="oscillating-optimal", start=7, end=0, waypoints=[(9, 3)])
    assert opt.criterion <= s.criterion + 1e-9


def test_oscillating_dp_start_falls_back_to_argmin_when_pins_admit_no_dp_cut():
    e = smooth_map((5, 8), 0)
    first = next(iter_find_seam(e, method="oscillating", start=0, end=7)).seam
    expected = np.argmin(e, axis=1)
    expected[[0, 4]] = 0, 7
    assert np.array_equal(controls_of(first), expected)
    s = find_seam(e, method="oscillating", start=0, end=7)
    assert s.criterion == pytest.approx(osc_eps(e, controls_of(s)))


def test_oscillating_larger_o_max_not_worse_on_average():
    gaps = {1: [], 5: []}
    for seed in range(6):
        e = smooth_map((40, 10), seed)
        opt = find_seam(e, method="oscillating-optimal").criterion
        for o in gaps:
            s = find_seam(e, method="oscillating", o_max=o, init="argmin")
            gaps[o].append(s.criterion / opt - 1)
    assert np.mean(gaps[5]) <= np.mean(gaps[1]) + 1e-9


def test_oscillating_faithful_reproduces_the_spec_on_smoothed_random_maps():
    """The paper's algorithm (faithful, argmin start) on smoothed random 40x10 maps: the spec
    (ALGORITHMS §1.2) reports ~17 / 9 / 7 % above the optimum for o_max = 1 / 3 / 10;
    measured here (sigma 1): 15.1 / 7.9 / 4.3 %."""
    maps = [
        ndimage.gaussian_filter(np.random.default_rng(s).random((40, 10)), 1.0) for s in range(20)
    ]
    opt = np.array([find_seam(e, method="oscillating-optimal").criterion for e in maps])
    mean = {}
    for o_max in (1, 3, 10):
        osc = [
            find_seam(e, method="oscillating", o_max=o_max, variant="faithful", init="argmin")
            for e in maps
        ]
        mean[o_max] = float(np.mean([s.criterion for s in osc] / opt - 1))
    assert 0.10 <= mean[1] <= 0.22
    assert 0.05 <= mean[3] <= 0.12
    assert 0.02 <= mean[10] <= 0.08
    assert mean[1] > mean[3] > mean[10]


@pytest.fixture(scope="module")
def overlap_sets():
    """The samples' overlaps: random strip pairs and those the product cuts (template,
    candidate patch rings, best-match quilting), with their optima."""
    from benchmarks.seams import optima, product_overlaps, random_overlaps

    sets = {"random strips": random_overlaps(), **product_overlaps()}
    return {k: (v, optima(v)) for k, v in sets.items()}


def test_oscillating_default_within_15_percent_of_optimum_on_sample_overlaps(
    overlap_sets, record_property
):
    """Acceptance: the default setting stays within 15 % of ``oscillating-optimal`` on average
    over the bundled samples' overlaps. Measured (``python -m benchmarks.seams --quality``):
    +0.7 to +2.3 % per set; from the paper's start (``init="argmin"``) +31 to +65 %. The DP
    cut alone is already within the line (+1.8 to +8.8 %): the search must still improve on
    it, or the line would not test the search."""
    from benchmarks.seams import gaps

    assert set(overlap_sets) == {"random strips", "template", "patch ring", "quilting"}
    for name, (overlaps, opt) in overlap_sets.items():
        g, _ = gaps(overlaps, opt)
        g0, _ = gaps(overlaps, opt, start_only=True)  # the DP cut it starts from
        assert np.all(g >= -1e-9) and np.all(g <= g0 + 1e-9)
        record_property(f"oscillating_default_gap_{name}", float(g.mean()))
        print(f"oscillating default vs optimum, {name} ({len(g)}): +{100 * g.mean():.1f} %")
        assert g.mean() <= 0.15, name
        # the moves do part of the work: from the start's +1.8 / 8.8 / 3.8 / 3.9 % (random
        # strips / template / patch ring / quilting) down to +0.7 / 2.1 / 2.3 / 1.8 %
        assert g.mean() < 0.8 * g0.mean(), name


def test_oscillating_paper_start_misses_the_15_percent_line(overlap_sets):
    """The default's margin comes from its start: the published argmin start with the same
    moves ends far above the line (measured ~+47 % on the random strips)."""
    from benchmarks.seams import gaps

    overlaps, opt = overlap_sets["random strips"]
    g, _ = gaps(overlaps, opt, init="argmin")
    assert g.mean() > 0.30


@pytest.mark.parametrize("init", INITS)
def test_oscillating_cancel_returns_valid_path_no_worse_than_initial(init):
    # improvements are streamed in batches of one kernel call (~0.1 ms of search): the map must
    # keep the search busy for several calls (from the DP cut: a long real overlap)
    e = sample_map(2048, 128, "cobblestones") if init == "dp" else smooth_map((200, 24), 7)
    full = find_seam(e, method="oscillating", init=init)
    token = CancelToken()
    gen = iter_find_seam(e, method="oscillating", init=init, cancel=token)
    first = next(gen)
    for _ in range(5):
        next(gen)
    token.cancel()
    rest, result = events_and_result(gen)
    assert rest and rest[-1].final and rest[-1].seam is result
    assert_valid(result, e)
    assert result.criterion <= first.seam.criterion
    assert result.criterion > full.criterion  # it really stopped early


@pytest.mark.parametrize("cyclic", [False, True])
@pytest.mark.parametrize("init", INITS)
def test_oscillating_cancelled_before_start_returns_initial_path(init, cyclic):
    e = smooth_map((30, 6), 1)
    token = CancelToken()
    token.cancel()
    s = find_seam(e, method="oscillating", init=init, cyclic=cyclic, cancel=token)
    assert np.array_equal(controls_of(s), expected_start(e, init, cyclic))


@pytest.mark.parametrize("method", [m for m in METHODS if m != "oscillating"])
def test_non_anytime_methods_raise_cancelled(method):
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        find_seam(smooth_map((10, 5), 0), method=method, cancel=token)


# ----------------------------------------------------------------------------- graph methods
TINY = [(2, 3), (3, 3), (3, 4), (4, 3)]


@pytest.mark.parametrize("shape", TINY)
@pytest.mark.parametrize("connectivity", [8, 4])
def test_dijkstra_equals_brute_force(shape, connectivity):
    for seed in range(3):
        e = rand_map(shape, seed, integer=seed == 0)
        s = find_seam(e, method="dijkstra", connectivity=connectivity)
        assert_valid(s, e)
        steps = np.abs(np.diff(s.path, axis=0))
        assert np.all(steps.max(axis=1) == 1)
        if connectivity == 4:
            assert np.all(steps.sum(axis=1) == 1)
        assert s.criterion == pytest.approx(brute_graph(e, "sum", connectivity)[0])


def test_dijkstra_equals_scipy_csgraph():
    h, w = 12, 8
    for seed in range(3):
        e = rand_map((h, w), seed) + 0.01
        idx = np.arange(h * w).reshape(h, w)
        rows, cols = [], []
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr or dc:
                    a = idx[max(0, -dr) : h - max(0, dr), max(0, -dc) : w - max(0, dc)]
                    b = idx[max(0, dr) : h - max(0, -dr), max(0, dc) : w - max(0, -dc)]
                    rows.append(a.ravel())
                    cols.append(b.ravel())
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        g = csr_matrix((e.ravel()[cols], (rows, cols)), shape=(h * w, h * w))
        dist = cs_dijkstra(g, indices=idx[0])
        best = (dist[:, idx[-1]] + e[0][:, None]).min()
        assert find_seam(e, method="dijkstra").criterion == pytest.approx(best)


@pytest.mark.parametrize("shape", TINY)
def test_minimax_exact_and_lm_equal_brute_force(shape):
    for seed in range(4):
        e = rand_map(shape, seed, integer=True)
        peak, total = brute_graph(e, "minimax")
        s = find_seam(e, method="minimax")
        assert_valid(s, e)
        assert s.peak == peak and s.criterion == pytest.approx(total)
        lm = find_seam(e, method="minimax", variant="lm")
        assert_valid(lm, e)
        assert lm.peak == peak and lm.criterion >= total - 1e-9


def test_lm_comparator_not_sum_exact_but_exact_variant_is():
    # ALGORITHMS §3: on random integer maps the LM comparator sometimes misses the minimal sum
    worse = 0
    for seed in range(60):
        e = rand_map((10, 6), seed, integer=True)
        ex = find_seam(e, method="minimax")
        lm = find_seam(e, method="minimax", variant="lm")
        assert ex.peak == lm.peak
        assert ex.criterion <= lm.criterion + 1e-9
        worse += lm.criterion > ex.criterion + 1e-9
    assert worse > 0


@pytest.mark.parametrize("shape", TINY)
def test_minimax_sorted_equals_brute_force(shape):
    for seed in range(4):
        e = rand_map(shape, seed, integer=seed % 2 == 0)
        for levels in (4, 32):
            s = find_seam(e, method="minimax", variant="sorted", levels=levels)
            assert_valid(s, e)
            want = brute_graph(e, "sorted", levels=levels)
            got = path_key(e, s.path.tolist(), "sorted", levels)
            assert got[0] == want[0] and got[1] == pytest.approx(want[1])


def test_minimax_winds_around_a_peak():
    e = np.full((9, 7), 0.5)
    e[:, 3] = 0.0  # a cheap straight line...
    e[4, 0:6] = 1.5  # ...through a wall with a gap at the right edge
    d = find_seam(e, method="dijkstra")
    m = find_seam(e, method="minimax")
    assert d.peak == 1.5 and d.criterion == 1.5  # straight through the wall
    assert m.peak == 0.5  # around it
    assert (4, 6) in map(tuple, m.path.tolist())
    assert m.mask[4].all() and m.mask[4, :4].all() and not d.mask[4, 4:].any()


def test_graph_path_l_shaped_domain():
    rng = np.random.default_rng(0)
    cost = rng.random((12, 12))
    dom = np.zeros((12, 12), bool)
    dom[:, :4] = True
    dom[:4, :] = True
    src = np.zeros_like(dom)
    src[11, :4] = True
    tgt = np.zeros_like(dom)
    tgt[:4, 11] = True
    for metric in ("sum", "minimax", "lm", "sorted"):
        p = graph_path(cost, src, tgt, domain=dom, metric=metric)
        assert src[tuple(p[0])] and tgt[tuple(p[-1])]
        assert dom[p[:, 0], p[:, 1]].all()
        assert np.all(np.abs(np.diff(p, axis=0)).max(axis=1) == 1)
        assert tgt[p[:, 0], p[:, 1]].sum() == 1  # stops at the first target reached
    p = graph_path(cost, src, tgt, domain=dom, connectivity=4)
    assert np.all(np.abs(np.diff(p, axis=0)).sum(axis=1) == 1)
    with pytest.raises(ValueError, match="no path"):
        blocked = dom.copy()
        blocked[5, :] = False
        graph_path(cost, src, tgt, domain=blocked)
    with pytest.raises(TypeError, match="sources"):
        graph_path(cost, src.astype(int), tgt)
    with pytest.raises(ValueError, match="metric"):
        graph_path(cost, src, tgt, metric="max")


# ----------------------------------------------------------------------------- resistance
def runs(values):
    """Lengths of the runs of equal consecutive values."""
    out, n = [], 1
    for a, b in zip(values, values[1:], strict=False):
        if a == b:
            n += 1
        else:
            out.append(n)
            n = 1
    return out + [n]


def test_resistance_walk_rules():
    for seed in range(10):
        e = smooth_map((60, 12), seed, sigma=1.5)
        for max_run in (2, 5):
            s = find_seam(e, method="resistance", variant="walk", max_run=max_run)
            assert_valid(s, e)
            d = np.diff(s.path, axis=0)
            assert np.all(d[:, 0] >= 0), "walked upwards"
            assert np.all(np.abs(d).max(axis=1) == 1)
            assert np.count_nonzero(s.path[:, 0] == 59) == 1  # stops on reaching the bottom
            # the run limit may only be broken by forced downward steps
            assert max(runs(s.path[:, 0].tolist())) <= max_run
            assert s.path[0, 1] == np.argmin(e[0])


def test_resistance_follows_the_cheapest_step():
    e = np.ones((8, 5))
    e[:, 2] = 0.5
    e[3:6, 2] = 2.0
    e[3:6, 3] = 0.1
    s = find_seam(e, method="resistance", variant="walk", max_run=3)
    assert s.path.tolist() == [[0, 2], [1, 2], [2, 2], [3, 3], [4, 3], [5, 3], [6, 2], [7, 2]]


def test_resistance_image_step_cost():
    # the error map is flat; the colour image has a smooth column the walk should follow
    e = np.ones((10, 6))
    img = np.random.default_rng(0).random((10, 6, 3))
    img[:, 4] = 0.5
    s = find_seam(e, method="resistance", variant="walk", image=img, start=4, max_run=20)
    assert np.all(s.path[:, 1] == 4)
    with pytest.raises(ValueError, match="image"):
        find_seam(e, method="resistance", image=img[:5])


# ----------------------------------------------------------------------------- constraints
@pytest.mark.parametrize("method", METHODS)
def test_every_method_honours_start_end_waypoints(method):
    e = smooth_map((30, 10), 2, sigma=1.0)
    wps = [(8, 1), (20, 8)]
    s = find_seam(e, method=method, start=5, end=2, waypoints=wps)
    assert_valid(s, e, one_per_row=method == "dp")
    pts = set(map(tuple, s.path.tolist()))
    assert s.path[0].tolist() == [0, 5] and s.path[-1].tolist() == [29, 2]
    assert all(p in pts for p in wps)
    if method in ("dp", "dijkstra", "minimax", "resistance"):
        # ordered path: consecutive pixels are 8-neighbours, waypoints in order
        assert np.all(np.abs(np.diff(s.path, axis=0)).max(axis=1) == 1)
        order = [s.path.tolist().index(list(p)) for p in wps]
        assert order == sorted(order)


@pytest.mark.parametrize("method", ["dp", "oscillating", "oscillating-optimal"])
def test_cyclic_closes_the_wrap(method):
    e = smooth_map((24, 8), 4, sigma=1.0)
    e[0, :4] = e[-1, 4:] = 0.0  # tempting ends far apart
    s = find_seam(e, method=method, cyclic=True)
    plain = find_seam(e, method=method)
    if method == "dp":
        assert abs(s.path[0, 1] - s.path[-1, 1]) <= 1
    else:
        c = controls_of(s)
        assert s.criterion == pytest.approx(osc_eps(e, c, cyclic=True))
        assert osc_eps(e, controls_of(plain), cyclic=True) >= s.criterion - 1e-9


@pytest.mark.parametrize("method", ["dijkstra", "minimax", "resistance"])
def test_cyclic_unsupported_raises_value_error_naming_method(method):
    with pytest.raises(ValueError, match=method):
        find_seam(np.ones((4, 4)), method=method, cyclic=True)


def test_validation_messages():
    e = np.ones((5, 4))
    with pytest.raises(TypeError, match="o_mx"):
        find_seam(e, method="oscillating", o_mx=2)
    with pytest.raises(TypeError, match="o_max"):
        find_seam(e, method="dp", o_max=2)
    with pytest.raises(ValueError, match="method"):
        find_seam(e, method="graphcut")
    with pytest.raises(ValueError, match="start"):
        find_seam(e, start=4)
    with pytest.raises(TypeError, match="end"):
        find_seam(e, end=1.5)
    with pytest.raises(ValueError, match="distinct rows"):
        find_seam(e, waypoints=[(2, 1), (2, 3)])
    with pytest.raises(ValueError, match="outside"):
        find_seam(e, waypoints=[(5, 1)])
    with pytest.raises(ValueError, match="conflicts"):
        find_seam(e, start=1, waypoints=[(0, 2)])
    with pytest.raises(ValueError, match="variant"):
        find_seam(e, method="minimax", variant="fast")
    with pytest.raises(ValueError, match="connectivity"):
        find_seam(e, method="dijkstra", connectivity=6)
    with pytest.raises(ValueError, match="o_max"):
        find_seam(e, method="oscillating", o_max=0)
    with pytest.raises(ValueError, match="init"):
        find_seam(e, method="oscillating", init="random")
    with pytest.raises(ValueError, match="non-negative"):
        find_seam(-e)
    with pytest.raises(ValueError, match="finite"):
        find_seam(e * np.nan)
    # the error iterates lazily but validates eagerly
    with pytest.raises(TypeError):
        iter_find_seam(e, method="dp", bogus=1)


@pytest.mark.parametrize("method", METHODS)
def test_input_untouched_float32_accepted(method):
    e = smooth_map((16, 6), 0).astype(np.float32)
    before = e.copy()
    updates, seam = events_and_result(iter_find_seam(e, method=method))
    assert np.array_equal(e, before)
    assert isinstance(updates[-1], SeamUpdate) and updates[-1].final
    assert updates[-1].seam is seam and seam.method == method


def test_warmup_runs():
    warmup()


# ----------------------------------------------------------------------------- result type
def test_seam_is_immutable_picklable_and_lazy_seams_match_eager():
    import pickle

    e = smooth_map((40, 9), 3)
    work = e.copy()
    updates = list(iter_find_seam(work, method="oscillating"))
    work[:] = 99.0  # the caller reuses its buffer: streamed seams must not change
    for u in updates[:: max(1, len(updates) // 7)] + [updates[-1]]:
        s = u.seam
        c = controls_of(s)
        assert s.criterion == pytest.approx(osc_eps(e, c))
        assert s.peak == pytest.approx(e[s.path[:, 0], s.path[:, 1]].max())
        assert np.array_equal(s.mask, np.arange(9)[None, :] <= c[:, None])
    s = updates[-1].seam
    with pytest.raises(AttributeError):
        s.criterion = 0.0
    with pytest.raises(ValueError):
        s.path[0, 0] = 1
    t = pickle.loads(pickle.dumps(s))
    assert np.array_equal(t.path, s.path) and t.criterion == s.criterion and t.method == s.method
    assert not t.path.flags.writeable and not t.mask.flags.writeable
    assert "oscillating" in repr(s) and s.shape == (40, 9)


def test_benchmark_runs_and_baseline_matches_dp(capsys):
    from benchmarks.seams import main, numpy_dp

    e = smooth_map((50, 7), 0)
    assert np.array_equal(numpy_dp(e), find_seam(e).path[:, 1])
    assert main(["--sizes", "32x6", "--min-time", "0"]) == 0
    out = capsys.readouterr().out
    assert "numpy row DP" in out and "oscillating o_max=3" in out


def test_benchmark_quality_table_and_diagnosis_run():
    from benchmarks.seams import diagnose, quality, random_overlaps

    sets = {"random strips": random_overlaps(n_per_sample=1, h=24, w=8)}
    table = quality(sets)
    assert "paper: faithful, argmin, o_max=3" in table and "(default)" in table
    assert "random strips (5)" in table
    assert "argmin start" in diagnose(sets, limit=2)


class CountdownToken:
    """A cancel token that becomes set after ``n`` polls (cancellation from "inside" a run)."""

    def __init__(self, n):
        self.n = n

    @property
    def cancelled(self):
        self.n -= 1
        return self.n < 0


def test_optimal_cyclic_and_segmented_searches_poll_cancel_between_steps():
    e = smooth_map((30, 12), 0)
    with pytest.raises(Cancelled):
        find_seam(e, method="oscillating-optimal", cyclic=True, cancel=CountdownToken(4))
    with pytest.raises(Cancelled):
        find_seam(e, method="minimax", waypoints=[(10, 3), (20, 5)], cancel=CountdownToken(3))
    s = find_seam(e, method="oscillating", cancel=CountdownToken(2))  # anytime: no exception
    assert_valid(s, e)
