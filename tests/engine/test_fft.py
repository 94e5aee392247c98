"""engine.fft: scipy's fast lengths; ducc0's transforms (the default when installed) with their
fallback, scipy's pocketfft without importing scipy.fft; numpy's."""

import subprocess
import sys
import threading

import numpy as np
import pytest
import scipy.fft

from engine import fft
from engine.fft import default_backend, next_fast_len, transforms
from engine.matching import SampleSpectrum
from engine.quilting import Estimated, estimate, iter_quilt, scheduler
from engine.quilting.options import check_options
from engine.seams import SeamSpec
from tests.engine.helpers import events_and_result, smooth_texture


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


def test_every_run_takes_the_installed_backend_and_small_ones_time_no_reference(monkeypatch):
    """Every plan takes default_backend()'s transforms: ducc0, a dependency, when installed.
    Small dp runs skip machine_factor, whose reference FFT imports scipy.fft; numpy's
    transforms (twice slower) are never planned."""
    assert default_backend() == "ducc0"
    timed = []
    monkeypatch.setattr(estimate, "machine_factor", lambda: timed.append(1) or 1.0)
    assert _plan(128, 512).fft == "ducc0" and not timed  # synth job A
    for plan in (
        _plan(128, 2048),  # many blocks
        _plan(512, 512),  # a large sample
        _plan(128, 512, seam=SeamSpec("dp", blend="feather")),  # scipy anyway
        _plan(128, 512, seam=SeamSpec("dijkstra")),
    ):
        assert plan.fft == "ducc0"
    assert len(timed) == 4


def test_the_environment_can_ask_for_scipys_transforms(monkeypatch):
    monkeypatch.setenv(fft.ENV, "scipy")
    assert default_backend() == "scipy" and _plan(128, 512).fft == "scipy"
    assert SampleSpectrum(np.zeros((20, 20, 3), np.float32)).backend == "scipy"
    monkeypatch.setenv(fft.ENV, "ducc0")
    assert default_backend() == "ducc0"


def test_without_ducc0_every_run_takes_scipys_pocketfft():
    """The fallback: with ducc0 not importable the backend is scipy's, chosen before any run,
    and a quilting job runs on it (no scipy.fft import for a small job either)."""
    code = (
        "import sys; sys.modules['ducc0'] = None; import numpy as np; from engine import fft; "
        "from engine.quilting import iter_quilt, Estimated; "
        "assert fft.default_backend() == 'scipy'; "
        "s = np.random.default_rng(0).random((64, 64, 3), dtype=np.float32); "
        "plans = [e.plan for e in iter_quilt(s, (96, 96), block=24, overlap=6, rng=0, "
        "mode='exact') if isinstance(e, Estimated)]; "
        "assert plans[0].fft == 'scipy' and 'scipy.fft' not in sys.modules; print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "ok"


@pytest.mark.parametrize("backend", ["ducc0", "scipy"])
def test_the_same_output_for_any_thread_count_on_either_backend(backend, monkeypatch):
    monkeypatch.setattr(scheduler, "POOL_MIN_SAMPLE_AREA", 0)  # the pool, even for this sample
    monkeypatch.setattr(fft, "_DUCC", [None] if backend == "scipy" else [])
    assert default_backend() == backend
    s = smooth_texture((96, 96), seed=2)
    runs = [
        events_and_result(iter_quilt(s, (100, 120), block=24, overlap=6, rng=7, threads=t))
        for t in (1, 2)
    ]
    for events, _ in runs:
        assert [e.plan.fft for e in events if isinstance(e, Estimated)] == [backend]
    np.testing.assert_array_equal(runs[0][1].image, runs[1][1].image)


def _query(rng, n, c, g, bh, bw):
    t = rng.random((n, c, bh, bw), dtype=np.float32)
    w = (rng.random((n, g, bh, bw)) < 0.5).astype(np.float32)
    return t * w[:, [i % g for i in range(c)]], w, rng.random(n)


def test_ducc0s_queries_equal_scipys_up_to_round_off():
    """Odd padded sizes, two channel groups (texture transfer), several block shapes and batch
    sizes in turn: one spectrum gives what a fresh one gives, and scipy's errors up to float
    round-off."""
    rng = np.random.default_rng(3)
    s = rng.random((70, 91, 4), dtype=np.float32)
    groups = ((0, 1, 2), (3,))
    used = SampleSpectrum(s, groups=groups, backend="ducc0")
    for n, bh, bw in ((3, 16, 20), (1, 9, 31), (3, 16, 20), (2, 30, 7), (3, 16, 20)):
        k, w, const = _query(rng, n, 4, 2, bh, bw)
        fresh = SampleSpectrum(s, groups=groups, backend="ducc0")
        ref = SampleSpectrum(s, groups=groups, backend="scipy").ssd_terms(k, w, const)
        got = used.ssd_terms(k, w, const)
        np.testing.assert_array_equal(got, fresh.ssd_terms(k, w, const))
        np.testing.assert_allclose(got, ref, rtol=1e-4, atol=1e-3 * float(np.abs(ref).max()))
        corr = used.correlate(k)
        np.testing.assert_allclose(
            corr, SampleSpectrum(s, groups=groups, backend="scipy").correlate(k), atol=1e-3
        )


def test_one_ducc0_spectrum_queried_from_two_threads_gives_each_query_its_own_result():
    rng = np.random.default_rng(4)
    s = rng.random((96, 96, 3), dtype=np.float32)
    spec = SampleSpectrum(s, backend="ducc0")
    queries = [_query(rng, 2, 3, 1, bh, bw) for bh, bw in ((20, 20), (12, 24)) * 4]
    serial = [spec.ssd_terms(*q) for q in queries]
    out = {}

    def run(i):
        for _ in range(5):
            out[i] = spec.ssd_terms(*queries[i])

    threads = [threading.Thread(target=run, args=(i,)) for i in range(len(queries))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for i, e in enumerate(serial):
        np.testing.assert_array_equal(out[i], e)


def test_ducc0s_transforms_with_scipys_signature_give_numpys():
    t = transforms("ducc0")
    x = np.random.default_rng(5).random((5, 14, 18), dtype=np.float32)
    f = t.fft(t.rfft(x, n=24, axis=-1), n=16, axis=-2)
    ref = np.fft.fft(np.fft.rfft(x, n=24, axis=-1), n=16, axis=-2)
    assert f.dtype == np.complex64
    np.testing.assert_allclose(f, ref, rtol=1e-4, atol=1e-4)
    back = t.irfft(t.ifft(f, axis=-2), n=24)
    np.testing.assert_allclose(back[:, :14, :18], x, atol=1e-5)
    np.testing.assert_allclose(t.rfft(x, n=10), np.fft.rfft(x, n=10), rtol=1e-4, atol=1e-4)


@pytest.mark.parametrize("backend", ["ducc0", "scipy", "numpy"])
def test_query_spectra_from_a_threads_kept_buffers_equal_fresh_ones_and_numpys(backend):
    """engine.fft.spectra: half along the rows, columns first; ``reuse`` keeps the zero-padded
    buffers of the latest shape (taller, shorter, narrower kernels in turn: no stale rows or
    columns); the conjugate from the transforms of opposite sign; inverse() takes it back."""
    t = transforms(backend)
    rng = np.random.default_rng(6)
    shape = (24, 20)
    kshapes = ((2, 3, 10, 12), (2, 3, 7, 12), (2, 3, 10, 5), (2, 3, 10, 12), (1, 9, 4))
    kshapes += ((3, 3, 10, 12), (1, 3, 10, 12), (9, 4), (2, 1, 10, 12), (2, 3, 10, 12))
    for kshape in kshapes:
        k = rng.random(kshape, dtype=np.float32)
        kept = fft.spectra(t, k, shape, conj=True, reuse=True)
        np.testing.assert_array_equal(kept, fft.spectra(t, k, shape, conj=True))
        ref = np.fft.fft(np.fft.rfft(k, n=24, axis=-2), n=20, axis=-1)
        assert kept.shape == (*kshape[:-2], 13, 20) and kept.dtype == np.complex64
        np.testing.assert_allclose(kept, ref.conj(), rtol=1e-4, atol=1e-4)
        f = fft.spectra(t, k, shape)
        np.testing.assert_allclose(f, ref, rtol=1e-4, atol=1e-4)
        back = fft.inverse(t, f, shape, kshape[-2] - 1, kshape[-1] - 2)
        np.testing.assert_allclose(back, k[..., :-1, :-2], atol=1e-5)


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
    assert fft._works(
        fft._Pocketfft(fft._load_pocketfft())
    )  # the installed scipy's extension passes the check


def test_a_threads_kept_buffers_serve_smaller_batches_and_two_shapes():
    """Job A's batches of 1 to 8 blocks and its weight maps take the same kept buffers (the
    first n entries of the largest batch's) instead of allocating and zeroing new ones."""
    t = transforms("ducc0")
    if not isinstance(t, fft._Padded):
        pytest.skip("ducc0 not installed")
    rng = np.random.default_rng(7)
    shape = (24, 20)
    fft.spectra(t, rng.random((4, 3, 10, 12), dtype=np.float32), shape, conj=True, reuse=True)
    fft.spectra(t, rng.random((1, 1, 10, 12), dtype=np.float32), shape, conj=True, reuse=True)
    kept = {key: (pad, mid) for key, (pad, mid) in t._kept().items()}
    for n in (2, 1, 4, 3):
        k = rng.random((n, 3, 10, 12), dtype=np.float32)
        got = fft.spectra(t, k, shape, conj=True, reuse=True)
        np.testing.assert_array_equal(got, fft.spectra(t, k, shape, conj=True))
        w = rng.random((1, 1, 10, 12), dtype=np.float32)
        fft.spectra(t, w, shape, conj=True, reuse=True)
    now = t._kept()
    assert now.keys() == kept.keys()
    assert all(now[key][0] is kept[key][0] and now[key][1] is kept[key][1] for key in kept)
