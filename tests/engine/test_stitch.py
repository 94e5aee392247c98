"""Stitching: oriented stitches, cyclic template wrap, the L-shaped quilting cut, patching."""

import itertools

import numpy as np
import pytest
from scipy import ndimage

from engine.blend import adaptive_half_widths, clamped_half_widths
from engine.cancel import Cancelled, CancelToken
from engine.io import load_image
from engine.metrics import wrap_border_ratio
from engine.seams import SeamSpec, find_seam
from engine.stitch import (
    ORIENTATIONS,
    l_cut,
    patch,
    patch_cut,
    stitch,
    to_canonical,
)
from resources import sample_path

EDGE = {
    "right": (slice(None), 0),
    "left": (slice(None), -1),
    "bottom": (0, slice(None)),
    "top": (-1, slice(None)),
}


def pair(h, w, seed=0, channels=3):
    rng = np.random.default_rng(seed)
    return rng.random((h, w, channels), dtype=np.float32), rng.random(
        (h, w, channels), dtype=np.float32
    )


def shape_for(orientation, along=24, across=9):
    """(h, w) of an overlap whose seam runs ``along`` pixels."""
    return (along, across) if orientation in ("right", "left") else (across, along)


# ----------------------------------------------------------------------------- stitch
@pytest.mark.parametrize("orientation", ORIENTATIONS)
@pytest.mark.parametrize("method", ["dp", "dijkstra"])
def test_hard_cut_copies_r1_and_r2_exactly(orientation, method):
    r1, r2 = pair(*shape_for(orientation), seed=1)
    res = stitch(r1, r2, orientation=orientation, seam=SeamSpec(method))
    m = res.mask
    np.testing.assert_array_equal(res.image[m], r1[m])
    np.testing.assert_array_equal(res.image[~m], r2[~m])
    assert m[res.path[:, 0], res.path[:, 1]].all()  # the path belongs to R1
    assert m[EDGE[orientation]].all() and not m.all()  # R1 kept on its side
    # the canonical seam is the seam of the transformed problem
    direct = find_seam(to_canonical(res.error, orientation), method=method)
    np.testing.assert_array_equal(res.seam.path, direct.path)
    assert res.criterion == pytest.approx(direct.criterion)
    e = res.error
    assert res.criterion == pytest.approx(float(e[res.path[:, 0], res.path[:, 1]].sum()), 1e-5)


def test_orientations_are_transposes_of_each_other():
    r1, r2 = pair(20, 7, seed=2)
    right = stitch(r1, r2)
    left = stitch(r1[:, ::-1], r2[:, ::-1], orientation="left")
    bottom = stitch(r1.transpose(1, 0, 2), r2.transpose(1, 0, 2), orientation="bottom")
    top = stitch(r1.transpose(1, 0, 2)[::-1], r2.transpose(1, 0, 2)[::-1], orientation="top")
    np.testing.assert_array_equal(left.image, right.image[:, ::-1])
    np.testing.assert_array_equal(bottom.image, right.image.transpose(1, 0, 2))
    np.testing.assert_array_equal(top.image, right.image.transpose(1, 0, 2)[::-1])
    np.testing.assert_array_equal(
        top.path, np.column_stack([6 - right.seam.path[:, 1], right.seam.path[:, 0]])
    )


@pytest.mark.parametrize("orientation", ORIENTATIONS)
def test_adaptive_stitch_changes_only_pixels_within_its_width(orientation):
    r1, r2 = pair(*shape_for(orientation, 40, 14), seed=3)
    hard = stitch(r1, r2, orientation=orientation)
    soft = stitch(r1, r2, orientation=orientation, seam=SeamSpec(blend="adaptive", rho=3))
    changed = to_canonical(np.any(soft.image != hard.image, axis=2), orientation)
    assert changed.any()
    e = to_canonical(soft.error, orientation)
    cols = soft.seam.path[:, 1]  # dp: one pixel per row
    b = clamped_half_widths(cols, adaptive_half_widths(soft.seam, e, rho=3), e.shape[1])
    dist = np.abs(np.arange(e.shape[1])[None, :] - cols[:, None] - 0.5)
    assert not (changed & (dist >= b[:, None])).any()
    assert (b <= 6).all()


def test_waypoints_in_caller_coordinates_and_precomputed_error():
    for orientation in ORIENTATIONS:
        r1, r2 = pair(*shape_for(orientation, 16, 8), seed=4)
        h, w = r1.shape[:2]
        wp = (3, 5) if orientation in ("right", "left") else (5, 3)
        res = stitch(r1, r2, orientation=orientation, waypoints=[wp])
        assert tuple(wp) in set(map(tuple, res.path.tolist()))
    # a precomputed error map with a free corridor decides the path
    r1, r2 = pair(12, 9, seed=5)
    err = np.ones((12, 9), np.float32)
    err[:, 6] = 0
    res = stitch(r1, r2, error=err)
    assert (res.path[:, 1] == 6).all() and res.criterion == 0
    np.testing.assert_array_equal(res.error, err)


def test_apply_same_cut_to_material_maps():
    r1, r2 = pair(18, 8, seed=6)
    res = stitch(r1, r2, seam=SeamSpec(blend="feather", width=4))
    n1, n2 = pair(18, 8, seed=7, channels=1)
    out = res.apply(n1, n2)
    np.testing.assert_allclose(
        out, res.alpha[..., None] * n1 + (1 - res.alpha[..., None]) * n2, rtol=1e-6
    )
    np.testing.assert_allclose(res.apply(r1, r2), res.image)


def test_stitch_bad_input_and_cancel():
    r1, r2 = pair(8, 6)
    with pytest.raises(ValueError, match="r1 and r2 must have the same shape"):
        stitch(r1, r2[:, :5])
    with pytest.raises(ValueError, match="orientation must be one of"):
        stitch(r1, r2, orientation="up")
    with pytest.raises(ValueError, match="blend must be one of"):
        stitch(r1, r2, seam=SeamSpec(blend="smooth"))
    with pytest.raises(ValueError, match=r"error must be shaped \(8, 6\)"):
        stitch(r1, r2, error=np.zeros((6, 8)))
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        stitch(r1, r2, cancel=token)


# ----------------------------------------------------------------------------- template wrap
def make_tile(src, y, x, a, b, wt, *, blend, cyclic=False):
    """ALGORITHMS §1.7: stitch R_R over R_L (horizontal), then R_B over R_T (vertical)."""
    rows = src[y : y + b + wt]
    h = stitch(
        rows[:, x + a : x + a + wt],
        rows[:, x : x + wt],
        orientation="right",
        seam=SeamSpec(blend="adaptive"),
    )
    img = rows[:, x : x + a].copy()
    img[:, :wt] = h.image
    v = stitch(
        img[b : b + wt], img[:wt], orientation="bottom", seam=SeamSpec(blend=blend), cyclic=cyclic
    )
    img[:wt] = v.image
    return img[:b], v


@pytest.mark.parametrize("blend", ["none", "adaptive"])
def test_cyclic_template_tile_has_no_seam_across_the_wrap(blend):
    src = load_image(sample_path("cobblestones")).pixels
    wt = 16
    cyc_ratios, plain_ratios = [], []
    for y, x in [(30, 40), (100, 150), (200, 60)]:
        tile, v = make_tile(src, y, x, 120, 110, wt, cyclic=True, blend=blend)
        # the cyclic seam closes on itself: first and last columns are neighbours
        cols = v.seam.mask.sum(axis=1) - 1
        assert abs(int(cols[0]) - int(cols[-1])) <= 1
        quilt = np.tile(tile, (2, 2, 1))
        # whole tile: the joints look like the texture's own neighbour differences
        assert wrap_border_ratio(tile) < 1.6
        assert wrap_border_ratio(quilt[:, 60:180]) < 1.6
        cyc_ratios.append(wrap_border_ratio(tile[:wt], direction="horizontal"))
        plain, _ = make_tile(src, y, x, 120, 110, wt, blend=blend)
        plain_ratios.append(wrap_border_ratio(plain[:wt], direction="horizontal"))
    # in the stitched rows, the left/right wrap is as smooth as the texture; without the
    # cyclic seam the two ends of the cut disagree there and leave a visible step
    assert max(cyc_ratios) < 1.5
    assert np.mean(plain_ratios) > 1.5 * np.mean(cyc_ratios)


# ----------------------------------------------------------------------------- L-shaped cut
def monotone_paths(start, length, limit):
    """All one-per-step 8-connected index sequences of ``length`` from ``start`` in [0, limit)."""
    for steps in itertools.product((-1, 0, 1), repeat=length - 1):
        seq = np.concatenate([[start], start + np.cumsum(steps)]).astype(int)
        if ((seq >= 0) & (seq < limit)).all():
            yield seq


def brute_force_l(e, ovl, ovt):
    bh, bw = e.shape
    best = np.inf
    for qr, qc in itertools.product(range(ovt), range(ovl)):
        v = min(e[np.arange(qr, bh), c].sum() for c in monotone_paths(qc, bh - qr, ovl))
        h = min(e[r, np.arange(qc, bw)].sum() for r in monotone_paths(qr, bw - qc, ovt))
        best = min(best, v + h - e[qr, qc])
    return best


def in_l(shape, ovl, ovt):
    dom = np.zeros(shape, bool)
    dom[:, :ovl] = True
    dom[:ovt] = True
    return dom


def assert_two_regions(cut, ovl, ovt):
    mask = cut.mask
    assert not (mask & ~in_l(mask.shape, ovl, ovt)).any()  # old content only inside the L
    assert ndimage.label(mask)[1] == 1  # one 4-connected old region
    assert ndimage.label(~mask)[1] == 1  # one 4-connected new region
    assert mask[cut.path[:, 0], cut.path[:, 1]].all()
    on = np.zeros(mask.shape, bool)
    on[cut.path[:, 0], cut.path[:, 1]] = True
    assert ndimage.label(on, structure=np.ones((3, 3)))[1] == 1  # an 8-connected cut


def test_l_cut_dp_equals_brute_force_on_tiny_blocks():
    rng = np.random.default_rng(8)
    for _ in range(25):
        bh, bw = rng.integers(4, 7, 2)
        ovl, ovt = rng.integers(1, 4, 2)
        e = rng.random((bh, bw))
        cut = l_cut(e, overlap_left=int(ovl), overlap_top=int(ovt))
        assert cut.criterion == pytest.approx(brute_force_l(e, ovl, ovt))
        assert cut.criterion == pytest.approx(e[cut.path[:, 0], cut.path[:, 1]].sum())
        assert cut.peak == pytest.approx(e[cut.path[:, 0], cut.path[:, 1]].max())
        qr, qc = cut.meeting
        assert qr < ovt and qc < ovl
        assert_two_regions(cut, ovl, ovt)
        # the path runs from the left arm's bottom row to the top arm's right column
        assert cut.path[0, 0] == bh - 1 and cut.path[-1, 1] == bw - 1


@pytest.mark.parametrize(
    "method", ["dp", "dijkstra", "minimax", "oscillating", "oscillating-optimal", "resistance"]
)
def test_l_cut_regions_for_every_method(method):
    rng = np.random.default_rng(9)
    for _ in range(12):
        bh, bw = rng.integers(8, 30, 2)
        ovl, ovt = (int(v) for v in rng.integers(2, 7, 2))
        e = ndimage.uniform_filter(rng.random((bh, bw)), 3) ** 2
        cut = l_cut(e, overlap_left=ovl, overlap_top=ovt, seam=SeamSpec(method))
        assert_two_regions(cut, ovl, ovt)
        assert cut.path[0, 0] == bh - 1 and cut.path[0, 1] < ovl
        assert cut.path[-1, 1] == bw - 1 and cut.path[-1, 0] < ovt
        assert cut.criterion == pytest.approx(e[cut.path[:, 0], cut.path[:, 1]].sum())


def test_l_cut_graph_methods_use_the_l_domain():
    e = np.ones((12, 12))
    e[:, 1] = 0.01  # a cheap vertical corridor ...
    e[1, :] = 0.01  # ... and a cheap horizontal one, joined in the corner
    for method in ("dijkstra", "minimax"):
        cut = l_cut(e, overlap_left=4, overlap_top=4, seam=SeamSpec(method))
        assert in_l(e.shape, 4, 4)[cut.path[:, 0], cut.path[:, 1]].all()
        assert cut.peak == pytest.approx(0.01)
    with pytest.raises(TypeError, match="unexpected option"):
        l_cut(e, overlap_left=4, overlap_top=4, seam=SeamSpec("dijkstra", {"o_max": 3}))


def test_l_cut_single_strips():
    rng = np.random.default_rng(10)
    e = rng.random((10, 12))
    v = l_cut(e, overlap_left=4, overlap_top=0)
    direct = find_seam(e[:, :4])
    assert v.criterion == pytest.approx(direct.criterion)
    np.testing.assert_array_equal(v.mask[:, :4], direct.mask)
    assert not v.mask[:, 4:].any() and v.meeting is None
    h = l_cut(e, overlap_left=0, overlap_top=5)
    direct = find_seam(e[:5].T)
    assert h.criterion == pytest.approx(direct.criterion)
    np.testing.assert_array_equal(h.mask[:5], direct.mask.T)
    assert not h.mask[5:].any()
    for method in ("oscillating", "resistance", "minimax"):
        cut = l_cut(e, overlap_left=0, overlap_top=5, seam=SeamSpec(method))
        assert ndimage.label(cut.mask)[1] == 1 and ndimage.label(~cut.mask)[1] == 1


def test_l_cut_apply_and_bad_input():
    rng = np.random.default_rng(11)
    e = rng.random((9, 9))
    cut = l_cut(e, overlap_left=3, overlap_top=3)
    old, new = pair(9, 9, seed=12)
    out = cut.apply(old, new)
    np.testing.assert_array_equal(out[cut.mask], old[cut.mask])
    np.testing.assert_array_equal(out[~cut.mask], new[~cut.mask])
    with pytest.raises(ValueError, match="must not both be 0"):
        l_cut(e, overlap_left=0, overlap_top=0)
    with pytest.raises(ValueError, match="overlap_left must be <= the block width 9"):
        l_cut(e, overlap_left=10, overlap_top=2)
    with pytest.raises(ValueError, match="overlap_top must be >= 0"):
        l_cut(e, overlap_left=2, overlap_top=-1)
    with pytest.raises(ValueError, match="method must be one of"):
        l_cut(e, overlap_left=2, overlap_top=2, seam=SeamSpec("magic"))
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        l_cut(e, overlap_left=2, overlap_top=2, cancel=token)


# ----------------------------------------------------------------------------- patching
def loop_is_closed_8_connected(loop, shape):
    """One 8-connected set that separates the window's centre from its border."""
    on = np.zeros(shape, bool)
    on[loop[:, 0], loop[:, 1]] = True
    if ndimage.label(on, structure=np.ones((3, 3)))[1] != 1:
        return False
    labels, _ = ndimage.label(~on)  # 4-connected regions off the loop
    border = np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])
    centre = labels[shape[0] // 2, shape[1] // 2]
    return bool(centre > 0 and centre not in border)


@pytest.mark.parametrize("method", ["dp", "oscillating", "dijkstra"])
@pytest.mark.parametrize("blend", ["none", "feather", "adaptive"])
def test_patch_keeps_margin_and_closes_its_loop(method, blend):
    src = load_image(sample_path("cobblestones")).pixels
    target = src[:90, :100]
    res = patch(
        target,
        src,
        target_origin=(10, 12),
        source_origin=(200, 150),
        size=(64, 72),
        ring=12,
        margin=2,
        seam=SeamSpec(method, blend=blend),
    )
    cut = res.cut
    out = res.image
    # outside the window and on its outer margin: the target exactly
    keep = np.ones(target.shape[:2], bool)
    keep[12:72, 14:82] = False
    np.testing.assert_array_equal(out[keep], target[keep])
    assert (cut.alpha[:2] == 0).all() and (cut.alpha[:, -2:] == 0).all()
    # inside the loop (away from the blend) the source
    q = src[200:264, 150:222]
    inner = np.zeros(cut.mask.shape, bool)
    inner[14:-14, 14:-14] = True
    np.testing.assert_array_equal(out[10:74, 12:84][inner], q[inner])
    assert loop_is_closed_8_connected(cut.loop, cut.mask.shape)
    assert cut.mask[cut.loop[:, 0], cut.loop[:, 1]].all()
    assert ndimage.label(~cut.mask)[1] == 1  # one outside region, touching the border
    # corners pinned in their squares, on ring offsets >= margin
    (tlr, tlc), (trr, trc), (brr, brc), (blr, blc) = cut.corners
    assert 2 <= tlr < 12 and 2 <= tlc < 12 and 2 <= trr < 12 and 72 - 12 <= trc < 70
    assert 64 - 12 <= brr < 62 and 64 - 12 <= blr < 62 and 2 <= blc < 12
    # the loop runs in the ring only
    ring = np.ones(cut.mask.shape, bool)
    ring[12:-12, 12:-12] = False
    assert ring[cut.loop[:, 0], cut.loop[:, 1]].all()
    d = cut.error
    assert cut.criterion == pytest.approx(float(d[cut.loop[:, 0], cut.loop[:, 1]].sum()), 1e-5)


def test_patch_cut_follows_low_error_and_applies_to_other_maps():
    rng = np.random.default_rng(13)
    q, u = pair(40, 40, seed=14)
    err = np.ones((40, 40), np.float32)
    err[6, 5:35] = err[33, 5:35] = err[6:34, 5] = err[6:34, 34] = 0  # a free rectangle
    cut = patch_cut(q, u, ring=9, margin=2, error=err, seam=SeamSpec())
    assert cut.criterion == 0
    assert cut.mask[7:33, 6:34].all()
    assert not (
        cut.mask[:6].any() or cut.mask[34:].any() or cut.mask[:, :5].any() or cut.mask[:, 35:].any()
    )
    m1, m2 = rng.random((40, 40)), rng.random((40, 40))
    np.testing.assert_array_equal(cut.apply(m1, m2), np.where(cut.mask, m1, m2).astype(np.float32))


def test_patch_ramp_on_border_strips_equals_the_whole_window_ramp(monkeypatch):
    """The blend ramp is computed on four border strips (the loop lies in the ring): the same
    alpha, bit for bit, as the distance transforms of the whole window."""
    import engine.stitch as st

    rng = np.random.default_rng(21)
    strips = []
    ring_ramp = st._ring_ramp

    def spy(mask, barrier, b_at, ring):
        whole = st._loop_ramp(mask, barrier, b_at)
        fast = ring_ramp(mask, barrier, b_at, ring)
        d = ring + 2 * (st.math.ceil(float(b_at.max())) + 3)
        strips.append(4 * d * max(mask.shape) < mask.size)  # the strips path was taken
        np.testing.assert_array_equal(fast, whole)
        return fast

    monkeypatch.setattr(st, "_ring_ramp", spy)
    for k in range(6):
        ph, pw = (int(v) for v in rng.integers(150, 260, 2))
        q = ndimage.gaussian_filter(rng.random((ph, pw, 3)), (1.5, 1.5, 0))
        u = ndimage.gaussian_filter(rng.random((ph, pw, 3)), (1.5, 1.5, 0))
        method = ("dp", "dijkstra", "oscillating")[k % 3]
        for blend in ("adaptive", "feather"):
            patch_cut(
                q, u, ring=int(rng.integers(4, 14)), seam=SeamSpec(method, blend=blend, width=9)
            )
    assert len(strips) == 12 and all(strips)


def test_patch_bad_input():
    q, u = pair(40, 40)
    with pytest.raises(ValueError, match="margin must be smaller than ring"):
        patch_cut(q, u, ring=3, margin=3)
    with pytest.raises(ValueError, match=r"at least 2 \* ring = 50"):
        patch_cut(q, u, ring=25)
    with pytest.raises(ValueError, match="q and u must have the same shape"):
        patch_cut(q, u[:30], ring=5)
    with pytest.raises(ValueError, match="source_origin .* outside the 40x40 source"):
        patch(u, q, source_origin=(10, 0), size=(40, 40), ring=5)
