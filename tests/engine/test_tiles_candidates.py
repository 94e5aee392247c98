"""Connectable candidate tiles (ALGORITHMS.md §1.5, §1.8)."""

import numpy as np
import pytest
from scipy import ndimage

import resources
from engine.cancel import CancelToken
from engine.events import Progress, drain
from engine.io import load_image
from engine.metrics import border_ratio, grid_score
from engine.tiles import (
    CandidateTile,
    assemble,
    candidate_seed,
    candidates,
    default_patch_overlap,
    find_template,
    iter_candidates,
    make_candidate,
    make_seamless,
    random_layout,
)
from engine.tiles.candidates import MARGIN, CandidateSetup
from tests.engine.helpers import events_and_result, smooth_texture


def texture(shape=(140, 150), channels=3, seed=0, sigma=1.5):
    return smooth_texture(shape, channels, seed, sigma)


RECT, W_T = (10, 12, 64, 60), 8


@pytest.fixture(scope="module")
def small():
    S = texture()
    return S, make_seamless(S, RECT, overlap=W_T)


def ring(a, m):
    return np.concatenate([a[:m].ravel(), a[-m:].ravel(), a[:, :m].ravel(), a[:, -m:].ravel()])


def test_candidates_keep_the_template_border_and_stream(small):
    S, st = small
    events, cands = events_and_result(iter_candidates(S, st, 6, rng=3, workers=2, margin=2))
    items = [e for e in events if isinstance(e, CandidateTile)]
    assert all(isinstance(e, (CandidateTile, Progress)) for e in events)
    assert sorted(c.index for c in items) == list(range(6))
    assert [c.index for c in cands] == list(range(6))
    for c in cands:
        assert c.tile.shape == st.tile.shape and c.tile.dtype == np.float32
        np.testing.assert_array_equal(ring(c.tile, 2), ring(st.tile, 2))
        assert (ring(c.alpha, 2) == 0).all()
        x, y, w, h = c.patch_rect
        assert (y, x) == c.patch_origin and (h, w) == st.tile.shape[:2]
        # inside the loop the tile is the source patch (hard pixels are exact copies)
        inside = c.alpha == 1
        np.testing.assert_array_equal(c.tile[inside], S[y : y + h, x : x + w][inside])
        outside = c.alpha == 0
        np.testing.assert_array_equal(c.tile[outside], st.tile[outside])
        assert 0.4 < c.scores["changed"] <= 1 and c.scores["coverage"] > 0.4
        assert c.scores["criterion"] > 0 and c.scores["peak"] > 0
        # the loop is closed: it separates the inside from the border
        lab, _ = ndimage.label(~c.mask)
        assert lab[0, 0] > 0 and (lab[c.mask] == 0).all()


def test_same_seed_same_tiles_whatever_the_workers(small):
    S, st = small
    a = candidates(S, st, 5, rng=11, workers=1)
    b = candidates(S, st, 7, rng=11, workers=2)
    c = candidates(S, st, 6, rng=11, workers=3)
    for x, y, z in zip(a, b[:5], c[:5], strict=True):
        for other in (y, z):
            for field in ("tile", "alpha", "mask", "loop"):
                np.testing.assert_array_equal(getattr(x, field), getattr(other, field))
            assert x.patch_rect == other.patch_rect and x.seed == other.seed
            assert x.scores == other.scores
        assert x.seed == candidate_seed(11, x.index)
    c = candidates(S, st, 5, rng=12, workers=2)
    assert any(x.patch_rect != y.patch_rect for x, y in zip(a, c, strict=True))


@pytest.mark.parametrize("workers", [1, 2])
def test_cancel_keeps_the_candidates_already_made(small, workers):
    S, st = small
    full = candidates(S, st, 12, rng=5, workers=workers)
    token = CancelToken()
    gen = iter_candidates(S, st, 12, rng=5, workers=workers, cancel=token)
    got = []

    def on_event(ev):
        if isinstance(ev, CandidateTile):
            got.append(ev)
            if len(got) == 3:
                token.cancel()

    kept = drain(gen, on_event)
    assert 3 <= len(kept) < 12
    assert {c.index for c in got} == {c.index for c in kept}
    for c in kept:
        np.testing.assert_array_equal(c.tile, full[c.index].tile)


def test_closing_the_generator_stops_the_pool(small):
    S, st = small
    gen = iter_candidates(S, st, 20, rng=1, workers=2)
    for ev in gen:
        if isinstance(ev, CandidateTile):
            break
    gen.close()  # must not hang or raise


def test_make_candidate_from_origin_and_from_seed(small):
    S, st = small
    cands = candidates(S, st, 3, rng=9, workers=1)
    # the global search keeps candidate 2 away from the earlier ones: give their origins
    avoid = [c.patch_origin for c in cands[:2]]
    again = make_candidate(S, st, seed=cands[2].seed, index=2, avoid=avoid)
    np.testing.assert_array_equal(again.tile, cands[2].tile)
    local = candidates(S, st, 3, rng=9, workers=1, patch_search="local")
    again = make_candidate(S, st, seed=local[2].seed, index=2, patch_search="local")
    np.testing.assert_array_equal(again.tile, local[2].tile)
    moved = make_candidate(S, st, patch_origin=(40, 50), index=7)
    assert moved.patch_origin == (40, 50) and moved.index == 7 and moved.seed is None
    settled = make_candidate(S, st, patch_origin=(40, 50), neighbourhood=3)
    assert abs(settled.patch_origin[0] - 40) <= 3 and abs(settled.patch_origin[1] - 50) <= 3
    assert settled.scores["band_error"] <= moved.scores["band_error"]
    with pytest.raises(ValueError, match="outside"):
        make_candidate(S, st, patch_origin=(139, 0))


@pytest.mark.parametrize("channels", [3, 1])
def test_position_refinement_against_brute_force(small, channels):
    S, st = small
    if channels == 1:
        S = texture(channels=1, seed=7)
        st = make_seamless(S, RECT, overlap=W_T)
    setup = CandidateSetup(
        S,
        st,
        patch_size=None,
        patch_overlap=None,
        margin=2,
        neighbourhood=4,
        seam=None,
        excluded=None,
        maps=None,
        weights=None,
    )
    (y, x), cost = setup.refine((30, 40), 4)
    h, w = st.tile.shape[:2]
    r, c = np.mgrid[0:h, 0:w]
    d = np.minimum.reduce([r, c, h - 1 - r, w - 1 - c])
    band = (d >= 2) & (d < W_T)

    def brute(yy, xx):
        return np.sqrt(((S[yy : yy + h, xx : xx + w] - st.tile) ** 2).sum(2))[band].mean()

    costs = {(yy, xx): brute(yy, xx) for yy in range(26, 35) for xx in range(36, 45)}
    best = min(costs, key=costs.get)
    assert (y, x) == best and cost == pytest.approx(costs[best], rel=1e-5)


def test_excluded_patches_and_material_maps():
    S = texture(seed=4)
    height = texture(seed=5, channels=1)
    st = make_seamless(S, RECT, overlap=W_T, maps={"height": height})
    ex = np.zeros(S.shape[:2], bool)
    ex[:, 60:] = True  # only the left 60 columns may be used
    cands = candidates(
        S, st, 4, rng=2, workers=1, excluded=ex, maps={"height": height}, patch_size=(48, 52)
    )
    for c in cands:
        x, y, w, h = c.patch_rect
        assert (h, w) == (48, 52) and not ex[y : y + h, x : x + w].any()
        tx, ty = c.target_rect[:2]
        assert (ty, tx) == ((60 - 48) // 2, (64 - 52) // 2)
        # the height map follows the same cut
        hm = c.maps["height"]
        inside = c.alpha == 1
        src = np.zeros_like(hm)
        src[ty : ty + h, tx : tx + w] = height[y : y + h, x : x + w]
        np.testing.assert_array_equal(hm[inside], src[inside])
        np.testing.assert_array_equal(hm[c.alpha == 0], st.maps["height"][c.alpha == 0])
    with pytest.raises(ValueError, match="maps"):
        candidates(S, st, 2, rng=0)


def test_bad_input(small):
    S, st = small
    with pytest.raises(TypeError, match="SeamlessTile"):
        candidates(S, st.tile, 2)
    with pytest.raises(ValueError, match="patch_size"):
        candidates(S, st, 2, patch_size=100)
    with pytest.raises(ValueError, match="2 \\* patch_overlap"):
        candidates(S, st, 2, patch_size=15)
    with pytest.raises(ValueError, match="margin"):
        candidates(S, st, 2, margin=8)
    with pytest.raises(ValueError, match="excluded"):
        candidates(S, st, 2, excluded=np.ones(S.shape[:2], bool))
    ex = np.zeros(S.shape[:2], bool)
    ex[::30, ::30] = True
    with pytest.raises(ValueError, match="no 64x60 patch fits"):
        candidates(S, st, 2, excluded=ex)
    with pytest.raises(ValueError, match="channels"):
        candidates(S[:, :, :1], st, 2)
    with pytest.raises(TypeError, match="SeamSpec"):
        candidates(S, st, 2, seam={"method": "dp"})
    with pytest.raises(TypeError, match="bogus"):
        iter_candidates(S, st, 2, bogus=3)
    with pytest.warns(UserWarning, match="margin 0"):
        iter_candidates(S, st, 1, margin=0)
    with pytest.raises(TypeError, match="rng"):
        candidates(S, st, 2, rng="seed")
    flat = np.full((100, 100, 3), 0.3, np.float32)
    with pytest.warns(UserWarning, match="flat"):
        fst = make_seamless(flat, (0, 0, 40, 40), overlap=4)
    with pytest.warns(UserWarning, match="flat"):
        fc = candidates(flat, fst, 2, rng=0, workers=1)
    assert all(np.array_equal(c.tile, fst.tile) for c in fc)


def pair_ratios(tiles, direction):
    """border_ratio(a, b) for every ordered pair (a, b), vectorised (checked on a few pairs)."""
    t = np.stack([np.asarray(x, np.float64) for x in tiles])
    if direction == "vertical":
        t = t.transpose(0, 2, 1, 3)
    steps = np.abs(np.diff(t, axis=2)).mean(axis=3)  # (n, h, w-1)
    inner = steps.sum(axis=(1, 2))
    joint = np.abs(t[:, None, :, -1] - t[None, :, :, 0]).mean(axis=(2, 3))  # (n, n)
    ratio = joint / ((inner[:, None] + inner[None, :]) / (2 * steps[0].size))
    for i, j in ((0, 1), (3, 2), (5, 5)):
        assert ratio[i, j] == pytest.approx(border_ratio(tiles[i], tiles[j], direction=direction))
    return ratio.ravel()


def test_default_patch_ring_is_scale_aware():
    """[REC] w_P = min(w_T, max(8, w_T // 2)): half the template overlap, never below 8 px
    and never wider than w_T (benchmarks/tileset.py --patch-rings)."""
    got = {w: default_patch_overlap(w) for w in (2, 6, 8, 13, 16, 17, 26, 103)}
    assert got == {2: 2, 6: 6, 8: 8, 13: 8, 16: 8, 17: 8, 26: 13, 103: 51}
    with pytest.raises(ValueError, match="overlap"):
        default_patch_overlap(0)


def test_candidates_default_to_that_ring():
    """The closed cut runs in the default ring (offsets margin .. w_P - 1 from the patch
    window's border), not in a ring of w_T; make_candidate uses the same default."""
    S = texture((200, 210), seed=4)
    st = make_seamless(S, (20, 16, 120, 110), overlap=24)  # w_T 24 -> w_P 12
    ring_px = default_patch_overlap(24)
    assert ring_px == 12
    for c in candidates(S, st, 4, rng=1, workers=1):
        h, w = c.mask.shape
        r, col = c.loop[:, 0], c.loop[:, 1]
        depth = np.minimum.reduce([r, col, h - 1 - r, w - 1 - col])
        assert depth.min() >= MARGIN and depth.max() <= ring_px - 1, (depth.min(), depth.max())
    kw = dict(patch_origin=(30, 40))
    default = make_candidate(S, st, **kw)
    np.testing.assert_array_equal(default.tile, make_candidate(S, st, patch_overlap=12, **kw).tile)
    assert not np.array_equal(default.tile, make_candidate(S, st, patch_overlap=24, **kw).tile)


def test_connectability_and_variety_on_samples():
    """Acceptance: 30 candidates per sample; all ordered pairs, h and v: median border
    ratio <= 1.2 and max <= 1.6; an 8x8 preview of 8 picked tiles has a grid score at most
    0.35 x that of the template repeated."""
    assert len(resources.SAMPLE_NAMES) >= 5  # brick, grass, gravel, cobblestones, lichen
    for name in resources.SAMPLE_NAMES:
        S = load_image(resources.sample_path(name)).pixels
        st = make_seamless(S, find_template(S, tile_min=256, tile_max=256))
        cands = candidates(S, st, 30, rng=0, workers=2)
        tiles = [c.tile for c in cands]
        ratios = np.concatenate([pair_ratios(tiles, d) for d in ("horizontal", "vertical")])
        assert np.median(ratios) <= 1.2, name
        assert max(ratios) <= 1.6, name
        changed = np.mean([c.scores["changed"] for c in cands])
        assert changed > 0.6, name
        if name != "cobblestones":  # the grid score of 2048 px previews is slow: one sample
            continue  # here, every sample in benchmarks/tileset.py
        picked = sorted(cands, key=lambda c: c.scores["criterion"])[:8]
        layout = random_layout(8, 8, 8, rng=0, no_equal_neighbours=True)
        preview = assemble(picked, layout)
        single = assemble([st.tile], np.zeros((8, 8), int))
        g = grid_score(preview, st.shape, source=S)
        g0 = grid_score(single, st.shape, source=S)
        assert g <= 0.35 * g0, (name, g, g0)
