"""Work-around for a reference-counting bug of the Qt binding, active only where a probe
finds it.

PySide6 / shiboken6 6.12.0 on Python 3.11: functions that return ``None`` (every ``void``
Qt method: ``QPainterPath.addRect``, ``QGraphicsItem.setPos`` ...) and ``SignalInstance.emit``
(which returns ``True``) hand back the singleton without a new reference, so every such call
from Python takes one reference away from ``None`` / ``True``. Python 3.12+ makes these
singletons immortal, so the bug is harmless there; on 3.11 an editor session ends, after
some hundred thousand calls, with "Fatal Python error: none_dealloc: deallocating None"
(or ``bool_dealloc``). The real fix is a binding without the bug (or Python >= 3.12); until
then :func:`top_up` adds the stolen references back in bulk: the main window calls it every
second, so the count never gets near zero. It does nothing where the probe finds no leak.
"""

from __future__ import annotations

import ctypes
import sys

PROBE_CALLS = 32
FLOOR = 500_000  # top up when a singleton has fewer references than this
RESERVE = 1_000_000  # references added per top-up

_leaking: tuple | None = None


def _count_drop(obj, call) -> int:
    before = sys.getrefcount(obj)
    for _ in range(PROBE_CALLS):
        call()
    return before - sys.getrefcount(obj)


def leaking_singletons() -> tuple:
    """The singletons (None, True, False) the binding takes references from (probed once)."""
    global _leaking
    if _leaking is None:
        from PySide6.QtCore import QObject, Signal
        from PySide6.QtGui import QPainterPath

        class _Probe(QObject):
            ping = Signal(object)

        probe, path = _Probe(), QPainterPath()
        found = []
        if _count_drop(None, lambda: path.moveTo(0.0, 0.0)) >= PROBE_CALLS:
            found.append(None)
        if _count_drop(True, lambda: probe.ping.emit(1)) >= PROBE_CALLS:
            found += [True, False]
        immortal = sys.version_info >= (3, 12) or sys.implementation.name != "cpython"
        _leaking = () if immortal else tuple(found)
    return _leaking


def _add_refs(obj, n: int) -> None:
    """Add ``n`` to the reference count of ``obj`` (CPython < 3.12 object layout: the count
    is the first field). Only ever applied to None / True / False, which are never freed."""
    ctypes.c_ssize_t.from_address(id(obj)).value += n


def top_up() -> bool:
    """Give the leaking singletons a large reserve of references again; True if it did."""
    added = False
    for obj in leaking_singletons():
        if sys.getrefcount(obj) < FLOOR:
            _add_refs(obj, RESERVE)
            added = True
    return added
