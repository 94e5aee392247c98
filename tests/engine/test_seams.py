"""Seam engine: every method against its oracle, constraints, streaming and cancellation."""

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra as cs_dijkstra

import resources
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
from engine.seams.oscillating import criterion as osc_criterion
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


def run_stream(gen):
    """All events left in an event generator, and its return value."""
    events = []
    while True:
        try:
            events.append(next(gen))
        except StopIteration as stop:
            return events, stop.value


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


@pytest.mark.parametrize("variant", ["resume", "faithful"])
@pytest.mark.parametrize("cyclic", [False, True])
@pytest.mark.parametrize("o_max", [1, 3])
def test_oscillating_monotone_and_locally_optimal(variant, cyclic, o_max):
    for seed in range(3):
        e = smooth_map((24, 7), seed, sigma=1.0)
        updates = list(
            iter_find_seam(e, method="oscillating", o_max=o_max, variant=variant, cyclic=cyclic)
        )
        crits = [u.seam.criterion for u in updates]
        assert all(b <= a + 1e-12 for a, b in zip(crits, crits[1:], strict=False))
        assert len(updates) > 2, "the search never improved the initial path"
        assert [u.final for u in updates] == [False] * (len(updates) - 1) + [True]
        assert updates[-1].seam is updates[-2].seam
        # the first path is the per-row argmin
        assert np.array_equal(controls_of(updates[0].seam), np.argmin(e, axis=1))
        final = updates[-1].seam
        assert_valid(final, e)
        c = controls_of(final)
        assert final.criterion == pytest.approx(osc_eps(e, c, cyclic))
        assert not improves(e, c, o_max, cyclic)


def test_oscillating_frozen_points_and_waypoints():
    e = smooth_map((20, 8), 5, sigma=1.0)
    s = find_seam(e, method="oscillating", start=7, end=0, waypoints=[(9, 3)])
    c = controls_of(s)
    assert (c[0], c[19], c[9]) == (7, 0, 3)
    assert not improves(e, c, 3, False, frozen={0, 9, 19})
    opt = find_seam(e, method="oscillating-optimal", start=7, end=0, waypoints=[(9, 3)])
    assert opt.criterion <= s.criterion + 1e-9


def test_oscillating_larger_o_max_not_worse_on_average():
    gaps = {1: [], 5: []}
    for seed in range(6):
        e = smooth_map((40, 10), seed)
        opt = find_seam(e, method="oscillating-optimal").criterion
        for o in gaps:
            gaps[o].append(find_seam(e, method="oscillating", o_max=o).criterion / opt - 1)
    assert np.mean(gaps[5]) <= np.mean(gaps[1]) + 1e-9


def sample_overlaps(n_per_sample=8, h=64, w=16, seed=0):
    """Error maps (RGB Euclidean) between two random 64x16 strips of the same sample."""
    rng = np.random.default_rng(seed)
    for name in resources.SAMPLE_NAMES:
        img = np.asarray(Image.open(resources.sample_path(name)).convert("RGB"), float) / 255
        H, W = img.shape[:2]
        for _ in range(n_per_sample):
            y1, y2 = rng.integers(0, H - h, 2)
            x1, x2 = rng.integers(0, W - w, 2)
            a = img[y1 : y1 + h, x1 : x1 + w]
            b = img[y2 : y2 + h, x2 : x2 + w]
            yield name, np.sqrt(((a - b) ** 2).sum(axis=2))


def test_oscillating_gap_to_optimum_on_samples(record_property):
    """Mean relative excess of the oscillating search over the exact optimum on real overlaps.

    Measured on these 40 overlaps: o_max=3 (default) ~ +47 %, o_max=8 ~ +21 %, o_max=16 ~ +13.5 %
    (resume variant). The acceptance target (<= 15 %) holds from o_max = h/4; the default
    o_max=3 is guarded against regressions only (see the report / benchmarks/seams.py).
    """
    maps = [e for _, e in sample_overlaps()]
    opt = np.array([find_seam(e, method="oscillating-optimal").criterion for e in maps])
    means = {}
    for o_max in (3, 16):
        osc = np.array([find_seam(e, method="oscillating", o_max=o_max).criterion for e in maps])
        assert np.all(osc >= opt - 1e-9)
        means[o_max] = float(np.mean(osc / opt - 1))
        record_property(f"oscillating_gap_o_max_{o_max}", means[o_max])
    print(
        f"oscillating vs optimum, {len(maps)} sample overlaps 64x16: "
        + ", ".join(f"o_max={o}: +{100 * m:.1f} %" for o, m in means.items())
    )
    assert means[16] <= 0.15
    assert means[3] <= 0.60


def test_oscillating_cancel_returns_valid_path_no_worse_than_initial():
    e = smooth_map((200, 24), 7)
    full = find_seam(e, method="oscillating")
    token = CancelToken()
    gen = iter_find_seam(e, method="oscillating", cancel=token)
    first = next(gen)
    for _ in range(5):
        next(gen)
    token.cancel()
    rest, result = run_stream(gen)
    assert rest and rest[-1].final and rest[-1].seam is result
    assert_valid(result, e)
    assert result.criterion <= first.seam.criterion
    assert result.criterion > full.criterion  # it really stopped early


def test_oscillating_cancelled_before_start_returns_initial_path():
    e = smooth_map((30, 6), 1)
    token = CancelToken()
    token.cancel()
    s = find_seam(e, method="oscillating", cancel=token)
    assert np.array_equal(controls_of(s), np.argmin(e, axis=1))


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
            s = find_seam(e, method="resistance", max_run=max_run)
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
    s = find_seam(e, method="resistance", max_run=3)
    assert s.path.tolist() == [[0, 2], [1, 2], [2, 2], [3, 3], [4, 3], [5, 3], [6, 2], [7, 2]]


def test_resistance_image_step_cost():
    # the error map is flat; the colour image has a smooth column the walk should follow
    e = np.ones((10, 6))
    img = np.random.default_rng(0).random((10, 6, 3))
    img[:, 4] = 0.5
    s = find_seam(e, method="resistance", image=img, start=4, max_run=20)
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
    updates, seam = run_stream(iter_find_seam(e, method=method))
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
    assert "oscillating" in repr(s) and s.shape == (40, 9)


def test_benchmark_runs_and_baseline_matches_dp(capsys):
    from benchmarks.seams import main, numpy_dp

    e = smooth_map((50, 7), 0)
    assert np.array_equal(numpy_dp(e), find_seam(e).path[:, 1])
    assert main(["--sizes", "32x6", "--min-time", "0"]) == 0
    out = capsys.readouterr().out
    assert "numpy row DP" in out and "oscillating o_max=3" in out


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
