"""engine.fft: scipy's fast lengths without scipy, numpy's transforms for small runs only."""

import numpy as np
import pytest
import scipy.fft

from engine.fft import next_fast_len, transforms
from engine.matching import SampleSpectrum
from engine.quilting import estimate
from engine.quilting.options import check_options
from engine.seams import SeamSpec


def test_next_fast_len_is_scipys():
    for n in range(1, 5000):
        assert next_fast_len(n) == scipy.fft.next_fast_len(n, real=True), n


def test_both_backends_give_the_same_errors_up_to_round_off():
    rng = np.random.default_rng(0)
    s = rng.random((70, 90, 3), dtype=np.float32)
    t = rng.random((4, 16, 20, 3), dtype=np.float32)
    w = (rng.random((4, 16, 20)) < 0.4).astype(np.float32)
    a = SampleSpectrum(s).ssd(t, w)
    b = SampleSpectrum(s, backend="numpy").ssd(t, w)
    assert a.dtype == b.dtype == np.float32
    assert np.allclose(a, b, rtol=1e-4, atol=1e-4)
    with pytest.raises(ValueError, match="backend"):
        transforms("fftw")


def _plan(sample_side, out_side, block=32, overlap=6, seam=None):
    s = np.zeros((sample_side, sample_side, 3), np.float32)
    opts = check_options(
        s,
        (out_side, out_side),
        block=block,
        overlap=overlap,
        select="best",
        tolerance=0.1,
        candidates=None,
        seam=seam,
        excluded=None,
        tileable=False,
        adaptive_threshold=None,
        min_block=None,
        mode="exact",
    )
    return estimate.plan(opts, 1)


def test_only_small_dp_runs_take_numpys_transforms(monkeypatch):
    monkeypatch.setattr(estimate, "machine_factor", lambda: 1.0)
    assert _plan(128, 512).fft == "numpy"  # synth job A
    assert _plan(128, 2048).fft == "scipy"  # many blocks
    assert _plan(512, 512).fft == "scipy"  # a large sample
    assert _plan(128, 512, seam=SeamSpec("dp", blend="feather")).fft == "scipy"  # scipy anyway
    assert _plan(128, 512, seam=SeamSpec("dijkstra")).fft == "scipy"
