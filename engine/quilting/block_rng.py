"""Each quilting block's generator, ``np.random.default_rng([seed, index])``, at a tenth of its
cost.

Every block draws from its own generator (the output does not depend on the order the blocks
are placed in, nor on the threads). Building one through ``SeedSequence`` and ``PCG64`` takes
about 15 µs, as long as a small block's cut; most blocks then draw a single bounded integer
(their choice within the tolerance). :class:`BlockRng` seeds PCG64 exactly as numpy does
(SeedSequence's hash mixing, ``pcg64_set_seed``) and draws ``integers(n)`` with numpy's
algorithm (Lemire's bounded 32-bit draws from the buffered halves of 64-bit outputs), in
compiled code: the same values. Any other use hands over to a real ``Generator`` in the same
state. The scheduler takes it once numba is loaded (:func:`engine._jit.loaded`).
"""

from __future__ import annotations

import numpy as np

from engine import _jit as jit
from engine._jit import njit
from engine.matching import kth_at_most, least_and_count, select_within_tolerance

__all__ = ["BlockRng"]

M32 = np.uint64(0xFFFFFFFF)


@njit(cache=True, nogil=True)
def _mulhi(a, b):  # pragma: no cover - compiled
    a_lo, a_hi = a & M32, a >> np.uint64(32)
    b_lo, b_hi = b & M32, b >> np.uint64(32)
    p0 = a_lo * b_lo
    p1 = a_lo * b_hi
    p2 = a_hi * b_lo
    p3 = a_hi * b_hi
    mid = (p0 >> np.uint64(32)) + (p1 & M32) + (p2 & M32)
    return p3 + (p1 >> np.uint64(32)) + (p2 >> np.uint64(32)) + (mid >> np.uint64(32))


@njit(cache=True, nogil=True)
def _step(st):  # pragma: no cover - compiled
    """state = state * MULT + inc (128-bit, st = [s_hi, s_lo, i_hi, i_lo, has32, u32])."""
    m_hi = np.uint64(2549297995355413924)
    m_lo = np.uint64(4865540595714422341)
    s_hi, s_lo = st[0], st[1]
    lo = s_lo * m_lo
    hi = _mulhi(s_lo, m_lo) + s_lo * m_hi + s_hi * m_lo
    lo2 = lo + st[3]
    carry = np.uint64(1) if lo2 < lo else np.uint64(0)
    st[0] = hi + st[2] + carry
    st[1] = lo2


@njit(cache=True, nogil=True)
def _hashmix(v, h):  # pragma: no cover - compiled
    v = (v ^ h) & M32
    h = (h * np.uint64(0x931E8875)) & M32
    v = (v * h) & M32
    return v ^ (v >> np.uint64(16)), h


@njit(cache=True, nogil=True)
def _mix(x, y):  # pragma: no cover - compiled
    r = (np.uint64(0xCA01F9DD) * x - np.uint64(0x4973F715) * y) & M32
    return r ^ (r >> np.uint64(16))


@njit(cache=True, nogil=True)
def seed_state(seed, k):  # pragma: no cover - compiled
    """[state_hi, state_lo, inc_hi, inc_lo, has_uint32, uinteger] of PCG64 as
    np.random.default_rng([seed, k]) seeds it (0 <= seed < 2**63, 0 <= k < 2**32)."""
    ent = np.zeros(3, np.uint64)
    n = 0
    s = np.uint64(seed)
    ent[0] = s & M32
    n = 1
    if (s >> np.uint64(32)) != 0:
        ent[1] = s >> np.uint64(32)
        n = 2
    ent[n] = np.uint64(k)
    n += 1
    pool = np.zeros(4, np.uint64)
    h = np.uint64(0x43B0D7E5)
    for i in range(4):
        v = ent[i] if i < n else np.uint64(0)
        pool[i], h = _hashmix(v, h)
    for a in range(4):
        for d in range(4):
            if a != d:
                hv, h = _hashmix(pool[a], h)
                pool[d] = _mix(pool[d], hv)
    for a in range(4, n):
        for d in range(4):
            hv, h = _hashmix(ent[a], h)
            pool[d] = _mix(pool[d], hv)
    hb = np.uint64(0x8B51F9DD)
    words = np.zeros(8, np.uint64)
    for i in range(8):
        v = pool[i % 4] ^ hb
        hb = (hb * np.uint64(0x58F38DED)) & M32
        v = (v * hb) & M32
        words[i] = v ^ (v >> np.uint64(16))
    u0 = words[0] | (words[1] << np.uint64(32))
    u1 = words[2] | (words[3] << np.uint64(32))
    u2 = words[4] | (words[5] << np.uint64(32))
    u3 = words[6] | (words[7] << np.uint64(32))
    st = np.zeros(6, np.uint64)
    # inc = (u2:u3 << 1) | 1
    st[2] = (u2 << np.uint64(1)) | (u3 >> np.uint64(63))
    st[3] = (u3 << np.uint64(1)) | np.uint64(1)
    st[0], st[1] = 0, 0
    _step(st)
    lo = st[1] + u1
    carry = np.uint64(1) if lo < st[1] else np.uint64(0)
    st[0] = st[0] + u0 + carry
    st[1] = lo
    _step(st)
    return st


@njit(cache=True, nogil=True)
def _next32(st):  # pragma: no cover - compiled
    if st[4]:
        st[4] = 0
        return st[5]
    _step(st)
    hi, lo = st[0], st[1]
    rot = hi >> np.uint64(58)
    x = hi ^ lo
    out = (x >> rot) | (x << ((np.uint64(64) - rot) & np.uint64(63)))
    st[4] = 1
    st[5] = out >> np.uint64(32)
    return out & M32


@njit(cache=True, nogil=True)
def bounded(st, n):  # pragma: no cover - compiled
    """Generator.integers(n) for 1 <= n <= 2**32 (Lemire, numpy's buffered 32-bit path)."""
    rng = np.uint64(n - 1)
    if rng == 0:
        return 0
    excl = rng + np.uint64(1)
    m = _next32(st) * excl
    left = m & M32
    if left < excl:
        thr = (np.uint64(0xFFFFFFFF) - rng) % excl
        while left < thr:
            m = _next32(st) * excl
            left = m & M32
    return np.int64(m >> np.uint64(32))


@njit(cache=True, nogil=True)
def _select_drawn(flat, tolerance, zero_level, st):  # pragma: no cover - compiled
    """select_within_tolerance's compiled path with ``integers(n)`` drawn from state ``st``:
    (pick, least error, count); count 0 (nothing drawn) when no entry is within the limit."""
    i, e, n, limit = least_and_count(flat, tolerance, zero_level)
    if n == 0:
        return i, e, n
    return kth_at_most(flat, limit, bounded(st, n)), e, n


class BlockRng:
    """``np.random.default_rng([seed, index])`` (``0 <= seed < 2**63``, ``0 <= index < 2**32``):
    ``integers(n)`` compiled, anything else on a numpy ``Generator`` in the same state."""

    __slots__ = ("_gen", "_st")

    def __init__(self, seed: int, index: int):
        self._st = seed_state(seed, index)
        self._gen = None

    def integers(self, *args, **kwargs):
        if self._gen is None and len(args) == 1 and not kwargs:
            n = args[0]
            if isinstance(n, int | np.integer) and 1 <= n <= 2**32:
                return bounded(self._st, int(n))
        return self.generator().integers(*args, **kwargs)

    def select(self, errors: np.ndarray, *, tolerance: float, zero_level: float):
        """:func:`engine.matching.select_within_tolerance` with this generator (the same
        choice and draw): once numba is loaded, with float tolerances and no numpy generator
        yet, in one compiled call (the least error, the count, the draw and the pick)."""
        if self._gen is None and jit.loaded() and type(tolerance) is type(zero_level) is float:
            flat = errors.ravel()
            i, e_min, n = _select_drawn(flat, tolerance, zero_level, self._st)
            if n == 0:  # nothing drawn: every position excluded, or float round-off
                return select_within_tolerance(
                    errors, tolerance=tolerance, zero_level=zero_level, rng=self
                )
            return int(i), e_min, int(n)
        return select_within_tolerance(errors, tolerance=tolerance, zero_level=zero_level, rng=self)

    def generator(self) -> np.random.Generator:
        """The numpy generator in this one's state (from now on every draw goes to it)."""
        if self._gen is None:
            st = [int(v) for v in self._st]
            bits = np.random.PCG64(0)
            bits.state = {
                "bit_generator": "PCG64",
                "state": {"state": st[0] << 64 | st[1], "inc": st[2] << 64 | st[3]},
                "has_uint32": st[4],
                "uinteger": st[5],
            }
            self._gen = np.random.Generator(bits)
        return self._gen

    def __getattr__(self, name):
        return getattr(self.generator(), name)
