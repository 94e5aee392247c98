"""Regenerate the procedural colour samples in resources/samples (deterministic, CC0).

Run: python tools/make_samples.py
"""

from pathlib import Path

import numpy as np
from PIL import Image
from scipy import ndimage
from scipy.spatial import cKDTree

OUT = Path(__file__).resolve().parent.parent / "resources" / "samples"


def _noise(rng, shape, sigma):
    n = ndimage.gaussian_filter(rng.standard_normal(shape), sigma, mode="wrap")
    return n / (n.std() + 1e-9)


def cobblestones(size=512, seed=7):
    """Rounded stones of varied warm colours in dark mortar, with grain."""
    rng = np.random.default_rng(seed)
    pts = rng.random((140, 2)) * size
    yy, xx = np.mgrid[0:size, 0:size].astype(np.float64)
    warp = 6 * np.stack([_noise(rng, (size, size), 12), _noise(rng, (size, size), 12)])
    q = np.stack([yy + warp[0], xx + warp[1]], -1).reshape(-1, 2)
    d, idx = cKDTree(pts).query(q, k=2)
    edge = (d[:, 1] - d[:, 0]).reshape(size, size)
    cell = idx[:, 0].reshape(size, size)
    base = np.array(
        [[0.62, 0.48, 0.36], [0.55, 0.53, 0.50], [0.70, 0.60, 0.45], [0.45, 0.38, 0.33]]
    )
    colours = base[rng.integers(0, len(base), len(pts))] * rng.uniform(0.8, 1.15, (len(pts), 1))
    img = colours[cell]
    shade = np.clip(edge / 9.0, 0, 1) ** 0.6
    grain = (
        0.06 * _noise(rng, (size, size), 1.0)[..., None]
        + 0.05 * _noise(rng, (size, size), 4)[..., None]
    )
    mortar = np.array([0.22, 0.20, 0.18])
    img = img * (0.55 + 0.45 * shade[..., None]) + grain
    img = np.where((edge < 2.5)[..., None], mortar + grain * 0.5, img)
    return np.clip(img, 0, 1)


def lichen(size=512, seed=11):
    """Green-grey stochastic lichen on stone: a colour texture without structure."""
    rng = np.random.default_rng(seed)
    a = _noise(rng, (size, size), 3) + 0.6 * _noise(rng, (size, size), 10)
    b = _noise(rng, (size, size), 1.5)
    stone = np.array([0.52, 0.52, 0.50]) + 0.08 * b[..., None]
    moss = np.array([0.45, 0.58, 0.22]) + 0.10 * _noise(rng, (size, size), 2)[..., None] * np.array(
        [0.6, 1, 0.3]
    )
    t = np.clip((a - 0.2) * 1.5, 0, 1)[..., None]
    return np.clip(stone * (1 - t) + moss * t, 0, 1)


if __name__ == "__main__":
    for name, fn in (("cobblestones", cobblestones), ("lichen", lichen)):
        Image.fromarray(np.round(fn() * 255).astype(np.uint8)).save(
            OUT / f"{name}.png", optimize=True
        )
        print("wrote", OUT / f"{name}.png")
