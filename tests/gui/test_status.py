"""The status bar while several jobs run (issue 13 item 11)."""

from __future__ import annotations

import re
import threading

from engine.events import Progress
from tests.gui.helpers import WAIT_MS, make_window


def held(n, done, gate, *, cancel=None):
    """A job at ``done`` of ``n`` steps until ``gate`` opens (or it is cancelled)."""
    yield Progress(done, n, "candidates")
    while not gate.wait(0.01):
        if cancel is not None and cancel.cancelled:
            return None
    return None


def waiting(gate):
    gate.wait(10)


def test_a_long_job_keeps_its_progress_and_time_left_and_the_others_are_named(qtbot):
    w = make_window(qtbot)
    gate = threading.Event()
    try:
        long = w.jobs.start("candidates", held, 10, 3, gate, label="Generating 10 candidates")
        qtbot.waitUntil(lambda: long.progress is not None, timeout=WAIT_MS)
        long.started_at -= 6.0  # it has run 6 s for 3 of 10 steps: ~14 s left
        auto = w.jobs.start("autosave", waiting, gate, label="Autosaving", pass_cancel=False)
        auto.started_at -= 1.0
        status = w.job_status
        status._refresh()
        assert status.isVisibleTo(w)
        assert status.label.text().startswith("Generating 10 candidates")
        assert re.search(r"~1[4-9] s left", status.label.text())  # 6 s more or less
        assert status.bar.format() == "3/10"
        assert "Autosaving" in status.others.text()  # named, not "(+1)"
    finally:
        gate.set()
    qtbot.waitUntil(lambda: not w.jobs.running(), timeout=WAIT_MS)
