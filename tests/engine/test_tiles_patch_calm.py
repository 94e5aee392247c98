"""Calm windows (engine.tiles.patch_plan.calm_windows, issue 10's pair line): a patch much
calmer than the template's shared wrap joint is not used, so the joint does not show beside
a tile; windows no calmer than the texture's own are kept."""

import importlib
import warnings

import numpy as np
import pytest

from benchmarks import evalset
from engine.metrics import luminance
from engine.settings import TilesetSettings
from engine.tiles import candidates
from engine.tiles.candidate_kernels import coarse_interior_steps, to_origins
from engine.tiles.pipeline import tileset

patch_plan = importlib.import_module("engine.tiles.patch_plan")


def test_interior_steps_equal_the_brute_force():
    """Oracle: k = 1 is exact; k = 4 follows it (every 4th row / column, origins on a 4 px
    grid)."""
    rng = np.random.default_rng(0)
    img = rng.random((90, 110, 3)).astype(np.float32)
    img[30:70, 20:60] *= 0.1  # a calm block
    L = luminance(img)
    h, w, r = 40, 50, 6
    sy, sx = coarse_interior_steps(img, (h, w), r, 1)
    assert sy.shape == sx.shape == (90 - h + 1, 110 - w + 1)
    for y, x in [(0, 0), (11, 23), (50, 60), (25, 17)]:
        want_y = np.abs(np.diff(L[y + r : y + h - r + 1, x + r : x + w - r], axis=0)).mean()
        want_x = np.abs(np.diff(L[y + r : y + h - r, x + r : x + w - r + 1], axis=1)).mean()
        assert sy[y, x] == pytest.approx(want_y, rel=1e-5)
        assert sx[y, x] == pytest.approx(want_x, rel=1e-5)
    cy, cx = (to_origins(m, img.shape, (h, w), 4) for m in coarse_interior_steps(img, (h, w), r, 4))
    assert cy.shape == sy.shape
    assert np.corrcoef(cy.ravel(), sy.ravel())[0, 1] > 0.9
    assert np.corrcoef(cx.ravel(), sx.ravel())[0, 1] > 0.9


@pytest.fixture(scope="module")
def page():
    S = evalset.load("page").astype(np.float32)[..., None] / 255
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = tileset(S, TilesetSettings(seed=0))
    return S, res


def self_pair_ratios(tiles, template):
    """Issue 10's pair ratio of every tile beside itself, horizontally: the shared joint's
    step over the tile's own mean step."""
    T = np.asarray(template, np.float64)
    joint = np.abs(T[:, -1] - T[:, 0]).mean()
    return np.array(
        [joint / np.abs(np.diff(np.asarray(t, np.float64), axis=1)).mean() for t in tiles]
    )


def test_page_patches_are_not_calmer_than_the_shared_joint(page, monkeypatch):
    """The public page: its template's left/right joint crosses a line of text, and without
    the rule the band match draws blank-paper patches (pair ratio up to 4.4 beside itself);
    with it every candidate keeps the pair line (1.6)."""
    S, res = page
    st, s = res.seamless, res.settings
    ratios = self_pair_ratios([c.tile for c in res.candidates], st.tile)
    assert len(res.candidates) >= 20
    assert ratios.max() < 1.6
    monkeypatch.setattr(patch_plan, "CALM", 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        old = candidates(S, st, 30, patch_overlap=s.patch_overlap, rng=0, workers=1)
    assert self_pair_ratios([c.tile for c in old], st.tile).max() > 2.5


def test_no_calm_windows_where_the_joint_is_clean(page):
    """A joint smoother than the blank paper (whose steps are ~0.0012) excludes nothing."""
    S, res = page
    st = res.seamless
    T = np.asarray(st.tile).copy()
    rng = np.random.default_rng(1)
    T[:, -1] = T[:, 0] + rng.normal(0, 5e-4, T[:, 0].shape)  # smoother than the paper
    T[-1] = T[0] + rng.normal(0, 5e-4, T[0].shape)
    st2 = type(st)(**{**{f: getattr(st, f) for f in st.__dataclass_fields__}, "tile": T})
    assert patch_plan.calm_windows(res_setup(S, st2)) is None
    assert patch_plan.calm_windows(res_setup(S, st)).any()  # the real joint: blank paper is calm


def res_setup(S, st):
    from engine.tiles.candidates import CandidateSetup  # the setup under test

    return CandidateSetup(
        S,
        st,
        patch_size=None,
        patch_overlap=7,
        margin=1,
        neighbourhood=5,
        seam=None,
        excluded=None,
        maps=None,
        weights=None,
    )
