"""Blending after a cut: hard, feather, adaptive (ALGORITHMS §0, §1.3)."""

import numpy as np
import pytest
from scipy import ndimage

from engine.blend import (
    BLEND_MODES,
    adaptive_half_widths,
    blend_weights,
    composite,
    cut_columns,
    ramp_from_mask,
)
from engine.seams import make_seam, mask_from_columns


def random_seam(h, w, rng, error=None):
    """A random one-point-per-row 8-connected seam (and its error map)."""
    e = rng.random((h, w)) if error is None else error
    cols = [int(rng.integers(0, w))]
    for _ in range(h - 1):
        cols.append(int(np.clip(cols[-1] + rng.integers(-1, 2), 0, w - 1)))
    cols = np.array(cols)
    path = np.column_stack([np.arange(h), cols])
    return make_seam(e, path, "test", mask_from_columns(cols, w)), e, cols


def spec_adaptive(e, cols, rho):
    """ALGORITHMS §1.3 written out row by row (the oracle), with the documented edge clamp."""
    h, w = e.shape
    ej = np.array([e[j, cols[j]] for j in range(h)])
    sm = np.array([ej[max(0, j - rho) : j + rho + 1].mean() for j in range(h)])
    b = np.minimum(np.floor(rho * sm / e.mean()), 2 * rho)
    alpha = np.zeros((h, w))
    for j in range(h):
        bj = max(0.0, min(b[j], cols[j] + 0.5, w - 1.5 - cols[j]))
        for i in range(w):
            if bj == 0:
                alpha[j, i] = float(i <= cols[j])
            else:
                alpha[j, i] = np.clip(0.5 - (i - cols[j] - 0.5) / (2 * bj), 0, 1)
    return alpha, b


def test_hard_cut_is_the_mask():
    rng = np.random.default_rng(0)
    seam, e, _ = random_seam(9, 7, rng)
    a = blend_weights(seam, e, mode="none")
    assert a.dtype == np.float32
    np.testing.assert_array_equal(a, seam.mask)
    assert BLEND_MODES == ("none", "feather", "adaptive")


def test_adaptive_matches_the_spec_row_by_row():
    rng = np.random.default_rng(1)
    for _ in range(20):
        h, w = rng.integers(3, 25), rng.integers(2, 16)
        e = rng.random((h, w)) ** 3  # skewed: some rows sharp, some blended
        seam, e, cols = random_seam(h, w, rng, e)
        rho = int(rng.integers(1, 5))
        expected, b = spec_adaptive(e, cols, rho)
        np.testing.assert_allclose(adaptive_half_widths(seam, e, rho=rho), b)
        np.testing.assert_allclose(blend_weights(seam, e, mode="adaptive", rho=rho), expected, 1e-6)


def test_adaptive_changes_only_pixels_within_its_width_of_the_path():
    rng = np.random.default_rng(2)
    for _ in range(30):
        h, w = rng.integers(4, 40), rng.integers(3, 24)
        seam, e, cols = random_seam(h, w, rng, rng.random((h, w)) ** 2)
        rho = int(rng.integers(1, 5))
        alpha = blend_weights(seam, e, mode="adaptive", rho=rho)
        b = adaptive_half_widths(seam, e, rho=rho)
        changed = alpha != seam.mask
        dist = np.abs(np.arange(w)[None, :] - cols[:, None] - 0.5)
        assert not (changed & (dist >= b[:, None])).any()
        assert (b <= 2 * rho).all()
        # the overlap's first and last columns are exact copies (never blended)
        assert not changed[:, [0, -1]].any()
        # R1 side stays R1 up to the band, R2 side likewise
        assert ((alpha == 1) | changed | ~seam.mask).all()


def test_adaptive_blends_bad_rows_and_keeps_good_rows_sharp():
    h, w = 30, 21
    e = np.full((h, w), 0.01)
    e[:, 10] = 0.001  # a good straight path in column 10 ...
    e[20:, 10] = 5.0  # ... that is bad in its lower third
    seam = make_seam(
        e,
        np.column_stack([np.arange(h), np.full(h, 10)]),
        "t",
        mask_from_columns(np.full(h, 10), w),
    )
    alpha = blend_weights(seam, e, mode="adaptive", rho=3)
    np.testing.assert_array_equal(alpha[:10], seam.mask[:10])  # sharp where the path is good
    assert ((alpha[24:] > 0) & (alpha[24:] < 1)).sum(axis=1).min() == 12  # 2 * 2rho blended


def test_feather_width_and_straight_cut_values():
    h, w = 5, 12
    cols = np.full(h, 5)
    seam = make_seam(
        np.ones((h, w)), np.column_stack([np.arange(h), cols]), "t", mask_from_columns(cols, w)
    )
    a = blend_weights(seam, np.ones((h, w)), mode="feather", width=4)
    np.testing.assert_allclose(a[0], [1, 1, 1, 1, 0.875, 0.625, 0.375, 0.125, 0, 0, 0, 0])
    # near the overlap edge the ramp narrows so column 0 stays R1
    cols = np.full(h, 1)
    seam = make_seam(
        np.ones((h, w)), np.column_stack([np.arange(h), cols]), "t", mask_from_columns(cols, w)
    )
    a = blend_weights(seam, np.ones((h, w)), mode="feather", width=8)
    assert a[0, 0] == 1 and 0 < a[0, 1] < 1 and a[0, 3] == 0


def test_cyclic_smoothing_wraps_around():
    h, w = 12, 9
    e = np.full((h, w), 0.1)
    e[0, 4] = 100.0  # a bad path pixel in the first row only
    cols = np.full(h, 4)
    seam = make_seam(e, np.column_stack([np.arange(h), cols]), "t", mask_from_columns(cols, w))
    plain = adaptive_half_widths(seam, e, rho=2)
    ring = adaptive_half_widths(seam, e, rho=2, cyclic=True)
    assert plain[-1] == 0 and ring[-1] > 0 and ring[-1] == ring[1]  # row 11 neighbours row 0
    a = blend_weights(seam, e, mode="adaptive", rho=2, cyclic=True)
    np.testing.assert_array_equal(a[-1], a[1])


def test_winding_seam_uses_edt_ramp_within_its_width():
    h, w = 14, 12
    e = np.random.default_rng(3).random((h, w))
    # a hook: down column 8, left along row 7, up column 2, then down column 0
    pts = [(r, 8) for r in range(7)] + [(7, c) for c in range(7, 2, -1)]
    pts += [(6, 2), (5, 2), (4, 2), (3, 1)] + [(r, 0) for r in range(4, h)]
    seam = make_seam(e, np.array(pts), "t")
    assert cut_columns(seam.mask) is None
    for mode in ("feather", "adaptive"):
        alpha = blend_weights(seam, e, mode=mode, width=4, rho=3)
        changed = alpha != seam.mask
        assert changed.any()
        on_path = np.zeros((h, w), bool)
        on_path[tuple(np.array(pts).T)] = True
        dist = ndimage.distance_transform_edt(~on_path)
        bmax = 2.0 if mode == "feather" else 6.0
        assert dist[changed].max() <= bmax + 1
        assert not changed[:, [0, -1]].any()


def test_ramp_from_mask_straight_and_wrapped():
    m = np.zeros((6, 10), bool)
    m[:, :4] = True
    np.testing.assert_allclose(
        ramp_from_mask(m, 2)[0], [1, 1, 0.875, 0.625, 0.375, 0.125, 0, 0, 0, 0]
    )
    np.testing.assert_array_equal(ramp_from_mask(m, 0), m)
    # a blob near the top edge: the wrapped ramp equals the middle of a 3x tiled ramp
    m = np.zeros((8, 10), bool)
    m[0:3, 3:7] = True
    tiled = ramp_from_mask(np.tile(m, (3, 1)), 2.5)[8:16]
    np.testing.assert_allclose(ramp_from_mask(m, 2.5, wrap_rows=True), tiled)
    assert not np.allclose(ramp_from_mask(m, 2.5), tiled)
    with pytest.raises(ValueError, match="half_width"):
        ramp_from_mask(m, -1)


def test_composite_exact_copies_and_inputs():
    rng = np.random.default_rng(4)
    r1, r2 = rng.random((5, 6, 3), dtype=np.float32), rng.random((5, 6, 3), dtype=np.float32)
    alpha = rng.random((5, 6)).astype(np.float32)
    alpha[:, :2] = 1
    alpha[:, 4:] = 0
    out = composite(alpha, r1, r2)
    assert out.dtype == np.float32
    np.testing.assert_array_equal(out[:, :2], r1[:, :2])
    np.testing.assert_array_equal(out[:, 4:], r2[:, 4:])
    np.testing.assert_allclose(out, alpha[..., None] * r1 + (1 - alpha[..., None]) * r2, 1e-6)
    gray = composite(alpha, r1[..., 0], r2[..., 0])
    assert gray.shape == (5, 6)
    u8 = composite(np.ones((2, 2)), np.full((2, 2), 255, np.uint8), np.zeros((2, 2), np.uint8))
    np.testing.assert_array_equal(u8, 1.0)
    with pytest.raises(ValueError, match="same shape"):
        composite(alpha, r1, r2[:, :5])
    with pytest.raises(ValueError, match="alpha must be shaped"):
        composite(alpha[:4], r1, r2)


def test_bad_options():
    rng = np.random.default_rng(5)
    seam, e, _ = random_seam(5, 5, rng)
    with pytest.raises(ValueError, match="mode must be one of"):
        blend_weights(seam, e, mode="soft")
    with pytest.raises(ValueError, match="width must be"):
        blend_weights(seam, e, mode="feather", width=-1)
    with pytest.raises(ValueError, match="rho must be >= 0"):
        blend_weights(seam, e, mode="adaptive", rho=-1)
    with pytest.raises(ValueError, match="error must be shaped"):
        blend_weights(seam, e[:4], mode="adaptive")
