"""Error maps: Euclidean, squared and CIELAB distances; gray, RGB and alpha handled."""

import numpy as np
import pytest

from engine.errormap import METRICS, error_map


@pytest.fixture
def pair():
    rng = np.random.default_rng(0)
    return rng.random((5, 7, 3), dtype=np.float32), rng.random((5, 7, 3), dtype=np.float32)


def test_euclid_and_ssd_values(pair):
    a, b = pair
    d = a.astype(np.float64) - b
    expected = np.sqrt((d * d).sum(axis=2))
    e = error_map(a, b)
    assert e.dtype == np.float32 and e.shape == (5, 7)
    np.testing.assert_allclose(e, expected, rtol=1e-5)
    np.testing.assert_allclose(error_map(a, b, metric="ssd"), expected**2, rtol=1e-5)
    assert METRICS == ("euclid", "ssd", "lab")


def test_inputs_not_modified_and_symmetric(pair):
    a, b = pair
    a0, b0 = a.copy(), b.copy()
    for m in METRICS:
        np.testing.assert_allclose(error_map(a, b, metric=m), error_map(b, a, metric=m), atol=1e-5)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b, b0)


def test_gray_2d_3d_and_against_rgb():
    rng = np.random.default_rng(1)
    g1, g2 = rng.random((4, 6)), rng.random((4, 6))
    np.testing.assert_allclose(error_map(g1, g2), np.abs(g1 - g2), rtol=1e-5)
    np.testing.assert_allclose(error_map(g1[:, :, None], g2[:, :, None]), np.abs(g1 - g2), 1e-5)
    # gray against RGB: gray is replicated to R = G = B
    rgb2 = np.repeat(g2[:, :, None], 3, axis=2)
    np.testing.assert_allclose(error_map(g1, rgb2), np.sqrt(3) * np.abs(g1 - g2), rtol=1e-5)


def test_alpha_is_ignored():
    rng = np.random.default_rng(2)
    rgb = rng.random((3, 3, 3))
    a1 = np.concatenate([rgb, np.zeros((3, 3, 1))], axis=2)
    a2 = np.concatenate([rgb, np.ones((3, 3, 1))], axis=2)
    for m in METRICS:
        assert error_map(a1, a2, metric=m).max() == 0
    ga1 = np.stack([rgb[:, :, 0], np.zeros((3, 3))], axis=2)
    ga2 = np.stack([rgb[:, :, 0], np.ones((3, 3))], axis=2)
    assert error_map(ga1, ga2).max() == 0


def test_lab_delta_e():
    black = np.zeros((1, 2, 3))
    white = np.ones((1, 2, 3))
    np.testing.assert_allclose(error_map(black, white, metric="lab"), 100.0, rtol=1e-4)
    # perceptual: equal RGB steps are not equal Lab steps (dark differences weigh more)
    dark = error_map(np.full((1, 1, 3), 0.05), np.full((1, 1, 3), 0.15), metric="lab")[0, 0]
    light = error_map(np.full((1, 1, 3), 0.85), np.full((1, 1, 3), 0.95), metric="lab")[0, 0]
    assert dark > 1.2 * light
    # gray is compared as R = G = B
    g = error_map(np.full((1, 1), 0.2), np.full((1, 1), 0.6), metric="lab")
    rgb = error_map(np.full((1, 1, 3), 0.2), np.full((1, 1, 3), 0.6), metric="lab")
    np.testing.assert_allclose(g, rgb, rtol=1e-5)


def test_integer_inputs_are_scaled():
    a = np.zeros((2, 2, 3), np.uint8)
    b = np.full((2, 2, 3), 255, np.uint8)
    np.testing.assert_allclose(error_map(a, b), np.sqrt(3), rtol=1e-5)
    np.testing.assert_allclose(
        error_map(a.astype(np.uint16), b.astype(np.uint16) * 257), np.sqrt(3)
    )


def test_bad_input_messages():
    a = np.zeros((4, 5, 3))
    with pytest.raises(ValueError, match="same height and width.*5x4 and 4x4"):
        error_map(a, np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match="metric must be one of.*'cie'"):
        error_map(a, a, metric="cie")
    with pytest.raises(ValueError, match="compatible channels"):
        error_map(np.zeros((4, 5, 3)), np.zeros((4, 5, 5)))
    with pytest.raises(ValueError, match="r2 contains NaN"):
        error_map(a, np.full((4, 5, 3), np.nan))
