"""Garbage collection in the GUI thread only (quilt_gui.gc_thread)."""

from __future__ import annotations

import gc
import threading

from PySide6.QtCore import QObject

from quilt_gui.gc_thread import GuiThreadCollector, due_generation
from tests.gui.helpers import WAIT_MS


class _Cycle:
    """A reference cycle holding a Qt object, as an editor window's widgets and jobs are."""

    def __init__(self, freed_in: list):
        self.me, self.qt, self.freed_in = self, QObject(), freed_in

    def __del__(self):
        self.freed_in.append(threading.current_thread())


def test_a_cycle_with_a_qt_object_is_freed_in_the_gui_thread_not_in_a_busy_thread(qtbot):
    collector = GuiThreadCollector()
    try:
        freed_in: list = []
        _Cycle(freed_in)
        kept: list = []
        # enough lasting allocations for dozens of collections of the youngest generation,
        # which automatic collection would run in this thread (and free the cycle there)
        busy = threading.Thread(target=lambda: kept.extend([] for _ in range(50_000)))
        busy.start()
        busy.join(WAIT_MS / 1000)
        assert not freed_in, "collected in the busy thread"
        qtbot.waitUntil(lambda: bool(freed_in), timeout=WAIT_MS)
        assert freed_in == [threading.main_thread()]
    finally:
        collector.stop()


def test_stop_collects_and_restores_automatic_collection_as_it_was(qapp):
    was = gc.isenabled()
    try:
        for before in (True, False):
            (gc.enable if before else gc.disable)()
            collector = GuiThreadCollector()
            assert not gc.isenabled()
            freed_in: list = []
            _Cycle(freed_in)
            collector.stop()
            assert freed_in == [threading.main_thread()]
            assert gc.isenabled() is before
        gc.enable()
        collector = GuiThreadCollector()
        collector.stop(restore=False)  # the editor's quit: a late job thread frees nothing
        assert not gc.isenabled()
    finally:
        (gc.enable if was else gc.disable)()


def test_due_generation_is_the_oldest_past_its_threshold():
    thresholds, was = gc.get_threshold(), gc.isenabled()
    gc.disable()
    try:
        gc.collect()
        kept = [[] for _ in range(100)]
        gc.set_threshold(10**9, 10, 10)
        assert due_generation() is None
        gc.set_threshold(50, 10**9, 10)
        assert due_generation() == 0
        gc.set_threshold(50, 0, 0)  # a zero threshold: that generation is never due
        assert due_generation() == 0
        assert kept
    finally:
        gc.set_threshold(*thresholds)
        (gc.enable if was else gc.disable)()
