"""benchmarks.template_alone: where a template's ring sits among the windows' centres."""

import numpy as np

from benchmarks.template_alone import among_centres
from engine.metrics import edge_distance, luminance


def test_among_centres_matches_brute_force():
    rng = np.random.default_rng(5)
    S = rng.random((20, 24, 3)).astype(np.float32)
    T = rng.random((9, 11, 3)).astype(np.float32)
    wp = 2
    L, t = luminance(S).astype(np.float64), luminance(T)
    ring = edge_distance(t.shape) < wp
    r = t[ring].mean()
    centres, own = [], []
    for y in range(20 - 9 + 1):
        for x in range(24 - 11 + 1):
            w = L[y : y + 9, x : x + 11]
            centres.append(w[~ring].mean())
            own.append(abs(w[ring].mean() - w[~ring].mean()))
    centres = np.array(centres)
    darker, spread = among_centres(S, T, wp)
    assert darker == (centres < r).mean()
    np.testing.assert_allclose(spread, np.abs(r - centres).mean() / np.mean(own), rtol=1e-9)
