"""The candidate-set oracle (benchmarks/candidate_oracle.py) and the continued lattice floor
(benchmarks/continued_floor.py): issue 10's interior metrics on sets whose right answer is
known."""

import numpy as np

from benchmarks.candidate_oracle import PLANTED, Surrogate, ideal_candidates
from benchmarks.continued_floor import continued_floor_lattice
from benchmarks.wang_oracle import Field
from engine.metrics import edge_distance, lattice


def test_ideal_candidates_keep_the_templates_ring_and_the_planted_set_a_wider_one():
    field = Field(2.0, np.random.default_rng(3), size=128)
    tpl, tiles, rings = ideal_candidates(field, (24, 20), n=4)
    one = edge_distance((24, 20)) == 0
    wide = edge_distance((24, 20)) < PLANTED
    for t, p in zip(tiles, rings, strict=True):
        assert np.array_equal(t[one], tpl[one])
        assert np.array_equal(p[wide], tpl[wide])
        assert not np.array_equal(t[~one], tpl[~one])


def test_the_surrogate_has_the_sources_power_spectrum():
    rng = np.random.default_rng(0)
    L = rng.random((64, 48)).cumsum(axis=1) / 20  # smooth along x, white along y
    sur = Surrogate(L, np.random.default_rng(1))
    assert np.isclose(sur.cov[0, 0], L.var())
    draws = np.stack([sur.draw() for _ in range(200)])
    power = np.abs(np.fft.fft2(draws - draws.mean(axis=(1, 2), keepdims=True))) ** 2 / L.size
    mean_power = power.mean(axis=0)
    mean_power[0, 0] = sur.power[0, 0] = 0
    assert np.allclose(mean_power.sum(), sur.power.sum(), rtol=0.1)
    t = sur.torus(20, 16)
    assert t.shape == (20, 16) and abs(t.mean() - L.mean()) < 3 * L.std()


def test_a_flawless_set_of_a_smooth_field_fails_the_pasted_floor_not_the_continued_one():
    """The oracle behind README "Interior metrics": exact draws given the template's 1 px ring
    (no cut, no blend) read well above engine.metrics.lattice's pasted floor on a field with
    4 px correlation, and about 0 above the floor continued by kriging."""
    field = Field(4.0, np.random.default_rng(501), size=256)
    S = field.draw()[..., None].astype(np.float32)
    tpl, tiles, _ = ideal_candidates(field, 32, n=16)
    pasted = lattice(tiles, S, template=tpl, margin=1).above
    value, floor, above = continued_floor_lattice(tiles, S, template=tpl, layouts=8)
    assert pasted > 2.5
    assert abs(above) < 1.5
    assert np.isclose(value, lattice(tiles, S, template=tpl, margin=1, layouts=8).value)
