"""Garbage collection in the GUI thread only.

Python's collector runs in whichever thread allocates when a generation is due, and in the
editor that is mostly a job's thread (the engine allocates far more than the GUI). A collection
there frees every unreachable cycle, Qt objects included: with ``gc.DEBUG_SAVEALL`` over the
GUI tests (one process, at 480790d), 10 of the 37 collections that held Qt objects ran in a job's
thread or an engine pool's, most with a whole editor window (QWidget, the views, the undo
stacks, a Job and its QTimer). A Qt object deleted outside its thread can crash the process
later: an active QTimer freed in another thread stays registered with the GUI thread's event
loop ("Timers cannot be stopped from another thread") and the process segfaults once that loop
runs (a 200-timer demo, PySide6 6.11.3: 3 of 3 runs; 0 of 3 collected in the GUI thread). The
suspected cause of the one segfault seen in CI (in the collector, in a test process that had run
GUI tests; not reproduced). So while the editor runs, automatic collection is off and
:class:`GuiThreadCollector` runs the same collections from a timer in the GUI thread.
"""

from __future__ import annotations

import gc

from PySide6.QtCore import QObject, QTimer

__all__ = ["INTERVAL_MS", "GuiThreadCollector", "due_generation"]

INTERVAL_MS = 100
"""How often the GUI thread looks whether a collection is due."""


def due_generation() -> int | None:
    """The oldest generation that is past its threshold with every younger one, or None (as
    pyqtgraph's GarbageCollector decides; CPython's own rule also puts off a full collection
    until the objects waiting for one are a quarter of the long-lived ones, so this one may
    collect the oldest generation more often)."""
    due = None
    for generation, (count, threshold) in enumerate(
        zip(gc.get_count(), gc.get_threshold(), strict=False)
    ):
        if threshold and count > threshold:
            due = generation
        else:
            break
    return due


class GuiThreadCollector(QObject):
    """Turns automatic collection off and runs the due collections from a timer in the thread
    that makes it (the GUI thread); :meth:`stop` collects and turns automatic collection back
    on if it was on before."""

    def __init__(self, parent: QObject | None = None, interval_ms: int = INTERVAL_MS) -> None:
        super().__init__(parent)
        self.timer = QTimer(self)
        self.timer.timeout.connect(self.collect_due)
        self.timer.start(interval_ms)
        self.was_enabled = gc.isenabled()
        gc.disable()

    def collect_due(self) -> None:
        generation = due_generation()
        if generation is not None:
            gc.collect(generation)

    def stop(self, *, restore: bool = True) -> None:
        """Stop the timer, collect, and with ``restore`` turn automatic collection back on if
        it was on (not at the editor's quit: a job thread that did not stop in time could then
        free Qt objects)."""
        self.timer.stop()
        gc.collect()
        if restore and self.was_enabled:
            gc.enable()
