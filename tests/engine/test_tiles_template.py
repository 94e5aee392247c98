"""Template search (ALGORITHMS.md §1.6): phases against brute force, periodic oracle, events."""

import warnings

import numpy as np
import pytest

from engine.cancel import Cancelled, CancelToken
from engine.events import Progress, drain
from engine.tiles import (
    Template,
    TemplateUpdate,
    default_overlap,
    find_template,
    iter_find_template,
    template_cost,
)
from engine.tiles.detail import DETAIL_WEIGHT
from engine.tiles.template_scan import Scan, argmin_cost, pair_cost
from tests.engine.helpers import events_and_result


def periodic(period=(23, 29), shape=(90, 100), channels=3, seed=0):
    rng = np.random.default_rng(seed)
    cell = rng.random((period[0], period[1], channels), dtype=np.float32)
    reps = (shape[0] // period[0] + 1, shape[1] // period[1] + 1, 1)
    return np.tile(cell, reps)[: shape[0], : shape[1]]


def dist(p, q):
    return np.sqrt(((p.astype(np.float64) - q) ** 2).sum(-1))


def brute_energy(S):
    """Squared 4-neighbour Laplacian per channel (mirrored border), mean over channels."""
    S = np.asarray(S, dtype=np.float64)
    P = np.pad(S, ((1, 1), (1, 1), (0, 0)), mode="symmetric")
    c = P[1:-1, 1:-1]
    lap = P[:-2, 1:-1] + P[2:, 1:-1] + P[1:-1, :-2] + P[1:-1, 2:] - 4 * c
    return (lap**2).mean(axis=2)


def brute_unrelated(S):
    """Mean distance of pixels a few fixed wrapped offsets apart (every 4th pixel)."""
    sub = np.asarray(S, dtype=np.float64)[::4, ::4]
    h, w = sub.shape[:2]
    offsets = ((1 / 2, 1 / 2), (1 / 3, 3 / 5), (5 / 7, 1 / 4))
    return np.mean(
        [dist(sub, np.roll(sub, (int(h * fy), int(w * fx)), (0, 1))).mean() for fy, fx in offsets]
    )


def brute_starts(last):
    """Up to 64 window starts spread evenly over 0 .. last."""
    return sorted({int(round(v)) for v in np.linspace(0, last, min(last + 1, 64))})


def brute_reference(E, hf, wf):
    """The upper quartile of the window means (each by .mean()) on the starts' grid."""
    H, W = E.shape
    means = [
        E[y : y + hf, x : x + wf].mean() for y in brute_starts(H - hf) for x in brute_starts(W - wf)
    ]
    return float(np.quantile(means, 0.75))


_REFS: dict = {}  # per image: energy and unit; per image and size: the reference


def brute_detail_penalty(S, rect, w, kappa):
    """κ · C · max(0, 1 − q): q the footprint's mean energy over the upper quartile of the
    window means of its size, C the unrelated pixels' distance."""
    if kappa == 0:
        return 0.0
    x, y, a, b = rect
    hf, wf = b + w, a + w
    image = S.tobytes()
    if image not in _REFS:
        _REFS[image] = brute_energy(S), brute_unrelated(S)
    E, unit = _REFS[image]
    key = (image, hf, wf)
    if key not in _REFS:
        _REFS[key] = brute_reference(E, hf, wf)
    q = E[y : y + hf, x : x + wf].mean() / _REFS[key]
    return kappa * unit * min(1.0, max(0.0, 1.0 - q))


def brute_rect_cost(S, rect, w, lam=0.0, kappa=0.0):
    """(D_h + D_v) / 2 + λ (G_h + G_v) / 2 + the detail term, G the step across the natural
    wrap joints."""
    x, y, a, b = rect
    rows, cols = slice(y, y + b + w), slice(x, x + a + w)
    dh = dist(S[rows, x : x + w], S[rows, x + a : x + a + w]).mean()
    dv = dist(S[y : y + w, cols], S[y + b : y + b + w, cols]).mean()
    gh = dist(S[rows, x + a - 1], S[rows, x + a]).mean()
    gv = dist(S[y + b - 1, cols], S[y + b, cols]).mean()
    return (dh + dv) / 2 + lam * (gh + gv) / 2 + brute_detail_penalty(S, rect, w, kappa)


@pytest.mark.parametrize("masked", [False, True])
@pytest.mark.parametrize("lam", [0.0, 0.7])
def test_scan_costs_match_brute_force(masked, lam):
    rng = np.random.default_rng(1)
    S = rng.random((20, 40, 3), dtype=np.float32)
    valid = rng.random((20, 40)) > 0.2 if masked else np.ones((20, 40), bool)
    shifts = np.arange(8, 15)
    w = 4
    sc = Scan(S, valid if masked else None, (3, 17), shifts, w, lam)
    for _ in sc.chunks():
        pass
    costs = sc.costs(None)
    r = slice(3, 17)
    for k, a in enumerate(shifts):
        for x in range(40):
            if x + a + w > 40:
                assert costs[k, x] == np.inf
                continue
            ok = valid[r, x : x + w] & valid[r, x + a : x + a + w]
            d = dist(S[r, x : x + w], S[r, x + a : x + a + w])[ok].mean()
            gk = valid[r, x + a - 1] & valid[r, x + a]
            g = dist(S[r, x + a - 1], S[r, x + a])[gk].mean()
            assert costs[k, x] == pytest.approx(d + lam * g, rel=1e-6, abs=1e-9)
            dd, gg = pair_cost(S, valid if masked else None, (3, 17), x, int(a), w)
            assert (dd, gg) == pytest.approx((d, g), rel=1e-6, abs=1e-9)
    x, a, c = argmin_cost(costs, shifts)
    assert c == pytest.approx(np.nanmin(costs))


def test_scan_detail_term_matches_brute_force():
    from engine.tiles.detail import DetailTerm

    rng = np.random.default_rng(4)
    S = rng.random((22, 36, 3), dtype=np.float32)
    S[:, :14] *= 0.1  # a calm left part: its footprints lack detail
    shifts, w, rows = np.arange(6, 12), 3, (2, 19)
    term = DetailTerm.of(S, 2.0)
    depth = rows[1] - rows[0]
    fp = (term, term.line_energy(rows), depth, term.reference(depth, shifts + w))
    sc = Scan(S, None, rows, shifts, w, 0.3, fp)
    for _ in sc.chunks():
        pass
    costs = sc.costs(None)
    plain = Scan(S, None, rows, shifts, w, 0.3)
    for _ in plain.chunks():
        pass
    base = plain.costs(None)
    penalised = 0
    for k, a in enumerate(shifts):
        for x in range(36 - a - w + 1):
            rect = (x, rows[0], int(a), depth - w)
            pen = brute_detail_penalty(S, rect, w, 2.0)
            penalised += pen > 0
            assert costs[k, x] == pytest.approx(base[k, x] + pen, rel=1e-6, abs=1e-9)
            assert term.rect_detail(rect, w)[1] == pytest.approx(pen, rel=1e-6, abs=1e-12)
    assert penalised > 10


@pytest.mark.parametrize("dtype", [np.uint8, np.float32, np.float64])
def test_periodic_source_finds_its_period(dtype):
    S = periodic()
    src = (S * 255).round().astype(np.uint8) if dtype == np.uint8 else S.astype(dtype)
    before = src.copy()
    t = find_template(src, tile_min=(18, 20), tile_max=(30, 34), overlap=4)
    assert isinstance(t, Template)
    x, y, w, h = t.rect
    assert (h, w) == (23, 29)
    assert (t.cost_horizontal, t.cost_vertical) == pytest.approx((0, 0), abs=1e-6)
    f = S if dtype != np.uint8 else src / np.float32(255)
    detail = brute_detail_penalty(f.astype(np.float32), t.rect, 4, t.detail_weight)
    assert t.cost == pytest.approx(
        t.joint_weight * (t.joint_horizontal + t.joint_vertical) / 2 + detail
    )
    assert t.detail_weight == DETAIL_WEIGHT and 0.5 < t.detail < 2
    pure = find_template(
        src, tile_min=(18, 20), tile_max=(30, 34), overlap=4, joint_weight=0, detail_weight=0
    )
    assert pure.rect[2:] == (29, 23) and pure.cost == pytest.approx(0, abs=1e-6)
    assert t.footprint == (x, y, w + 4, h + 4)
    np.testing.assert_array_equal(src, before)


def test_gray_source_and_reported_costs():
    S = periodic(channels=1)[:, :, 0] * 0.5 + np.linspace(0, 0.3, 100)[None, :]
    for lam, kappa in ((0.0, 0.0), (0.5, 0.0), (3.0, 0.0), (0.5, 1.0), (0.0, 4.0)):
        kw = dict(joint_weight=lam, detail_weight=kappa)
        t = find_template(S, tile_min=20, tile_max=32, overlap=4, **kw)
        assert t.joint_weight == lam and t.detail_weight == kappa
        cost, ch, cv = template_cost(S, t.rect, overlap=4, **kw)
        assert cost == pytest.approx(t.cost)
        assert (ch, cv) == pytest.approx((t.cost_horizontal, t.cost_vertical))
        brute = brute_rect_cost(S[:, :, None].astype(np.float32), t.rect, 4, lam, kappa)
        assert cost == pytest.approx(brute, rel=1e-6)
        assert (ch + cv) / 2 == pytest.approx(brute_rect_cost(S[:, :, None], t.rect, 4))
    # the default λ is the search's default: a user-fixed rectangle scores like a found one
    t = find_template(S, tile_min=20, tile_max=32, overlap=4)
    assert template_cost(S, t.rect, overlap=4)[0] == pytest.approx(t.cost)


def test_refine_never_worse_and_two_phase_near_brute_force():
    rng = np.random.default_rng(3)
    # smooth random field: costs vary smoothly, so a global brute force is meaningful
    from scipy import ndimage

    S = ndimage.gaussian_filter(rng.random((48, 52, 3)), (3, 3, 0)).astype(np.float32)
    w = 3
    coarse = find_template(S, tile_min=16, tile_max=22, overlap=w, refine=False)
    fine = find_template(S, tile_min=16, tile_max=22, overlap=w, refine=True)
    assert fine.cost <= coarse.cost + 1e-12
    coarse = find_template(S, tile_min=16, tile_max=22, overlap=w, refine=False, detail_weight=0)
    fine = find_template(S, tile_min=16, tile_max=22, overlap=w, refine=True, detail_weight=0)
    best = min(
        brute_rect_cost(S, (x, y, a, b), w)
        for a in range(16, 23)
        for b in range(16, 23)
        for x in range(0, 52 - a - w + 1, 2)
        for y in range(0, 48 - b - w + 1, 2)
    )
    # two independent phases are a heuristic: within 2x of the (sub-sampled) global optimum
    assert fine.cost <= 2.0 * best


def test_stream_improves_and_ends_with_result():
    S = periodic(shape=(80, 90))
    gen = iter_find_template(S, tile_min=18, tile_max=30, overlap=3)
    events, result = events_and_result(gen)
    ups = [e for e in events if isinstance(e, TemplateUpdate)]
    assert ups and all(isinstance(e, (TemplateUpdate, Progress)) for e in events)
    costs = [u.cost for u in ups]
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    assert ups[-1].rect == result.rect and ups[-1].cost == result.cost
    prog = [e for e in events if isinstance(e, Progress)]
    assert prog[-1].fraction == 1.0


def test_excluded_region_is_avoided():
    S = periodic(shape=(90, 100))
    free = find_template(S, tile_min=20, tile_max=30, overlap=4)
    ex = np.zeros(S.shape[:2], bool)
    x, y, w, h = free.footprint
    ex[y + h // 2, x + w // 2] = True  # one pixel in the middle of the best footprint
    t = find_template(S, tile_min=20, tile_max=30, overlap=4, excluded=ex)
    x, y, w, h = t.footprint
    assert not ex[y : y + h, x : x + w].any()
    assert t.rect[2:] == (29, 23)  # the period is still found elsewhere


def test_cancel_before_and_after_first_rectangle():
    S = periodic(shape=(80, 90))
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        find_template(S, tile_min=18, tile_max=30, overlap=3, cancel=token)
    token = CancelToken()
    gen = iter_find_template(S, tile_min=18, tile_max=30, overlap=3, cancel=token)
    first = None

    def on_event(ev):
        nonlocal first
        if isinstance(ev, TemplateUpdate) and first is None:
            first = ev
            token.cancel()

    result = drain(gen, on_event)
    assert result.rect == first.rect


def test_bad_input_messages():
    S = periodic(shape=(60, 70))
    with pytest.raises(ValueError, match="smaller than the minimum tile"):
        find_template(S, tile_min=64, tile_max=80, overlap=4)
    with pytest.raises(ValueError, match="must not exceed tile_max"):
        find_template(S, tile_min=30, tile_max=20, overlap=4)
    with pytest.raises(ValueError, match="overlap"):
        find_template(S, tile_min=10, tile_max=20, overlap=6)
    with pytest.raises(TypeError, match="tile_min"):
        find_template(S, tile_min="big", overlap=4)
    with pytest.raises(ValueError, match="whole source"):
        find_template(S, tile_min=20, overlap=4, excluded=np.ones((60, 70), bool))
    ex = np.zeros((60, 70), bool)
    ex[:, ::20] = True  # stripes: no 24-px-wide footprint is free
    with pytest.raises(ValueError, match="excluded"):
        find_template(S, tile_min=20, overlap=4, excluded=ex)
    with pytest.raises(ValueError, match="excluded must be"):
        find_template(S, tile_min=20, overlap=4, excluded=np.zeros((5, 5), bool))
    with pytest.warns(UserWarning, match="does not fit"):
        t = find_template(S, tile_min=20, tile_max=100, overlap=4)
    assert t.rect[2] + 4 <= 70 and t.rect[3] + 4 <= 60
    assert any("does not fit" in w for w in t.warnings)
    with pytest.raises(ValueError, match="outside"):
        template_cost(S, (50, 0, 20, 20), overlap=4)
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="joint_weight"):
            find_template(S, tile_min=20, overlap=4, joint_weight=bad)
    with pytest.raises(TypeError, match="joint_weight"):
        template_cost(S, (0, 0, 20, 20), overlap=4, joint_weight="high")


def test_flat_source_warns_and_still_works():
    S = np.full((60, 60, 3), 0.4, np.float32)
    with pytest.warns(UserWarning, match="flat"):
        t = find_template(S, tile_min=20, tile_max=30, overlap=4)
    assert t.cost == 0.0 and t.warnings


def test_default_overlap_is_a_tenth_of_the_tile():
    assert default_overlap(256) == 26
    assert default_overlap(200, 300) == 25
    assert default_overlap((10, 12)) == 2
    assert default_overlap(40, 400) == 20  # 22 would not fit twice in the smallest tile
    assert find_template(periodic(shape=(120, 130)), tile_min=8, tile_max=88).overlap == 4
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # (that tiles of 20..30 hold under three periods: said)
        warnings.filterwarnings("ignore", message="the texture repeats about every")
        t = find_template(periodic(), tile_min=20, tile_max=30)
    assert t.overlap == 2 or t.overlap == default_overlap(20, 30)


def test_coarse_to_fine_finds_the_period_and_is_chosen_by_size():
    from engine.tiles.template import _coarse_factor

    S = periodic(period=(46, 58), shape=(260, 280))
    t = find_template(S, tile_min=(40, 50), tile_max=(60, 70), overlap=6, coarse=2)
    assert t.rect[2:] == (58, 46)
    assert (t.cost_horizontal, t.cost_vertical) == pytest.approx((0, 0), abs=1e-6)
    full = find_template(S, tile_min=(40, 50), tile_max=(60, 70), overlap=6, coarse=1)
    assert full.rect[2:] == (58, 46)
    assert _coarse_factor((512, 512), 257) == 1  # bundled samples: full resolution
    assert _coarse_factor((4096, 4096), 257) >= 3  # a 4096 px photo with a wide range
    with pytest.raises(ValueError, match="coarse"):
        find_template(S, tile_min=40, coarse=0)


def test_coarse_to_fine_cost_close_to_the_full_search_on_samples():
    import resources
    from engine.io import load_image

    for name in resources.SAMPLE_NAMES:
        S = load_image(resources.sample_path(name)).pixels
        full = find_template(S, tile_min=128, tile_max=256, coarse=1)
        for f in (2, 4):
            c = find_template(S, tile_min=128, tile_max=256, coarse=f)
            assert c.cost <= 1.15 * full.cost, (name, f, c.cost, full.cost)
