"""Properties that hold for any input (hypothesis): seams, metrics, layouts.

The example-based tests check exact results on chosen inputs; these check invariants on inputs
nobody chose: every seam is a connected top-to-bottom path whose criterion is what it says, the
methods' optima are ordered as their path models are, metrics ignore what they should, and
random layouts keep their promises.
"""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from engine.metrics import border_ratio, grid_border_ratio
from engine.seams import SeamSpec, find_seam
from engine.tiles import assemble, random_layout

FAST = settings(max_examples=40)  # the examples are the same on every run (tests/conftest.py)

error_maps = st.tuples(st.integers(2, 12), st.integers(2, 9)).flatmap(
    lambda shape: arrays(np.float64, shape, elements=st.floats(0, 1, width=32))
)


def _is_seam(path: np.ndarray, shape) -> bool:
    """Starts in the top row, ends in the bottom row, every step to an 8-neighbour."""
    steps = np.abs(np.diff(path, axis=0))
    return (
        path[0, 0] == 0
        and path[-1, 0] == shape[0] - 1
        and bool((steps.max(axis=1) == 1).all())
        and ((path >= 0) & (path < shape)).all()
    )


@FAST
@given(error_maps, st.sampled_from(["dp", "dijkstra", "minimax", "oscillating", "resistance"]))
def test_every_seam_is_a_connected_path_scored_by_its_own_pixels(e, method):
    seam = find_seam(e, method=method)
    path = np.asarray(seam.path)
    assert _is_seam(path, e.shape)
    values = e[path[:, 0], path[:, 1]]
    assert np.isclose(seam.criterion, values.sum()) and np.isclose(seam.peak, values.max())
    mask = np.asarray(seam.mask)
    assert mask[path[:, 0], path[:, 1]].all()  # R1 keeps the path


@FAST
@given(error_maps)
def test_the_optima_are_ordered_as_their_path_models(e):
    """dijkstra searches a superset of dp's paths (it may wind), so its sum is never higher;
    exact minimax minimises the peak first, so its peak is never higher than dp's.
    (oscillating-optimal is in neither relation: its control-point paths are neither a subset
    nor a superset of dp's one-pixel-per-row paths, so either optimum may be the lower one.)"""
    dp = find_seam(e, method="dp")
    assert find_seam(e, method="dijkstra").criterion <= dp.criterion + 1e-9
    assert find_seam(e, method="minimax").peak <= dp.peak + 1e-9


@FAST
@given(error_maps, st.integers(0, 8))
def test_a_pinned_start_is_kept(e, col):
    start = col % e.shape[1]
    path = np.asarray(find_seam(e, seam=SeamSpec("dp"), start=start).path)
    assert path[0, 1] == start


images = st.tuples(st.integers(3, 10), st.integers(3, 10)).flatmap(
    lambda shape: arrays(np.float32, (*shape, 3), elements=st.floats(0, 0.5, width=32))
)


@FAST
@given(images, images, st.floats(0, 0.5, width=32))
def test_border_ratio_ignores_a_common_brightness_offset(a, b, offset):
    if a.shape[0] != b.shape[0]:
        b = np.resize(b, (a.shape[0], *b.shape[1:]))
    r = border_ratio(a, b)
    shifted = border_ratio(a + np.float32(offset), b + np.float32(offset))
    assert np.isclose(r, shifted, rtol=1e-3, atol=1e-5) or (np.isinf(r) and np.isinf(shifted))


@FAST
@given(st.integers(1, 4), st.integers(1, 4), st.integers(2, 6), st.integers(0, 2**16))
def test_a_layout_of_one_tile_repeated_has_no_grid(rows, cols, size, seed):
    """A tile repeated with itself across every joint: the grid joints are its own wrap."""
    tile = np.random.default_rng(seed).random((size, size, 3)).astype(np.float32)
    layout = random_layout(1, rows, cols, rng=seed)
    image = assemble([tile], layout)
    assert image.shape == (rows * size, cols * size, 3)
    if rows > 1 and cols > 1:
        wrap = grid_border_ratio(np.tile(tile, (2, 2, 1)), (size, size))
        assert np.isclose(grid_border_ratio(image, (size, size)), wrap, rtol=1e-5)


@FAST
@given(
    st.integers(2, 6),
    st.integers(1, 9),
    st.integers(1, 9),
    st.integers(0, 2**31 - 1),
    st.booleans(),
)
def test_random_layouts_keep_their_promises(n, rows, cols, seed, distinct):
    weights = np.ones(n)
    weights[0] = 0.0  # never used
    if distinct and n < 3:
        weights[:] = 1.0  # two usable tiles are needed to avoid equal neighbours
    m = random_layout(n, rows, cols, rng=seed, no_equal_neighbours=distinct, weights=weights)
    assert m.shape == (rows, cols) and m.dtype == np.int64
    assert ((m >= 0) & (m < n)).all()
    if weights[0] == 0:
        assert not (m == 0).any()
    if distinct:
        assert (m[:, 1:] != m[:, :-1]).all() and (m[1:] != m[:-1]).all()
    assert np.array_equal(
        m, random_layout(n, rows, cols, rng=seed, no_equal_neighbours=distinct, weights=weights)
    )
