"""Products of spectra for the masked-SSD search (:class:`engine.matching.SampleSpectrum`).

A query's spectrum is ``Σ_c conj(F(K_c)) · F(S_c)`` over the channels (and the weight term
added): :func:`product_sum`, one compiled pass per query once numba is loaded, and a numpy
twin with the same bits while it is not (a small job). Its own module: ``engine.fft`` is
imported at a worker pool's fork (``engine.quilting.workers``), where registering a kernel
would wait for a loading lock another thread may hold.
"""

from __future__ import annotations

import numpy as np

from engine import _jit as jit
from engine._jit import njit

__all__ = ["product_sum"]


def product_sum(fk: np.ndarray, hs: np.ndarray, add=None) -> np.ndarray:
    """``Σ_c fk[:, c] · hs[c]`` (+ ``add[i]`` for query ``i``), complex64 (n, ...).

    Each complex product is taken as ``(ar·br − ai·bi, ar·bi + ai·br)``, every product rounded
    to float32 on its own, and the channels added in order, then ``add``: one compiled pass per
    query once numba is loaded (:func:`_product_sum_kernel`; numpy's SIMD complex multiply
    fuses one product of each part into the other, other bits), the same operations on the
    real and imaginary planes from numpy while it is not (:func:`_product_sum_numpy`). Inputs
    are taken as complex64 (numpy < 2's FFTs give complex128), so both paths see the same
    operands."""
    fk, hs = np.asarray(fk, np.complex64), np.asarray(hs, np.complex64)
    if add is not None:
        add = np.asarray(add, np.complex64)
        if add.shape != (fk.shape[0], *fk.shape[2:]):
            raise ValueError(f"add has shape {add.shape}, not {(fk.shape[0], *fk.shape[2:])}")
    if not jit.loaded():
        return _product_sum_numpy(fk, hs, add)
    n, c = fk.shape[:2]
    x = np.empty((n, *fk.shape[2:]), np.complex64)
    a = np.empty((n, 0), np.complex64) if add is None else add.reshape(n, -1)
    _product_sums(fk.reshape(n, c, -1), hs.reshape(c, -1), a, x.reshape(n, -1))
    return x


def _product_sum_numpy(fk, hs, add=None) -> np.ndarray:
    """:func:`product_sum` from numpy (the kernel's operations, in its order: the same bits)."""
    n, c = fk.shape[:2]
    x = np.empty((n, *fk.shape[2:]), np.complex64)
    fr, fi, hr, hi = fk.real, fk.imag, hs.real, hs.imag
    t, p = np.empty((2, *x.shape), np.float32)
    for ch in range(c):
        for out, a, b, op in ((x.real, hr, hi, np.subtract), (x.imag, hi, hr, np.add)):
            # out (+)= fr·a ∓ fi·b, each product rounded to float32
            q = np.multiply(fr[:, ch], a[ch], out=p if ch else out)
            op(q, np.multiply(fi[:, ch], b[ch], out=t), out=q)
            if ch:
                out += q
    if add is not None:
        for i in range(n):
            x[i] += add[i]
    return x


@njit(cache=True, nogil=True)
def _product_sums(fk, hs, add, out):  # pragma: no cover - compiled
    """:func:`_product_sum_kernel` for each query ``i`` of ``fk`` (n, c, m) into ``out`` (n, m),
    ``add`` (n, m) or (n, 0): one call per batch instead of one per query."""
    for i in range(fk.shape[0]):
        _product_sum_kernel(fk[i], hs, add[i], out[i])


@njit(cache=True, nogil=True)
def _product_sum_kernel(fk, hs, add, out):  # pragma: no cover - compiled
    """out[m] = Σ_c fk[c, m] · hs[c, m] (+ add[m] when ``add`` is not empty), the products as
    :func:`product_sum` takes them. Three channels and ``add`` (a colour query) in one pass
    (32 against numpy's 56 us for job B's 129 x 256 spectra), else a pass per channel."""
    c, m = fk.shape
    if c == 3 and add.size:
        for j in range(m):
            a, b = fk[0, j], hs[0, j]
            xr = a.real * b.real - a.imag * b.imag
            xi = a.real * b.imag + a.imag * b.real
            a, b = fk[1, j], hs[1, j]
            xr = xr + (a.real * b.real - a.imag * b.imag)
            xi = xi + (a.real * b.imag + a.imag * b.real)
            a, b = fk[2, j], hs[2, j]
            xr = xr + (a.real * b.real - a.imag * b.imag)
            xi = xi + (a.real * b.imag + a.imag * b.real)
            a = add[j]
            out[j] = np.complex64(complex(xr + a.real, xi + a.imag))
        return
    for j in range(m):
        a, b = fk[0, j], hs[0, j]
        out[j] = np.complex64(
            complex(a.real * b.real - a.imag * b.imag, a.real * b.imag + a.imag * b.real)
        )
    for ch in range(1, c):
        for j in range(m):
            a, b, o = fk[ch, j], hs[ch, j], out[j]
            xr = o.real + (a.real * b.real - a.imag * b.imag)
            xi = o.imag + (a.real * b.imag + a.imag * b.real)
            out[j] = np.complex64(complex(xr, xi))
    if add.size:
        for j in range(m):
            a, o = add[j], out[j]
            out[j] = np.complex64(complex(o.real + a.real, o.imag + a.imag))
