"""The status bar while several jobs run (issue 13 item 11)."""

from __future__ import annotations

import re
import threading

import numpy as np

from engine.events import Progress
from tests.gui.helpers import WAIT_MS, make_window, open_sample, wait_idle


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


def test_closing_the_banner_takes_its_line_off_the_status_bar(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"out_width": 128, "out_height": 128})
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    w.tabs.setCurrentWidget(w.source_view)
    painted = np.zeros(w.doc.source.shape, bool)
    painted[:40, :40] = True
    w.doc.set_painted(painted)  # the quilt shown runs again without these pixels: says so
    wait_idle(qtbot, w)
    assert w.last_message().startswith("Synthesized 128×128")
    w.message_bar.dismiss()  # closed (or faded already on a slow machine)
    assert w.statusBar().currentMessage() == ""  # not the quilt's line on the Source tab
    w.show_message("info", "a note")  # the same, without the 10 s fade a slow machine may reach
    assert w.statusBar().currentMessage() == "a note"
    w.message_bar.dismiss()
    assert w.statusBar().currentMessage() == ""
    w.show_message("warning", "a question")
    w.statusBar().showMessage("a newer line")
    w.message_bar.dismiss()
    assert w.statusBar().currentMessage() == "a newer line"  # only the banner's own text goes


def test_a_banner_with_a_button_is_as_tall_as_its_text_beside_the_button(qtbot):
    from PySide6.QtWidgets import QWidget

    from quilt_gui.widgets.status import MessageBar

    parent = QWidget()
    qtbot.addWidget(parent)
    parent.resize(700, 400)
    parent.show()
    bar = MessageBar(parent)
    words = "a tile size that holds whole periods avoids it: 144 px"
    bar.show_message("warning", words)
    full = bar.label.width()
    narrower = full - 180  # about a button's room
    text = words
    while bar.label.heightForWidth(narrower) <= bar.label.heightForWidth(full):
        text += " " + words  # until the button's room costs a line
        bar.label.setText(text)
    bar.show_message("warning", text, [("Use 144 px tiles", lambda: None)])
    need = bar.label.heightForWidth(bar.label.width())
    qtbot.waitUntil(lambda: bar.label.width() < full, timeout=WAIT_MS)
    assert bar.label.height() >= bar.label.heightForWidth(bar.label.width()) >= need


def test_a_job_line_too_long_for_the_status_bar_ends_with_an_ellipsis(qtbot, monkeypatch):
    """polish13b: a window narrower than the status bar's labels cut the job's line off
    ("Making 256 Wang tiles — ~3 min le"); it ends with "…" like the Parameters panel's long
    choice names (its time left goes first), whole in its tooltip."""
    from PySide6.QtWidgets import QStylePainter

    painted: list[str] = []
    draw = QStylePainter.drawItemText

    def recording(painter, rect, flags, palette, enabled, text, *role):
        painted.append(text)
        draw(painter, rect, flags, palette, enabled, text, *role)

    w = make_window(qtbot)
    gate = threading.Event()
    try:
        job = w.jobs.start("wang", held, 256, 3, gate, label="Making 256 Wang tiles")
        qtbot.waitUntil(lambda: job.progress is not None, timeout=WAIT_MS)
        job.started_at -= 6.0  # ~8 min left
        status = w.job_status
        status._refresh()
        label = status.label
        full = label.text()
        assert full.startswith("Making 256 Wang tiles — ~") and full.endswith(" left")
        monkeypatch.setattr(QStylePainter, "drawItemText", recording)
        # the seams' line of the published oscillating search, in a 1100 px window
        w.criterion_label.setText(
            "seam H 0.123 · V 0.456 — oscillating as published (restart, per-row argmin start, "
            "o_max 5)"
        )
        w.resize(1100, w.height())
        width = label.fontMetrics().horizontalAdvance
        qtbot.waitUntil(lambda: label.width() < width(full), timeout=WAIT_MS)
        label.grab()
        assert painted, "the label's text is not drawn elided"
        shown = painted[-1]
        assert shown.endswith("…") and full.startswith(shown[:-1]) and len(shown) > 4
        assert width(shown) <= label.contentsRect().width()
        assert label.toolTip() == full
        w.criterion_label.setText("")  # room again: the whole line
        qtbot.waitUntil(lambda: label.width() >= width(full), timeout=WAIT_MS)
        label.grab()
        assert painted[-1] == full
    finally:
        gate.set()
    qtbot.waitUntil(lambda: not w.jobs.running(), timeout=WAIT_MS)


def test_the_seams_line_and_the_other_jobs_end_with_an_ellipsis_in_a_narrow_window(
    qtbot, monkeypatch
):
    """polish13c: in a narrow window the seams' line ("oscillating as published (restart,
    per…") and the "· also …" list of other jobs were cut off; they end with "…" like the job's
    line, each whole in its tooltip (the seams' line above what it means)."""
    from PySide6.QtWidgets import QStylePainter

    painted: dict[int, str] = {}
    draw = QStylePainter.drawItemText

    def recording(painter, rect, flags, palette, enabled, text, *role):
        painted[id(painter.device())] = text
        draw(painter, rect, flags, palette, enabled, text, *role)

    w = make_window(qtbot)
    gate = threading.Event()
    try:
        job = w.jobs.start("wang", held, 256, 3, gate, label="Making 256 Wang tiles")
        other = w.jobs.start("candidates", held, 30, 1, gate, label="Generating 30 candidates")
        qtbot.waitUntil(lambda: job.progress and other.progress, timeout=WAIT_MS)
        job.started_at -= 6.0
        other.started_at -= 1.0
        status = w.job_status
        status._refresh()
        seams = (
            "seam H 0.123 · V 0.456 — oscillating as published (restart, per-row argmin start, "
            "o_max 5)"
        )
        w.criterion_label.setText(seams)
        also = status.others.text()
        assert also == "· also Generating 30 candidates"
        assert w.criterion_label.toolTip().startswith(seams + "\nSeam criterion (sum")
        assert status.others.toolTip() == also + "\nOther jobs running at the same time"
        monkeypatch.setattr(QStylePainter, "drawItemText", recording)
        w.resize(700, w.height())
        labels = (w.criterion_label, status.others)
        for label in labels:
            width = label.fontMetrics().horizontalAdvance
            narrowed = lambda label=label, width=width: label.width() < width(label.text())  # noqa: E731
            qtbot.waitUntil(narrowed, timeout=WAIT_MS)
            painted.clear()
            label.grab()
            shown = painted.get(id(label), "")  # drawn elided, not cut off (a QLabel: not here)
            assert shown.endswith("…") and label.text().startswith(shown[:-1]) and len(shown) > 4
            assert width(shown) <= label.contentsRect().width()
    finally:
        gate.set()
    qtbot.waitUntil(lambda: not w.jobs.running(), timeout=WAIT_MS)
