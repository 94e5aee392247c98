"""Gradient-domain blending (engine.poisson) against a dense least-squares brute force, and
the tiles it makes (seamless tile on the torus, candidates)."""

import numpy as np
import pytest

from engine.metrics import luminance, ring_tone, wrap_border_ratio
from engine.poisson import poisson_torus, poisson_window, solve_maps
from engine.seams import SeamSpec
from engine.stitch import PATCH_SEAM
from engine.tiles import candidates, make_seamless
from tests.engine.helpers import smooth_texture


def brute_least_squares(c, guidance, free, *, wrap, screen=0.0):
    """argmin Σ_edges (f_q − f_p − v_pq)² + screen · Σ_free (f − c)² over the ``free`` pixels
    of a 2-D image (the others keep ``c``); on a torus (``wrap``) with every pixel free, the
    mean of ``c`` is kept."""
    h, w = c.shape
    idx = -np.ones((h, w), int)
    idx[free] = np.arange(free.sum())
    rows, rhs = [], []
    for y in range(h):
        for x in range(w):
            for dy, dx in ((0, 1), (1, 0)):
                qy, qx = y + dy, x + dx
                if wrap:
                    qy, qx = qy % h, qx % w
                elif qy >= h or qx >= w:
                    continue
                if idx[y, x] < 0 and idx[qy, qx] < 0:
                    continue
                row = np.zeros(free.sum())
                r = guidance(y, x, qy, qx)
                for (py, px), sign in (((qy, qx), 1.0), ((y, x), -1.0)):
                    if idx[py, px] >= 0:
                        row[idx[py, px]] += sign
                    else:
                        r -= sign * c[py, px]
                rows.append(row)
                rhs.append(r)
    for y, x in zip(*np.nonzero(free), strict=True):
        if screen:
            row = np.zeros(free.sum())
            row[idx[y, x]] = np.sqrt(screen)
            rows.append(row)
            rhs.append(np.sqrt(screen) * c[y, x])
    A, b = np.array(rows), np.array(rhs)
    if wrap:  # fix the free constant: keep the mean
        A = np.vstack([A, np.full(free.sum(), 1e3)])
        b = np.append(b, 1e3 * c[free].sum())
    sol = np.linalg.lstsq(A, b, rcond=None)[0]
    out = c.astype(np.float64).copy()
    out[free] = sol
    return out


def test_window_matches_brute_force():
    rng = np.random.default_rng(0)
    h, w = 9, 11
    Q, U = rng.random((h, w)), rng.random((h, w))
    mask = np.zeros((h, w), bool)
    mask[2:7, 3:9] = True
    mask[4, 2] = True  # a ragged cut
    mask[2, 3] = False

    def guidance(y, x, qy, qx):
        if mask[y, x] and mask[qy, qx]:
            return Q[qy, qx] - Q[y, x]
        if not mask[y, x] and not mask[qy, qx]:
            return U[qy, qx] - U[y, x]
        return 0.5 * (Q[qy, qx] - Q[y, x] + U[qy, qx] - U[y, x])

    for fixed, reach in ((1, None), (2, None), (1, 3.0), (2, 1.5)):
        free = np.zeros((h, w), bool)
        free[fixed:-fixed, fixed:-fixed] = True
        c = np.where(mask, Q, U)
        screen = 0.0 if reach is None else 1 / reach**2
        brute = brute_least_squares(c, guidance, free, wrap=False, screen=screen)
        got = poisson_window(Q[..., None], U[..., None], mask, fixed=fixed, reach=reach)[..., 0]
        np.testing.assert_allclose(got, brute, atol=1e-9)
        np.testing.assert_array_equal(got[~free], U[~free])  # the fixed ring is the target's


def test_torus_matches_brute_force():
    rng = np.random.default_rng(1)
    S = rng.random((12, 14))
    h, w = 6, 7
    # a tile of two source windows joined along a ragged vertical cut, wrapping
    yx = np.zeros((h, w, 2), int)
    cut = np.array([2, 3, 3, 2, 4, 3])
    for y in range(h):
        for x in range(w):
            src = (1 + y, 2 + x) if x < cut[y] else (5 + y, 5 + x)
            yx[y, x] = src
    T = S[yx[..., 0], yx[..., 1]]

    def guidance(y, x, qy, qx):
        (py, px), (ny, nx) = yx[y, x], yx[qy, qx]
        dy, dx = (qy - y) % h, (qx - x) % w
        if (ny - py, nx - px) == (dy, dx):
            return S[ny, nx] - S[py, px]
        return 0.5 * (S[py + dy, px + dx] - S[py, px] + S[ny, nx] - S[ny - dy, nx - dx])

    brute = brute_least_squares(T, guidance, np.ones((h, w), bool), wrap=True)
    got = poisson_torus(T[..., None], yx, S[..., None])[..., 0]
    np.testing.assert_allclose(got, brute, atol=1e-6)
    assert got.mean() == pytest.approx(T.mean())
    # a plain crop is cut only across its wrap: the step there becomes a natural one
    ramp = np.linspace(0, 1, 30)[None, :] + 0.05 * rng.random((30, 30))
    coords = np.stack(np.mgrid[0:20, 0:20], axis=2) + 5
    crop = ramp[5:25, 5:25, None]
    out = poisson_torus(crop, coords, ramp[..., None])[..., 0]
    step = np.abs(crop[:, 0, 0] - crop[:, -1, 0]).mean()
    assert np.abs(out[:, 0] - out[:, -1]).mean() < 0.2 * step


def test_a_tone_step_vanishes_and_detail_stays():
    rng = np.random.default_rng(2)
    U = 0.4 + 0.1 * rng.random((40, 40, 3))
    Q = U + 0.2  # the same texture, brighter
    mask = np.zeros((40, 40), bool)
    mask[5:35, 6:33] = True
    out = poisson_window(Q, U, mask, fixed=1)
    np.testing.assert_allclose(out, U, atol=1e-9)  # nothing left of the step
    detail = rng.random((40, 40, 3)) * 0.3  # a patch with its own detail
    out = poisson_window(detail + 0.3, U, mask, fixed=1)
    inside = out[15:25, 15:25]
    # inside, the detail's steps stay (the correction is smooth: its steps are tiny)
    np.testing.assert_allclose(
        np.diff(inside, axis=1), np.diff(detail[15:25, 15:25], axis=1), atol=0.005
    )


def test_maps_follow_and_normals_stay_unit():
    rng = np.random.default_rng(3)
    mask = np.zeros((20, 20), bool)
    mask[4:16, 4:16] = True
    n1 = rng.random((20, 20, 3)).astype(np.float32)
    n2 = rng.random((20, 20, 3)).astype(np.float32)
    q = {"main": rng.random((20, 20, 4)).astype(np.float32), "normal": n1}
    u = {"main": rng.random((20, 20, 4)).astype(np.float32), "normal": n2}
    out = solve_maps(q, u, mask)
    assert set(out) == {"main", "normal"} and all(v.dtype == np.float32 for v in out.values())
    assert out["main"].min() >= 0 and out["main"].max() <= 1
    hard = np.where(mask[..., None], q["main"], u["main"])
    np.testing.assert_array_equal(out["main"][..., 3], hard[..., 3])
    v = out["normal"] * 2 - 1
    assert np.allclose(np.linalg.norm(v, axis=2)[mask], 1, atol=1e-2)
    ring = ~np.pad(np.ones((18, 18), bool), 1)
    for k in out:
        np.testing.assert_array_equal(out[k][ring], u[k][ring])
    with pytest.raises(ValueError, match="fixed"):
        poisson_window(q["main"], u["main"], np.pad(np.ones((19, 19), bool), ((1, 0), (1, 0))))


def lit_texture(shape=(120, 130), seed=4):
    """Smooth noise under a lighting gradient across x (+60 % from left to right)."""
    S = smooth_texture(shape, 3, seed, 1.5) * 0.5
    return (S + np.linspace(0.15, 0.45, shape[1])[None, :, None]).astype(np.float32)


def cut_steps(tile, cut):
    """Mean |luminance step| across the tile's edges (wrapping) where ``cut`` (h, w, 2: the
    x and y edge of each pixel) is True, and where it is False."""
    L = luminance(tile)
    d = np.stack([np.roll(L, -1, 1) - L, np.roll(L, -1, 0) - L], axis=2)
    return float(np.abs(d[cut]).mean()), float(np.abs(d[~cut]).mean())


def test_seamless_tile_on_the_torus_loses_the_tone_step_and_stays_seamless():
    S = lit_texture()
    rect, w_t = (10, 12, 64, 60), 10
    hard = make_seamless(S, rect, overlap=w_t, seam=SeamSpec(blend="none"))
    soft = make_seamless(S, rect, overlap=w_t, seam=SeamSpec(blend="poisson"))
    assert soft.tile.shape == hard.tile.shape and soft.tile.dtype == np.float32
    # the edges the hard cuts made: two neighbours that are not neighbours in the source
    # (found from the hard tile: its pixels are exact source pixels at known positions)
    cut = np.zeros(hard.tile.shape[:2] + (2,), bool)
    h, w = hard.tile.shape[:2]
    for r in range(h):
        for c in range(w):
            for k, (dr, dc) in enumerate(((0, 1), (1, 0))):
                cut[r, c, k] = not _natural(hard.tile, S, rect, w_t, r, c, dr, dc)
    hard_cut, hard_rest = cut_steps(hard.tile, cut)
    soft_cut, soft_rest = cut_steps(soft.tile, cut)
    assert hard_cut > 2 * hard_rest  # the lighting's step along the cut
    assert soft_cut < 1.3 * soft_rest  # spread: the cut's edges step as the texture does
    assert soft_rest == pytest.approx(hard_rest, rel=0.05)  # detail kept
    assert abs(float(soft.tile.mean()) - float(hard.tile.mean())) < 1e-3  # the mean kept
    # seamless on the torus: its wrap joint is as calm as its interior
    assert wrap_border_ratio(soft.tile) <= 1.15


def _natural(tile, S, rect, w_t, r, c, dr, dc):
    """Whether tile pixels (r, c) and its torus neighbour are the same pair in the source
    ``S`` at one of the positions the seamless construction can take them from."""
    x, y, a, b = rect
    h, w = tile.shape[:2]
    r2, c2 = (r + dr) % h, (c + dc) % w
    rows = lambda i: (y + i, y + b + i) if i < w_t else (y + i,)  # noqa: E731
    cols = lambda j: (x + j, x + a + j) if j < w_t else (x + j,)  # noqa: E731
    for sy in rows(r):
        for sx in cols(c):
            if not np.array_equal(S[sy, sx], tile[r, c]):
                continue
            ny, nx = sy + dr, sx + dc
            if ny < S.shape[0] and nx < S.shape[1] and np.array_equal(S[ny, nx], tile[r2, c2]):
                return True
    return False


def test_poisson_candidates_keep_the_border_and_lose_the_tone_step():
    S = lit_texture((160, 200), seed=5)
    st = make_seamless(S, (60, 40, 64, 64), overlap=10)
    ring_px = 8
    sets = {}
    for blend in ("none", "poisson"):
        seam = PATCH_SEAM.replace(blend=blend)
        sets[blend] = candidates(S, st, 8, rng=2, seam=seam, margin=2, patch_overlap=ring_px)
    for c in sets["poisson"]:
        m = 2  # the outer margin is the template's bit for bit: every tile still connects
        for part in (np.s_[:m], np.s_[-m:], np.s_[:, :m], np.s_[:, -m:]):
            np.testing.assert_array_equal(c.tile[part], st.tile[part])
    # same patches, same cuts: only the blend differs
    for hard, soft in zip(sets["none"], sets["poisson"], strict=True):
        assert hard.patch_origin == soft.patch_origin
        np.testing.assert_array_equal(hard.mask, soft.mask)
    # across the closed cut the tone step is gone: the cut's edges step as the texture does
    steps = {}
    for k, tiles in sets.items():
        across, rest = [], []
        for c in tiles:
            d = np.abs(np.diff(luminance(c.tile), axis=1))
            edge = c.mask[:, 1:] != c.mask[:, :-1]
            across.append(d[edge].mean())
            rest.append(d[~edge].mean())
        steps[k] = np.mean(across) / np.mean(rest)
    assert steps["none"] > 2 and steps["poisson"] < 1.3, steps
    # the screened solve leaves the patch its own tone further in (no lattice of one tone);
    # the ring tone still drops a little (a lighting offset is Flatten lighting's job)
    tone = {k: ring_tone(v, S, width=ring_px) for k, v in sets.items()}
    assert tone["poisson"] < tone["none"], tone


def test_only_tile_sets_take_the_gradient_domain_blend():
    from engine.heal import heal
    from engine.quilting import quilt

    img = smooth_texture((48, 48), 3, 0)
    mask = np.zeros((48, 48), bool)
    mask[20:28, 20:28] = True
    with pytest.raises(ValueError, match="tile sets; heal takes"):
        heal(img, mask, seam=SeamSpec(blend="poisson"))
    with pytest.raises(ValueError, match="tile sets; quilting takes"):
        quilt(img, (64, 64), block=16, seam=SeamSpec("dp", blend="poisson"))
