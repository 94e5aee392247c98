"""Work-around for a bug of the Qt binding, active only where a probe finds it.

PySide6 6.12.0: ``SignalInstance.emit`` returns its bool result without a new reference,
so every ``emit`` made from Python takes one reference away from ``True``. On Python < 3.12
(``True`` is not immortal) a session ends, after enough signals, with "Fatal Python error:
bool_dealloc: deallocating True or False". Patching ``emit`` is not possible (PySide
connects signal-to-signal through the builtin ``emit``), so :func:`top_up` keeps a reserve
of references to ``True`` and ``False`` that the stolen ones come out of; the main window
tops it up every second. Cost: 8 bytes per emitted signal, about 1.6 MB per top-up.
"""

from __future__ import annotations

import ctypes
import sys

PROBE_EMITS = 16
RESERVE = 200_000  # references per top-up

_bug: bool | None = None


def _hold(obj, n: int) -> None:
    """Add ``n`` references to ``obj`` that are never released (a list that is leaked on
    purpose: freeing it at exit would hand back references the binding already took)."""
    refs = [obj] * n
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(refs))


def emit_steals_references() -> bool:
    """True when ``SignalInstance.emit`` drops a reference to its result (probed once)."""
    global _bug
    if _bug is None:
        from PySide6.QtCore import QObject, Signal

        class _Probe(QObject):
            ping = Signal(object)

        probe = _Probe()
        before = sys.getrefcount(True)
        for _ in range(PROBE_EMITS):
            probe.ping.emit(None)
        _bug = before - sys.getrefcount(True) >= PROBE_EMITS
        if _bug:
            _hold(True, PROBE_EMITS)  # give back what the probe took
    return _bug


def top_up() -> bool:
    """Refill the reserve of ``True``/``False`` references if low; True if it did."""
    if not emit_steals_references():
        return False
    added = False
    for obj in (True, False):
        if sys.getrefcount(obj) < RESERVE:
            _hold(obj, RESERVE)
            added = True
    return added
