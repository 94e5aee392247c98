"""Candidates whose cut shows are blended in the gradient domain (issue 10: frame)."""

import warnings

import numpy as np

from engine.tiles import candidates, make_seamless
from engine.tiles.candidate_kernels import cut_shows, natural_step
from tests.engine.helpers import smooth_texture


def test_a_planted_step_along_a_cut_shows_and_a_seamless_cut_does_not():
    rng = np.random.default_rng(0)
    lum = rng.random((64, 64)) * 0.2
    mask = np.zeros((64, 64), dtype=bool)
    mask[8:56, 8:56] = True
    natural = natural_step(lum)
    assert not cut_shows(lum, mask, natural, 1.5)  # the same texture on both sides
    stepped = lum + 0.3 * mask  # a tone step of 0.3 along the cut
    assert cut_shows(stepped, mask, natural, 1.5)
    assert not cut_shows(stepped, np.zeros_like(mask), natural, 1.5)  # no cut, nothing shows


def test_cuts_that_show_are_blended_and_the_border_is_kept():
    S = smooth_texture((160, 160), 3, 4, 4.0)  # smooth: no hard cut near the margin hides
    st = make_seamless(S, (20, 20, 64, 64), overlap=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        blended = candidates(S, st, 8, rng=1, workers=1)
        hard = candidates(S, st, 8, rng=1, workers=1, seam_shows=0)
    flags = [c.scores["gradient_blend"] for c in blended]
    assert any(flags) and not any(c.scores["gradient_blend"] for c in hard)
    T = np.asarray(st.tile)
    for c, h in zip(blended, hard, strict=True):
        t = np.asarray(c.tile)
        assert np.array_equal(t[0], T[0]) and np.array_equal(t[:, -1], T[:, -1])
        if not c.scores["gradient_blend"]:
            assert np.array_equal(t, np.asarray(h.tile))


def test_large_patches_keep_the_hard_cut(monkeypatch):
    """Above SEAM_SHOWS_MAX_PIXELS the re-blend is skipped (its solve would break the speed
    line of 1024 px tiles)."""
    import importlib

    module = importlib.import_module("engine.tiles.candidates")
    monkeypatch.setattr(module, "SEAM_SHOWS_MAX_PIXELS", 64 * 64 - 1)
    S = smooth_texture((160, 160), 3, 4, 4.0)
    st = make_seamless(S, (20, 20, 64, 64), overlap=8)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cands = candidates(S, st, 8, rng=1, workers=1)
    assert not any(c.scores["gradient_blend"] for c in cands)
