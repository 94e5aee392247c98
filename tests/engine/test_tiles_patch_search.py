"""The global patch search of the candidates (issue 10): aligned structure, no duplicates,
fewer candidates with a reason rather than repeats."""

import warnings

import numpy as np
import pytest

from engine.events import drain
from engine.metrics import duplicates
from engine.tiles import candidates, iter_candidates, make_candidate, make_seamless
from engine.tiles.candidates import SEARCH_BAND, CandidatesNotice, default_min_distance
from tests.engine.helpers import smooth_texture

COURSE = 16  # brick course height (px); mortar rows are the first 3 of every course


def brick_wall(size=256, seed=0):
    """Running-bond bricks: light mortar rows every COURSE px, head joints shifted per
    course, per-brick tone and grain (no lighting)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size]
    row = yy // COURSE
    shift = (row * 13) % 40
    col = (xx + shift) // 40
    tone = rng.uniform(0.3, 0.5, (row.max() + 1) * 100)[row * 100 + col]
    img = tone + rng.normal(0, 0.02, (size, size))
    joint = ((yy % COURSE) < 3) | (((xx + shift) % 40) < 3)
    img = np.where(joint, 0.85 + rng.normal(0, 0.02, (size, size)), img)
    return np.clip(img, 0, 1).astype(np.float32)[..., None].repeat(3, axis=2)


def mortar_rows(tile, mask, ring):
    """Rows (tile coordinates) whose mean luminance over the patch interior (inside the cut,
    at least ``ring`` px from the tile border) is mortar-bright."""
    h, w = mask.shape
    inner = mask.copy()
    inner[:ring] = inner[-ring:] = False
    inner[:, :ring] = inner[:, -ring:] = False
    lum = tile.mean(axis=2)
    rows = []
    for r in range(h):
        sel = inner[r]
        if sel.sum() >= 8 and np.median(lum[r, sel]) > 0.7:
            rows.append(r)
    return np.array(rows)


def phase_error(rows, template_rows) -> int:
    """Largest distance (px) from a mortar row of the patch to the nearest of the template's
    (rows of the template extended by the course period)."""
    ext = np.concatenate([template_rows + k * COURSE for k in range(-2, 3)])
    return int(max(np.abs(ext[None, :] - rows[:, None]).min(axis=1)))


@pytest.fixture(scope="module")
def wall():
    S = brick_wall()
    st = make_seamless(S, (20, 8, 96, 96), overlap=10)  # 96 = 6 courses: rows wrap in phase
    return S, st


def test_structure_continues_across_the_patch_cut(wall):
    S, st = wall
    ring = 2 * 8
    full = np.ones(st.tile.shape[:2], bool)
    t_rows = mortar_rows(st.tile, full, ring)
    assert len(t_rows) >= 9  # three mortar rows in each of the inner courses
    cands = candidates(S, st, 12, rng=0, workers=1)
    assert len(cands) == 12
    for c in cands:
        rows = mortar_rows(c.tile, c.mask, ring)
        assert len(rows) >= 6
        assert phase_error(rows, t_rows) <= 1, (c.index, c.patch_origin)


def test_the_papers_local_search_cuts_structure(wall):
    """The check above can fail: the paper's random positions (±5 px) land off phase."""
    S, st = wall
    ring = 2 * 8
    t_rows = mortar_rows(st.tile, np.ones(st.tile.shape[:2], bool), ring)
    local = candidates(S, st, 12, rng=0, workers=1, patch_search="local", neighbourhood=1)
    errors = [phase_error(mortar_rows(c.tile, c.mask, ring), t_rows) for c in local]
    assert max(errors) > 1


def test_no_duplicates_template_excluded_and_distance_kept():
    S = smooth_texture((150, 160), 3, 5, 1.5)
    st = make_seamless(S, (30, 25, 64, 60), overlap=8)
    th, tw = st.tile.shape[:2]
    d = default_min_distance((th, tw), (150 - th + 1) * (160 - tw + 1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cands = candidates(S, st, 30, rng=2, workers=2)
    assert duplicates(cands, st.tile).count == 0
    origins = np.array([c.patch_origin for c in cands] + [(25, 30)])  # the template's own
    cheb = np.abs(origins[:, None] - origins[None, :]).max(axis=2)
    np.fill_diagonal(cheb, 10**6)
    assert cheb.min() >= d
    # a re-roll keeps away from the others too
    again = make_candidate(S, st, rng=5, avoid=[c.patch_origin for c in cands[:5]])
    far = np.abs(np.array([c.patch_origin for c in cands[:5]]) - again.patch_origin).max(axis=1)
    assert far.min() >= d


def test_a_small_source_gives_fewer_candidates_and_says_why():
    S = smooth_texture((90, 96), 3, 1, 1.5)
    st = make_seamless(S, (8, 6, 64, 60), overlap=8)
    with pytest.warns(UserWarning, match="made [0-9]+ of 40 candidates"):
        gen = iter_candidates(S, st, 40, rng=0, workers=1, min_distance=10)
        events = []
        cands = drain(gen, events.append)
    notes = [e for e in events if isinstance(e, CandidatesNotice)]
    assert len(notes) == 1 and "minimum distance" in notes[0].message
    assert 1 <= len(cands) < 40
    assert [c.index for c in cands] == list(range(len(cands)))
    assert duplicates(cands, st.tile).count == 0


def test_global_search_validation(wall):
    S, st = wall
    with pytest.raises(ValueError, match="patch_search"):
        candidates(S, st, 2, patch_search="nearby")
    with pytest.raises(ValueError, match="tolerance"):
        candidates(S, st, 2, tolerance=-1)
    with pytest.raises(TypeError, match="min_distance"):
        candidates(S, st, 2, min_distance=2.5)


def test_flat_regions_give_no_duplicates_either():
    """Distinct positions in a flat region have the same content: they are redrawn."""
    rng = np.random.default_rng(0)
    S = np.full((160, 200, 3), 0.5, np.float32)
    S += rng.normal(0, 0.2 / 255, S.shape).astype(np.float32)  # flat to the eye
    S[:, 120:] = smooth_texture((160, 80), 3, 2, 1.5)
    st = make_seamless(S, (10, 20, 48, 48), overlap=6)  # in the flat part
    with pytest.warns(UserWarning, match="alike"):
        cands = candidates(S, st, 20, rng=1, workers=1)
    assert len(cands) < 20  # fewer, said why, rather than repeats
    assert duplicates(cands, st.tile).count == 0


def test_the_global_search_matches_the_ring_where_the_cut_runs():
    """The patch must fit the template in the ring's outer SEARCH_BAND px, where the
    outward-drawn cut runs; what lies further in is the patch's own (matching it too made
    every tile resemble the template there: a lattice). Of two planted windows, the one that
    repeats the template's outer band wins over one that repeats the rest of its ring."""
    S = smooth_texture((200, 200), 3, 11, 1.5)
    st = make_seamless(S, (10, 10, 64, 64), overlap=8)
    T = np.asarray(st.tile)
    h, w = T.shape[:2]
    r, c = np.mgrid[0:h, 0:w]
    d = np.minimum.reduce([r, c, h - 1 - r, w - 1 - c])  # distance to the tile edge
    outer = d < 1 + SEARCH_BAND  # the margin and the searched band
    inner_ring = ~outer & (d < 8)  # the rest of the ring w_P = 8
    for (y, x), part in (((120, 120), outer), ((120, 30), inner_ring)):
        S[y : y + h, x : x + w][part] = T[part]
    c = make_candidate(S, st, rng=0, tolerance=0.0)
    assert c.patch_origin == (120, 120)


def test_interior_means_against_brute_force():
    from engine.tiles.candidate_kernels import interior_means

    L = np.random.default_rng(0).random((37, 53)).astype(np.float32)
    for h, w, i in ((10, 12, 2), (11, 9, 3), (8, 8, 1), (9, 14, 4)):
        got = interior_means(L, (h, w), i)
        want = [
            [L[y + i : y + h - i, x + i : x + w - i].mean() for x in range(53 - w + 1)]
            for y in range(37 - h + 1)
        ]
        np.testing.assert_allclose(got, want, atol=1e-6)


def test_patch_interiors_keep_the_ring_tone(monkeypatch):
    """A photo whose regions differ in tone (blocks of ±0.1): the candidates' interiors are
    chosen close to the tone of the template's ring they share (engine.tiles.candidates.TONE),
    so a layout shows no tone blocks; without the tone term they differ ~2x more."""
    import importlib

    cmod = importlib.import_module("engine.tiles.candidates")

    rng = np.random.default_rng(3)
    S = 0.5 + 0.5 * (smooth_texture((256, 256), 3, 4, 1.5) - 0.5)
    S = S + np.kron(rng.uniform(-0.1, 0.1, (8, 8)), np.ones((32, 32)))[..., None]
    S = np.clip(S, 0, 1).astype(np.float32)
    st = make_seamless(S, (96, 96, 64, 64), overlap=8)
    T = np.asarray(st.tile).mean(axis=2)
    wp = 8
    ring_tone = np.concatenate(
        [T[:wp].ravel(), T[-wp:].ravel(), T[:, :wp].ravel(), T[:, -wp:].ravel()]
    ).mean()

    def gap():
        cands = candidates(S, st, 10, rng=0, patch_overlap=wp)
        return np.mean([abs(c.tile.mean(axis=2)[wp:-wp, wp:-wp].mean() - ring_tone) for c in cands])

    with_tone = gap()
    monkeypatch.setattr(cmod, "TONE", 0.0)
    without = gap()
    assert with_tone < 0.5 * without, (with_tone, without)


def test_coarse_interior_means_follow_the_exact_ones():
    from engine.metrics import luminance
    from engine.tiles.candidate_kernels import coarse_interior_means, interior_means

    S = smooth_texture((300, 280), 3, 1, 6.0)
    exact = interior_means(luminance(S).astype(np.float32), (100, 90), 6)
    np.testing.assert_array_equal(coarse_interior_means(S, (100, 90), 6, 1), exact)
    for k in (2, 4):
        got = coarse_interior_means(S, (100, 90), 6, k)
        assert got.shape == exact.shape
        assert np.abs(got - exact).max() < 0.02
