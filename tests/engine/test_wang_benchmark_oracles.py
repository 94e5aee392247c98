"""Oracles behind the Wang benchmark's detail and lattice figures (benchmarks/wang*.py)."""

import numpy as np
import pytest
from scipy import ndimage

from benchmarks.wang import crop_detail, crop_frame, pooled_frame, wang_frame
from benchmarks.wang_lattice import continued_lattice
from benchmarks.wang_oracle import Field, ideal_set
from engine.metrics import detail_ratio, frame, lattice
from engine.tiles.wang_layout import wang_layout
from tests.engine.helpers import running_bond


def _crops(S, T, n, seed):
    g = np.random.default_rng(seed)
    H, W = S.shape[:2]
    ys, xs = g.integers(0, H - T + 1, n), g.integers(0, W - T + 1, n)
    return [S[y : y + T, x : x + T] for y, x in zip(ys, xs, strict=True)]


def test_crops_of_a_skewed_source_score_detail_one_against_crop_detail_and_blur_does_not():
    # calm on the left, busy on the right: the median crop is calmer than the whole source,
    # so genuine (unblurred) crops score a raw median well below 1
    rng = np.random.default_rng(0)
    S = rng.random((192, 192, 1))
    S[:, :128] = 0.5 + 0.2 * (S[:, :128] - 0.5)
    T = 32
    crops = _crops(S, T, 16, 1)
    raw = np.median([detail_ratio(c, S) for c in crops])
    ref = crop_detail(S, T)
    assert raw < 0.8
    assert 0.85 < raw / ref < 1.15
    blurred = [ndimage.gaussian_filter(c, (0.7, 0.7, 0)) for c in crops]
    assert np.median([detail_ratio(c, S) for c in blurred]) / ref < 0.5


def test_the_ideal_wang_set_of_a_gaussian_field_sits_on_the_continued_floor():
    # exact draws of a 4 px field given their edges: no construction flaw, yet far above the
    # pasted-pixel floor; the continued floor puts it near 0 and the pasted-edge crops below
    # (means over three fields: one small set's figure moves by about 1 dB)
    figures = []
    for seed in range(3):
        field = Field(4, np.random.default_rng(seed), size=256)
        S = field.draw()[..., None]
        tiles, sigs, floors = ideal_set(field, 32)
        layouts = [wang_layout(sigs, 8, 8, rng=k, no_equal_neighbours=True) for k in range(16)]
        figures.append(
            (
                lattice(tiles, S, margin=1, layouts=layouts).above,
                continued_lattice(tiles, S, layouts=layouts)[2],
                continued_lattice(floors, S, layouts=layouts)[2],
            )
        )
    pasted, ideal, floor = np.mean(figures, axis=0)
    assert pasted > 2.5
    assert abs(ideal) < 1.5
    assert floor < ideal - 1.5


def test_wang_frame_reads_an_aligned_set_of_a_periodic_texture_as_no_frame():
    # crops of a periodic texture all in one phase (what a Wang set continuing the courses
    # across every joint is) have their mortar lines at the same distances from the tile edge:
    # against random-phase crops that reads as a frame, against crops in the set's phase not
    # (the tile, 64 px, holds two courses and one brick: whole periods on both axes)
    rng = np.random.default_rng(0)
    S = running_bond(rng, (384, 384), 32, 64)
    T, y0, x0 = 64, 9, 21  # a phase that puts a mortar line near the tile edge
    g = np.random.default_rng(1)
    ys = y0 + 64 * g.integers(0, 4, 16)
    xs = x0 + 64 * g.integers(0, 4, 16)
    aligned = [S[y : y + T, x : x + T] for y, x in zip(ys, xs, strict=True)]
    assert wang_frame(aligned, S, 16).value < 1.1
    assert frame(aligned, S, limit=16, wrap=False).value > 1.3
    # a stochastic texture keeps its random crops: the same figure as before
    noise = ndimage.gaussian_filter(rng.standard_normal((256, 256)), 2)[..., None]
    crops = _crops(noise, 48, 16, 2)
    assert wang_frame(crops, noise, 12).value == frame(crops, noise, limit=12, wrap=False).value


def test_crop_frame_is_about_one_on_a_stationary_texture_and_counts_genuine_crops():
    rng = np.random.default_rng(3)
    noise = ndimage.gaussian_filter(rng.standard_normal((256, 256)), 2)[..., None]
    assert 0.95 < crop_frame(noise, 48, 12) < 1.1
    # on running bonds the crops lie in one phase: an aligned set, no frame either
    bricks = running_bond(rng, (384, 384), 32, 64)
    assert crop_frame(bricks, 64, 16) < 1.1


def test_pooled_frame_keeps_a_frame_every_set_shows_and_averages_out_chance_peaks():
    # three flawless sets whose profiles each peak by chance at another distance: the median
    # of their maxima reads the chance peak as a frame, their mean profile does not
    flat = np.ones(16)
    chance = [flat.copy() for _ in range(3)]
    for i, d in enumerate((2, 7, 12)):
        chance[i][d] = 1.2
    assert np.median([r.max() for r in chance]) == 1.2
    assert pooled_frame(chance) < 1.1
    # a frame every set has at the same distance (a cut 3 px from the edge) stays in full
    framed = [flat.copy() for _ in range(3)]
    for r in framed:
        r[3] = 1.4
    assert pooled_frame(framed) == pytest.approx(1.4)
    assert pooled_frame([framed[0]]) == framed[0].max()


def test_pooled_crop_frame_is_the_pooled_statistic_of_genuine_sets():
    # one set: the frame of 16 genuine crops (as before); three sets pooled: not above it by
    # more than the draws' noise, and about one on a stationary texture
    rng = np.random.default_rng(5)
    noise = ndimage.gaussian_filter(rng.standard_normal((192, 192)), 2)[..., None]
    one, three = crop_frame(noise, 32, 8), crop_frame(noise, 32, 8, sets=3)
    assert 0.95 < three < 1.08
    assert three <= one + 0.02


def test_continued_floor_in_the_sets_phase_reads_an_aligned_set_lower():
    # aligned crops of running-bond bricks put the courses' harmonics on the lattice's bins;
    # so do crops in their phase (a floor of random phases reads them about 3 dB higher).
    # The continued floor is not exact here (non-Gaussian: aligned crops still read about
    # +2 dB above it); on a stochastic texture the same draws as without a template.
    rng = np.random.default_rng(0)
    S = running_bond(rng, (512, 512), 32, 64)
    g = np.random.default_rng(1)
    ys, xs = 9 + 64 * g.integers(0, 6, 16), 21 + 64 * g.integers(0, 6, 16)
    tiles = [S[y : y + 64, x : x + 64] for y, x in zip(ys, xs, strict=True)]
    layouts = [np.random.default_rng(k).integers(0, 16, (8, 8)) for k in range(8)]
    random_phase = continued_lattice(tiles, S, layouts=layouts)[2]
    in_phase = continued_lattice(tiles, S, layouts=layouts, template=tiles[0])[2]
    assert in_phase < random_phase - 2
    noise = ndimage.gaussian_filter(rng.standard_normal((256, 256)), 2)[..., None]
    crops = _crops(noise, 32, 16, 3)
    plain = continued_lattice(crops, noise, layouts=layouts[:2])
    assert continued_lattice(crops, noise, layouts=layouts[:2], template=crops[0]) == plain
