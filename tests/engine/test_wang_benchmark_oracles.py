"""Oracles behind the Wang benchmark's detail and lattice figures (benchmarks/wang*.py)."""

import numpy as np
from scipy import ndimage

from benchmarks.wang import crop_detail
from benchmarks.wang_lattice import continued_lattice
from benchmarks.wang_oracle import Field, ideal_set
from engine.metrics import detail_ratio, lattice
from engine.tiles.wang_layout import wang_layout


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
