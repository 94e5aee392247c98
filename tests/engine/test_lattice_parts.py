"""benchmarks/lattice_causes.lattice_parts: the issue-10 lattice split by harmonic kind."""

import numpy as np
import pytest

from benchmarks.lattice_causes import lattice_parts
from engine.metrics import lattice


def _set(mark=None, n=12, seed=1):
    """Crops of white noise sharing a template's 1 px margin; ``mark`` plants a dark row or
    column (a repeated landmark) inside every tile."""
    g = np.random.default_rng(seed)
    S = g.random((200, 220, 3)).astype(np.float32)
    T = S[10:50, 20:64]
    tiles = []
    for y, x in g.integers(0, 150, (n, 2)):
        t = S[y : y + 40, x : x + 44].copy()
        t[:1], t[-1:], t[:, :1], t[:, -1:] = T[:1], T[-1:], T[:, :1], T[:, -1:]
        if mark == "row":
            t[5:7, 1:-1] *= 0.2
        elif mark == "column":
            t[1:-1, 5:7] *= 0.2
        tiles.append(t)
    return tiles, S, T


def test_all_is_the_metric_itself():
    tiles, S, T = _set()
    parts = lattice_parts(tiles, S, template=T, margin=1)
    assert parts["all"] == pytest.approx(lattice(tiles, S, template=T, margin=1).above, abs=1e-9)


@pytest.mark.parametrize(("mark", "kind"), [("row", "along y"), ("column", "along x")])
def test_a_repeated_line_shows_in_its_own_kind(mark, kind):
    tiles, S, T = _set(mark)
    parts = lattice_parts(tiles, S, template=T, margin=1)
    other = "along x" if kind == "along y" else "along y"
    assert parts[kind] > 10
    assert parts[kind] > parts[other] + 10
    assert parts[kind] > parts["mixed"] + 5


def test_tone_spread_reads_tiles_alike_in_tone():
    tiles, S, T = _set()
    assert 0.6 < lattice_parts(tiles, S, template=T, margin=1)["tone spread"] < 1.6
    flat = [t - t[1:-1, 1:-1].mean(axis=(0, 1)) + 0.5 for t in tiles]  # the same mean tone
    for t, f in zip(tiles, flat, strict=True):
        f[:1], f[-1:], f[:, :1], f[:, -1:] = t[:1], t[-1:], t[:, :1], t[:, -1:]
    assert lattice_parts(flat, S, template=T, margin=1)["tone spread"] < 0.3
