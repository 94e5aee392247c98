"""The exact search through a colour lower bound (``engine.colour_bound``): the errors, the
candidates and the choice of a brute-force search; the same bits from the kernels and their
numpy twins; the same records on any thread count and with or without numba."""

from __future__ import annotations

import numpy as np
import pytest

from engine import _jit
from engine import colour_bound as cb
from engine.matching import select_within_tolerance
from engine.quilting import quilt
from engine.quilting.block_rng import BlockRng
from engine.quilting.core import Quilter
from engine.quilting.scheduler import POOL_MIN_SAMPLE_AREA

DIRECTIONS = np.array([[0.6, 0.6, 0.5], [0.7, -0.7, 0.1], [0.3, 0.3, -0.9]])


def coloured(seed: int, axes: int, size=(210, 200)) -> np.ndarray:
    """A smooth random texture whose colours vary along ``axes`` directions (and a little
    along every one): the bound needs ``axes`` channels."""
    rng = np.random.default_rng(seed)
    h, w = size
    out = np.full((h, w, 3), 0.5)
    for d in DIRECTIONS[:axes]:
        f = rng.random((h + 4, w + 4))
        f = sum(f[i : i + h, j : j + w] for i in range(5) for j in range(5)) / 25 - 0.5
        out += 3.0 * f[:, :, None] * d / np.linalg.norm(d)
    out += 0.004 * rng.standard_normal((h, w, 3))
    return np.clip(out, 0, 1).astype(np.float32)


def brute_force(sample, old, filled) -> np.ndarray:
    """Σ_filled Σ_c (sample window − old)² at every anchor, float64."""
    s = sample.astype(np.float64)
    bh, bw = filled.shape
    rows, cols = s.shape[0] - bh + 1, s.shape[1] - bw + 1
    e = np.zeros((rows, cols))
    for u, v in zip(*np.nonzero(filled), strict=True):
        e += ((s[u : u + rows, v : v + cols] - old[u, v].astype(np.float64)) ** 2).sum(axis=2)
    return e


def block(sample, rng, bh=28, bw=24):
    """A block's content (another window of the sample, slightly changed) and an L overlap."""
    y, x = rng.integers(0, sample.shape[0] - bh), rng.integers(0, sample.shape[1] - bw)
    old = sample[y : y + bh, x : x + bw] + 0.02 * rng.standard_normal((bh, bw, 3))
    filled = np.zeros((bh, bw), bool)
    filled[: rng.integers(0, 9)] = True
    filled[:, : rng.integers(1, 9)] = True
    return old.astype(np.float32), filled


@pytest.mark.parametrize("axes", [1, 2])
@pytest.mark.parametrize("tolerance", [0.0, 0.1, 0.5])
def test_the_bound_scores_every_candidate_of_a_brute_force_search(axes, tolerance):
    _jit.load()
    sample = coloured(axes, axes)
    bound = cb.ColourBound.build(sample)
    assert bound is not None and bound.m == axes
    rng = np.random.default_rng(10 + axes)
    for case in range(12):
        old, filled = block(sample, rng)
        e = brute_force(sample, old, filled)
        valid = None
        if case % 3 == 2:  # excluded anchors, the least among them
            valid = np.ones(e.shape, bool)
            valid[np.unravel_index(np.argmin(e), e.shape)] = False
            valid[:40, :30] = False
        zero = [0.0, float(np.median(e)) / 50][case % 2]
        got = bound.search(old, filled, valid, tolerance=tolerance, zero_level=zero)
        assert got is not None
        idx, errs = got
        assert np.all(np.diff(idx) > 0)
        np.testing.assert_allclose(errs, e.flat[idx], rtol=1e-10, atol=1e-10)
        ev = e if valid is None else np.where(valid, e, np.inf)
        limit = (1 + tolerance) * max(ev.min(), zero)
        want = np.flatnonzero(ev <= limit)
        mine = idx[errs <= (1 + tolerance) * max(errs.min(), zero)]
        assert np.array_equal(mine, want), case
        assert errs.min() == pytest.approx(ev.min(), rel=1e-12)


def test_a_flat_block_takes_the_full_map():
    """More than CAP anchors within the limit (a flat sample: every window a near copy)."""
    _jit.load()
    sample = np.full((210, 200, 3), 0.5, np.float32)
    sample[..., 0] += np.linspace(0, 0.01, 200, dtype=np.float32)
    bound = cb.ColourBound.build(sample)
    old = np.full((28, 24, 3), 0.5, np.float32)
    filled = np.zeros((28, 24), bool)
    filled[:, :4] = True
    assert bound.search(old, filled, None, tolerance=0.1, zero_level=1.0) is None


@pytest.mark.parametrize("axes", [1, 2])
def test_the_kernels_and_their_numpy_twins_give_the_same_bits(axes, monkeypatch):
    _jit.load()
    sample = coloured(20 + axes, axes)
    bound = cb.ColourBound.build(sample)
    rng = np.random.default_rng(axes)
    for case in range(10):
        old, filled = block(sample, rng)
        a = cb.rotate_content(old, filled, bound.lead)
        b = cb.rotate_content_numpy(old, filled, bound.lead)
        assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
        valid = None if case % 2 else rng.random((210 - 27, 200 - 23)) > 0.2
        tol, zero = [0.1, 0.3][case % 2], [0.0, 2.0][case // 5]
        runs = []
        for loaded in (True, False):
            monkeypatch.setattr(_jit, "loaded", lambda loaded=loaded: loaded)
            runs.append(bound.search(old, filled, valid, tolerance=tol, zero_level=zero))
        monkeypatch.undo()
        (i1, e1), (i2, e2) = runs
        assert np.array_equal(i1, i2) and np.array_equal(e1, e2), case
    sq = rng.random((5, 77))
    buf = np.zeros(80)
    values = np.zeros(77)
    runs_ = np.array([[0, 77]], np.int64)
    for row in range(5):  # the lanes' sum of squares itself
        flat = np.sqrt(sq[row]).astype(np.float32)
        want = cb._ssd_at(flat, 0, runs_, values, buf)
        d = flat.astype(np.float64)
        assert cb.lane_sums_numpy((d * d)[None])[0] == want


def _brute_choices(monkeypatch):
    """Wraps Quilter.choose: every block the bound searched must choose as a brute-force
    search of its content with a fresh copy of its generator does; returns the counts."""
    seen = {"scored": 0, "map": 0}
    real = Quilter.choose

    def choose(self, wk):
        fresh = BlockRng(self.seed, wk.index) if isinstance(wk.rng, BlockRng) else None
        got = real(self, wk)
        if wk.found is None or wk.found[0] not in seen:
            return got
        seen[wk.found[0]] += 1
        if wk.found[0] == "scored" and fresh is not None:
            e = brute_force(self.match_sample, wk.old, wk.filled)
            v, _ = self.valid(wk.h, wk.w)
            if v is not None:
                e[~v] = np.inf
            zero = self.zero_level_for(wk)
            k, e_min, n = select_within_tolerance(
                e, tolerance=self.tolerance, zero_level=zero, rng=fresh
            )
            assert got[3] == n and got[2] == pytest.approx(e_min, rel=1e-12)
            if wk.depth == 0:  # a split block's children draw on from its generator
                assert got[0] == divmod(k, e.shape[1])
        return got

    monkeypatch.setattr(Quilter, "choose", choose)
    return seen


@pytest.mark.parametrize(
    "axes, options",
    [
        (1, {}),
        (2, {}),
        (1, dict(tileable=True)),  # wrap-around blocks with bottom and right arms
        (1, dict(adaptive_threshold=0.0005, min_block=13)),  # split blocks' children
    ],
)
def test_quilting_through_the_bound_chooses_as_brute_force(axes, options, monkeypatch):
    _jit.load()
    seen = _brute_choices(monkeypatch)
    quilt(coloured(30 + axes, axes), (120, 130), block=28, overlap=6, rng=4, threads=1, **options)
    assert seen["scored"] >= 20 and seen["map"] == 0


def _bound_spies(monkeypatch):
    """Spies on Quilter.make_bound and Quilter._bounded: ``built`` gets, per run, whether its
    bound was built; ``bounded[i]`` counts run i's blocks searched through it (in this
    process)."""
    built, bounded = [], []
    make, search = Quilter.make_bound, Quilter._bounded

    def make_bound(self):
        got = make(self)
        built.append(got is not None)
        bounded.append(0)
        return got

    def _bounded(self, wk, valid):
        got = search(self, wk, valid)
        bounded[-1] += got
        return got

    monkeypatch.setattr(Quilter, "make_bound", make_bound)
    monkeypatch.setattr(Quilter, "_bounded", _bounded)
    return built, bounded


def test_the_bound_is_built_only_where_blocks_are_searched_alone(monkeypatch):
    """Below scheduler.POOL_MIN_SAMPLE_AREA the blocks are searched in batches, never through
    the bound: it (and its probe searches) is not built there (190² sample, 200² output,
    block 32: 29.1 ms with the unused bound against 26.0 ms without); above, it is."""
    _jit.load()
    builds = []
    real = cb.ColourBound.__init__

    def init(self, *args, **kwargs):
        builds.append(args[0].shape)
        real(self, *args, **kwargs)

    monkeypatch.setattr(cb.ColourBound, "__init__", init)
    _, bounded = _bound_spies(monkeypatch)
    kw = dict(block=28, overlap=6, rng=4, mode="exact")
    small = coloured(80, 1, (190, 200))
    assert small.shape[0] * small.shape[1] < POOL_MIN_SAMPLE_AREA
    for threads in (1, 2):
        quilt(small, (120, 130), threads=threads, **kw)
    assert builds == [] and bounded == [0, 0]
    large = coloured(80, 1, (200, 200))
    assert large.shape[0] * large.shape[1] >= POOL_MIN_SAMPLE_AREA
    quilt(large, (120, 130), threads=1, **kw)
    assert builds == [(200, 200, 3)] and bounded[-1] >= 20


@pytest.mark.parametrize("sample", ["one axis", "two axes", "bright, low contrast", "grey RGB"])
@pytest.mark.parametrize("compiled", [True, False])
def test_the_transforms_stay_within_the_round_off_margin(sample, compiled, monkeypatch):
    """The bound's FFT values (``rows + const``, as the search takes them) against the bound
    computed directly in float64 from the rotated float32 sample: within the margin ``δ``, and
    well within it (measured: at most 0.4 % of ``δ``), so a margin of 0 or a wrong transform
    fails."""
    _jit.load()
    size = (64, 72)
    if sample == "one axis":
        s = coloured(70, 1, size)
    elif sample == "two axes":
        s = coloured(71, 2, size)
    elif sample == "bright, low contrast":  # the constant term's rounding counts
        s = (0.92 + 0.02 * (coloured(72, 1, size) - 0.5)).astype(np.float32)
    else:
        s = np.repeat(np.random.default_rng(73).random((*size, 1), dtype=np.float32), 3, axis=2)
    bound = cb.ColourBound.build(s)
    assert bound is not None
    rot = np.empty((*size, bound.m), np.float32)
    rot[:] = s.astype(np.float64) @ bound.lead.T
    monkeypatch.setattr(_jit, "loaded", lambda: compiled)
    rng = np.random.default_rng(1)
    for case in range(6):
        bh, bw = [(20, 24), (17, 31), (32, 9)][case % 3]
        y, x = rng.integers(0, size[0] - bh), rng.integers(0, size[1] - bw)
        old = s[y : y + bh, x : x + bw] + 0.01 * rng.standard_normal((bh, bw, 3))
        filled = np.zeros((bh, bw), bool)
        filled[: rng.integers(1, 8)] = True
        filled[:, : rng.integers(1, 8)] = True
        k, wts, const, count = cb.rotate_content_numpy(old.astype(np.float32), filled, bound.lead)
        got = np.array(bound.spec.rows(k, wts)[0], np.float64) + const
        want = brute_force(rot, k[0].transpose(1, 2, 0), filled)
        delta = cb.margin(
            bound.norm_s, bound.norm_q, np.sqrt(const), count, const, bound.spec.padded
        )
        worst = np.abs(got - want).max()
        assert worst <= delta / 10, (case, worst, delta)


@pytest.mark.parametrize("options", [{}, dict(tileable=True)])
def test_quilting_through_the_bound_is_the_same_on_any_thread_count_and_without_numba(
    options, monkeypatch
):
    _jit.load()
    sample = coloured(40, 1)
    built, bounded = _bound_spies(monkeypatch)
    kw = dict(block=28, overlap=6, rng=3, mode="exact", **options)
    runs = [quilt(sample, (150, 170), threads=t, **kw) for t in (1, 2, 3)]
    with monkeypatch.context() as m:
        m.setattr(_jit, "loaded", lambda: False)
        runs.append(quilt(sample, (150, 170), threads=1, **kw))
    # every run went through the bound (worker processes' searches are not counted here: on
    # 2 and 3 threads only the blocks placed before the fork)
    assert built == [True] * 4 and bounded[0] >= 20 and bounded[3] >= 20, (built, bounded)
    assert all(bounded[1:3]), bounded
    for run in runs[1:]:
        assert np.array_equal(run.image, runs[0].image)
        for a, b in zip(run.blocks, runs[0].blocks, strict=True):
            assert (a.source, a.position, a.candidates) == (b.source, b.position, b.candidates)
            same = np.array_equal(
                [a.match_error, a.best_error], [b.match_error, b.best_error], True
            )
            assert same


def test_samples_the_bound_does_not_help_keep_the_full_maps():
    grey = np.random.default_rng(0).random((50, 60, 1), dtype=np.float32)
    rgb = np.random.default_rng(0).random((50, 60, 3), dtype=np.float32)  # every axis needed
    assert cb.ColourBound.build(grey) is None and cb.ColourBound.build(rgb) is None
    grey3 = np.repeat(grey, 3, axis=2)  # a grey photo stored as RGB: one axis
    assert cb.ColourBound.build(grey3).m == 1


@pytest.mark.parametrize("axes", [1, 2])
def test_the_memory_a_bound_holds_is_what_the_estimate_counts(axes):
    """``extra_bytes`` (added to the peak estimate of a run that takes the bound) against the
    memory a built bound holds (traced: rotated copy, spectra); and a whole run's traced peak
    within 60-125 % of its estimate, as tests/engine/test_quilting_estimate.py asks."""
    import tracemalloc

    from engine.quilting import iter_quilt
    from engine.quilting.estimate import Estimated

    _jit.load()
    s = coloured(50 + axes, axes, (600, 600))
    cb.ColourBound.build(s[:300, :300])  # numpy's and ducc0's first calls allocate
    tracemalloc.start()
    try:
        bound = cb.ColourBound.build(s)
        held, _ = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        del bound
        quilt(s[:300, :300], (100, 100), block=48, overlap=8, rng=0, threads=1)
        tracemalloc.stop()
        tracemalloc.start()
        for ev in iter_quilt(s, (300, 300), block=48, overlap=8, mode="exact", rng=0, threads=1):
            if isinstance(ev, Estimated):
                plan = ev.plan
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert 0.8 * held <= cb.extra_bytes(s) <= 1.25 * held
    assert 0.6 * plan.peak_bytes <= peak <= 1.25 * plan.peak_bytes


def test_a_mostly_flat_sample_keeps_the_full_maps(monkeypatch):
    """Its blocks would mostly take the full map after the bound's transforms (job B with 90 %
    of its sample flat: 0.78 s against 0.49 s): its probes say so before the run, and the run
    is the full maps' search, block for block."""
    _jit.load()
    textured = coloured(60, 1)
    flat = textured.copy()
    flat[:190] = np.array([0.55, 0.6, 0.7], np.float32)
    flat[:190] += 0.002 * np.random.default_rng(0).standard_normal((190, 200, 3)).astype(np.float32)
    bounds = []
    real = Quilter.make_bound

    def make_bound(self):
        bounds.append(real(self))
        return bounds[-1]

    monkeypatch.setattr(Quilter, "make_bound", make_bound)
    seen = _brute_choices(monkeypatch)
    kw = dict(block=28, overlap=6, rng=4, threads=1)
    quilt(flat, (120, 130), **kw)
    assert bounds == [None] and seen["scored"] == 0 and seen["map"] > 20
    quilt(textured, (120, 130), **kw)
    assert bounds[1] is not None and seen["scored"] > 20
    bound = cb.ColourBound.build(flat)
    share = bound.fallback_share((28, 28), 6, tolerance=0.1, zero_level=0.05)
    assert share > cb.MAX_FALLBACK
