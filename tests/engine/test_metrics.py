"""Quality metrics (DESIGN.md "Quality"), including the reference figures on the brick sample."""

import numpy as np
import pytest
from scipy import ndimage

from engine.io import load_image
from engine.metrics import (
    border_ratio,
    detail_ratio,
    grid_border_ratio,
    grid_score,
    laplacian_variance,
    seam_stats,
    wrap_border_ratio,
)
from engine.seams import make_seam
from resources import sample_path


@pytest.fixture(scope="module")
def brick():
    return load_image(sample_path("brick")).pixels


def periodic_texture(h, w, seed=0, channels=3):
    """A smooth random texture that is exactly periodic with period (h, w)."""
    rng = np.random.default_rng(seed)
    noise = rng.random((h, w, channels))
    return ndimage.gaussian_filter(noise, sigma=(2, 2, 0), mode="wrap").astype(np.float32)


def test_border_ratio_of_a_ramp():
    t = np.tile(np.arange(8.0) / 8, (4, 1))
    # inside: every step is 1/8; the joint jumps from 7/8 back to 0
    assert border_ratio(t, t) == pytest.approx(7.0)
    assert border_ratio(t.T, t.T, direction="vertical") == pytest.approx(7.0)
    # a continuing ramp: B starts where A ends
    assert border_ratio(t, t + 1) == pytest.approx(1.0)


def test_border_ratio_channels_averaged_and_alpha_dropped():
    rng = np.random.default_rng(0)
    a, b = rng.random((6, 5, 3)), rng.random((6, 4, 3))
    joint = np.abs(a[:, -1] - b[:, 0]).mean()
    inner = np.concatenate([np.abs(np.diff(a, axis=1)).ravel(), np.abs(np.diff(b, axis=1)).ravel()])
    assert border_ratio(a, b) == pytest.approx(joint / inner.mean())
    alpha = np.concatenate([a, rng.random((6, 5, 1))], axis=2)
    alpha_b = np.concatenate([b, rng.random((6, 4, 1))], axis=2)
    assert border_ratio(alpha, alpha_b) == pytest.approx(border_ratio(a, b))
    # vertical is the transpose of horizontal
    assert border_ratio(a.transpose(1, 0, 2), b.transpose(1, 0, 2), direction="vertical") == (
        pytest.approx(border_ratio(a, b))
    )


def test_border_ratio_flat_and_bad_input():
    flat = np.zeros((3, 3))
    assert border_ratio(flat, flat) == 1.0
    assert border_ratio(flat, flat + 0.5) == float("inf")
    with pytest.raises(ValueError, match="same height"):
        border_ratio(np.zeros((3, 3)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match="direction must be one of"):
        border_ratio(flat, flat, direction="diagonal")


def test_wrap_border_ratio_periodic_tile_is_smooth_and_crop_is_not():
    t = periodic_texture(48, 64)
    assert wrap_border_ratio(t) == pytest.approx(1.0, abs=0.3)
    crop = periodic_texture(96, 96, seed=3)[:40, :50]  # not periodic at 40 x 50
    h = wrap_border_ratio(crop, direction="horizontal")
    v = wrap_border_ratio(crop, direction="vertical")
    assert wrap_border_ratio(crop) == pytest.approx((h + v) / 2)
    assert min(h, v) > 2.0


def test_grid_border_ratio_sees_block_grid_lines():
    rng = np.random.default_rng(4)
    smooth = periodic_texture(32, 32, seed=5)
    assert grid_border_ratio(np.tile(smooth, (3, 3, 1)), 32) == pytest.approx(1.0, abs=0.3)
    # blocks of unrelated content: jumps on every grid line at offset (0, 0) ...
    blocks = np.concatenate(
        [
            np.concatenate([periodic_texture(20, 20, s) for s in rng.integers(0, 99, 4)], 1)
            for _ in range(3)
        ],
        0,
    )
    assert grid_border_ratio(blocks, (20, 20)) > 2.0
    # ... and nothing special on lines shifted by half a block
    assert grid_border_ratio(blocks, (20, 20), offset=(10, 10)) < 1.0
    assert grid_border_ratio(blocks, (20, 20), direction="horizontal") > 2.0
    with pytest.raises(ValueError, match="no grid line"):
        grid_border_ratio(blocks, (200, 200))


def _reference_laplacian_variance(image) -> float:
    """The definition: float64 4-neighbour Laplacian over the interior, variance per colour
    channel (alpha dropped), averaged over channels."""
    from engine._validate import as_image
    from engine.errormap import colour_channels

    x = colour_channels(as_image(image)).astype(np.float64)
    lap = x[:-2, 1:-1] + x[2:, 1:-1] + x[1:-1, :-2] + x[1:-1, 2:] - 4.0 * x[1:-1, 1:-1]
    return float(lap.reshape(-1, x.shape[2]).var(axis=0).mean())


@pytest.mark.parametrize("strip", [1, 7, 1 << 20])  # values per strip: 1 row ... one strip
@pytest.mark.parametrize(
    "make",
    [
        lambda r: r.random((37, 29, 3)).astype(np.float32),
        lambda r: r.random((37, 29)),  # gray float64
        lambda r: r.integers(0, 256, (37, 29, 4), dtype=np.uint8),  # RGBA: alpha dropped
        lambda r: r.integers(0, 65536, (40, 3, 2), dtype=np.uint16),  # gray + alpha, 3 wide
        lambda r: (r.random((3, 50, 3)) + 1000.0).astype(np.float32) / 1000.5,  # offset
    ],
)
def test_laplacian_variance_matches_the_definition_strip_by_strip(monkeypatch, make, strip):
    import engine.metrics as metrics

    monkeypatch.setattr(metrics, "_STRIP_VALUES", strip)
    image = make(np.random.default_rng(strip))
    before = image.copy()
    got = laplacian_variance(image)
    assert got == pytest.approx(_reference_laplacian_variance(image), rel=1e-5, abs=1e-12)
    np.testing.assert_array_equal(image, before)  # input untouched


def test_laplacian_variance_bad_input_and_flat():
    assert laplacian_variance(np.full((5, 6, 3), 0.25, np.float32)) == 0.0
    with pytest.raises(ValueError, match="at least 3x3"):
        laplacian_variance(np.zeros((2, 8)))
    with pytest.raises(ValueError, match="tile must be at least 3x3"):
        detail_ratio(np.zeros((8, 2)), np.ones((8, 8)))
    with pytest.raises(TypeError, match="image must be a numeric array"):
        laplacian_variance(np.array([["a"] * 4] * 4))
    with pytest.raises(ValueError, match="NaN"):
        laplacian_variance(np.full((4, 4), np.nan))


def test_laplacian_variance_of_a_large_source_uses_strips_not_copies():
    """A 2048x2048 RGB float32 source (48 MiB): the float64 whole-image Laplacian peaked at
    several times the source; strips keep the extra memory near 24 MiB whatever the size."""
    import tracemalloc

    source = np.random.default_rng(0).random((2048, 2048, 3), dtype=np.float32)
    tracemalloc.start()
    try:
        value = laplacian_variance(source)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 0.6 * source.nbytes, peak / 2**20
    assert value == pytest.approx(_reference_laplacian_variance(source[:600]), rel=0.02)


def test_detail_ratio_is_the_ratio_of_laplacian_variances(brick):
    tile = brick[:100, :120]
    assert detail_ratio(tile, brick) == pytest.approx(
        laplacian_variance(tile) / laplacian_variance(brick), rel=1e-12
    )


def test_detail_ratio_blur_lowers_it():
    src = periodic_texture(64, 64, seed=6)
    assert detail_ratio(src, src) == pytest.approx(1.0)
    blurred = ndimage.gaussian_filter(src, sigma=(1, 1, 0))
    assert detail_ratio(blurred, src) < 0.6
    with pytest.raises(ValueError, match="source has no detail"):
        detail_ratio(src, np.zeros((8, 8)))


def test_grid_score_repeated_tile_is_about_one(brick):
    tile = brick[100:164, 200:264]
    assert grid_score(np.tile(tile, (4, 4, 1)), (64, 64), source=brick) == pytest.approx(
        1.0, abs=0.1
    )
    # an image as varied as its source scores about 0 (here: another part of the source)
    assert abs(grid_score(brick[256:, 256:], (64, 64), source=brick)) < 0.25
    with pytest.raises(ValueError, match="period"):
        grid_score(tile, (64, 64), source=brick)


def test_seam_stats():
    rng = np.random.default_rng(7)
    e = rng.random((6, 5))
    seam = make_seam(e, [[0, 1], [1, 2], [2, 2], [3, 1], [4, 0], [5, 0]], "test")
    crit, peak = seam_stats(seam)
    assert (crit, peak) == (seam.criterion, seam.peak)
    vals = e[seam.path[:, 0], seam.path[:, 1]]
    assert seam_stats(seam.path, e) == pytest.approx((vals.sum(), vals.max()))
    assert seam_stats(seam, 2 * e) == pytest.approx((2 * vals.sum(), 2 * vals.max()))
    with pytest.raises(TypeError, match="needs an error map"):
        seam_stats(seam.path)
    with pytest.raises(ValueError, match="leaves"):
        seam_stats([[0, 9]], e)


def _cross_fade(crop, t, w):
    """A simple "make seamless": fade the w pixels after the tile into its first w pixels."""
    a = np.linspace(1, 0, w + 2)[1:-1][None, :, None]
    h = crop[:, :t].copy()
    h[:, :w] = a * crop[:, t : t + w] + (1 - a) * crop[:, :w]
    v = h[:t].copy()
    av = a.transpose(1, 0, 2)
    v[:w] = av * h[t : t + w] + (1 - av) * h[:w]
    return v


def test_reference_figures_on_brick(brick):
    """DESIGN.md: a naive crop scores ~10, a cross-fade ~1.2-1.5 with detail 0.65-0.87."""
    t, w = 128, 32
    rng = np.random.default_rng(0)
    naive, fade, detail = [], [], []
    for y, x in rng.integers(0, brick.shape[0] - t - w, (12, 2)):
        crop = brick[y : y + t + w, x : x + t + w].astype(np.float64)
        naive.append(wrap_border_ratio(crop[:t, :t]))
        tile = _cross_fade(crop, t, w)
        fade.append(wrap_border_ratio(tile))
        detail.append(detail_ratio(tile, brick))
    assert 5 < np.median(naive) < 15
    assert 0.9 < np.median(fade) < 1.8
    assert 0.65 < np.median(detail) < 0.95
