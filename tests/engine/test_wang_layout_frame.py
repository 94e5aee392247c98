"""Oracles of the layout frame (engine.metrics.layout_frame; benchmarks/wang.py's
layout_wang_frame and crop_layout_frame): tiles read inside their layouts, with their real
neighbours, instead of each tile reflected at its own border (issue 11, session 13)."""

import numpy as np
from scipy import ndimage

from benchmarks.wang import (
    context_frame,
    context_windows,
    crop_layout_frame,
    layout_wang_frame,
    wang_frame,
)
from benchmarks.wang_oracle import Field, ideal_set
from engine.metrics import edge_distance, layout_frame, tile_line_distance
from engine.tiles.wang_layout import wang_layout
from tests.engine.helpers import running_bond


def _noise(seed, size=384, sigma=2.0):
    n = ndimage.gaussian_filter(np.random.default_rng(seed).standard_normal((size, size)), sigma)
    return ((n - n.min()) / np.ptp(n))[..., None]


def _cells(image, T, offset):
    oy, ox = offset
    H, W = image.shape[:2]
    return [
        image[y : y + T, x : x + T]
        for y in range(oy, H - T + 1, T)
        for x in range(ox, W - T + 1, T)
    ]


def test_tile_line_distance_is_edge_distance_inside_every_cell_and_the_border_is_no_line():
    T = 16
    d = tile_line_distance((3 * T, 3 * T), T)
    assert (d[T : 2 * T, T : 2 * T] == edge_distance((T, T))).all()
    # the outer cells count only their inner lines: the image's border is not a tile line
    r, c = np.mgrid[0:T, 0:T]
    assert (d[:T, :T] == np.minimum(T - 1 - r, T - 1 - c)).all()
    shifted = tile_line_distance((40, 40), T, offset=(5, 21))
    assert shifted[5, 30] == 0 and shifted[4, 30] == 0 and shifted[7, 21] == 0
    assert shifted[12, 28] == 7  # 7 px below the line at 5 and right of the one at 21


def test_genuine_source_cut_into_a_grid_reads_one():
    noise = _noise(3)
    for offset in ((0, 0), (5, 11), (17, 3)):
        assert 0.95 < layout_frame([noise], noise, tile=32, limit=8, offset=offset).value < 1.05


def test_a_line_across_the_tile_edge_is_no_frame_in_the_layout_though_reflected_it_is():
    # session 11's case: a mortar line cut by the tile edge reads as a frame when each tile
    # is reflected at its border, yet the source cut into that grid is the texture itself
    rng = np.random.default_rng(0)
    S = running_bond(rng, (384, 384), 32, 64)
    T, offset = 64, (2, 21)  # the mortar rows 0-3 of a course straddle the horizontal lines
    cells = _cells(S, T, offset)
    assert wang_frame(cells, S, 16).value > 1.3
    assert layout_frame([S], S, tile=T, limit=16, offset=offset, template=cells[0]).value < 1.08
    # the same crops measured one by one inside their windows (the benchmark's floor)
    wins = context_windows(S, T, [(y, x) for y in range(2, 321, 64) for x in range(21, 321, 64)])
    assert context_frame(wins, S, T, 16, cells[0]).value < 1.08


def test_a_planted_band_is_caught_as_strongly_as_by_the_reflected_yardstick():
    # every pixel within 3 px of a tile line from elsewhere (continuous across the line, as
    # a Wang tile's edge sample is): a hard cut 3 px inside every tile
    noise = _noise(3)
    T, offset = 32, (5, 11)
    band = (tile_line_distance(noise.shape[:2], T, offset) < 3)[..., None]
    planted = np.where(band, np.roll(noise, (97, 151), axis=(0, 1)), noise)
    new = layout_frame([planted], noise, tile=T, limit=8, offset=offset).value
    old = wang_frame(_cells(planted, T, offset), noise, 8).value
    assert new > 1.15
    assert new > old - 0.02


def test_the_ideal_wang_set_reads_one_in_its_layouts_and_a_planted_ring_is_caught():
    field = Field(4, np.random.default_rng(0), size=256)
    F = field.draw()[..., None]
    tiles, sigs, _ = ideal_set(field, 32)
    lays = [wang_layout(sigs, 8, 8, rng=k, no_equal_neighbours=True) for k in range(8)]
    assert 0.9 < layout_wang_frame(tiles, lays, F, 8).value < 1.05
    assert 0.95 < crop_layout_frame(F, 32, 8) < 1.06
    # the rings 1-2 px inside every tile from random crops: the edge pixels still join
    ring = ((edge_distance((32, 32)) < 3) & (edge_distance((32, 32)) >= 1))[..., None]
    g = np.random.default_rng(1)
    planted = []
    for t in tiles:
        y, x = g.integers(0, 224, 2)
        planted.append(np.where(ring, F[y : y + 32, x : x + 32], t))
    assert layout_wang_frame(planted, lays, F, 8).value > 1.3


def test_the_batch_reads_a_wang_sets_frame_in_its_preview_layout():
    # the batch index's frame of a Wang set (engine.batch.quality.wang_figures): tiles whose
    # edges cut the mortar rows, laid out as they join (the layout is the bricks themselves),
    # read no frame; reflected tile by tile they read 1.3 and more (a false warning)
    from engine.batch.quality import wang_figures

    rng = np.random.default_rng(0)
    S = running_bond(rng, (384, 384), 32, 64)
    T, offset = 64, (2, 21)
    cells = _cells(S, T, offset)  # 5 x 5 cells, row by row
    layout = np.array([[5 * r + c for c in range(4)] for r in range(4)])  # as they lie
    fig = wang_figures(S, cells, band=8, margin=1, layout=layout)
    assert fig["frame"] < 1.1
    assert wang_frame(cells, S, 16).value > 1.3


def test_the_layouts_border_is_left_out():
    # the pixels within the blur's reach of the layout's outer border are not profiled (no
    # reflected or wrapped pixel is read): a 2 px bright stripe along that border moves the
    # figure only through the blur's far tail (4 sigma), where reading the border moves it
    # by 0.07 and more
    noise = _noise(3)
    stripe = noise.copy()
    stripe[:2], stripe[-2:], stripe[:, :2], stripe[:, -2:] = 1.0, 1.0, 1.0, 1.0
    for offset in ((0, 0), (5, 11), (3, 3)):
        plain = layout_frame([noise], noise, tile=32, limit=8, offset=offset)
        framed = layout_frame([stripe], noise, tile=32, limit=8, offset=offset)
        assert np.abs(framed.ratio - plain.ratio).max() < 1e-3
