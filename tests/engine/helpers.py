"""Shared helpers of the engine tests."""

import numpy as np
from scipy import ndimage

from engine.events import drain
from engine.seams import SeamSpec


def events_and_result(gen):
    """Every event (left) in an engine event generator, and its return value."""
    events = []
    result = drain(gen, events.append)
    return events, result


def cut(method: str = "dp", **kw) -> SeamSpec:
    """A quilting seam: ``method`` on the squared error (quilting's default metric)."""
    return SeamSpec(method, **{"metric": "ssd", **kw})


def smooth_texture(shape, channels=3, seed=0, sigma=2.0):
    """Gaussian-smoothed noise of ``shape`` + (channels,), stretched to [0, 1], float32."""
    rng = np.random.default_rng(seed)
    x = ndimage.gaussian_filter(rng.random(shape + (channels,)), (sigma, sigma, 0))
    return ((x - x.min()) / (x.max() - x.min())).astype(np.float32)


def blob_texture(size=256, cell=64, seed=0):
    """Voronoi blobs about ``cell`` px across (one tone each, fine grain on top): stones."""
    rng = np.random.default_rng(seed)
    seeds = rng.random((size, size)) < 1.2 / cell**2
    _, (iy, ix) = ndimage.distance_transform_edt(~seeds, return_indices=True)
    tone = rng.random((size, size, 3))[iy, ix]
    return np.clip(0.2 + 0.6 * tone + 0.03 * rng.standard_normal((size, size, 3)), 0, 1)


def running_bond(rng, shape, course, brick):
    """Running-bond bricks (mortar rows 0-3 of every course) with a stationary grain: periodic
    in structure, no two crops alike."""
    yy, xx = np.mgrid[0 : shape[0], 0 : shape[1]]
    shift = (yy // course % 2) * (brick // 2)
    joint = (yy % course < 4) | ((xx + shift) % brick < 4)
    grain = ndimage.gaussian_filter(rng.standard_normal(shape), 1.2, mode="wrap")
    grain /= grain.std()
    return np.where(joint, 0.75, 0.45 + 0.05 * grain)[..., None]
