"""numba's ``njit``, applied when a kernel is first called: importing a module costs no numba.

Importing numba takes ~0.2 s and its first call of any compiled function another ~0.4 s (it
loads its typing and lowering registries, even for a kernel read from the cache). A small
command-line job that calls no kernel (the small-job numpy paths of :mod:`engine.matching` and
:mod:`engine.stitch`) should pay neither. ``@njit(...)`` from here registers the function; the
first call of any registered kernel (or :func:`load`) imports numba, compiles every registered
kernel lazily as ``numba.njit(...)`` would, and puts the dispatchers in place of the stand-ins
in the ``engine`` modules, so kernels find each other by their global names as numba needs (a
stand-in numba still meets, e.g. in a thread racing the swap, is typed as its dispatcher).
Kernels registered after :func:`load` are dispatchers at once.

:func:`loaded` says whether numba is in use: a caller with an identical numpy path takes it
while numba is not loaded and the work is small (the results are the same, the numpy path only
saves numba's start-up).
"""

from __future__ import annotations

import functools
import sys
import threading

__all__ = ["LOADING_LOCK", "Kernel", "load", "loaded", "njit"]

_KERNELS: list[Kernel] = []
LOADING_LOCK = threading.RLock()
"""Held while kernels are registered or loaded (a process forked meanwhile must not inherit it
held: :mod:`engine.quilting.workers` takes it around its forks)."""
_LOADED = False


class Kernel:
    """Stand-in for a numba dispatcher until :func:`load`; then forwards to it."""

    def __init__(self, fn, options: dict):
        functools.update_wrapper(self, fn)
        self.py_func = fn
        self.options = options
        self.dispatcher = None

    def __call__(self, *args, **kwargs):
        if self.dispatcher is None:
            load()
        return self.dispatcher(*args, **kwargs)

    def __repr__(self) -> str:
        return f"<lazy numba kernel {self.__module__}.{self.__qualname__}>"


def njit(*args, **options):
    """``numba.njit`` (same options), compiled when first called; ``@njit`` or ``@njit(...)``."""
    if len(args) == 1 and callable(args[0]) and not options:
        return _register(args[0], {})
    if args:
        raise TypeError("njit takes keyword options only (no signatures)")
    return lambda fn: _register(fn, options)


def _register(fn, options: dict):
    with LOADING_LOCK:
        if _LOADED:
            import numba

            return numba.njit(**options)(fn)
        kernel = Kernel(fn, options)
        _KERNELS.append(kernel)
        return kernel


def loaded() -> bool:
    """Whether numba is loaded (its kernels are in use)."""
    return _LOADED


def load() -> None:
    """Import numba and make every registered kernel a dispatcher (once; thread-safe)."""
    global _LOADED
    if _LOADED:
        return
    with LOADING_LOCK:
        if _LOADED:
            return
        import numba
        from numba.extending import typeof_impl

        swap = {id(k): numba.njit(**k.options)(k.py_func) for k in _KERNELS}
        # a kernel compiled while another thread still sees stand-ins (or one handed a stand-in)
        # types it as its dispatcher
        typeof_impl.register(Kernel)(lambda kernel, c: typeof_impl(swap[id(kernel)], c))
        for k in _KERNELS:
            k.dispatcher = swap[id(k)]
        for name, module in list(sys.modules.items()):
            if module is None or not (name == "engine" or name.startswith("engine.")):
                continue
            space = vars(module)
            for attr, value in list(space.items()):
                if isinstance(value, Kernel):
                    space[attr] = swap[id(value)]
        _LOADED = True
