"""Shared helpers of the GUI tests."""

from __future__ import annotations

from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDropEvent

from quilt_gui.main_window import MainWindow

#: how long a test waits for a job (ms): a margin for a loaded machine, not a bound (a job of a
#: few seconds of CPU took 17 s at load 10; the kernels are compiled before the first test);
#: a hang still fails, here or at pytest-timeout's limit
WAIT_MS = 120_000


def wait_idle(qtbot, window: MainWindow, timeout: int = WAIT_MS) -> None:
    """Wait until no job runs and no recompute is scheduled (:data:`WAIT_MS`, a margin)."""
    qtbot.waitUntil(lambda: not window.pipeline.busy(), timeout=timeout)


def open_sample(qtbot, window: MainWindow, name: str | None = None) -> None:
    from resources import sample_path

    with qtbot.waitSignal(window.doc.source_changed, timeout=WAIT_MS):
        if name is None:
            window.open_initial(None)
        else:
            window.files.open_path(str(sample_path(name)), confirm=False)
    wait_idle(qtbot, window)


def template(qtbot, window: MainWindow, rect=(150, 120, 128, 112)) -> None:
    """Draw the tile rectangle and wait for its seamless tile."""
    window.doc.tileset.set_template_rect(rect)
    wait_idle(qtbot, window)
    assert window.doc.tileset.seamless is not None


def generate(qtbot, window: MainWindow, n: int = 30, rect=(150, 120, 128, 112)) -> None:
    """Template at ``rect`` and ``n`` candidates."""
    template(qtbot, window, rect)
    window.doc.set_param("n_candidates", n)
    window.act_generate.trigger()
    wait_idle(qtbot, window)
    assert len(window.doc.tileset.candidates) == n


def click_candidate(qtbot, window: MainWindow, row: int, modifier=Qt.KeyboardModifier.NoModifier):
    view = window.gallery
    ix = view.model().index(row, 0)
    view.scrollTo(ix)
    pos: QPoint = view.visualRect(ix).center()
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, modifier, pos)


def drop(w: MainWindow, path) -> None:
    """Drop the file ``path`` on the window, as from a file manager."""
    mime = QMimeData()
    mime.setUrls([QUrl.fromLocalFile(str(path))])
    ev = QDropEvent(
        QPointF(50, 50),
        Qt.DropAction.CopyAction,
        mime,
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
    )
    w.dropEvent(ev)


def make_window(qtbot) -> MainWindow:
    w = MainWindow()
    qtbot.addWidget(w)
    w.files.ask_save_changes = lambda: "discard"  # never a modal dialog in tests
    w.files.ask_discard_output = lambda: True  # a new quilt replaces the last
    w.resize(1400, 900)
    w.show()
    qtbot.waitExposed(w)
    return w


def drag(qtbot, canvas, a, b, *, button=Qt.MouseButton.LeftButton, modifier=None, steps=6):
    """Press at view point ``a``, move to ``b`` in ``steps``, release (a painted stroke)."""
    mod = Qt.KeyboardModifier.ShiftModifier if modifier is None else modifier
    qtbot.mousePress(canvas.viewport(), button, mod, a)
    for k in range(1, steps + 1):
        qtbot.mouseMove(canvas.viewport(), a + (b - a) * (k / steps))
    qtbot.mouseRelease(canvas.viewport(), button, mod, b)
