"""The small-job numpy paths (engine.stitch_numpy, select_within_tolerance's numpy branch) give
exactly what the numba kernels give: the same costs and steps, the same cut, old side and
meeting point, the same chosen index, ties included (maps of small integers tie often)."""

from functools import partial

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from engine import _jit, matching, stitch, stitch_numpy
from engine.seams import SeamSpec

FAST = settings(max_examples=60)

#: error maps with many ties (small integers) or none (random floats)
values = st.one_of(st.integers(0, 3).map(float), st.floats(0, 1, width=32))


def maps(min_side=1, max_side=14):
    shape = st.tuples(st.integers(min_side, max_side), st.integers(min_side, max_side))
    return shape.flatmap(lambda s: arrays(np.float64, s, elements=values))


def both_paths(monkeypatch, run):
    """``run()`` as a fresh small job does (numba not loaded: the numpy paths) and with numba."""
    out = []
    for loaded in (False, True):
        monkeypatch.setattr(_jit, "loaded", lambda loaded=loaded: loaded)
        out.append(run())
    return out


@FAST
@given(maps())
def test_dp_to_bottom_is_the_kernels(e):
    cost, step = stitch_numpy.dp_to_bottom(e)
    k_cost, k_step = stitch._dp_to_bottom(np.ascontiguousarray(e))
    assert np.array_equal(cost, k_cost) and np.array_equal(step, k_step)
    c0 = int(np.argmin(cost[0]))
    assert np.array_equal(stitch_numpy.trace_down(step, 0, c0), stitch._trace_down(k_step, 0, c0))


@FAST
@given(maps(2, 16), st.data())
def test_the_dp_l_cut_is_the_kernels(e, data):
    bh, bw = e.shape
    ovl = data.draw(st.integers(1, bw))
    ovt = data.draw(st.integers(1, bh))
    path, mask, qr, qc = stitch_numpy.dp_l_cut(e, ovl, ovt)
    k_path, k_mask, k_qr, k_qc = stitch._dp_l_cut(e, ovl, ovt)
    assert (qr, qc) == (k_qr, k_qc)
    assert path.dtype == k_path.dtype and np.array_equal(path, k_path)
    assert np.array_equal(mask, k_mask)


def test_a_stack_of_l_cuts_is_each_maps_own():
    rng = np.random.default_rng(4)
    for bh, bw, ovl, ovt in ((32, 32, 6, 6), (32, 18, 6, 6), (12, 30, 3, 5), (9, 9, 9, 1)):
        e = rng.integers(0, 3, (5, bh, bw)) * 1.0
        e[1:3] = rng.random((2, bh, bw))
        for got, m in zip(stitch_numpy.dp_l_cuts(e, ovl, ovt), e, strict=True):
            want = stitch._dp_l_cut(m, ovl, ovt)
            assert all(np.array_equal(g, w) for g, w in zip(got, want, strict=True))


@FAST
@given(st.tuples(st.integers(1, 12), st.integers(1, 12)), st.data())
def test_the_old_side_of_any_barrier_is_the_kernels(shape, data):
    barrier = data.draw(arrays(bool, shape))
    for left, top in ((True, True), (True, False), (False, True), (False, False)):
        got = stitch_numpy.old_side_of_barrier(barrier, left, top)
        assert np.array_equal(got, stitch._old_side_of_barrier(barrier, left, top))


def test_random_l_cuts_of_quilting_size_agree(monkeypatch):
    """l_cut itself, both paths, on the sizes quilting uses (cropped edge blocks too)."""
    rng = np.random.default_rng(5)
    for _ in range(200):
        bh, bw = rng.integers(8, 40, size=2)
        e = rng.random((bh, bw)) if rng.random() < 0.5 else rng.integers(0, 3, (bh, bw)) * 1.0
        ovl, ovt = int(rng.integers(0, bw // 2 + 1)), int(rng.integers(0, bh // 2 + 1))
        if ovl == ovt == 0:
            ovl = 1
        cut = partial(stitch.l_cut, e, overlap_left=ovl, overlap_top=ovt)
        small, big = both_paths(monkeypatch, cut)
        assert np.array_equal(small.path, big.path) and np.array_equal(small.mask, big.mask)
        assert (small.criterion, small.peak, small.meeting) == (
            big.criterion,
            big.peak,
            big.meeting,
        )


def test_other_seam_methods_share_the_numpy_old_side(monkeypatch):
    e = np.random.default_rng(1).random((20, 24))
    spec = SeamSpec("dijkstra")
    small, big = both_paths(
        monkeypatch, lambda: stitch.l_cut(e, overlap_left=5, overlap_top=4, seam=spec)
    )
    assert np.array_equal(small.mask, big.mask) and np.array_equal(small.path, big.path)


selection_maps = arrays(
    st.sampled_from([np.float32, np.float64]),
    st.integers(1, 200),
    elements=st.one_of(
        st.integers(0, 4).map(float), st.floats(0, 10), st.just(np.inf), st.just(np.nan)
    ),
)


@FAST
@given(selection_maps, st.sampled_from([0.0, 0.1, 0.5]), st.sampled_from([0.0, 1.0, 3.0]))
def test_the_numpy_selection_is_the_kernels(errors, tolerance, zero_level):
    def select():
        try:
            return matching.select_within_tolerance(
                errors, tolerance=tolerance, zero_level=zero_level, rng=np.random.default_rng(3)
            )
        except ValueError as exc:  # every position excluded: both refuse
            return str(exc)

    with pytest.MonkeyPatch.context() as mp:
        small, big = both_paths(mp, select)
    assert small == big


def test_a_small_quilt_is_the_same_with_and_without_numba(monkeypatch):
    """Without numba the blocks of a batch are cut together (Quilter.precut); with it, one by
    one by the kernels: the same image and records."""
    from engine.quilting import quilt

    s = np.random.default_rng(2).random((48, 48, 3), dtype=np.float32)
    run = partial(quilt, s, (90, 90), block=16, overlap=4, rng=7, threads=1)
    runs = both_paths(monkeypatch, run)
    assert np.array_equal(runs[0].image, runs[1].image)
    for a, b in zip(runs[0].blocks, runs[1].blocks, strict=True):
        assert np.array_equal(a.path, b.path) and a.source == b.source
        same = [a.criterion, a.peak, a.match_error, a.candidates]
        assert np.array_equal(same, [b.criterion, b.peak, b.match_error, b.candidates], True)
        for x, y in ((a.keep_old, b.keep_old), (a.error, b.error)):
            assert (x is None and y is None) or np.array_equal(x, y)
