"""The template search's detail term and the source's stationarity check (issue 10, item 3)."""

import warnings

import numpy as np
import pytest
from scipy import ndimage

from engine.metrics import detail_ratio
from engine.tiles import find_template, make_seamless
from engine.tiles.detail import DetailTerm
from engine.tiles.stationarity import DETAIL_LIMIT, LIGHTING_LIMIT, check_stationarity
from tests.engine.test_tiles_template import brute_energy, brute_reference


def noise(shape=(160, 200), sigma=1.2, seed=0):
    rng = np.random.default_rng(seed)
    n = ndimage.gaussian_filter(rng.standard_normal((*shape, 3)), (sigma, sigma, 0), mode="wrap")
    return np.clip(0.5 + 0.12 * n / n.std(), 0, 1).astype(np.float32)


def half_blurred(seed=0):
    """Sharp texture on the right, the same texture blurred (depth of field) on the left."""
    S = noise(seed=seed)
    B = ndimage.gaussian_filter(S, (3, 3, 0))
    S[:, :100] = B[:, :100]
    return S


def test_energy_and_reference_match_brute_force():
    S = noise((30, 26))
    term = DetailTerm.of(S, 1.0)
    np.testing.assert_allclose(term.E, brute_energy(S), rtol=1e-5, atol=1e-9)
    for hf, wf in ((10, 8), (30, 5), (3, 26)):
        assert term.reference(hf, wf)[0] == pytest.approx(brute_reference(term.E, hf, wf))
    big = noise((150, 90))
    term = DetailTerm.of(big, 1.0)  # more starts than the grid holds: a sample of them
    assert term.reference(20, 30)[0] == pytest.approx(brute_reference(term.E, 20, 30))
    assert np.isnan(term.reference(151, 30)[0])
    assert DetailTerm.of(S, 0) is None


def test_detail_term_keeps_the_template_out_of_the_blurred_part():
    S = half_blurred()
    kw = dict(tile_min=48, tile_max=48, overlap=6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        paper = find_template(S, detail_weight=0, **kw)
        ours = find_template(S, **kw)
    # without the term the search drifts into the blurred half (a low mismatch is easy there)
    assert paper.rect[0] + paper.rect[2] + 6 <= 100
    assert ours.rect[0] >= 100 - 0.15 * 54 and ours.detail > 0.85  # (almost) all sharp
    for t, low in ((paper, True), (ours, False)):
        d = detail_ratio(make_seamless(S, t).tile, S[:, 100:])
        assert (d < 0.5) if low else (d > 0.85)


def test_stationary_texture_passes_the_check():
    st = check_stationarity(noise())
    assert st.lighting < LIGHTING_LIMIT / 2 and st.detail < DETAIL_LIMIT / 2
    assert st.warnings == ()


def test_a_lighting_gradient_is_reported():
    S = noise()
    ramp = np.linspace(0.6, 1.4, S.shape[1], dtype=np.float32)[None, :, None]
    st = check_stationarity(S * ramp)
    assert st.lighting > LIGHTING_LIMIT and st.detail < DETAIL_LIMIT
    assert len(st.warnings) == 1 and "Flatten lighting" in st.warnings[0]


def test_varying_sharpness_is_reported_and_reaches_the_template():
    S = half_blurred()
    st = check_stationarity(S)
    assert st.detail > DETAIL_LIMIT and st.lighting < LIGHTING_LIMIT
    assert len(st.warnings) == 1 and "sharpness varies" in st.warnings[0]
    with pytest.warns(UserWarning, match="sharpness varies"):
        t = find_template(S, tile_min=48, tile_max=48, overlap=6)
    assert any("sharpness varies" in w for w in t.warnings)
    empty = np.full((60, 80, 3), 0.5, np.float32)  # an empty margin beside the texture
    empty[:, 40:] = noise((60, 40))
    assert ["no detail at all" in w for w in check_stationarity(empty).warnings] == [True]
    assert check_stationarity(np.zeros((10, 10))).warnings == ()  # too small to judge
