"""Flatten lighting (issue 10, item 4a)."""

import numpy as np
import pytest
from scipy import ndimage

from engine.settings import TilesetSettings
from engine.tiles.pipeline import tileset
from engine.tone import flatten_lighting, flatten_scale


def lit_texture(size=192, seed=0):
    rng = np.random.default_rng(seed)
    tex = ndimage.gaussian_filter(rng.random((size, size, 3)), (1.5, 1.5, 0), mode="wrap")
    tex = 0.3 + 0.4 * (tex - tex.min()) / np.ptp(tex)
    light = np.linspace(0.6, 1.4, size)[None, :, None]
    return tex, np.clip(tex * light, 0, 1).astype(np.float32)


def test_flatten_removes_a_light_gradient_and_keeps_the_mean_colour():
    tex, lit = lit_texture()
    flat = flatten_lighting(lit, scale=48)
    cols = lambda a: a[16:-16].mean(axis=(0, 2))  # noqa: E731 - mean per column
    assert np.ptp(cols(lit)[16:-16]) > 0.15
    assert np.ptp(cols(flat)[16:-16]) < 0.05
    np.testing.assert_allclose(flat.mean(axis=(0, 1)), lit.mean(axis=(0, 1)), atol=0.02)
    # detail is kept: the high frequencies match the unlit texture's
    hp = lambda a: a - ndimage.gaussian_filter(a, (4, 4, 0))  # noqa: E731
    r = np.corrcoef(hp(flat)[32:-32, 32:-32].ravel(), hp(tex)[32:-32, 32:-32].ravel())[0, 1]
    assert r > 0.9


def test_flatten_subtract_alpha_and_validation():
    _, lit = lit_texture(64)
    rgba = np.concatenate([lit, np.full((64, 64, 1), 0.5, np.float32)], axis=2)
    out = flatten_lighting(rgba, scale=16, mode="subtract")
    assert out.shape == rgba.shape and (out[..., 3] == 0.5).all()
    with pytest.raises(ValueError, match="scale"):
        flatten_lighting(lit, scale=0)
    with pytest.raises(ValueError, match="mode"):
        flatten_lighting(lit, scale=4, mode="log")
    assert flatten_scale((96, 128)) == 128


def test_flatten_setting_evens_out_the_tiles_tone():
    _, lit = lit_texture(192)
    base = TilesetSettings(tile_min=48, tile_max=64, candidates=8)
    plain = tileset(lit, base)
    flat = tileset(lit, base.replace(flatten=True))
    assert flat.settings.flatten and not plain.settings.flatten

    def ramp(tile):  # the light gradient inside a tile: right third over left third
        w = tile.shape[1] // 3
        return abs(float(tile[:, -w:].mean() - tile[:, :w].mean()))

    assert ramp(flat.seamless.tile) < 0.4 * ramp(plain.seamless.tile)
    assert np.mean([ramp(c.tile) for c in flat.candidates]) < 0.4 * np.mean(
        [ramp(c.tile) for c in plain.candidates]
    )
