"""Quilting's compiled per-block steps give exactly what the general numpy path gives."""

from __future__ import annotations

import numpy as np
import pytest

from engine import _jit
from engine.quilting import quilt
from engine.quilting.block_rng import BlockRng
from engine.seams import SeamSpec


@pytest.mark.parametrize("seed", [0, 1, 2**32 - 1, 2**32, 987654321987654321, 2**63 - 1])
def test_block_rng_draws_what_default_rng_draws(seed):
    for index in (0, 1, 7, 399, 2**32 - 1):
        ours, numpy_rng = BlockRng(seed, index), np.random.default_rng([seed, index])
        for n in (1, 2, 3, 97 * 97, 2**31 + 5, 2**32, 17, 1):
            assert ours.integers(n) == numpy_rng.integers(n)
        # any other use goes on from the same state
        assert ours.integers(2**40) == numpy_rng.integers(2**40)
        picks = ours.choice(50, 4, replace=False), numpy_rng.choice(50, 4, replace=False)
        assert np.array_equal(*picks)
        assert ours.integers(9) == numpy_rng.integers(9)


def _records(result):
    out = []
    for b in result.blocks:
        out.append(
            (
                b.position,
                b.source,
                b.arms,
                b.criterion,
                b.peak,
                b.match_error,
                b.best_error,
                b.candidates,
                None if b.error is None else b.error.tobytes(),
                None if b.keep_old is None else b.keep_old.tobytes(),
                np.asarray(b.path).tobytes(),
            )
        )
    return out


@pytest.mark.parametrize(
    "options",
    [
        dict(),
        dict(tileable=True),
        dict(adaptive_threshold=0.01),
        dict(seam=SeamSpec("dp", metric="euclid")),
        dict(alpha=True),
    ],
    ids=["plain", "tileable", "adaptive", "euclid", "alpha"],
)
def test_the_compiled_steps_give_the_numpy_paths_blocks(monkeypatch, options):
    rng = np.random.default_rng(3)
    channels = 4 if options.pop("alpha", False) else 3
    sample = rng.random((56, 56, channels), dtype=np.float32)
    sample[20:40, 10:30] = sample[0:20, 30:50]  # exact repeats: zero errors and uncut overlaps
    runs = []
    for loaded in (False, True):
        monkeypatch.setattr(_jit, "loaded", lambda loaded=loaded: loaded)
        runs.append(
            quilt(sample, (96, 96), block=20, overlap=5, rng=11, mode="exact", threads=1, **options)
        )
    assert np.array_equal(runs[0].image, runs[1].image)
    assert _records(runs[0]) == _records(runs[1])


def test_the_l_cuts_old_side_is_the_whole_block_fills():
    from engine import stitch

    rng = np.random.default_rng(5)
    for case in range(600):
        bh, bw = (int(v) for v in rng.integers(2, 30, size=2))
        ovl, ovt = int(rng.integers(1, bw + 1)), int(rng.integers(1, bh + 1))
        e = rng.random((bh, bw))
        if case % 3 == 1:
            e = np.round(e * 3)  # ties
        elif case % 3 == 2:
            e = (e < 0.3).astype(float)
        path, mask, _, _ = stitch.dp_l_cut_kernel(e, ovl, ovt)
        barrier = np.zeros((bh, bw), bool)
        barrier[path[:, 0], path[:, 1]] = True
        assert np.array_equal(mask, stitch._old_side_of_barrier(barrier, True, True)), case


def test_records_are_identical_on_one_two_and_three_threads():
    """A sample large enough for the pool: one thread places one block per task, more threads
    three (scheduler.BATCH); each block's search is a query of its own (Quilter.alone), so every
    record is the same to the last bit (best errors included: they once differed on two
    threads, whose sample spectra ducc0 computed on two threads)."""
    _jit.load()
    sample = np.random.default_rng(6).random((210, 200, 3), dtype=np.float32)
    runs = [
        quilt(sample, (150, 170), block=28, overlap=6, rng=3, mode="exact", threads=t)
        for t in (1, 2, 3)
    ]
    for run in runs[1:]:
        assert np.array_equal(run.image, runs[0].image)
        assert _records(run) == _records(runs[0])


def test_the_paths_sum_adds_as_numpy_does():
    """The kernel's sum of the error along a cut has the bits of numpy's pairwise ``sum`` (the
    records' criterion is compared bit for bit), for every length it takes."""
    from engine.quilting import kernels

    _jit.load()
    rng = np.random.default_rng(5)
    for n in list(range(0, kernels.PAIRWISE_BLOCK + 1)) * 3:
        values = (rng.random(n) * 10.0 ** rng.integers(-4, 6, n)).astype(np.float32)
        values = values.astype(np.float64)
        assert kernels._pairwise_sum(values) == values.sum()
        if n:
            assert kernels._nan_max(values) == values.max()
    assert np.isnan(kernels._nan_max(np.array([1.0, np.nan, 3.0])))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_block_rngs_compiled_select_chooses_and_draws_as_numpy_does(dtype):
    """BlockRng.select (one compiled call) against select_within_tolerance drawing from the
    numpy generator of the same seed: the same pick, least error and count, and the same
    next draw, on maps with ties, forbidden entries and calm zeros."""
    from engine.matching import select_within_tolerance

    _jit.load()
    gen = np.random.default_rng(5)
    for trial in range(300):
        errors = gen.integers(0, 6, 40).astype(dtype) * dtype(0.25)  # many ties
        errors[gen.random(40) < 0.3] = np.inf
        if trial % 50 == 0:
            errors[:] = np.inf
            errors[gen.integers(40)] = 0.0
        tol, zero = float(gen.choice([0.0, 0.1, 0.5])), float(gen.choice([0.0, 0.3]))
        ours = BlockRng(trial, 7)
        theirs = np.random.default_rng([trial, 7])
        got = ours.select(errors, tolerance=tol, zero_level=zero)
        want = select_within_tolerance(errors, tolerance=tol, zero_level=zero, rng=theirs)
        assert (got[0], float(got[1]), got[2]) == (want[0], float(want[1]), want[2])
        assert ours.integers(1000) == theirs.integers(1000)


def test_query_inputs_give_the_stacked_products_and_einsums_bits():
    """The exact search's inputs in one compiled pass (weights, weighted content, its sum of
    squares) equal what SampleSpectrum.ssd makes from the stacked blocks with numpy, bit for
    bit: content of either sign and signed zeros, blocks of one to eight."""
    from engine.quilting.kernels import SQUARE_SUM_MAX, query_inputs, square_sum_is_einsums

    _jit.load()
    same_sums = square_sum_is_einsums()  # else quilting keeps the einsum (numpy adds otherwise)
    rng = np.random.default_rng(5)
    canvas = rng.standard_normal((90, 110, 3)).astype(np.float32)
    canvas[rng.random((90, 110, 3)) < 0.1] = -0.0
    filled = rng.random((90, 110)) < 0.6
    for n, (h, w) in ((1, (32, 32)), (3, (48, 48)), (8, (20, 37))):
        assert h * w * 3 <= SQUARE_SUM_MAX
        ys, xs = rng.integers(0, 90 - h, n), rng.integers(0, 110 - w, n)
        wts, k, const = query_inputs(canvas, filled, ys, xs, h, w, 3)
        t = np.stack([canvas[y : y + h, x : x + w] for y, x in zip(ys, xs, strict=True)])
        m = np.stack([filled[y : y + h, x : x + w] for y, x in zip(ys, xs, strict=True)])
        want_w = np.asarray(m, np.float32)[:, None]
        want_k = want_w * t.transpose(0, 3, 1, 2)
        want_c = np.einsum("nchw,nchw->n", want_k, t.transpose(0, 3, 1, 2), dtype=np.float64)
        assert wts.tobytes() == want_w.tobytes()
        got_k = k.transpose(0, 3, 1, 2)
        assert got_k.strides == want_k.strides and got_k.tobytes() == want_k.tobytes()
        if same_sums:
            assert const.tobytes() == want_c.tobytes()
        else:
            np.testing.assert_allclose(const, want_c, rtol=1e-12)


def test_exact_search_without_the_compiled_square_sum_keeps_its_output(monkeypatch):
    """Where square_sum does not add as this numpy's einsum does (another build), quilting takes
    the einsum path: it must give the same records and image (on this machine both sums agree,
    so the two paths must agree bit for bit)."""
    from engine.quilting import kernels

    _jit.load()
    rng = np.random.default_rng(3)
    sample = rng.random((64, 64, 3), dtype=np.float32)
    kw = dict(block=20, overlap=5, rng=1, mode="exact")
    fast = quilt(sample, (100, 100), **kw)
    monkeypatch.setattr(kernels, "_SAME_SUMS", [False])
    slow = quilt(sample, (100, 100), **kw)
    assert kernels.square_sum_is_einsums() is False
    assert slow.image.tobytes() == fast.image.tobytes()

    def key(b):
        return b.source, b.match_error, b.best_error, b.candidates

    assert [key(b) for b in slow.blocks] == [key(b) for b in fast.blocks]
