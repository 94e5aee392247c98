"""The work-around for the binding's reference-count bug keeps a long session alive."""

from __future__ import annotations

import sys

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QPainterPath

from quilt_gui import _compat


class _Emitter(QObject):
    sig = Signal(object)


def test_many_binding_calls_never_exhaust_the_singletons(qtbot):
    e, path = _Emitter(), QPainterPath()
    n = _compat.FLOOR // 2 + 100_000  # more than the reserve left after one top-up
    for _ in range(3):
        for _ in range(n // 4):
            e.sig.emit(1)  # takes a reference from True (6.12.0 on Python 3.11)
            path.moveTo(0.0, 0.0)  # takes one from None
        _compat.top_up()  # the main window does this every second
    for obj in (None, True, False):
        assert sys.getrefcount(obj) > 1000
    for obj in _compat.leaking_singletons():  # topped up to at least the floor
        assert sys.getrefcount(obj) >= _compat.FLOOR
    if not _compat.leaking_singletons():
        assert not _compat.top_up()  # a correct binding is left alone
