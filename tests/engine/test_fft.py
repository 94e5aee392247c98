"""engine.fft: scipy's fast lengths and transforms without importing scipy.fft; numpy's."""

import subprocess
import sys

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


def test_every_run_takes_scipys_transforms_and_small_ones_time_no_reference(monkeypatch):
    """Small dp runs load scipy's pocketfft by itself (engine.fft) and skip machine_factor,
    whose reference FFT imports scipy.fft; numpy's transforms (twice slower) are never planned."""
    timed = []
    monkeypatch.setattr(estimate, "machine_factor", lambda: timed.append(1) or 1.0)
    assert _plan(128, 512).fft == "scipy" and not timed  # synth job A
    for plan in (
        _plan(128, 2048),  # many blocks
        _plan(512, 512),  # a large sample
        _plan(128, 512, seam=SeamSpec("dp", blend="feather")),  # scipy anyway
        _plan(128, 512, seam=SeamSpec("dijkstra")),
    ):
        assert plan.fft == "scipy"
    assert len(timed) == 4


def test_scipys_transforms_load_without_scipy_fft_and_give_its_numbers():
    code = (
        "import sys, numpy as np; from engine.fft import transforms; t = transforms('scipy'); "
        "x = np.random.default_rng(0).random((3, 20, 24), dtype=np.float32); "
        "a = t.irfft(t.ifft(t.fft(t.rfft(x, n=32, axis=-1), n=40, axis=-2), axis=-2), n=32); "
        "assert 'scipy' not in sys.modules, 'scipy imported'; import scipy.fft as f; "
        "b = f.irfft(f.ifft(f.fft(f.rfft(x, n=32, axis=-1), n=40, axis=-2), axis=-2), n=32); "
        "assert a.dtype == b.dtype and np.array_equal(a, b); print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "ok"


def test_an_extension_that_no_longer_takes_scipys_arguments_falls_back_to_scipy_fft(monkeypatch):
    import scipy.fft as sfft

    from engine import fft

    class Changed:  # a scipy release whose private extension changed its call signature
        def r2c(self, *args):
            raise TypeError("r2c() takes 3 positional arguments")

        c2c = c2r = r2c

    monkeypatch.setattr(fft, "_POCKETFFT", [])
    monkeypatch.setattr(fft, "_load_pocketfft", Changed)
    assert fft.transforms("scipy") is sfft
    monkeypatch.setattr(fft, "_POCKETFFT", [])
    monkeypatch.undo()
    assert fft._works(fft._load_pocketfft())  # the installed scipy's extension passes the check
