"""The best-set program of benchmarks/set_bound.py against a brute force over every subset."""

from itertools import combinations

import numpy as np

from benchmarks.set_bound import FRAME_LINE, TONE_LINE, best_set


def _brute(fig, k, lines):
    org, R, T, md = fig["origins"], fig["ratios"], fig["terms"], fig["min_distance"]
    best = np.inf
    for sub in combinations(range(len(org)), k):
        far = all(np.abs(org[i] - org[j]).max() >= md for i, j in combinations(sub, 2))
        if not far:
            continue
        z = []
        if "frame" in lines:
            z.append(R[list(sub)].mean(axis=0).max() / FRAME_LINE)
        if "tone" in lines:
            z.append(T[list(sub)].mean() / TONE_LINE)
        best = min(best, max(z))
    return best


def test_the_best_set_is_the_brute_forces_and_keeps_the_minimum_distance():
    rng = np.random.default_rng(4)
    yy, xx = np.mgrid[0:8:2, 0:6:2]
    origins = np.stack([yy.ravel(), xx.ravel()], axis=1)  # a regular 4 x 3 grid, 2 px apart
    fig = {
        "origins": origins,
        "ratios": rng.uniform(0.8, 1.6, (len(origins), 5)),
        "terms": rng.uniform(0.2, 2.5, len(origins)),
        "min_distance": 3,  # neighbours on the grid (2 px) may not both be chosen
    }
    for lines in (("frame", "tone"), ("frame",), ("tone",)):
        got = best_set(fig, 3, lines, time_limit=30)
        chosen = origins[got["chosen"]]
        assert len(chosen) == 3
        assert all(np.abs(a - b).max() >= 3 for a, b in combinations(chosen, 2))
        assert np.isclose(got["z"], _brute(fig, 3, lines), atol=1e-6)
        assert got["lp"] <= got["z"] + 1e-9  # the relaxation bounds every set
