"""The cut beside the fixed margin (engine/tiles/patch_stitch.py): a structure the template
holds just inside its edge is not kept by every candidate."""

import numpy as np
import pytest

from engine.stitch import PATCH_SEAM
from engine.tiles.patch_stitch import continuing_margin, stitch_patch
from engine.tiles.seamless import MAIN
from tests.engine.helpers import smooth_texture


def test_continuing_margin_changes_only_the_first_free_pixels():
    e = np.random.default_rng(0).random((12, 10))
    for m in (1, 2):
        out = continuing_margin(e, m)
        h, w = e.shape
        changed = out != e
        r, c = np.mgrid[0:h, 0:w]
        d = np.minimum.reduce([r, c, h - 1 - r, w - 1 - c])
        assert not changed[d != m].any()
        # each first free pixel costs the smaller of its own error and its outer neighbour's
        np.testing.assert_array_equal(
            out[m, m + 1 : w - m - 1], np.minimum(e[m], e[m - 1])[m + 1 : w - m - 1]
        )
        np.testing.assert_array_equal(
            out[h - 1 - m, m + 1 : w - m - 1], np.minimum(e[h - 1 - m], e[h - m])[m + 1 : w - m - 1]
        )
        np.testing.assert_array_equal(
            out[m + 1 : h - m - 1, m], np.minimum(e[:, m], e[:, m - 1])[m + 1 : h - m - 1]
        )
        np.testing.assert_array_equal(
            out[m + 1 : h - m - 1, w - 1 - m],
            np.minimum(e[:, w - 1 - m], e[:, w - m])[m + 1 : h - m - 1],
        )
        assert (out <= e).all()
    np.testing.assert_array_equal(continuing_margin(e, 0), e)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_line_just_inside_the_templates_edge_is_not_kept(seed):
    """The template's window holds a dark line 1-2 px inside its top edge (a plank's butt
    joint, a stroke along the edge); the patch is the same texture without it. A cut judged
    by the pixel error alone goes round the line (dark against light costs a lot) and keeps
    it; judged by how the patch continues the margin, the cut runs beside the margin and the
    patch replaces the line."""
    rng = np.random.default_rng(seed)
    q = smooth_texture((64, 64), seed=seed)
    u = np.clip(q + rng.normal(0, 0.01, q.shape), 0, 1).astype(np.float32)
    u[1:3, 8:56] *= 0.2  # the line: rows 1-2 (the margin is row 0)
    ring, margin = 8, 1
    r, c = np.mgrid[0:64, 0:64]
    d = np.minimum.reduce([r, c, 63 - r, 63 - c])
    depth = np.where(d < ring, np.clip((d - margin) / (ring - 1 - margin), 0, 1), 0.0)

    def stitched(continue_margin):
        out, cut = stitch_patch(
            {MAIN: q},
            {MAIN: u},
            ring=ring,
            margin=margin,
            seam=PATCH_SEAM,
            weights=None,
            outward=0.7,
            depth=depth,
            continue_margin=continue_margin,
        )
        return out[MAIN]

    def line_kept(out):  # fraction of the line's pixels still dark
        return float((out[1:3, 8:56].mean(axis=2) < 0.5 * q[1:3, 8:56].mean(axis=2)).mean())

    assert line_kept(stitched(False)) > 0.8
    assert line_kept(stitched(True)) < 0.2
