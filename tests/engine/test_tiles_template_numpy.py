"""The template search's and the dp cut's numpy twins give exactly the numba kernels' values
(ties included), and a small template + seamless tile starts no numba."""

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from engine.seams import dp
from engine.tiles import template_scan

FAST = settings(max_examples=80, deadline=None)


@pytest.mark.parametrize("shape", [(37, 53, 3), (9, 12, 1), (20, 7, 4), (64, 80, 3)])
@pytest.mark.parametrize("masked", [False, True])
def test_shift_sums_numpy_is_the_kernel(shape, masked):
    rng = np.random.default_rng(sum(shape) + masked)
    S = (rng.random(shape) ** 3).astype(np.float32)
    W = shape[1]
    valid = rng.random(shape[:2]) > 0.2 if masked else np.ones((1, 1), dtype=np.bool_)
    shifts = np.array([1, 2, W // 2, W - 2, W - 1, W, W + 3], dtype=np.int64)
    start = rng.random((shifts.size, W))  # sums carried over from earlier rows
    out = []
    for f in (template_scan._shift_sums, template_scan._shift_sums_numpy):
        s, c = start.copy(), start.copy()
        f(S, valid, masked, 2, shape[0] - 1, shifts, s, c)
        out.append((s, c))
    assert np.array_equal(out[0][0], out[1][0])
    assert np.array_equal(out[0][1], out[1][1])


values = st.one_of(st.integers(0, 3).map(float), st.floats(0, 1, width=32))


@st.composite
def dp_problems(draw):
    h, w = draw(st.integers(1, 16)), draw(st.integers(1, 9))
    e = draw(arrays(np.float64, (h, w), elements=values))
    lo = np.array(draw(st.lists(st.integers(0, w - 1), min_size=h, max_size=h)), np.int64)
    width = np.array(draw(st.lists(st.integers(0, w), min_size=h, max_size=h)), np.int64)
    return e, lo, np.minimum(lo + width, w - 1)


@FAST
@given(dp_problems(), st.booleans(), st.booleans())
def test_dp_numpy_is_the_kernel(problem, cyclic, free):
    e, lo, hi = problem
    if free:  # no constraint: the common case
        lo, hi = np.zeros_like(lo), np.full_like(hi, e.shape[1] - 1)
    cols_k, cols_n = np.zeros(e.shape[0], np.int64), np.zeros(e.shape[0], np.int64)
    cost_k = dp._dp_kernel(e, lo, hi, cyclic, cols_k)
    cost_n = dp._dp_numpy(e, lo, hi, cyclic, cols_n)
    assert cost_k == cost_n or (np.isinf(cost_k) and np.isinf(cost_n))
    if np.isfinite(cost_k):
        assert np.array_equal(cols_k, cols_n)


PROBE = """
import hashlib, sys
import numpy as np
from engine import _jit
from engine.tiles import find_template, make_seamless

rng = np.random.default_rng(3)
S = np.cumsum(np.cumsum(rng.random((160, 150, 3)), 0), 1)
S = ((S - S.min()) / np.ptp(S) * 0.3 + rng.random(S.shape) * 0.7).astype(np.float32)

def run():
    t = find_template(S, tile_min=64, tile_max=64)
    st = make_seamless(S, t)
    return t.rect, hashlib.sha1(np.ascontiguousarray(st.tile).tobytes()).hexdigest()

first = run()
print("numba" in sys.modules, _jit.loaded())
# a search over tile sizes: many scans, numba's start-up pays
find_template(np.tile(S, (2, 2, 1)), tile_min=48, tile_max=96)
print(_jit.loaded())
print(run() == first)
"""


def test_a_small_template_and_seamless_tile_start_no_numba_and_match_the_kernels():
    """... while a search over a range of tile sizes loads the kernels (their start-up pays
    for its many scans: 512², 224..288 took 3.2 s on the numpy twins against 0.49 s)."""
    out = subprocess.run(
        [sys.executable, "-c", PROBE], capture_output=True, text=True, check=True, timeout=300
    )
    assert out.stdout.split() == ["False", "False", "True", "True"]
