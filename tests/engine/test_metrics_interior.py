"""Interior metrics of a tile set (issue 10): frame, ring tone, duplicates, lattice, share."""

import numpy as np
import pytest
from scipy import ndimage

from engine.metrics import (
    duplicates,
    edge_distance,
    frame,
    lattice,
    lattice_db,
    luminance,
    ring_tone,
    template_share,
)
from engine.tileset_metrics import _harmonic_spectra


@pytest.fixture(scope="module")
def source():
    """A stochastic texture, 256x256 RGB, periodic with period 64: every 64x64 crop is a
    seamless tile whose wrap shows exactly its neighbours in the source (so crops are
    what an ideal candidate set looks like)."""
    rng = np.random.default_rng(3)
    x = ndimage.gaussian_filter(rng.random((64, 64, 3)), sigma=(1.5, 1.5, 0), mode="wrap")
    x = (x - x.min()) / (x.max() - x.min())
    return np.tile(x, (4, 4, 1)).astype(np.float32)


def crops(src, n, size, seed):
    rng = np.random.default_rng(seed)
    ys = rng.integers(0, src.shape[0] - size + 1, n)
    xs = rng.integers(0, src.shape[1] - size + 1, n)
    return [src[y : y + size, x : x + size].copy() for y, x in zip(ys, xs, strict=True)]


def test_luminance_and_edge_distance():
    rgb = np.zeros((2, 3, 3), np.float32)
    rgb[..., 1] = 1.0
    assert luminance(rgb) == pytest.approx(np.full((2, 3), 0.7154))
    assert luminance(np.full((2, 2), 0.5)) == pytest.approx(np.full((2, 2), 0.5))
    d = edge_distance((5, 6))
    assert d[0].tolist() == [0] * 6
    assert d[2].tolist() == [0, 1, 2, 2, 1, 0]
    assert d.max() == 2


def test_clean_crops_score_about_one(source):
    cs = crops(source, 30, 64, seed=1)
    f = frame(cs, source, limit=16, rng=2)
    assert 0.92 <= f.value <= 1.04
    assert f.ratio.shape == (16,)
    assert 0.6 < ring_tone(cs, source, width=8, rng=2) < 1.4
    assert duplicates(cs).count == 0
    assert lattice(cs, source, template=cs[0], margin=0, rng=2).above == pytest.approx(0, abs=1.0)


def test_planted_frame_is_detected(source):
    cs = crops(source, 30, 64, seed=1)
    ring = edge_distance((64, 64)) == 5
    framed = []
    for c in cs:
        c = c.copy()
        c[ring] = c[ring] * 0.5  # a dark line along every tile edge
        framed.append(c)
    f = frame(framed, source, limit=16)
    assert f.value > 1.25
    assert abs(f.distance - 5) <= 3


def test_planted_tone_ring_is_detected(source):
    cs = crops(source, 30, 64, seed=1)
    ring = edge_distance((64, 64)) < 8
    toned = []
    for c in cs:
        c = c.copy()
        c[ring] = np.clip(c[ring] + 0.08, 0, 1)
        toned.append(c)
    assert ring_tone(toned, source, width=8) > 3
    assert frame(toned, source, limit=16).value > 1.15


def test_blurred_ring_reads_below_one(source):
    cs = crops(source, 30, 64, seed=1)
    ring = edge_distance((64, 64)) < 8
    blurred = []
    for c in cs:
        b = ndimage.gaussian_filter(c, sigma=(3, 3, 0))
        c = c.copy()
        c[ring] = b[ring]
        blurred.append(c)
    assert frame(blurred, source, limit=16).low < 0.8


def test_duplicates_of_the_template_and_of_each_other(source):
    cs = crops(source, 6, 32, seed=4)
    t = cs[0]
    tiles = [cs[1], t + 0.2 / 255, cs[2], cs[1].copy(), cs[3], cs[4]]
    d = duplicates(tiles, t)
    assert d.of_template == (1,)
    assert d.pairs == ((0, 3),)
    assert d.count == 2
    assert duplicates(cs[1:], t).count == 0


def test_template_share_counts_exact_pixels(source):
    t = source[:20, :20]
    c = t.copy()
    c[5:15, 5:15] = 1 - c[5:15, 5:15]  # 100 of 400 pixels changed
    c[0, 0] += 0.1 / 255  # within half a step: still the template's
    assert template_share([c, t], t).tolist() == pytest.approx([0.75, 1.0])


def test_lattice_spectra_equal_the_assembled_image_dft():
    rng = np.random.default_rng(1)
    stack = rng.random((5, 6, 10))
    layout = rng.integers(0, 5, (4, 8))
    image = np.block([[stack[layout[i, j]] for j in range(8)] for i in range(4)])
    h, m = _harmonic_spectra(stack, layout)
    assert 10 * np.log10(h / m) == pytest.approx(lattice_db(image, (6, 10)), rel=1e-6)


def test_lattice_sees_a_shared_ring(source):
    cs = crops(source, 30, 64, seed=1)
    t = cs[0]
    wide = edge_distance((64, 64)) < 10
    shared = []
    for c in cs:
        c = c.copy()
        c[wide] = t[wide]
        shared.append(c)
    lat = lattice(shared, source, template=t, margin=1, rng=0)
    assert lat.above > 3.0
    thin = lattice(cs, source, template=t, margin=1, rng=0)
    assert thin.above < lat.above - 3.0


def test_validation(source):
    cs = crops(source, 3, 32, seed=0)
    with pytest.raises(ValueError, match="empty"):
        frame([], source, limit=4)
    with pytest.raises(ValueError, match="one size"):
        duplicates([cs[0], cs[1][:20]])
    with pytest.raises(ValueError, match="larger than the source"):
        ring_tone([np.zeros((300, 300))], source, width=4)
    with pytest.raises(ValueError, match="even"):
        lattice(cs, source, template=cs[0], margin=1, grid=(3, 4))
    with pytest.raises(ValueError, match="no centre"):
        ring_tone(cs, source, width=16)


def test_tileset_quality_and_its_warnings_in_words(source):
    from engine.metrics import quality_warnings, tileset_quality

    cs = crops(source, 30, 64, seed=1)
    t = crops(source, 1, 64, seed=9)[0]
    clean = tileset_quality(cs, source, template=t, ring=8, margin=1)
    assert set(clean) >= {"frame", "ring_tone", "duplicates", "lattice", "template_share"}
    assert quality_warnings(clean) == []
    ring = edge_distance((64, 64)) == 5
    framed = [np.where(ring[..., None], c * 0.5, c) for c in cs]
    words = quality_warnings(tileset_quality(framed, source, template=t, ring=8, margin=1))
    assert any(w.startswith("the tiles show a frame") for w in words)


def test_quality_warnings_suggest_flatten_lighting_only_while_it_is_off():
    from engine.metrics import quality_warnings

    q = {"frame": 1.3, "ring_tone": 1.5, "duplicates": 0, "lattice": 0.0}
    off, on = quality_warnings(q), quality_warnings(q, flattened=True)
    assert [w.split(":")[-1] for w in off] == [
        " try Flatten lighting, a wider patch search or a smaller patch ring",
        " try Flatten lighting or another template position",
    ]
    assert all("although Flatten lighting is on: try" in w for w in on), on
    assert not any("try Flatten lighting" in w for w in on), on


def test_the_per_tile_pieces_make_the_frame_and_the_ring_tone(source):
    """What benchmarks/set_bound.py measures of each grid candidate: the tiles' own gradient
    profiles (their mean is the frame's) and ring steps (their mean over the crops' is the
    ring tone)."""
    from engine.tileset_metrics import frame_profiles, ring_reference, ring_steps

    tiles = crops(source, 6, 48, seed=5)
    ring = edge_distance((48, 48)) < 4
    tiles[0][ring] *= 0.5  # one tile's ring darkened: the tiles differ
    f = frame(tiles, source, limit=8)
    each = frame_profiles(tiles, limit=8)
    assert each.shape == (6, 8) and not np.allclose(each[0], each[1])
    np.testing.assert_allclose(each.mean(axis=0), f.profile, rtol=1e-12)
    steps, ref = ring_steps(tiles, width=4), ring_reference(source, (48, 48), width=4)
    assert steps.shape == (6,) and steps[0] > steps[1:].max()
    assert ring_tone(tiles, source, width=4) == pytest.approx(steps.mean() / ref, rel=1e-12)
