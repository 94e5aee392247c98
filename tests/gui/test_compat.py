"""The PySide6 6.12.0 emit-refcount work-around keeps a long session alive."""

from __future__ import annotations

import sys

from PySide6.QtCore import QObject, Signal

from quilt_gui import _compat


class _Emitter(QObject):
    sig = Signal(object)


def test_many_emits_never_exhaust_true(qtbot):
    e = _Emitter()
    for _ in range(5):
        for _ in range(60_000):
            e.sig.emit(1)
        _compat.top_up()  # the main window does this every second
    assert sys.getrefcount(True) > 1000 and sys.getrefcount(False) > 1000
    if not _compat.emit_steals_references():
        assert not _compat.top_up()  # a correct binding is left alone
