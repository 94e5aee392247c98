"""Evaluation sets of textures for tile sets (issue 10): public and private, deterministic.

* **public** (16): the 5 bundled samples; scikit-image's ``text``, ``page``, ``coins``, ``moon``,
  a ``retina`` crop and ``cell`` (all shipped with scikit-image, no download); procedural
  structured textures with a lighting gradient: ``bricks`` (courses), ``weave``, ``shelves``
  (shelves of discs), ``planks``.
* **private** (held out for generalisation checks, never used to tune defaults): crops of
  other scikit-image photos — ``fur`` (chelsea's forehead), ``tissue``
  (immunohistochemistry), ``deepsky`` (hubble_deep_field), ``field`` (camera's grass),
  ``hair`` (astronaut) — the bundled gravel under a vignette (``gravel-lit``), and textures
  made differently from the public ones: ``rice`` (scattered grains), ``cans`` (a
  near-regular grid of lids), ``tiles`` (ceramic tiles with grout), ``basket`` (a twill
  weave), ``wood`` (grain with knots).

``python tools/make_evalset.py OUT`` writes them as PNGs. Each entry is an (H, W[, 3]) uint8
array; every generator takes only a seed, so the sets are the same on every machine.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

import resources

__all__ = ["PRIVATE", "PUBLIC", "load", "texture_names"]


def _noise(rng, shape, sigma):
    n = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    return n / (n.std() + 1e-9)


def _u8(x) -> np.ndarray:
    return np.round(np.clip(x, 0, 1) * 255).astype(np.uint8)


def _lighting(size, strength=0.45, angle=0.6):
    """A smooth multiplicative light field: brighter towards one corner, by ``strength``."""
    yy, xx = np.mgrid[0:size, 0:size] / (size - 1)
    ramp = np.cos(angle) * xx + np.sin(angle) * yy
    ramp = (ramp - ramp.min()) / (ramp.max() - ramp.min())
    return (1 - strength / 2 + strength * ramp)[..., None]


# ----------------------------------------------------------------------------- public procedural
def bricks(size=512, seed=21):
    """Running-bond brick courses (32 px) with light mortar, per-brick colour, grain, light."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size]
    course, length, mortar = 32, 72, 4
    row = yy // course
    shift = (row % 2) * (length // 2) + (row * 7) % 5
    col = (xx + shift) // length
    brick_id = row * 1000 + col
    tone = rng.uniform(0.75, 1.15, brick_id.max() + 1)[brick_id]
    base = np.array([0.62, 0.33, 0.24])
    img = base * tone[..., None] * (1 + 0.08 * _noise(rng, (size, size), 1.2)[..., None])
    img += 0.04 * _noise(rng, (size, size), 6)[..., None]
    joint = ((yy % course) < mortar) | (((xx + shift) % length) < mortar)
    mortar_c = np.array([0.72, 0.70, 0.66]) * (1 + 0.06 * _noise(rng, (size, size), 1)[..., None])
    img = np.where(joint[..., None], mortar_c, img)
    return _u8(img * _lighting(size))


def weave(size=512, seed=22):
    """Basket weave: over-under strands 24 px wide, shaded across each strand, light."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    p = 24
    i, j = (yy // p).astype(int), (xx // p).astype(int)
    over_h = (i + j) % 2 == 0
    u = (yy % p) / p  # across a horizontal strand
    v = (xx % p) / p
    shade_h = 0.55 + 0.45 * np.sin(np.pi * u) ** 0.6
    shade_v = 0.55 + 0.45 * np.sin(np.pi * v) ** 0.6
    fib = _noise(rng, (size, size), (0.6, 4))  # fibres along x
    fibv = _noise(rng, (size, size), (4, 0.6))
    h_col = np.array([0.78, 0.64, 0.40]) * (shade_h * (1 + 0.07 * fib))[..., None]
    v_col = np.array([0.70, 0.56, 0.34]) * (shade_v * (1 + 0.07 * fibv))[..., None]
    img = np.where(over_h[..., None], h_col, v_col)
    return _u8(img * _lighting(size, 0.5, 0.3))


def shelves(size=512, seed=23):
    """Shelves every 64 px (dark board) holding discs (jars seen from the front), light."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    img = np.ones((size, size, 3)) * np.array([0.30, 0.26, 0.22])
    img *= (1 + 0.05 * _noise(rng, (size, size), 2))[..., None]
    pitch, board = 64, 8
    for r0 in range(0, size, pitch):
        x = rng.uniform(0, 10)
        while x < size + 20:
            rad = rng.uniform(11, 16)
            cx, cy = x + rad, r0 + pitch - board - rad - 1
            col = rng.choice(
                [[0.80, 0.25, 0.20], [0.25, 0.55, 0.75], [0.85, 0.75, 0.30], [0.35, 0.65, 0.35]]
            ) * rng.uniform(0.85, 1.1)
            d = np.hypot(yy - cy, xx - cx)
            inside = d < rad
            hl = np.clip(1.15 - 0.5 * d / rad, 0.6, 1.2)
            img[inside] = col * hl[inside][:, None]
            x += 2 * rad + rng.uniform(2, 8)
        band = (yy >= r0 + pitch - board) & (yy < r0 + pitch)
        img[band] = np.array([0.50, 0.36, 0.22]) * (0.9 + 0.1 * ((yy[band] - r0) % 3))[:, None]
    return _u8(img * _lighting(size, 0.5, 1.2))


def planks(size=512, seed=24):
    """Vertical planks 48 px wide with grain, dark gaps and butt joints, light."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    w = 48
    k = (xx // w).astype(int)
    ends = rng.uniform(0, size, (k.max() + 1, 2))
    seg = ((yy > ends[k, 0]).astype(int) + (yy > ends[k, 1]).astype(int)) + 3 * k
    tone = rng.uniform(0.8, 1.15, seg.max() + 1)[seg]
    grain = _noise(rng, (size, size), (14, 0.8)) + 0.5 * _noise(rng, (size, size), (30, 2))
    ring = 0.5 + 0.5 * np.sin(grain * 3 + xx * 0.25)
    base = np.array([0.66, 0.47, 0.28])
    img = base * (tone * (0.85 + 0.2 * ring))[..., None]
    gap = (xx % w) < 2
    joint = (np.abs(yy - ends[k, 0]) < 1.5) | (np.abs(yy - ends[k, 1]) < 1.5)
    img[gap | joint] *= 0.35
    return _u8(img * _lighting(size, 0.5, 0.9))


# ----------------------------------------------------------------------------- private procedural
def rice(size=512, seed=31):
    """Scattered rice grains (random ellipses) on a dark cloth."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    img = np.ones((size, size)) * 0.18 + 0.03 * _noise(rng, (size, size), 1.5)
    for _ in range(900):
        cy, cx = rng.uniform(0, size, 2)
        th = rng.uniform(0, np.pi)
        a, b = rng.uniform(7, 10), rng.uniform(2.5, 3.5)
        y0, y1 = int(max(0, cy - 11)), int(min(size, cy + 12))
        x0, x1 = int(max(0, cx - 11)), int(min(size, cx + 12))
        dy, dx = yy[y0:y1, x0:x1] - cy, xx[y0:y1, x0:x1] - cx
        u = dx * np.cos(th) + dy * np.sin(th)
        v = -dx * np.sin(th) + dy * np.cos(th)
        r = (u / a) ** 2 + (v / b) ** 2
        sub = img[y0:y1, x0:x1]
        sub[r < 1] = (0.78 + 0.15 * (1 - r) + rng.normal(0, 0.02))[r < 1]
    return _u8(img * _lighting(size, 0.3, 0.2)[..., 0])


def cans(size=512, seed=32):
    """Lids of cans in a near-regular grid (58 px, jittered), rims and highlights."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    img = np.ones((size, size, 3)) * 0.12
    p = 58
    for cy in np.arange(p / 2, size + p, p):
        for cx in np.arange(p / 2 + (cy // p % 2) * p / 2 - p, size + p, p):
            jy, jx = rng.normal(0, 1.5, 2)
            d = np.hypot(yy - cy - jy, xx - cx - jx)
            col = np.array([0.75, 0.76, 0.78]) * rng.uniform(0.85, 1.05)
            lid = d < 26
            img[lid] = col * (0.8 + 0.2 * np.cos(d[lid] / 26 * 6))[:, None]
            img[(d > 23) & (d < 26)] *= 0.6
    img *= (1 + 0.04 * _noise(rng, (size, size), 1))[..., None]
    return _u8(img * _lighting(size, 0.35, 2.0))


def tiles(size=512, seed=33):
    """Ceramic tiles (40 px) with grout, per-tile glaze tone, mottling."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size]
    p = 40
    tid = (yy // p) * 100 + xx // p
    tone = rng.uniform(0.85, 1.1, tid.max() + 1)[tid]
    base = np.array([0.35, 0.52, 0.55])
    img = base * (tone * (1 + 0.1 * _noise(rng, (size, size), 3)))[..., None]
    grout = ((yy % p) < 3) | ((xx % p) < 3)
    img[grout] = np.array([0.85, 0.83, 0.78])
    return _u8(img)


def basket(size=512, seed=34):
    """A twill weave: strands 16 px, over two under two, stepping diagonally."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    p = 16
    i, j = (yy // p).astype(int), (xx // p).astype(int)
    over = ((i + j) // 2) % 2 == 0
    sh = 0.6 + 0.4 * np.sin(np.pi * (yy % p) / p)
    sv = 0.6 + 0.4 * np.sin(np.pi * (xx % p) / p)
    g = _noise(rng, (size, size), 0.8)
    img = np.where(over, sh, sv * 0.9) * (1 + 0.06 * g)
    col = np.array([0.70, 0.62, 0.45])
    return _u8(col * img[..., None])


def wood(size=512, seed=35):
    """Wood grain with knots (one board): wavy rings stretched along y."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:size, 0:size].astype(float)
    warp = 25 * _noise(rng, (size, size), (60, 20))
    for _ in range(4):
        ky, kx = rng.uniform(0, size, 2)
        d = np.hypot((yy - ky) / 2.5, xx - kx)
        warp += 40 * np.exp(-d / 12)
    rings = np.sin((xx + warp) * 0.35) * 0.5 + 0.5
    fine = _noise(rng, (size, size), (8, 0.6))
    img = 0.55 + 0.25 * rings + 0.05 * fine
    col = np.array([0.85, 0.6, 0.36])
    return _u8(col * img[..., None])


def _gravel_lit(seed=36):
    from engine.io import load_image

    g = load_image(resources.sample_path("gravel")).pixels[..., 0]
    h, w = g.shape
    yy, xx = np.mgrid[0:h, 0:w]
    vig = 1.0 - 0.55 * (((yy - h * 0.3) / h) ** 2 + ((xx - w * 0.7) / w) ** 2)
    return _u8(g * vig)


# ----------------------------------------------------------------------------- registry
def _sample(name):
    def load_sample():
        from engine.io import load_image

        return _u8(load_image(resources.sample_path(name)).pixels.squeeze())

    return load_sample


def _skimage(name, crop=None):
    def load_skimage():
        import skimage.data

        a = getattr(skimage.data, name)()
        if crop is not None:
            (y0, y1), (x0, x1) = crop
            a = a[y0:y1, x0:x1]
        return np.ascontiguousarray(a)

    return load_skimage


PUBLIC = {
    **{n: _sample(n) for n in resources.SAMPLE_NAMES},
    "text": _skimage("text"),
    "page": _skimage("page"),
    "coins": _skimage("coins"),
    "moon": _skimage("moon"),
    "retina": _skimage("retina", ((450, 962), (450, 962))),
    "cell": _skimage("cell"),
    "bricks": bricks,
    "weave": weave,
    "shelves": shelves,
    "planks": planks,
}

PRIVATE = {
    "fur": _skimage("chelsea", ((10, 110), (150, 330))),
    "tissue": _skimage("immunohistochemistry"),
    "deepsky": _skimage("hubble_deep_field", ((100, 612), (200, 712))),
    "field": _skimage("camera", ((380, 512), (0, 512))),
    "hair": _skimage("astronaut", ((20, 130), (160, 300))),
    "gravel-lit": _gravel_lit,
    "rice": rice,
    "cans": cans,
    "tiles": tiles,
    "basket": basket,
    "wood": wood,
}


def texture_names(which: str = "public") -> list[str]:
    """Names of the ``public``, ``private`` or ``all`` set."""
    sets = {"public": PUBLIC, "private": PRIVATE, "all": {**PUBLIC, **PRIVATE}}
    if which not in sets:
        raise ValueError(f"which must be one of {sorted(sets)}, got {which!r}")
    return list(sets[which])


def load(name: str) -> np.ndarray:
    """The texture ``name`` of either set as a uint8 (H, W[, 3]) array."""
    fn = PUBLIC.get(name) or PRIVATE.get(name)
    if fn is None:
        raise KeyError(f"no texture {name!r}; known: {texture_names('all')}")
    return fn()
