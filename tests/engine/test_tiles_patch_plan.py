"""The global search's spread term (engine.tiles.patch_plan, issue 10's lattice): patches that
do not all resemble the template near the tile edges, but not on periodic textures."""

import importlib

import numpy as np
from scipy import ndimage

from engine.metrics import lattice
from engine.tiles import candidates, make_seamless
from engine.tiles.patch_plan import SPREAD, Spread
from engine.tiles.scale import structure_scale
from tests.engine.test_tiles_patch_search import brick_wall

patch_candidates = importlib.import_module("engine.tiles.candidates")


def streaks(size=384, seed=3):
    """Long vertical streaks of random tone (no period): a band match at the top and bottom
    edges makes a window repeat the template's streaks all the way down."""
    rng = np.random.default_rng(seed)
    x = ndimage.gaussian_filter(rng.random((size, size)), (40, 2.5), mode="reflect")
    x = (x - x.min()) / (x.max() - x.min())
    return x.astype(np.float32)[..., None].repeat(3, axis=2)


def test_resemblance_is_each_windows_correlation_with_the_set():
    """Oracle: the FFT term equals 2 <A - mean(A), W> / (pixels x variance) by brute force."""
    rng = np.random.default_rng(0)
    L = rng.random((70, 90))
    sp = Spread(L, (30, 40), weight=0.7)
    assert sp.f == 1
    sp.add(rng.random((30, 40)))
    sp.add_origin((5, 17))
    ys, xs = np.mgrid[0:41, 0:51]
    got = sp.resemblance(ys.ravel(), xs.ravel())
    A = sp.A - sp.A.mean()
    want = [
        0.7 * 2 * np.sum(A * L[y : y + 30, x : x + 40]) / (30 * 40 * L.var())
        for y, x in zip(ys.ravel(), xs.ravel(), strict=True)
    ]
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def windows(S, st, cands, m=1):
    """The candidates' source windows whole, with only the template's outer m px."""
    T = np.asarray(st.tile)
    h, w = T.shape[:2]
    out = []
    for c in cands:
        y, x = c.patch_origin
        q = S[y : y + h, x : x + w].copy()
        q[:m], q[-m:], q[:, :m], q[:, -m:] = T[:m], T[-m:], T[:, :m], T[:, -m:]
        out.append(q)
    return out


def test_spread_keeps_the_windows_from_repeating_the_templates_structure():
    """On long streaks the band match alone picks windows that continue the template's
    streaks through the whole tile (their layout reads a lattice far above the floor); with
    the spread term the same search picks windows whose layout stays near the floor."""
    S = streaks()
    assert not any(structure_scale(S).periodic)
    st = make_seamless(S, (40, 60, 96, 96), overlap=10)
    figures = {}
    for spread in (0.0, SPREAD):
        cands = candidates(S, st, 20, rng=0, spread=spread, workers=1)
        assert len(cands) == 20
        figures[spread] = lattice(windows(S, st, cands), S, template=st.tile, margin=1).above
    assert figures[0.0] > 3.0  # measured +4.3 dB (with the tone term; +7.1 without)
    assert figures[SPREAD] < figures[0.0] - 3.0  # measured +0.4 dB at 0.25


def test_periodic_textures_keep_the_band_match_alone():
    """On running-bond bricks every patch must keep the template's courses: no spread term,
    the same patches as with spread 0."""
    S = brick_wall()
    st = make_seamless(S, (20, 8, 96, 96), overlap=10)
    setup = patch_candidates.CandidateSetup(
        S, st, patch_size=None, patch_overlap=None, margin=1, neighbourhood=5, seam=None,
        excluded=None, maps=None, weights=None,
    )  # fmt: skip
    assert setup.spread_term() is None
    a = candidates(S, st, 8, rng=1, workers=1)
    b = candidates(S, st, 8, rng=1, workers=1, spread=0)
    assert [c.patch_origin for c in a] == [c.patch_origin for c in b]
