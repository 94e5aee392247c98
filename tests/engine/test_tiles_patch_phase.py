"""Patch sources in the template's phase on periodic textures (engine/tiles/patch_phase.py)."""

import itertools

import numpy as np
import pytest

from engine.reference_crops import phase_axes
from engine.tiles import candidates, make_seamless
from engine.tiles.patch_phase import patch_phase_class, phase_class, window_maxima
from engine.tiles.scale import Scale
from tests.engine.helpers import smooth_texture

PITCH = 32  # shelf period (px)


def shelves(size=256, seed=1, board=8):
    """Shelves every PITCH px (a board with a 3-px stripe pattern) holding shaded discs of four
    colours at random spacing (the evaluation set's shelves at half the scale): the board's
    phase barely moves a ring-band match, the discs' colours move it a lot."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    img = np.ones((size, size, 3)) * np.array([0.30, 0.26, 0.22])
    img *= (1 + 0.05 * rng.standard_normal((size, size)))[..., None]
    palette = np.array(
        [[0.8, 0.25, 0.2], [0.25, 0.55, 0.75], [0.85, 0.75, 0.3], [0.35, 0.65, 0.35]]
    )
    for r0 in range(0, size, PITCH):
        x = rng.uniform(0, 5)
        while x < size + 10:
            rad = rng.uniform(PITCH / 6, PITCH / 4)
            d = np.hypot(yy - (r0 + PITCH - board - rad - 1), xx - x - rad)
            shade = np.clip(1.15 - 0.5 * d / rad, 0.6, 1.2)
            inside = d < rad
            img[inside] = palette[rng.integers(4)] * rng.uniform(0.85, 1.1) * shade[inside, None]
            x += 2 * rad + rng.uniform(1, 4)
        band = (yy >= r0 + PITCH - board) & (yy < r0 + PITCH)
        img[band] = np.array([0.5, 0.36, 0.22]) * (0.9 + 0.1 * ((yy[band] - r0) % 3))[:, None]
    return np.clip(img, 0, 1).astype(np.float32)


def brute_window_maxima(score, span):
    """The positions that are the maximum of the span window around them (centred, moved
    inside the array at its borders), one by one."""
    H, W = score.shape
    sy, sx = min(span[0], H), min(span[1], W)
    out = np.zeros(score.shape, bool)
    for y, x in itertools.product(range(H), range(W)):
        y0 = min(max(0, y - sy // 2), H - sy)
        x0 = min(max(0, x - sx // 2), W - sx)
        out[y, x] = score[y, x] >= score[y0 : y0 + sy, x0 : x0 + sx].max()
    return out


@pytest.mark.parametrize("span", [(1, 1), (4, 1), (1, 5), (6, 3), (7, 8), (40, 2)])
@pytest.mark.parametrize("seed", [0, 1])
def test_window_maxima_equal_the_brute_force(span, seed):
    score = np.random.default_rng(seed).random((23, 17))
    score[5, 5] = score[5, 6]  # a tie
    np.testing.assert_array_equal(window_maxima(score, span), brute_window_maxima(score, span))


def test_the_phase_class_is_every_period_around_the_template():
    S = shelves()
    y0, x0, h, w = 40, 20, 4 * PITCH, 100
    T = S[y0 : y0 + h, x0 : x0 + w]
    scale = Scale(float(PITCH), 15.0, (True, False))
    assert phase_axes(scale, (h, w)) == (True, False)
    mask = phase_class(S, T, scale=scale)
    assert mask.shape == (S.shape[0] - h + 1, S.shape[1] - w + 1)
    rows = np.flatnonzero(mask.any(axis=1))
    off = (rows - y0 + PITCH // 2) % PITCH - PITCH // 2
    assert np.abs(off).max() <= 1, rows  # aligned rows (±1 px) only
    assert mask[y0, x0] and set(range(-1, 2)) <= set(off)
    assert mask.all(axis=1)[rows].mean() > 0.5  # x is free: most columns of an aligned row
    # no period the tile holds whole (or none at all): no phase to keep
    assert phase_class(S, T, scale=Scale(float(PITCH), 15.0, (False, False))) is None
    assert phase_class(S, S[:, :100][y0 : y0 + 100], scale=scale) is None  # 100 = 3.1 periods
    noise = smooth_texture((96, 96), seed=2)
    assert phase_class(noise, noise[:40, :40]) is None


def test_patch_positions_follow_the_tile_positions():
    S = shelves()
    T = S[40 : 40 + 4 * PITCH, 20:120]
    scale = Scale(float(PITCH), 15.0, (True, False))
    tile = phase_class(S, T, scale=scale)
    patch = patch_phase_class(S, T, (T.shape[0] - 10, T.shape[1] - 6), scale=scale)
    assert patch.shape == (S.shape[0] - T.shape[0] + 11, S.shape[1] - T.shape[1] + 7)
    np.testing.assert_array_equal(patch[5 : 5 + tile.shape[0], 3 : 3 + tile.shape[1]], tile)
    assert not patch[:5].any() and not patch[:, :3].any()


def offsets(cands, st):
    x0, y0 = st.rect[:2]
    dy = np.array([c.patch_origin[0] - y0 for c in cands])
    return (dy + PITCH // 2) % PITCH - PITCH // 2


def test_candidates_keep_the_templates_phase_on_a_periodic_texture():
    S = shelves()
    st = make_seamless(S, (20, 40, 100, 4 * PITCH), overlap=10)
    scale = Scale(float(PITCH), 15.0, (True, False))
    cands = candidates(S, st, 12, rng=0, workers=1, scale=scale)
    assert len(cands) == 12
    assert np.abs(offsets(cands, st)).max() <= 1
    # the ring band alone (no period known) draws patches off the shelves' phase
    free = candidates(S, st, 12, rng=0, workers=1, scale=Scale(float(PITCH), 15.0, (False, False)))
    assert np.abs(offsets(free, st)).max() >= 2


@pytest.mark.filterwarnings("ignore:made 51 of 60")
def test_the_phase_class_fills_up_with_other_positions_when_it_runs_out():
    S = shelves()
    st = make_seamless(S, (20, 40, 100, 4 * PITCH), overlap=10)
    scale = Scale(float(PITCH), 15.0, (True, False))
    cands = candidates(S, st, 60, rng=0, workers=1, scale=scale, min_distance=16)
    aligned = np.abs(offsets(cands, st)) <= 1
    assert aligned[: aligned.sum()].all() and not aligned.all()  # aligned ones first
