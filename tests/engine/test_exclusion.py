import numpy as np
import pytest

from engine.exclusion import box_sums, exclusion_mask, valid_anchors


def _brute_valid(ex, bh, bw, eh=0, ew=0):
    h, w = ex.shape
    out = np.zeros((h - bh - eh + 1, w - bw - ew + 1), bool)
    for y in range(out.shape[0]):
        for x in range(out.shape[1]):
            out[y, x] = not ex[y : y + bh + eh, x : x + bw + ew].any()
    return out


@pytest.mark.parametrize("ext", [(0, 0), (2, 3)])
def test_valid_anchors_matches_brute_force(ext):
    rng = np.random.default_rng(0)
    ex = rng.random((23, 31)) < 0.01
    got = valid_anchors(ex, (5, 4), extension=ext)
    np.testing.assert_array_equal(got, _brute_valid(ex, 5, 4, *ext))


def test_single_pixel_invalidates_the_right_quadrant():
    # Bhatia's scan marks anchors to the left/below; the anchors really invalid are those
    # whose block covers the pixel: rows y-bh+1..y, cols x-bw+1..x (ALGORITHMS §4 FIX).
    ex = np.zeros((20, 20), bool)
    ex[10, 12] = True
    v = valid_anchors(ex, (4, 3))
    bad = np.argwhere(~v)
    assert bad[:, 0].min() == 7 and bad[:, 0].max() == 10
    assert bad[:, 1].min() == 10 and bad[:, 1].max() == 12
    assert len(bad) == 12


def test_box_sums_counts():
    m = np.ones((5, 6), bool)
    np.testing.assert_array_equal(box_sums(m, (2, 3)), np.full((4, 4), 6))
    assert box_sums(m, (6, 1)).size == 0


def test_exclusion_mask_color_range_and_paint():
    img = np.zeros((4, 5, 3), np.float32)
    img[1] = (0.9, 0.1, 0.1)  # a red row
    ex = exclusion_mask(img, color_range=((0.8, 0, 0), (1, 0.2, 0.2)))
    assert ex[1].all() and ex.sum() == 5
    painted = np.zeros((4, 5), bool)
    painted[3, 4] = True
    ex2 = exclusion_mask(img, color_range=((0.8, 0, 0), (1, 0.2, 0.2)), painted=painted)
    assert ex2.sum() == 6 and ex2[3, 4]
    # scalar bounds apply to every channel; uint8 input is scaled to [0, 1]
    u8 = (img * 255).astype(np.uint8)
    assert exclusion_mask(u8, color_range=(0.0, 0.05)).sum() == 15
    # RGB bounds on a gray image: gray replicated
    gray = np.full((3, 3), 0.5, np.float32)
    assert exclusion_mask(gray, color_range=((0.4, 0.4, 0.4), (0.6, 0.6, 0.6))).all()


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"color_range": ((0, 0), (1, 1))}, "color_range lo"),
        ({"color_range": ((0.5,) * 3, (0.1,) * 3)}, "lo must be <= hi"),
        ({"color_range": (0, 1, 2)}, "pair"),
        ({"painted": np.zeros((2, 2), bool)}, "painted"),
    ],
)
def test_exclusion_mask_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        exclusion_mask(np.zeros((4, 5, 3)), **kwargs)


def test_valid_anchors_errors():
    with pytest.raises(ValueError, match="block_shape"):
        valid_anchors(np.zeros((4, 4), bool), (0, 2))
    with pytest.raises(ValueError, match="extension"):
        valid_anchors(np.zeros((4, 4), bool), (2, 2), extension=(-1, 0))
    assert valid_anchors(np.zeros((4, 4), bool), (5, 2)).size == 0
