"""The block search's FFTs from scipy.fft (threaded) or numpy.fft (no scipy to import).

Importing :mod:`scipy.fft` costs ~0.25 s (it loads ``scipy.special``); a small synthesis whose
whole search takes less has its transforms from :mod:`numpy.fft` instead (numpy >= 2 computes
float32 in float32, as scipy does). The two round differently in the last bits, so which one a
run uses is decided from the run's own size (:func:`engine.quilting.estimate.plan`), never from
what happens to be imported: the same inputs always give the same output.
"""

from __future__ import annotations

import threading

import numpy as np

__all__ = ["BACKENDS", "next_fast_len", "transforms"]

BACKENDS = ("scipy", "numpy")


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
    if backend != "scipy":
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    return _scipy()


_POCKETFFT: list = []  # the extension, once loaded (None: not loadable here)
_LOCK = threading.Lock()


def _scipy():
    """scipy.fft's transforms, from its pocketfft extension loaded by itself when it can be.

    Importing :mod:`scipy.fft` costs ~0.25 s (its package loads ``scipy.special``); the compiled
    extension behind its FFTs loads in a few milliseconds (privately: no ``scipy`` module is
    imported, and a later ``import scipy.fft`` loads its own). :class:`_Pocketfft` prepares the
    arguments as ``scipy.fft`` does: the same results, and less time per call than scipy.fft's
    dispatch (its backends) takes."""
    with _LOCK:
        if not _POCKETFFT:
            module = _load_pocketfft()
            _POCKETFFT.append(module if module is not None and _works(module) else None)
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


def _works(module) -> bool:
    """Whether the extension, called as :class:`_Pocketfft` calls it, gives numpy's transforms
    of a small array: its call signature is scipy's private API, so a scipy release that changes
    it falls back to ``scipy.fft`` instead of failing in the middle of a search."""
    x = np.random.default_rng(0).random((6, 10), dtype=np.float32)
    try:
        t = _Pocketfft(module)
        f = t.fft(t.rfft(x, n=12), n=8, axis=0)
        back = t.irfft(t.ifft(f, axis=0), n=12)
    except Exception:
        return False
    ref = np.fft.fft(np.fft.rfft(x, n=12), n=8, axis=0)
    return bool(
        np.allclose(f, ref, rtol=1e-4, atol=1e-4)
        and np.allclose(back[:6, :10], x, atol=1e-5)
        and back.dtype == np.float32
    )


class _Pocketfft:
    """scipy.fft's ``rfft``, ``fft``, ``ifft``, ``irfft`` (for native float32/complex64 input,
    default norm) calling its extension as scipy.fft does (``scipy/fft/_pocketfft/basic.py``)."""

    def __init__(self, module):
        self.m = module

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
        return self.m.r2c(tmp, (axis,), True, 0, None, workers or 1)

    def fft(self, x, n=None, axis=-1, workers=None):
        tmp, copied = self._padded(x, n, axis)
        return self.m.c2c(tmp, (axis,), True, 0, tmp if copied else None, workers or 1)

    def ifft(self, x, n=None, axis=-1, workers=None):
        tmp, copied = self._padded(x, n, axis)
        return self.m.c2c(tmp, (axis,), False, 2, tmp if copied else None, workers or 1)

    def irfft(self, x, n=None, axis=-1, workers=None):
        x = np.asarray(x)
        if n is None:
            n = (x.shape[axis] - 1) * 2
        tmp, _ = self._padded(x, n // 2 + 1, axis)
        return self.m.c2r(tmp, (axis,), n, False, 2, None, workers or 1)
