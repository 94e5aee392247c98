"""The block search's FFTs: ducc0 when installed, else scipy's pocketfft (or numpy.fft).

ducc0 (by pocketfft's author) is the default: a query of job B's exact search takes 8-13 %
less time with it (``benchmarks/fft_backends.py``, README). Which backend a run uses is
:func:`default_backend`'s rule: ducc0 if it is installed (and works), else scipy's pocketfft —
decided by the installation alone, never by timing or by what happens to be imported, so the
same inputs give the same output on one installation (the backends round differently in the
last bits). scipy's transforms come from its pocketfft extension loaded by itself (importing
:mod:`scipy.fft` costs ~0.25 s, more than a small synthesis); numpy's remain for callers who ask.
"""

from __future__ import annotations

import os
import threading

import numpy as np

__all__ = [
    "BACKENDS",
    "BUFFER_BYTES",
    "ENV",
    "LOADING_LOCK",
    "default_backend",
    "inverse",
    "next_fast_len",
    "spectra",
    "transforms",
]

BACKENDS = ("ducc0", "scipy", "numpy")


def next_fast_len(n: int) -> int:
    """The smallest 5-smooth number >= ``n`` (``scipy.fft.next_fast_len(n, real=True)``)."""
    if n <= 6:
        return max(int(n), 1)
    best = 2 * n
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            # the smallest power of two times p35 that reaches n
            q = -(-n // p35)
            p2 = 1 << (q - 1).bit_length()
            best = min(best, p2 * p35)
            p35 *= 3
        p5 *= 5
    return best


class _Numpy:
    """numpy.fft with scipy.fft's signature (``workers`` ignored: numpy has one thread)."""

    @staticmethod
    def rfft(x, n=None, axis=-1, workers=None):
        return np.fft.rfft(x, n=n, axis=axis)

    @staticmethod
    def fft(x, n=None, axis=-1, workers=None):
        return np.fft.fft(x, n=n, axis=axis)

    @staticmethod
    def ifft(x, n=None, axis=-1, workers=None):
        return np.fft.ifft(x, n=n, axis=axis)

    @staticmethod
    def irfft(x, n=None, axis=-1, workers=None):
        return np.fft.irfft(x, n=n, axis=axis)


def transforms(backend: str = "scipy"):
    """An object with scipy.fft's ``rfft``, ``fft``, ``ifft``, ``irfft`` from ``backend``."""
    if backend == "numpy":
        return _Numpy
    if backend == "ducc0":
        module = _ducc0()
        if module is None:
            raise ValueError("the ducc0 backend is not installed (see default_backend)")
        return _Ducc(module)
    if backend != "scipy":
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    return _scipy()


ENV = "QUILT_STUDIO_FFT"
"""Environment variable that picks the search's transforms: ``scipy`` (or ``ducc0``)."""


def default_backend() -> str:
    """``"ducc0"`` when ducc0 is installed (and computes a small transform right), else
    ``"scipy"``; ``QUILT_STUDIO_FFT=scipy`` in the environment asks for scipy's (benchmarks
    compare the two). The rule behind every exact search's transforms: it depends on what is
    installed and on that variable only, never on timing or on what happens to be imported, so
    the same inputs give the same output in every run on one installation (the two round
    differently in the last bits)."""
    if os.environ.get(ENV, "").strip().lower() == "scipy" or _ducc0() is None:
        return "scipy"
    return "ducc0"


_DUCC: list = []  # ducc0.fft once imported (None: not installed or not working)


def _ducc0():
    with LOADING_LOCK:
        if not _DUCC:
            try:
                import ducc0.fft as module
            except ImportError:
                module = None
            ok = module is not None and _works(_Ducc(module))
            _DUCC.append(module if ok else None)
    return _DUCC[0]


_POCKETFFT: list = []  # the extension, once loaded (None: not loadable here)
LOADING_LOCK = threading.Lock()
"""Held while a backend is imported and checked (taken around forks, as ``engine._jit``'s)."""


def _scipy():
    """scipy.fft's transforms, from its pocketfft extension loaded by itself when it can be.

    Importing :mod:`scipy.fft` costs ~0.25 s (its package loads ``scipy.special``); the compiled
    extension behind its FFTs loads in a few milliseconds (privately: no ``scipy`` module is
    imported, and a later ``import scipy.fft`` loads its own). :class:`_Pocketfft` prepares the
    arguments as ``scipy.fft`` does: the same results, and less time per call than scipy.fft's
    dispatch (its backends) takes."""
    with LOADING_LOCK:
        if not _POCKETFFT:
            module = _load_pocketfft()
            ok = module is not None and _works(_Pocketfft(module))
            _POCKETFFT.append(module if ok else None)
    if _POCKETFFT[0] is None:
        import scipy.fft

        return scipy.fft
    return _Pocketfft(_POCKETFFT[0])


def _load_pocketfft():
    import importlib.util
    from pathlib import Path

    try:
        spec = importlib.util.find_spec("scipy")
        folder = Path(spec.origin).parent / "fft" / "_pocketfft"
        path = next(folder.glob("pypocketfft.*"))
        ext = importlib.util.spec_from_file_location("pypocketfft", path)
        module = importlib.util.module_from_spec(ext)
        ext.loader.exec_module(module)
    except Exception:  # another scipy layout: import scipy.fft instead
        return None
    return module


def _works(t) -> bool:
    """Whether transforms ``t`` (:class:`_Pocketfft`, :class:`_Ducc`) give numpy's of a small
    array: the pocketfft extension's call signature is scipy's private API, so a scipy release
    that changes it falls back to ``scipy.fft`` instead of failing in the middle of a search
    (and a ducc0 that does not work here is not used)."""
    x = np.random.default_rng(0).random((6, 10), dtype=np.float32)
    try:
        f = t.fft(t.rfft(x, n=12), n=8, axis=0)
        back = t.irfft(t.ifft(f, axis=0), n=12)
        g = t.spectra(x, (8, 12), conj=True)  # the opposite sign, out= and inorm of its calls
        back2 = inverse(t, np.conjugate(g), (8, 12), 6, 10)
    except Exception:
        return False
    ref = np.fft.fft(np.fft.rfft(x, n=12), n=8, axis=0)
    ref2 = np.fft.fft(np.fft.rfft(x, n=8, axis=0), n=12)
    return bool(
        np.allclose(f, ref, rtol=1e-4, atol=1e-4)
        and np.allclose(back[:6, :10], x, atol=1e-5)
        and back.dtype == np.float32
        and np.allclose(g, ref2.conj(), rtol=1e-4, atol=1e-4)
        and np.allclose(back2, x, atol=1e-5)
    )


BUFFER_BYTES = 4 * 2**20
"""Largest zero-padded input a thread keeps between calls of :meth:`_Padded.spectra` (the
kernels of a batch of three blocks of job B: 2.8 MB): a larger one (a large sample's) is
allocated per call, where its transforms dwarf the allocation."""


KEPT_SHAPES = 8
"""Shapes whose buffers a thread keeps: a search's kernels and its weight maps, of each block
shape (job A's blocks come in four: cropped at the right and at the bottom edge), together at
most :data:`BUFFER_BYTES` (the oldest go first; the peak memory estimate counts one buffer)."""


def spectra(t, k, shape, *, conj=False, workers=1, reuse=False) -> np.ndarray:
    """2-D DFT of real ``k`` (..., kh, kw) zero-padded to ``shape`` = (hp, wp), half along the
    rows: (..., hp // 2 + 1, wp), or its complex conjugate; from transforms ``t``
    (:func:`transforms`). The columns are transformed first, over the kernel's kw columns only,
    so the long pass (every kept frequency row) runs along contiguous memory (a third faster
    than along strided columns). ``reuse``: see :meth:`_Padded.spectra`."""
    if isinstance(t, _Padded):
        return t.spectra(k, shape, conj=conj, workers=workers, reuse=reuse)
    hp, wp = shape
    f = t.fft(t.rfft(k, n=hp, axis=-2, workers=workers), n=wp, axis=-1, workers=workers)
    return np.conjugate(f, out=f) if conj else f


def inverse(t, x, shape, rows: int, cols: int, *, workers: int = 1, out=None) -> np.ndarray:
    """The first ``rows`` x ``cols`` values of the real inverse of :func:`spectra`'s layout
    (normalised): a (..., rows, cols) view. ``x`` may be overwritten. ``out``: a float32 array
    (..., hp, cols) for the whole inverse (:class:`_Padded` transforms; others ignore it)."""
    hp, _ = shape
    if isinstance(t, _Padded):
        y = t._c2c(x, -1, False, x, workers)[..., :cols]
        return t._c2r(y, -2, hp, workers, out)[..., :rows, :]
    y = t.ifft(x, axis=-1, workers=workers)[..., :cols]
    return t.irfft(y, n=hp, axis=-2, workers=workers)[..., :rows, :]


class _Padded:
    """scipy.fft's ``rfft``, ``fft``, ``ifft``, ``irfft`` signature (float32/complex64 input,
    default norm: the inverses scaled by 1/n) over a library's ``_r2c``, ``_c2c``, ``_c2r``;
    ``n`` pads with zeros or crops along ``axis`` as scipy.fft does."""

    def __init__(self, module):
        self.m = module
        self._local = threading.local()

    def spectra(self, k, shape, *, conj=False, workers=1, reuse=False) -> np.ndarray:
        """:func:`spectra`. ``reuse``: the zero-padded copies of ``k`` and their spectra live
        in buffers the calling thread keeps for the next call of the same shape (no allocation
        per call; :data:`KEPT_SHAPES` shapes, together up to :data:`BUFFER_BYTES`, with room for
        the largest batch seen: job A's batches of 1 to 8 blocks allocated and zeroed their
        buffers in 94 % of the calls). The rows' pass runs in place (job A 2-3 % faster than
        into a new array: its output stays in cache), so the spectra returned are then the
        kept buffer: valid until the thread's next call with ``reuse`` (of any shape: read
        them first), and its padding columns are zeroed again at the next call. The
        conjugate comes from the transforms of opposite sign (no pass of its own)."""
        hp, wp = shape
        k = np.asarray(k)
        *lead, kh, kw = k.shape
        n = lead[0] if lead else 1
        shape_in = (n, *lead[1:], hp, kw)
        shape_mid = (n, *lead[1:], hp // 2 + 1, wp)
        # rows past kh, columns past kw stay zero; a kept buffer has room for the largest batch
        # seen (batches of a level's last blocks are smaller): the first n of its entries
        key = (shape_in[1:], shape_mid[1:], kh)
        store = self._kept() if reuse else {}
        kept = store.get(key)
        reused = kept is not None and len(kept[0]) >= n
        if reused:
            pad, mid = kept[0][:n], kept[1][:n]
        else:
            pad, mid = np.zeros(shape_in, np.float32), np.zeros(shape_mid, np.complex64)
            kept = (pad, mid) if pad.nbytes + mid.nbytes <= BUFFER_BYTES else None
            if kept is not None and reuse:
                store.pop(key, None)
                size = pad.nbytes + mid.nbytes
                while store and (
                    len(store) >= KEPT_SHAPES
                    or size + sum(p.nbytes + m.nbytes for p, m in store.values()) > BUFFER_BYTES
                ):
                    del store[next(iter(store))]  # the oldest
                store[key] = kept
        if not lead:
            pad, mid = pad[0], mid[0]
        if reused:  # the last call's transform filled its padding
            mid[..., kw:] = 0
        pad[..., :kh, :] = k
        self._r2c(pad, -2, workers, not conj, mid[..., :kw])
        # in place: the spectra stay in the buffer the columns' pass just wrote (in cache)
        return self._c2c(mid, -1, not conj, mid, workers, inorm=0)

    def _kept(self) -> dict:
        """The calling thread's kept buffers: {shape key: (padded input, middle)}."""
        store = getattr(self._local, "kept", None)
        if store is None:
            store = self._local.kept = {}
        return store

    @staticmethod
    def _padded(x, n, axis):
        x = np.asarray(x)
        if n is None or x.shape[axis] == n:
            return x, False
        if x.shape[axis] > n:
            return x[(slice(None),) * (axis % x.ndim) + (slice(0, n),)], False
        shape = list(x.shape)
        shape[axis] = n
        z = np.zeros(shape, x.dtype)
        z[(slice(None),) * (axis % x.ndim) + (slice(0, x.shape[axis]),)] = x
        return z, True

    def rfft(self, x, n=None, axis=-1, workers=None):
        tmp, _ = self._padded(x, n, axis)
        return self._r2c(tmp, axis, workers or 1)

    def fft(self, x, n=None, axis=-1, workers=None):
        tmp, copied = self._padded(x, n, axis)  # a padded copy is transformed in place
        return self._c2c(tmp, axis, True, tmp if copied else None, workers or 1)

    def ifft(self, x, n=None, axis=-1, workers=None):
        tmp, copied = self._padded(x, n, axis)
        return self._c2c(tmp, axis, False, tmp if copied else None, workers or 1)

    def irfft(self, x, n=None, axis=-1, workers=None):
        x = np.asarray(x)
        if n is None:
            n = (x.shape[axis] - 1) * 2
        tmp, _ = self._padded(x, n // 2 + 1, axis)
        return self._c2r(tmp, axis, n, workers or 1)


class _Pocketfft(_Padded):
    """scipy's pocketfft extension called as scipy.fft calls it
    (``scipy/fft/_pocketfft/basic.py``)."""

    def _r2c(self, x, axis, workers, forward=True, out=None):
        return self.m.r2c(x, (axis,), forward, 0, out, workers)

    def _c2c(self, x, axis, forward, out, workers, inorm=None):
        inorm = (0 if forward else 2) if inorm is None else inorm
        return self.m.c2c(x, (axis,), forward, inorm, out, workers)

    def _c2r(self, x, axis, n, workers, out=None):
        return self.m.c2r(x, (axis,), n, False, 2, out, workers)


class _Ducc(_Padded):
    """``ducc0.fft`` (the successor of pocketfft by its author)."""

    def _r2c(self, x, axis, workers, forward=True, out=None):
        return self.m.r2c(x, axes=(axis,), forward=forward, out=out, nthreads=workers)

    def _c2c(self, x, axis, forward, out, workers, inorm=None):
        inorm = (0 if forward else 2) if inorm is None else inorm
        return self.m.c2c(x, axes=(axis,), forward=forward, inorm=inorm, out=out, nthreads=workers)

    def _c2r(self, x, axis, n, workers, out=None):
        return self.m.c2r(
            x, axes=(axis,), lastsize=n, forward=False, inorm=2, nthreads=workers, out=out
        )
