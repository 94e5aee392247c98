"""Index matrices and tiled synthesis (ALGORITHMS.md §1.8)."""

import numpy as np
import pytest

from engine.tiles import CandidateTile, assemble, random_layout


def test_layout_shape_range_and_seed():
    a = random_layout(5, 6, 7, rng=3)
    assert a.shape == (6, 7) and a.dtype == np.int64
    assert a.min() >= 0 and a.max() <= 4
    np.testing.assert_array_equal(a, random_layout(5, 6, 7, rng=3))
    assert not np.array_equal(a, random_layout(5, 6, 7, rng=4))
    assert set(np.unique(random_layout(3, 20, 20, rng=0))) == {0, 1, 2}


@pytest.mark.parametrize("n", [2, 3, 8])
def test_no_equal_neighbours(n):
    for seed in range(5):
        m = random_layout(n, 9, 11, rng=seed, no_equal_neighbours=True)
        assert (m[:, 1:] != m[:, :-1]).all() and (m[1:] != m[:-1]).all()


def test_weights_set_frequencies():
    m = random_layout(4, 100, 100, rng=1, weights=[0, 1, 1, 2])
    counts = np.bincount(m.ravel(), minlength=4) / m.size
    assert counts[0] == 0
    np.testing.assert_allclose(counts[1:], [0.25, 0.25, 0.5], atol=0.02)
    m = random_layout(4, 30, 30, rng=1, weights=[0, 1, 0, 3], no_equal_neighbours=True)
    assert set(np.unique(m)) == {1, 3}
    assert (m[:, 1:] != m[:, :-1]).all() and (m[1:] != m[:-1]).all()


def test_layout_bad_input():
    with pytest.raises(ValueError, match="at least two tiles"):
        random_layout(1, 2, 2, no_equal_neighbours=True)
    assert random_layout(1, 1, 1, no_equal_neighbours=True).tolist() == [[0]]
    with pytest.raises(ValueError, match="at least two tiles"):
        random_layout(3, 2, 2, weights=[0, 0, 1], no_equal_neighbours=True)
    with pytest.raises(ValueError, match="one value per tile"):
        random_layout(3, 2, 2, weights=[1, 1])
    with pytest.raises(ValueError, match=">= 0"):
        random_layout(2, 2, 2, weights=[1, -1])
    with pytest.raises(ValueError, match="positive weight"):
        random_layout(2, 2, 2, weights=[0, 0])
    with pytest.raises(ValueError, match="rows"):
        random_layout(2, 0, 2)
    with pytest.raises(TypeError, match="n_tiles"):
        random_layout(2.5, 2, 2)


def test_assemble_arrays_dicts_and_candidates():
    rng = np.random.default_rng(0)
    tiles = [rng.random((4, 5, 3)).astype(np.float32) for _ in range(3)]
    layout = np.array([[0, 2], [1, -1]])
    img = assemble(tiles, layout)
    assert img.shape == (8, 10, 3)
    np.testing.assert_array_equal(img[:4, 5:], tiles[2])
    np.testing.assert_array_equal(img[4:, :5], tiles[1])
    assert (img[4:, 5:] == 0).all()
    cands = [
        CandidateTile(
            index=i,
            tile=t,
            maps={"height": t[:, :, :1]},
            patch_rect=(0, 0, 5, 4),
            patch_origin=(0, 0),
            target_rect=(0, 0, 5, 4),
            loop=np.zeros((0, 2)),
            mask=np.zeros((4, 5), bool),
            alpha=np.zeros((4, 5), np.float32),
        )
        for i, t in enumerate(tiles)
    ]
    np.testing.assert_array_equal(assemble(cands, layout), img)
    np.testing.assert_array_equal(assemble(cands, layout, map_name="height"), img[:, :, :1])
    dicts = [{"albedo": t} for t in tiles]
    np.testing.assert_array_equal(assemble(dicts, layout), img)
    with pytest.raises(ValueError, match="tile ids"):
        assemble(tiles, [[3]])
    with pytest.raises(ValueError, match="all must match"):
        assemble([tiles[0], tiles[1][:2]], [[0, 1]])
    with pytest.raises(ValueError, match="empty"):
        assemble([], [[0]])
