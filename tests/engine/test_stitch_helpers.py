"""engine.stitch helpers: the compiled old side of an L-cut against the scipy.ndimage
construction it replaces, and the public point mapper."""

import numpy as np
import pytest
from scipy import ndimage

from engine.stitch import ORIENTATIONS, _old_side_of_barrier, l_cut, map_points, to_canonical


def old_side_ndimage(barrier, seed_left, seed_top):
    """Label ``~barrier`` (4-connected), keep the labels on the seed edges, add the barrier,
    fill the holes: the definition of the old side."""
    labels, _ = ndimage.label(~barrier)
    seeds = []
    if seed_left:
        seeds.append(labels[:, 0])
    if seed_top:
        seeds.append(labels[0, :])
    ids = np.unique(np.concatenate(seeds))
    return ndimage.binary_fill_holes(np.isin(labels, ids[ids > 0]) | barrier)


def random_walk(rng, shape, steps):
    """An 8-connected winding path (revisits allowed) from a random pixel."""
    h, w = shape
    r, c = int(rng.integers(h)), int(rng.integers(w))
    pts = [(r, c)]
    for _ in range(steps):
        r = int(np.clip(r + rng.integers(-1, 2), 0, h - 1))
        c = int(np.clip(c + rng.integers(-1, 2), 0, w - 1))
        pts.append((r, c))
    return np.array(pts)


@pytest.mark.parametrize("seeds", [(True, True), (True, False), (False, True)])
def test_compiled_old_side_equals_label_and_fill_holes(seeds):
    rng = np.random.default_rng(20)
    for k in range(300):
        shape = tuple(int(v) for v in rng.integers(1, 24, 2))
        if k % 2:  # scattered barrier pixels of any density
            barrier = rng.random(shape) < rng.random()
        else:  # winding paths, pockets and crossings included
            barrier = np.zeros(shape, bool)
            for _ in range(int(rng.integers(1, 4))):
                p = random_walk(rng, shape, int(rng.integers(1, 80)))
                barrier[p[:, 0], p[:, 1]] = True
        np.testing.assert_array_equal(
            _old_side_of_barrier(barrier, *seeds), old_side_ndimage(barrier, *seeds)
        )


def test_dp_l_cut_mask_is_the_old_side_of_its_path():
    rng = np.random.default_rng(21)
    for _ in range(200):
        bh, bw = (int(v) for v in rng.integers(2, 20, 2))
        ovl, ovt = int(rng.integers(1, bw + 1)), int(rng.integers(1, bh + 1))
        e = rng.random((bh, bw)) ** 4  # sharp valleys: arms that cross and enclose pockets
        cut = l_cut(e, overlap_left=ovl, overlap_top=ovt)
        barrier = np.zeros((bh, bw), bool)
        barrier[cut.path[:, 0], cut.path[:, 1]] = True
        assert len(cut.path) == barrier.sum()  # each pixel once
        np.testing.assert_array_equal(cut.mask, old_side_ndimage(barrier, True, True))


@pytest.mark.parametrize("orientation", ORIENTATIONS)
def test_map_points_follow_the_canonical_view(orientation):
    a = np.arange(5 * 7).reshape(5, 7)
    canon = to_canonical(a, orientation)
    pts = np.argwhere(np.ones(a.shape, bool))
    c = map_points(pts, orientation, a.shape)
    np.testing.assert_array_equal(canon[c[:, 0], c[:, 1]], a[pts[:, 0], pts[:, 1]])
    np.testing.assert_array_equal(map_points(c, orientation, a.shape, inverse=True), pts)
    assert c.dtype == np.intp
