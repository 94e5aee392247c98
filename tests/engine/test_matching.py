import numpy as np
import pytest

from engine import spectral
from engine.matching import (
    PCAMatcher,
    SampleSpectrum,
    masked_ssd,
    select_within_tolerance,
    ssd_at,
)


def brute_ssd(sample, target, weights):
    s = np.asarray(sample, np.float64)
    t = np.asarray(target, np.float64)
    if s.ndim == 2:
        s, t = s[:, :, None], t[:, :, None]
    bh, bw = t.shape[:2]
    out = np.empty((s.shape[0] - bh + 1, s.shape[1] - bw + 1))
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            out[y, x] = (weights[:, :, None] * (s[y : y + bh, x : x + bw] - t) ** 2).sum()
    return out


def l_mask(bh, bw, top, left):
    m = np.zeros((bh, bw), bool)
    m[:top] = True
    m[:, :left] = True
    return m


@pytest.mark.parametrize(
    "shape, block, channels",
    [((23, 29), (7, 9), 3), ((31, 17), (5, 5), 1), ((16, 16), (16, 16), 3), ((19, 40), (8, 3), 4)],
)
def test_exact_masked_ssd_equals_brute_force(shape, block, channels):
    rng = np.random.default_rng(sum(shape))
    sample = rng.random((*shape, channels)).astype(np.float32)
    target = rng.random((*block, channels)).astype(np.float32)
    mask = l_mask(*block, top=2, left=3)
    got = masked_ssd(sample, target, mask)
    want = brute_ssd(sample, target, mask)
    assert got.dtype == np.float32 and got.shape == want.shape
    # float32 FFT: absolute error far below one grey level squared over the overlap
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-4 * mask.sum() * channels)
    assert np.argmin(got) == np.argmin(want) or np.isclose(got.min(), want.min(), rtol=1e-4)


def test_union_mask_does_not_double_count_the_corner():
    rng = np.random.default_rng(1)
    sample = rng.random((20, 20, 3)).astype(np.float32)
    target = rng.random((6, 6, 3)).astype(np.float32)
    union = l_mask(6, 6, 2, 2)
    got = masked_ssd(sample, target, union)
    sum_of_strips = masked_ssd(sample, target, l_mask(6, 6, 2, 0)) + masked_ssd(
        sample, target, l_mask(6, 6, 0, 2)
    )
    np.testing.assert_allclose(got, brute_ssd(sample, target, union), rtol=1e-4, atol=1e-3)
    assert (sum_of_strips > got + 1e-3).all()  # the strips' sum counts the corner twice


def test_weighted_groups_and_batches():
    rng = np.random.default_rng(2)
    sample = rng.random((25, 30, 4)).astype(np.float32)
    spec = SampleSpectrum(sample, groups=((0, 1, 2), (3,)))
    targets = rng.random((3, 6, 7, 4)).astype(np.float32)
    weights = rng.random((3, 2, 6, 7)).astype(np.float32)
    got = spec.ssd(targets, weights)
    for i in range(3):
        want = brute_ssd(sample[..., :3], targets[i, ..., :3], weights[i, 0]) + brute_ssd(
            sample[..., 3], targets[i, ..., 3], weights[i, 1]
        )
        np.testing.assert_allclose(got[i], want, rtol=1e-4, atol=1e-3)


def test_exact_copy_scores_zero_and_is_found():
    rng = np.random.default_rng(3)
    sample = rng.random((40, 40, 3)).astype(np.float32)
    target = sample[11:19, 23:31].copy()
    e = masked_ssd(sample, target, l_mask(8, 8, 2, 2))
    assert e.min() >= 0
    assert np.unravel_index(np.argmin(e), e.shape) == (11, 23)
    assert e[11, 23] < 1e-3


def test_ssd_at_matches_brute_force():
    rng = np.random.default_rng(4)
    sample = rng.random((20, 22, 3)).astype(np.float32)
    target = rng.random((5, 6, 3)).astype(np.float32)
    mask = l_mask(5, 6, 1, 2)
    anchors = np.array([[0, 0], [15, 16], [7, 3]])
    want = brute_ssd(sample, target, mask)[anchors[:, 0], anchors[:, 1]]
    np.testing.assert_allclose(ssd_at(sample, anchors, target, mask), want, rtol=1e-10)


def test_select_within_tolerance():
    rng = np.random.default_rng(0)
    e = np.array([5.0, 1.0, 1.05, 1.2, np.inf, 1.09])
    picks = {
        select_within_tolerance(e, tolerance=0.1, zero_level=0, rng=rng)[0] for _ in range(200)
    }
    assert picks == {1, 2, 5}
    # e_min ≈ 0: the zero level widens the set beyond the exact copy
    e0 = np.array([0.0, 0.5, 0.9, 3.0])
    picks0 = {
        select_within_tolerance(e0, tolerance=0.1, zero_level=1.0, rng=rng)[0] for _ in range(200)
    }
    assert picks0 == {0, 1, 2}
    with pytest.raises(ValueError, match="no valid candidate"):
        select_within_tolerance(np.full(3, np.inf), tolerance=0.1, zero_level=0, rng=rng)


def test_pca_fast_mode_finds_the_best_candidates():
    """The fast ranking with exact re-ranking recovers the exact best window on a real texture
    (its errors are exact SSDs of real windows: never below the exhaustive minimum)."""
    from engine.io import load_image
    from resources import sample_path

    s = load_image(sample_path("cobblestones")).pixels[:96, :96]
    spec = SampleSpectrum(s)
    pca = PCAMatcher(spec, (24, 24), top=4, left=4, rng=0)
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(10):
        y, x = rng.integers(0, 60, 2)
        target = s[y : y + 24, x : x + 24] + rng.normal(0, 0.05, (24, 24, 3)).astype(np.float32)
        mask = l_mask(24, 24, 4, 4)
        exact = spec.ssd(target[None], mask[None])[0]
        ((anchors, errs),) = pca.query(
            [target], [pca.parts_for(4, 4)], None, rerank=16, mask_list=[mask]
        )
        assert errs[0] >= exact.min() - 1e-2
        np.testing.assert_allclose(errs, exact[anchors[:, 0], anchors[:, 1]], rtol=1e-4, atol=1e-3)
        hits += np.isclose(errs[0], exact.min(), rtol=1e-4, atol=1e-3)
    assert hits >= 8


def test_masked_ssd_errors():
    with pytest.raises(ValueError, match="mask"):
        masked_ssd(np.zeros((9, 9, 3)), np.zeros((3, 3, 3)), np.ones((2, 3)))
    with pytest.raises(ValueError, match="channels"):
        masked_ssd(np.zeros((9, 9, 3)), np.zeros((3, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError, match="larger than the sample"):
        masked_ssd(np.zeros((4, 4, 3)), np.zeros((5, 3, 3)), np.ones((5, 3)))


def test_pca_query_ranks_by_estimate_reranks_exactly_and_ignores_the_batch():
    """The re-ranked windows are the ``rerank`` lowest estimates (float64 recomputation, up to
    float32 round-off), their errors are exact SSDs in ascending order, excluded windows never
    appear, and a target gets the same answer alone or in a batch."""
    rng = np.random.default_rng(6)
    s = rng.random((40, 44, 3), dtype=np.float32)
    pca = PCAMatcher(SampleSpectrum(s), (12, 12), top=3, left=3, components=4, rng=1)
    valid = rng.random(pca.anchor_shape) < 0.8
    targets = [rng.random((12, 12, 3), dtype=np.float32) for _ in range(3)]
    shapes = [(3, 3), (0, 3), (3, 0)]
    parts = [pca.parts_for(*a) for a in shapes]
    masks = [l_mask(12, 12, *a) for a in shapes]
    batch = pca.query(targets, parts, valid, rerank=10, mask_list=masks)
    for i, (anchors, errs) in enumerate(batch):
        alone = pca.query([targets[i]], [parts[i]], valid, rerank=10, mask_list=[masks[i]])[0]
        np.testing.assert_array_equal(anchors, alone[0])
        np.testing.assert_array_equal(errs, alone[1])
        assert len(anchors) == 10 and valid[anchors[:, 0], anchors[:, 1]].all()
        np.testing.assert_array_equal(errs, ssd_at(s, anchors, targets[i], masks[i]))
        assert (np.diff(errs) >= 0).all()
        est = np.zeros(pca.anchor_shape)
        for name in parts[i]:
            y0, x0, rh, rw = pca.rects[name]
            a, b = pca.offsets[name]
            proj = (
                pca.bases[name].astype(np.float64) @ targets[i][y0 : y0 + rh, x0 : x0 + rw].ravel()
            )
            est += pca.norms[name] - 2 * (proj @ pca.features[a:b]).reshape(pca.anchor_shape)
        est[~valid] = np.inf
        cutoff = np.sort(est.ravel())[10]
        assert (est[anchors[:, 0], anchors[:, 1]] <= cutoff + 1e-4).all()
    few = np.zeros(pca.anchor_shape, bool)
    few[5, 7] = few[20, 1] = True  # fewer valid windows than rerank
    ((anchors, errs),) = pca.query(targets[:1], parts[:1], few, rerank=10, mask_list=masks[:1])
    assert sorted(map(tuple, anchors.tolist())) == [(5, 7), (20, 1)] and len(errs) == 2


def test_a_batchs_estimates_are_each_targets_own_bits():
    """The fast search's estimates of a batch (one pass over the index for all its targets)
    equal each target's alone, bit for bit: a batch of blocks may share a pass on any thread
    count without changing a record."""
    from engine import _jit, matching

    _jit.load()
    rng = np.random.default_rng(8)
    kk, nn = 12, 5000
    features = rng.standard_normal((kk, nn)).astype(np.float32)
    base = (rng.random((3, nn)) * 50).astype(np.float32)
    invalid = rng.random(nn) < 0.05
    q = rng.standard_normal((4, kk)).astype(np.float32)
    q[1, :4] = 0  # a target without some parts
    rows = np.array([0, 2, 1, 0], np.intp)
    batch = np.empty((4, nn), np.float32)
    matching._estimates(q, features, base, rows, invalid, batch)
    for i in range(4):
        alone = np.empty((1, nn), np.float32)
        matching._estimates(q[i : i + 1], features, base, rows[i : i + 1], invalid, alone)
        assert alone[0].tobytes() == batch[i].tobytes()
    want = base[rows].astype(np.float64) - 2 * q.astype(np.float64) @ features
    want[:, invalid] = np.inf
    np.testing.assert_allclose(batch, want, rtol=1e-4, atol=1e-2)


def test_the_sample_spectra_do_not_depend_on_the_workers():
    """ducc0 splits batched transforms by thread count (the last bits differ): the sample's
    spectra are made on one thread, so a run on two threads scores as one on one thread."""
    s = np.random.default_rng(1).random((120, 90, 3), dtype=np.float32)
    one, two = SampleSpectrum(s, workers=1), SampleSpectrum(s, workers=2)
    assert np.array_equal(one._hs, two._hs) and np.array_equal(one._fsq, two._fsq)


@pytest.mark.parametrize("shape", [(1, 3, 129, 256), (8, 3, 65, 128), (2, 1, 7, 5), (3, 4, 9, 6)])
def test_the_product_sums_kernel_gives_the_numpy_twins_bits(monkeypatch, shape):
    """The compiled product sum (numba loaded) and its numpy twin (a small job without numba)
    give the same bits, with and without the weight terms added, on any channel count; and
    the sum is the complex products' up to float32 round-off."""
    from engine import _jit

    rng = np.random.default_rng(sum(shape))

    def spectra(*s):
        scale = 10.0 ** rng.uniform(-4, 4, s)  # magnitudes far apart: rounding matters
        return (scale * (rng.standard_normal(s) + 1j * rng.standard_normal(s))).astype(np.complex64)

    fk, hs = spectra(*shape), spectra(*shape[1:])
    add = [spectra(*shape[2:]) for _ in range(shape[0])]
    for extra in (None, add):
        monkeypatch.setattr(_jit, "loaded", lambda: False)
        twin = spectral.product_sum(fk, hs, extra)
        monkeypatch.undo()
        _jit.load()
        kernel = spectral.product_sum(fk, hs, extra)
        assert kernel.dtype == twin.dtype == np.complex64
        assert np.array_equal(kernel.view(np.float32), twin.view(np.float32))
        wide = spectral.product_sum(fk.astype(complex), hs.astype(complex), extra)
        assert np.array_equal(wide.view(np.float32), twin.view(np.float32))  # numpy < 2's FFTs
        exact = np.einsum("nc...,c...->n...", fk.astype(complex), hs.astype(complex))
        if extra is not None:
            exact += np.stack(extra)
        bound = np.einsum("nc...,c...->n...", np.abs(fk), np.abs(hs)) + (
            0 if extra is None else np.abs(np.stack(extra))
        )
        assert np.all(np.abs(kernel - exact) <= 8 * np.finfo(np.float32).eps * bound)
