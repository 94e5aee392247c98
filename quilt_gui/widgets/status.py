"""Non-blocking messages and the running job's progress bar with its Cancel button."""

from __future__ import annotations

import time

from PySide6.QtCore import Qt, QTimer, Slot
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QProgressBar,
    QPushButton,
    QSizePolicy,
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
    """A banner above the canvas: never modal; errors stay until closed, info fades."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
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
        self.show()
        if level == "info" and not actions:
            self._timer.start(INFO_SECONDS * 1000)
        else:
            self._timer.stop()

    def waiting_for_answer(self) -> bool:
        """True while a message with action buttons is shown (info must not replace it)."""
        return self.isVisibleTo(self.parentWidget()) and self._actions.count() > 0

    @Slot()
    def dismiss(self) -> None:
        self._timer.stop()
        self.hide()


class JobStatus(QWidget):
    """Progress of the newest running job, and a Cancel button that stops it."""

    def __init__(self, manager: jobs.JobManager, parent=None) -> None:
        super().__init__(parent)
        self.manager = manager
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.label = QLabel()
        self.bar = QProgressBar()
        self.bar.setFixedWidth(160)
        self.bar.setTextVisible(True)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("Stop the running job (Esc)")
        self.cancel_button.clicked.connect(self.cancel)
        lay.addWidget(self.label)
        lay.addWidget(self.bar)
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
        shown = self.shown_jobs()
        return shown[-1] if shown else None

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
        n = len(self.shown_jobs())
        self.label.setText(job.label + (f" (+{n - 1})" if n > 1 else ""))
        p = job.progress
        if p is None or p.total <= 0:
            self.bar.setRange(0, 0)  # busy indicator
        else:
            self.bar.setRange(0, 1000)
            self.bar.setValue(int(p.fraction * 1000))
            self.bar.setFormat(f"{p.done}/{p.total}")
