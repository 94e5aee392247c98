"""Heal (engine.heal): oracles on small planted images."""

from __future__ import annotations

import numpy as np
import pytest
from skimage.util import img_as_float32

from engine.cancel import Cancelled, CancelToken
from engine.events import Progress
from engine.heal import HealBlock, HealResult, heal, iter_heal
from engine.seams import SeamSpec
from tests.engine.helpers import events_and_result, smooth_texture


def disk(shape, cy, cx, r):
    yy, xx = np.mgrid[: shape[0], : shape[1]]
    return (yy - cy) ** 2 + (xx - cx) ** 2 < r * r


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
@pytest.mark.parametrize("channels", [1, 3])
def test_pixels_outside_the_mask_are_unchanged_exactly(dtype, channels):
    tex = smooth_texture((72, 80), channels, seed=1)
    img = tex.astype(dtype) if dtype == np.float32 else (tex * np.iinfo(dtype).max).astype(dtype)
    img = img[:, :, 0] if channels == 1 else img
    mask = disk((72, 80), 36, 40, 12)
    r = heal(img, mask, block=16, rng=0)
    assert r.image.dtype == np.float32 and r.image.shape == (72, 80, channels)
    original = img_as_float32(img).reshape(72, 80, channels)
    np.testing.assert_array_equal(r.image[~mask], original[~mask])
    assert not np.array_equal(r.image[mask], original[mask])


def test_no_masked_pixel_is_copied_from_a_masked_source_position():
    img = smooth_texture((80, 80), 3, seed=2) * np.float32(0.6)  # no saturated red in it
    mask = disk((80, 80), 40, 40, 14) | disk((80, 80), 15, 60, 6)
    img[mask] = (1.0, 0.0, 0.0)  # the masked pixels are a colour found nowhere else
    excluded = np.zeros_like(mask)
    excluded[:, :8] = True
    r = heal(img, mask, block=12, excluded=excluded, rng=3)
    for b in r.blocks:  # every source window lies outside the mask and the excluded pixels
        sx, sy = b.source
        x, y, w, h = b.rect
        assert not mask[sy : sy + h, sx : sx + w].any()
        assert not excluded[sy : sy + h, sx : sx + w].any()
    red = r.image[..., 0] - r.image[..., 1:].max(axis=2)
    assert red[mask].max() < 0.5  # no trace of the planted colour
    assert np.allclose(r.image[mask].max(), img[~mask].max(), atol=0.35)


def test_a_planted_stripe_texture_is_healed_so_the_stripes_continue():
    h, w, period = 96, 96, 8
    xx = np.arange(w)[None, :].repeat(h, 0)
    truth = (0.5 + 0.4 * np.sin(2 * np.pi * xx / period)).astype(np.float32)
    noise = np.random.default_rng(0).normal(0, 0.02, (h, w)).astype(np.float32)
    img = np.clip(truth + noise, 0, 1)
    mask = disk((h, w), 48, 48, 18)
    r = heal(img, mask, block=16, rng=1)
    healed = r.image[..., 0][mask]
    err = np.abs(healed - truth[mask]).mean()
    shifted = np.abs(np.roll(truth, period // 2, axis=1)[mask] - truth[mask]).mean()
    assert err < 0.06 < shifted / 4  # the phase continues (a half-period shift errs ~0.5)
    # each healed row varies like the stripes (not a flat fill)
    assert np.std(r.image[48, 34:62, 0]) > 0.2


def test_material_maps_are_healed_with_the_same_windows_cuts_and_blends():
    img = smooth_texture((64, 72), 3, seed=4)
    height = 1.0 - img[:, :, :1]  # a map that is a function of the image
    mask = disk((64, 72), 30, 36, 11)
    r = heal(img, mask, maps={"height": height}, block=14, rng=5)
    assert set(r.maps) == {"height"}
    np.testing.assert_allclose(r.maps["height"][..., 0], 1.0 - r.image[..., 0], atol=1e-6)
    np.testing.assert_array_equal(r.maps["height"][~mask], height[~mask])


def test_streams_blocks_and_progress_and_is_reproducible():
    img = smooth_texture((64, 64), 3, seed=6)
    mask = disk((64, 64), 32, 32, 10)
    events, result = events_and_result(iter_heal(img, mask, block=12, rng=7))
    blocks = [e for e in events if isinstance(e, HealBlock)]
    progress = [e for e in events if isinstance(e, Progress)]
    assert isinstance(result, HealResult) and list(result.blocks) == blocks
    assert blocks and progress[-1].done == progress[-1].total
    assert {b.level for b in blocks} == {0, 1}  # the coarse fill and the rim
    assert all(not b.pixels.flags.writeable for b in blocks)
    again = heal(img, mask, block=12, rng=7)
    np.testing.assert_array_equal(again.image, result.image)
    other = heal(img, mask, block=12, rng=8)
    assert not np.array_equal(other.image, result.image)


def test_onion_order_starts_at_the_boundary():
    img = smooth_texture((96, 96), 3, seed=9)
    mask = np.zeros((96, 96), bool)
    mask[20:76, 20:76] = True
    r = heal(img, mask, block=16, refine=False, rng=0)
    first, last = r.blocks[0], r.blocks[-1]

    def depth(b):  # distance of the block's centre from the mask's edge
        x, y, w, h = b.rect
        cy, cx = y + h / 2, x + w / 2
        return min(cy - 20, 76 - cy, cx - 20, 76 - cx)

    assert depth(first) < depth(last)


def test_every_seam_method_heals():
    img = smooth_texture((56, 56), 3, seed=10)
    mask = disk((56, 56), 28, 28, 8)
    for method in ("dp", "dijkstra", "minimax", "oscillating", "resistance"):
        for blend in ("none", "feather", "adaptive"):
            spec = SeamSpec(method, metric="euclid", blend=blend)
            r = heal(img, mask, block=12, seam=spec, rng=0)
            np.testing.assert_array_equal(r.image[~mask], img[~mask])


def test_cancel_raises():
    img = smooth_texture((64, 64), 3, seed=11)
    token = CancelToken()
    gen = iter_heal(img, disk((64, 64), 32, 32, 12), block=12, cancel=token)
    next(gen)
    token.cancel()
    with pytest.raises(Cancelled):
        for _ in gen:
            pass


def test_bad_input_is_refused_eagerly_with_clear_messages():
    img = smooth_texture((40, 40), 3, seed=12)
    with pytest.raises(ValueError, match="empty"):
        iter_heal(img, np.zeros((40, 40), bool))
    with pytest.raises(ValueError, match="mask must be shaped"):
        iter_heal(img, np.ones((10, 10), bool))
    with pytest.raises(ValueError, match="outside the region to heal"):
        iter_heal(img, disk((40, 40), 20, 20, 19), block=30)
    with pytest.raises(TypeError, match="SeamSpec"):
        iter_heal(img, disk((40, 40), 20, 20, 5), seam="dp")
    with pytest.raises(ValueError, match="straight"):
        iter_heal(img, disk((40, 40), 20, 20, 5), seam=SeamSpec("straight"))
    with pytest.raises(ValueError, match="overlap"):
        iter_heal(img, disk((40, 40), 20, 20, 5), block=10, overlap=10)
