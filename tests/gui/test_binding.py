"""The installed Qt binding must not leak references to None / True.

PySide6 6.12.0 on Python 3.11 takes a reference from ``None`` on every call of a ``void``
method and one from ``True`` on every ``emit``; an editor session then aborts with
"deallocating None" after a few thousand calls. pyproject.toml excludes that release; this
test fails loudly if such a binding is installed anyway.
"""

from __future__ import annotations

import sys

from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QPainterPath


class _Emitter(QObject):
    sig = Signal(object)


def test_binding_keeps_reference_counts_of_none_and_true():
    emitter, path = _Emitter(), QPainterPath()
    none_before, true_before = sys.getrefcount(None), sys.getrefcount(True)
    for _ in range(200):
        path.moveTo(0.0, 0.0)
        emitter.sig.emit(1)
    none_lost = none_before - sys.getrefcount(None)
    true_lost = true_before - sys.getrefcount(True)
    assert none_lost < 100 and true_lost < 100, (
        f"the Qt binding leaks references (None: {none_lost}, True: {true_lost} per 200 calls); "
        "install a PySide6-Essentials release without the bug (see pyproject.toml)"
    )
