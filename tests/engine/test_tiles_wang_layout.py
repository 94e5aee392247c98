"""Random valid Wang layouts."""

import numpy as np
import pytest

from engine.tiles.wang import canonical_signatures
from engine.tiles.wang_layout import layout_mismatches, wang_layout

SIGS2 = canonical_signatures(2)


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("wrap", [False, True])
def test_layouts_are_valid_and_seeded(k, wrap):
    sigs = canonical_signatures(k)
    m = wang_layout(sigs, 9, 7, rng=3, wrap=wrap)
    assert m.shape == (9, 7) and m.dtype == np.int64
    assert layout_mismatches(sigs, m, wrap=wrap) == 0
    np.testing.assert_array_equal(m, wang_layout(sigs, 9, 7, rng=3, wrap=wrap))
    assert not np.array_equal(m, wang_layout(sigs, 9, 7, rng=4, wrap=wrap))
    assert len(np.unique(m)) > len(sigs) // 2  # every fitting tile is drawn


def test_mismatches_count_broken_joints():
    m = wang_layout(SIGS2, 4, 4, rng=0)
    assert layout_mismatches(SIGS2, m) == 0
    bad = m.copy()
    # a tile whose west colour differs from its left neighbour's east colour
    want = 1 - SIGS2[m[1, 0]][1]
    bad[1, 1] = next(i for i, s in enumerate(SIGS2) if s[3] == want)
    assert layout_mismatches(SIGS2, bad) >= 1
    holes = m.copy()
    holes[2, 2] = -1
    assert layout_mismatches(SIGS2, holes) == 0


def test_weights_steer_the_draw_and_zero_never_appears():
    w = np.ones(16)
    w[[0, 5]] = 0
    w[10] = 50
    m = wang_layout(SIGS2, 20, 20, rng=1, weights=w)
    assert layout_mismatches(SIGS2, m) == 0
    assert not np.isin(m, [0, 5]).any()
    counts = np.bincount(m.ravel(), minlength=16)
    assert counts[10] == counts.max()


def test_no_equal_neighbours():
    m = wang_layout(SIGS2, 12, 12, rng=2, no_equal_neighbours=True)
    assert layout_mismatches(SIGS2, m) == 0
    assert (m[:, 1:] != m[:, :-1]).all() and (m[1:] != m[:-1]).all()


def test_incomplete_sets_fail_with_the_cell_and_colours():
    sigs = [s for s in SIGS2 if s[3] == 0]  # no tile with a west colour 1
    with pytest.raises(ValueError, match=r"no tile with a positive weight fits cell \(0, \d\)"):
        wang_layout(sigs, 3, 8, rng=0)
    with pytest.raises(ValueError, match="signatures must be"):
        wang_layout([(0, 1, 2)], 2, 2)
