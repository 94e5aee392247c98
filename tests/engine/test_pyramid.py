"""The coarse-to-fine search: exact re-ranking against brute force, planted matches, levels."""

import numpy as np
import pytest

from engine.matching import ssd_at
from engine.pyramid import PyramidSearch, pyramid_levels, quilt_keeps, weighted_ssd_at
from tests.engine.helpers import smooth_texture


def brute_weighted(sample, anchors, weights, target):
    out = []
    h, w = target.shape[:2]
    for y, x in anchors:
        d = sample[y : y + h, x : x + w].astype(np.float64) - target
        out.append(float((weights * d * d).sum()))
    return np.array(out)


def l_mask(h, w, ov):
    m = np.zeros((h, w), bool)
    m[:ov] = True
    m[:, :ov] = True
    return m


def test_weighted_ssd_equals_brute_force_and_ssd_at_for_masks():
    rng = np.random.default_rng(0)
    s = rng.random((40, 50, 3), dtype=np.float32)
    t = rng.random((12, 9, 3), dtype=np.float32)
    wts = rng.random((12, 9, 3)).astype(np.float32) * (rng.random((12, 9, 1)) < 0.6)
    a = np.column_stack([rng.integers(0, 29, 20), rng.integers(0, 42, 20)])
    np.testing.assert_allclose(
        weighted_ssd_at(s, a, wts, t), brute_weighted(s, a, wts, t), rtol=1e-6
    )
    m = l_mask(12, 9, 3)
    mw = np.repeat(m[:, :, None], 3, axis=2).astype(np.float32)
    np.testing.assert_array_equal(weighted_ssd_at(s, a, mw, t), ssd_at(s, a, t, m))


@pytest.mark.parametrize("excluded", [False, True])
def test_query_reranks_exactly_and_returns_only_allowed_distinct_anchors(excluded):
    s = smooth_texture((300, 280), seed=3)
    pyr = PyramidSearch(s, levels=2, keep=8, coarse_keep=16)
    rng = np.random.default_rng(1)
    h, w = 32, 30
    valid = None
    if excluded:
        valid = rng.random((300 - h + 1, 280 - w + 1)) < 0.7
    target = rng.random((h, w, 3), dtype=np.float32)
    m = l_mask(h, w, 8)
    anchors, errors = pyr.query(target, m[:, :, None], valid=valid, seeds=[(5, 7), (-3, 400)])
    assert len(anchors) >= 8
    assert len({tuple(a) for a in anchors}) == len(anchors)
    assert np.all(np.diff(errors) >= 0)
    assert (anchors >= 0).all() and (anchors[:, 0] <= 300 - h).all()
    assert (anchors[:, 1] <= 280 - w).all()
    if valid is not None:
        assert valid[anchors[:, 0], anchors[:, 1]].all()
    np.testing.assert_allclose(errors, ssd_at(s, anchors, target, m), rtol=1e-12)
    mw = np.repeat(m[:, :, None], 3, axis=2)
    np.testing.assert_allclose(errors, brute_weighted(s, anchors, mw, target), rtol=1e-6)
    # the seed inside the sample is considered with its neighbours, the one outside is not
    assert {(5, 7), (4, 6), (6, 8)} <= {tuple(a) for a in anchors}


def test_query_finds_a_planted_window():
    """A target copied from the sample (plus a little noise) is found at its place, as the
    exhaustive search would (brute force over every anchor)."""
    s = smooth_texture((320, 320), seed=5, sigma=3.0)
    pyr = PyramidSearch(s, levels=2)
    rng = np.random.default_rng(2)
    h = w = 40
    m = l_mask(h, w, 8)
    for _ in range(5):
        y, x = (int(v) for v in rng.integers(0, 320 - h, 2))
        target = s[y : y + h, x : x + w] + rng.normal(0, 0.01, (h, w, 3)).astype(np.float32)
        anchors, errors = pyr.query(target, m[:, :, None])
        assert tuple(anchors[0]) == (y, x)
        ys, xs = np.mgrid[0 : 320 - h + 1, 0 : 320 - w + 1]
        every = np.column_stack([ys.ravel(), xs.ravel()])
        assert errors[0] == pytest.approx(ssd_at(s, every, target, m).min(), rel=1e-9)


def test_levels_follow_area_overlap_and_block():
    assert pyramid_levels((256, 256), (32, 32), 6) == 0  # small enough: exact
    assert pyramid_levels((1024, 1024), (96, 96), 16) == 2  # area: 256² after 2
    assert pyramid_levels((4096, 4096), (96, 96), 16) == 3  # the overlap keeps 2 px
    assert pyramid_levels((1024, 1024), (96, 96), 4) == 1  # the overlap keeps 2 px
    # a thin overlap on a huge sample: reduced to 256² anyway, the block keeps 2 px
    assert pyramid_levels((4096, 4096), (96, 96), 4) == 4
    assert pyramid_levels((4096, 4096), (12, 12), 8) == 2


class _Built(Exception):
    pass


@pytest.mark.parametrize(("side", "levels"), [(1100, 3), (600, 2)])
def test_quilting_keeps_more_places_in_deep_pyramids(monkeypatch, side, levels):
    """A 3-level pyramid (4096² with a 16-pixel overlap in issue 15) keeps 512 top-level places
    and 32 candidates per level (the seed-0 gap to the exact search closed); shallower ones keep
    the former 128 and 24."""
    import engine.quilting.core as core
    from engine.quilting import quilt

    built = {}

    def record(sample, **kw):
        built.update(kw)
        raise _Built

    monkeypatch.setattr(core, "PyramidSearch", record)
    s = smooth_texture((side, side))
    with pytest.raises(_Built):
        quilt(s, (200, 200), block=96, overlap=16, rng=0, mode="fast", threads=1)
    assert built["levels"] == levels
    assert (built["keep"], built["coarse_keep"]) == quilt_keeps(levels)
    assert quilt_keeps(levels) == ((32, 512) if levels >= 3 else (24, 128))
