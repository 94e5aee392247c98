"""The quilting schedule: block dependencies against their per-pixel definition."""

import numpy as np

from engine.quilting.layout import check_torus_axis, grid_rects
from engine.quilting.scheduler import dependencies


def dependencies_per_pixel(rects, shape, torus):
    """A block's predecessors are the last earlier writers of its pixels; its level is one
    more than theirs (the definition, pixel by pixel)."""
    H, W = shape
    last = np.full(shape, -1)
    preds, levels = [], []
    for k, (y, x, h, w) in enumerate(rects):
        idx = np.ix_(np.arange(y, y + h) % H, np.arange(x, x + w) % W)
        p = sorted(set(last[idx].ravel().tolist()) - {-1})
        preds.append(p)
        levels.append(1 + max((levels[j] for j in p), default=-1))
        last[idx] = k
    return preds, levels


def test_dependencies_equal_the_per_pixel_definition():
    rng = np.random.default_rng(30)
    checked = 0
    for _ in range(120):
        H, W = (int(v) for v in rng.integers(20, 120, 2))
        if rng.random() < 0.3:  # arbitrary overlapping rectangles
            rects = []
            for _ in range(25):
                y, x = int(rng.integers(0, H - 1)), int(rng.integers(0, W - 1))
                rects.append(
                    (y, x, int(rng.integers(1, H - y + 1)), int(rng.integers(1, W - x + 1)))
                )
            torus = False
        else:  # quilting grids, cropped or on a torus
            b = int(rng.integers(4, min(H, W) // 2 + 2))
            ov = int(rng.integers(0, b // 2 + 1))
            torus = bool(rng.integers(2))
            if torus:
                try:
                    check_torus_axis(H, b, ov, "height")
                    check_torus_axis(W, b, ov, "width")
                except ValueError:
                    continue
            rects = grid_rects((H, W), (b, b), ov, torus)
        assert dependencies(rects, (H, W), torus) == dependencies_per_pixel(rects, (H, W), torus)
        checked += 1
    assert checked > 80
