"""The block search's FFTs from scipy.fft (threaded) or numpy.fft (no scipy to import).

Importing :mod:`scipy.fft` costs ~0.25 s (it loads ``scipy.special``); a small synthesis whose
whole search takes less has its transforms from :mod:`numpy.fft` instead (numpy >= 2 computes
float32 in float32, as scipy does). The two round differently in the last bits, so which one a
run uses is decided from the run's own size (:func:`engine.quilting.estimate.plan`), never from
what happens to be imported: the same inputs always give the same output.
"""

from __future__ import annotations

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
    import scipy.fft

    return scipy.fft
