"""The Wang interior's gradient-domain correction reaches INTERIOR_REACH rings into the tile
(session 12: screened at 4 rings instead of the candidates' 2, README "Session 12")."""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from engine.tiles.patch_stitch import POISSON_REACH
from engine.tiles.wang import WangSample, WangSetup, make_wang_tile
from engine.tiles.wang_types import INTERIOR_REACH
from engine.tileset_metrics import edge_distance

T = 64
STEP = 0.4  # the window's tone above the edge samples'


def _source() -> np.ndarray:
    """Fine noise on two tones: rows 0-255 at 0.3 (the edge samples), 256-383 at 0.7 (the
    window)."""
    g = np.random.default_rng(0)
    n = ndimage.gaussian_filter(g.standard_normal((384, 256)), 1.5)
    tone = np.where(np.arange(384)[:, None] < 256, 0.3, 0.3 + STEP)
    return np.clip(tone + 0.05 * n / n.std(), 0, 1)[..., None].astype(np.float32)


def _samples() -> list[WangSample]:
    return [
        WangSample("h", 0, (128, 20), 0.0),
        WangSample("h", 1, (128, 150), 0.0),
        WangSample("v", 0, (20, 100), 0.0),
        WangSample("v", 1, (150, 160), 0.0),
    ]


def test_interior_reach_is_wider_than_the_candidates():
    assert INTERIOR_REACH > POISSON_REACH


def test_interior_correction_reaches_three_rings_in():
    """A bright window in a tile whose edge samples are dark: the correction that carries the
    ring's tone into the window fades about INTERIOR_REACH rings in, so three rings from the
    edge more than half of the step is still corrected (screened at 2 rings: about a quarter),
    and the tile's edge pixels stay the samples' own."""
    S = _source()
    ring = WangSetup(S, tile_size=T).ring
    origin = (300, 100)
    tile = make_wang_tile(S, _samples(), 0, tile_size=T, patch_origin=origin, seed=0)
    window = S[origin[0] : origin[0] + T, origin[1] : origin[1] + T, 0]
    correction = window - tile.tile[..., 0]
    d = edge_distance((T, T))
    deep = float(correction[d >= 3 * ring].mean())
    assert deep > 0.5 * STEP
    assert deep < STEP  # the window keeps some of its own tone: still screened
    oy, ox = _samples()[0].offset("n", T)  # signature (0, 0, 0, 0): row 0 is h sample 0's
    np.testing.assert_array_equal(tile.tile[0], S[oy, ox : ox + T])
