"""The detail term's and the stationarity check's numba kernels give numpy's bits."""

import numpy as np
import pytest

from engine import _jit
from engine.metrics import luminance
from engine.tiles import detail, stationarity


@pytest.mark.parametrize(
    "shape", [(37, 53, 3), (1, 9, 1), (5, 1, 4), (64, 80, 3), (40, 30, 1), (8, 8, 3)]
)
def test_kernels_give_the_numpy_bits(shape):
    _jit.load()
    rng = np.random.default_rng(sum(shape))
    S = (rng.random(shape) ** 5).astype(np.float32)
    E = detail._detail_energy_numpy(S)
    assert np.array_equal(detail.detail_energy(S), E)
    table = np.pad(E.cumsum(axis=0).cumsum(axis=1), ((1, 0), (1, 0)))
    assert np.array_equal(detail.summed_area(E), table)
    if shape[2] in (1, 3):
        assert np.array_equal(stationarity._luminance(S), luminance(S))
        assert stationarity.stationarity_of(S) == stationarity.check_stationarity(S)
