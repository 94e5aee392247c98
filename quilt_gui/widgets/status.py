"""Non-blocking messages and the running job's progress bar with its Cancel button."""

from __future__ import annotations

import time

from PySide6.QtCore import QEvent, QSize, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QPalette
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QStylePainter,
    QToolButton,
    QWidget,
)

from quilt_gui import jobs

_COLORS = {
    "info": ("#1f3b57", "#cfe3ff"),
    "warning": ("#5a4500", "#ffe9a8"),
    "error": ("#5c1a1a", "#ffd0d0"),
}
INFO_SECONDS = 8
SHOW_AFTER = 0.3  # seconds a job runs before its progress bar appears


class MessageBar(QWidget):
    """A banner floating over the bottom of ``parent`` (the canvas area): never modal; errors
    stay until closed, info fades. It takes no room in a layout, so nothing moves under the
    mouse when it comes and goes."""

    MARGIN = 8
    #: the height the banner covers at the bottom of its parent (0: hidden), for a view that
    #: must not be covered (the Wang tab's layout ends above it)
    covered = Signal(int)
    dismissed = Signal(str)  # the text of the message closed (by ✕, its answer or fading)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        if parent is not None:
            parent.installEventFilter(self)
        self.setObjectName("MessageBar")
        self.setAttribute(Qt.WidgetAttribute.WA_StyledBackground, True)
        lay = QHBoxLayout(self)
        lay.setContentsMargins(10, 5, 6, 5)
        self.label = QLabel()
        self.label.setWordWrap(True)
        self.label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.label.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Preferred)
        lay.addWidget(self.label, 1)
        self._actions = QHBoxLayout()
        lay.addLayout(self._actions)
        close = QToolButton()
        close.setText("✕")
        close.setToolTip("Dismiss this message")
        close.setAutoRaise(True)
        close.clicked.connect(self.dismiss)
        lay.addWidget(close)
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.dismiss)
        self.level = ""
        self.hide()

    @property
    def text(self) -> str:
        return self.label.text() if self.isVisibleTo(self.parentWidget()) else ""

    def show_message(self, level: str, text: str, actions=()) -> None:
        """Show ``text``; ``actions`` are (label, callable) buttons that also dismiss it."""
        self.level = level
        bg, fg = _COLORS.get(level, _COLORS["info"])
        self.setStyleSheet(f"#MessageBar {{ background: {bg}; }} QLabel {{ color: {fg}; }}")
        self.label.setText(text)
        while self._actions.count():
            w = self._actions.takeAt(0).widget()
            if w is not None:
                w.deleteLater()
        for label, fn in actions:
            b = QPushButton(label)
            b.clicked.connect(fn)
            b.clicked.connect(self.dismiss)
            self._actions.addWidget(b)
            # shown now, not when the event loop gets to it: place() measures the text's
            # height beside the buttons (a hidden one takes no room: a line was cut off)
            b.show()
        self.show()
        self.place()
        if level == "info" and not actions:
            self._timer.start(INFO_SECONDS * 1000)
        else:
            self._timer.stop()

    def place(self) -> None:
        """Span the parent's width at its bottom, above everything in it."""
        parent = self.parentWidget()
        if parent is None:
            return
        m = self.MARGIN
        width = max(100, parent.width() - 2 * m)
        # the wrapped text's height at this width (sizeHint wraps it narrower: 2-3x too tall)
        if self.hasHeightForWidth():
            height = max(self.heightForWidth(width), self.minimumSizeHint().height())
        else:
            height = self.sizeHint().height()
        self.setGeometry(m, max(0, parent.height() - height - m), width, height)
        self.raise_()
        self.covered.emit(height + 2 * m)

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt API
        if obj is self.parentWidget() and event.type() == QEvent.Type.Resize and self.isVisible():
            self.place()
        return False

    def waiting_for_answer(self) -> bool:
        """True while a message with action buttons is shown (info must not replace it)."""
        return self.isVisibleTo(self.parentWidget()) and self._actions.count() > 0

    @Slot(str)
    def retract(self, start: str) -> None:
        """Close the message shown if it starts with ``start`` (no longer true)."""
        if self.text.startswith(start):
            self.dismiss()

    @Slot()
    def dismiss(self) -> None:
        self._timer.stop()
        shown = self.isVisibleTo(self.parentWidget()) if self.parentWidget() else self.isVisible()
        self.hide()
        self.covered.emit(0)
        if shown:
            self.dismissed.emit(self.label.text())


#: Jobs that run beside a long one without taking the status bar from it.
BACKGROUND_KEYS = frozenset(
    {"autosave", "warmup", "tile_metrics", "set_quality", "preview", "save"}
)


def time_left(job: jobs.Job, now: float | None = None) -> float | None:
    """Seconds the job still needs at its rate so far, None before it can be told."""
    p = job.progress
    if p is None or p.total <= 0 or p.done <= 0 or p.done >= p.total:
        return None
    elapsed = (time.perf_counter() if now is None else now) - job.started_at
    if elapsed < 1.0:
        return None
    return elapsed * (p.total - p.done) / p.done


def duration_text(seconds: float) -> str:
    """``~12 s`` or ``~3 min``."""
    if seconds < 90:
        return f"~{max(1, round(seconds))} s"
    return f"~{round(seconds / 60)} min"


class ElidingLabel(QLabel):
    """A one-line label that ends a text too long for it with "…" (the status bar cut the job's
    line off: "Making 256 Wang tiles — ~3 min le"); the layout may narrow it down to ``least``
    and "…" (the job's name: its time left goes first). Its tooltip is the whole text, then
    ``about`` (what the label shows)."""

    least = ""

    def __init__(self, about: str = "", parent=None, *, least: str = "") -> None:
        super().__init__(parent)
        self.about, self.least = about, least
        self.setToolTip(about)

    def setText(self, text: str) -> None:  # noqa: N802 - Qt API
        super().setText(text)
        self.setToolTip("\n".join(t for t in (text, self.about) if t))

    def minimumSizeHint(self) -> QSize:  # noqa: N802 - Qt API
        hint = super().minimumSizeHint()
        least = self.fontMetrics().horizontalAdvance(self.least + "…") + hint.width()
        least -= self.fontMetrics().horizontalAdvance(self.text())  # the margins
        return QSize(min(hint.width(), least), hint.height())

    def shown_text(self) -> str:
        return self.fontMetrics().elidedText(
            self.text(), Qt.TextElideMode.ElideRight, self.contentsRect().width()
        )

    def paintEvent(self, _event) -> None:  # noqa: N802 - Qt API
        painter = QStylePainter(self)
        align = self.alignment() | Qt.AlignmentFlag.AlignVCenter
        painter.drawItemText(
            self.contentsRect(),
            int(align),
            self.palette(),
            self.isEnabled(),
            self.shown_text(),
            QPalette.ColorRole.WindowText,
        )


class JobStatus(QWidget):
    """The main running job (its n/N and the time left), the others named, and a Cancel
    button that stops them.

    The main job is the oldest running one with a known length, else the oldest: a
    background save or measurement never takes the bar from a long generation."""

    def __init__(self, manager: jobs.JobManager, parent=None) -> None:
        super().__init__(parent)
        self.manager = manager
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.label = ElidingLabel()  # its whole text in its tooltip
        self.others = ElidingLabel("Other jobs running at the same time", least="· also")
        self.bar = QProgressBar()
        self.bar.setFixedWidth(160)
        self.bar.setTextVisible(True)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("Stop the running job (Esc)")
        self.cancel_button.clicked.connect(self.cancel)
        lay.addWidget(self.label)
        lay.addWidget(self.bar)
        lay.addWidget(self.others)
        lay.addWidget(self.cancel_button)
        self._poll = QTimer(self)
        self._poll.setInterval(100)
        self._poll.timeout.connect(self._refresh)
        manager.started.connect(self._refresh)
        manager.progress.connect(self._refresh)
        manager.ended.connect(self._refresh)
        self._refresh()

    def shown_jobs(self) -> list[jobs.Job]:
        """Running jobs older than SHOW_AFTER (quick recomputes do not flash the bar)."""
        now = time.perf_counter()
        return [j for j in self.manager.running() if now - j.started_at >= SHOW_AFTER]

    def current(self) -> jobs.Job | None:
        """The job the bar shows (see the class docstring)."""
        shown = self.shown_jobs()
        if not shown:
            return None
        foreground = [j for j in shown if j.key not in BACKGROUND_KEYS] or shown
        measured = [j for j in foreground if j.progress is not None and j.progress.total > 0]
        return min(measured or foreground, key=lambda j: j.started_at)

    @Slot()
    def cancel(self) -> None:
        """Stop every running job (anytime searches keep their best result)."""
        self.manager.stop_all()

    @Slot(object)
    def _refresh(self, _job=None) -> None:
        if self.manager.running():
            if not self._poll.isActive():
                self._poll.start()
        else:
            self._poll.stop()
        job = self.current()
        if job is None:
            self.setVisible(False)
            return
        self.setVisible(True)
        others = [j.label for j in self.shown_jobs() if j is not job]
        self.others.setText(f"· also {', '.join(others)}" if others else "")
        self.others.setVisible(bool(others))
        p = job.progress
        left = time_left(job)
        note = f" — {duration_text(left)} left" if left else ""
        if not left and job.estimate:
            note = f" — {job.estimate}"
        self.label.least = job.label
        self.label.setText(job.label + note)
        extra = job.estimate if job.estimate and job.estimate not in note else ""
        self.label.setToolTip("\n".join(t for t in (job.label + note, extra) if t))
        if p is None or p.total <= 0:
            self.bar.setRange(0, 0)  # busy indicator
        else:
            self.bar.setRange(0, 1000)
            self.bar.setValue(int(p.fraction * 1000))
            self.bar.setFormat(f"{p.done}/{p.total}")
