"""Watch the search: Somol & Haindl's oscillating search as published, one improvement at a time.

The default seam starts the oscillating search from the exact DP cut, so it finds its path in
a couple of moves and nothing is seen working. *Watch the search* runs the paper's own
algorithm (variant ``faithful``, per-row ``argmin`` start, the user's o_max) on the current
tile in a worker: :func:`engine.tiles.iter_make_seamless` streams every improvement of both
overlaps (hundreds on a bundled sample). They reach the GUI thread as :class:`Improvement`
items (never coalesced) and wait in a queue; a timer draws one per tick, at most
:data:`MAX_PER_SECOND` a second, on the overlap panel and the source, while the criterion falls
in a small chart. The worker never waits for the drawing: the search ends in about a second and
the queue holds the rest. Then the person keeps the result (the seam parameters become the
paper's, which recomputes the same tile) or goes back to the default seam.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from PySide6.QtCore import QPointF, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QColor, QPainter, QPainterPath, QPen
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from engine.events import Item
from quilt_gui.document import Document
from quilt_gui.jobs import error_text
from quilt_gui.pipeline import Pipeline
from quilt_gui.widgets.source_view import SEAM_COLORS

#: the oscillating search as published (ALGORITHMS §1.2)
PAPER_OPTIONS = {"variant": "faithful", "init": "argmin"}
#: drawn improvements per second, at most (a pace a person can follow)
MAX_PER_SECOND = 30
INTERVAL_MS = -(-1000 // MAX_PER_SECOND)
SHORT = {"horizontal": "left/right", "vertical": "top/bottom"}

__all__ = ["MAX_PER_SECOND", "CriterionChart", "Improvement", "WatchSearch", "describe_seam"]


def describe_seam(spec) -> str:
    """Which variant of its method made a seam (for the status bar)."""
    o = spec.options
    if spec.method == "oscillating":
        if (o["variant"], o["init"]) == ("faithful", "argmin"):
            return f"oscillating as published (restart, per-row argmin start, o_max {o['o_max']})"
        start = {"dp": "the DP cut", "argmin": "per-row argmin", "smoothed": "smoothed argmin"}
        return f"oscillating ({o['variant']}, from {start[o['init']]}, o_max {o['o_max']})"
    if spec.method == "resistance":
        return f"resistance ({o['variant']}, runs <= {o['max_run']})"
    if spec.method == "minimax":
        return f"minimax ({o['variant']})"
    return spec.method


@dataclass(frozen=True, slots=True)
class Improvement(Item):
    """One streamed seam improvement, as an item: every one must reach the queue."""

    update: object  # engine.tiles.seamless.SeamlessUpdate


def watched_seamless(*args, cancel=None, **kwargs):
    """:func:`engine.tiles.iter_make_seamless` with its seam updates wrapped as items."""
    from engine.tiles import SeamlessUpdate, iter_make_seamless

    gen = iter_make_seamless(*args, cancel=cancel, **kwargs)
    while True:
        try:
            event = next(gen)
        except StopIteration as stop:
            return stop.value
        yield Improvement(event) if isinstance(event, SeamlessUpdate) else event


class CriterionChart(QWidget):
    """The criterion of each overlap's seam, one point per drawn improvement."""

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.series: dict[str, list[float]] = {k: [] for k in SEAM_COLORS}
        self.setMinimumHeight(64)
        self.setToolTip(
            "Seam criterion (sum of the error along the seam) after each improvement: "
            "left/right overlap green, top/bottom cyan"
        )

    def clear(self) -> None:
        for s in self.series.values():
            s.clear()
        self.update()

    def add(self, which: str, value: float) -> None:
        self.series[which].append(float(value))
        self.update()

    def paintEvent(self, _event) -> None:  # noqa: N802 - Qt API
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        r = self.rect().adjusted(4, 4, -4, -16)
        p.fillRect(self.rect(), self.palette().base())
        p.setPen(QPen(self.palette().mid().color(), 1))
        p.drawRect(r)
        n = max((len(s) for s in self.series.values()), default=0)
        texts = []
        for which, values in self.series.items():
            if not values:
                continue
            lo, hi = min(values), max(values)
            span = hi - lo or 1.0
            path = QPainterPath()
            for i, v in enumerate(values):
                x = r.left() + r.width() * (i / max(1, n - 1))
                y = r.top() + r.height() * (1.0 - (v - lo) / span)
                (path.lineTo if i else path.moveTo)(QPointF(x, y))
            p.setPen(QPen(QColor(SEAM_COLORS[which]), 1.5))
            p.drawPath(path)
            texts.append(f"{SHORT[which]} {values[0]:.1f} → {values[-1]:.1f}")
        p.setPen(self.palette().text().color())
        p.drawText(
            self.rect().adjusted(4, 0, -4, -1),
            Qt.AlignmentFlag.AlignBottom | Qt.AlignmentFlag.AlignLeft,
            "   ".join(texts) or "criterion per improvement",
        )
        p.end()


class WatchSearch(QWidget):
    """The "Watch the search" row of the seam panel: buttons, progress and the chart."""

    state_changed = Signal(str)  # "idle" | "watching" | "finished"

    def __init__(self, doc: Document, pipeline: Pipeline, parent=None) -> None:
        super().__init__(parent)
        self.doc = doc
        self.pipeline = pipeline
        self.state = "idle"
        self.queue: deque = deque()
        self.drawn = 0  # improvements drawn in this watch (the final repeats not counted)
        self.result = None  # the SeamlessTile the watched search made
        self.spec = None
        self._job_done = False
        self._skip = False
        self.timer = QTimer(self)
        self.timer.setInterval(INTERVAL_MS)
        self.timer.timeout.connect(self._tick)
        self._flush_timer = QTimer(self)
        self._flush_timer.setSingleShot(True)
        self._flush_timer.setInterval(0)
        self._flush_timer.timeout.connect(self._flush)
        self.watch_button = QPushButton("Watch the search")
        self.watch_button.setToolTip(
            "Run Somol & Haindl's oscillating search as published (restart after every "
            "improvement, per-row argmin start) on this tile and draw every improvement, "
            f"at most {MAX_PER_SECOND} a second"
        )
        self.skip_button = QPushButton("Skip to the end")
        self.keep_button = QPushButton("Keep")
        self.keep_button.setToolTip(
            "Use the published oscillating search for the seams from now on (Seam method, "
            "variant and start change; undo brings the old ones back)"
        )
        self.back_button = QPushButton("Back to default")
        self.back_button.setToolTip("Show the seams of the current parameters again")
        self.label = QLabel()  # one line that never resizes the panel while it changes
        self.label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        self.chart = CriterionChart()
        row = QHBoxLayout()
        row.setContentsMargins(0, 0, 0, 0)
        for b in (self.watch_button, self.skip_button, self.keep_button, self.back_button):
            row.addWidget(b)
        row.addStretch(1)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(row)
        lay.addWidget(self.label)
        lay.addWidget(self.chart)
        self.watch_button.clicked.connect(self.start)
        self.skip_button.clicked.connect(self.skip)
        self.keep_button.clicked.connect(self.keep)
        self.back_button.clicked.connect(self.back)
        for signal in (
            doc.source_changed,
            doc.maps_changed,
            doc.tileset.template_changed,
            doc.tileset.waypoints_changed,
            doc.tileset.map_weights_changed,
        ):
            signal.connect(self.abandon)
        doc.params_changed.connect(self._on_params_changed)
        self._set_state("idle")

    # ------------------------------------------------------------------ state
    def _set_state(self, state: str) -> None:
        self.state = state
        self.watch_button.setVisible(state != "watching")
        self.skip_button.setVisible(state == "watching")
        self.keep_button.setVisible(state == "finished")
        self.back_button.setVisible(state == "finished")
        self.chart.setVisible(state != "idle")
        self.label.setVisible(state != "idle")
        self.state_changed.emit(state)

    def variant_text(self) -> str:
        """What made the seams on screen while a watch is shown, else ''."""
        return "" if self.state == "idle" or self.spec is None else describe_seam(self.spec)

    # ------------------------------------------------------------------ actions
    @Slot()
    def start(self):
        """Run the published search on the current tile; returns the job (or None)."""
        req = self.pipeline.seamless_request()
        if req is None:
            self.pipeline.message.emit(
                "warning", "Make the seamless tile first: draw the tile rectangle or find it."
            )
            return None
        args, kwargs, _ = req
        options = {"o_max": self.doc.params["o_max"], **PAPER_OPTIONS}
        self.spec = kwargs["seam"].replace(method="oscillating", options=options)
        kwargs["seam"] = self.spec
        self.queue.clear()
        self.chart.clear()
        self.drawn, self.result, self._job_done, self._skip = 0, None, False, False
        self._set_state("watching")
        self.label.setText("searching...")
        return self.pipeline.jobs.start(
            "watch",
            watched_seamless,
            *args,
            label="Watching the oscillating search",
            on_event=self._on_event,
            on_done=self._on_done,
            on_error=self._on_error,
            on_cancel=self._on_cancel,
            **kwargs,
        )

    @Slot()
    def skip(self) -> None:
        """Draw what is left at once (the chart still gets every improvement)."""
        self._skip = True
        self._flush()

    @Slot()
    def keep(self) -> None:
        """The watched seams stay: the parameters become the paper's (one undo step)."""
        if self.result is None:
            return
        spec = self.spec
        values = {"method": "oscillating", "osc_variant": "faithful", "osc_init": "argmin"}
        self._finish_watch()
        if any(self.doc.params[k] != v for k, v in values.items()):
            self.doc.set_params(values, text="Keep the watched seam search")
        else:
            self.doc.tileset.seamless_changed.emit()  # the document's tile is the watched one
        self.pipeline.message.emit("info", f"Seams: {describe_seam(spec)}.")

    @Slot()
    def back(self) -> None:
        """Show the document's seams (the current parameters') again."""
        self._finish_watch()
        self.doc.tileset.seamless_changed.emit()
        s = self.doc.tileset.seamless
        if s is not None:
            self.pipeline.message.emit("info", f"Seams: {describe_seam(s.seam)} (default).")

    @Slot()
    def abandon(self) -> None:
        """An input of the tile changed: the watch is stale."""
        if self.state != "idle":
            self.pipeline.jobs.abort("watch")
            self._finish_watch()

    @Slot(object)
    def _on_params_changed(self, keys) -> None:
        from quilt_gui import params

        if keys & params.SEAMLESS_KEYS:
            self.abandon()

    def _finish_watch(self) -> None:
        self.timer.stop()
        self._flush_timer.stop()
        self.queue.clear()
        self.spec = None
        self._set_state("idle")

    # ------------------------------------------------------------------ streaming and pacing
    def _on_event(self, event) -> None:
        if isinstance(event, Improvement):
            self.queue.append(event.update)
            if self._skip:
                self._flush_timer.start()  # once for the whole batch
            elif not self.timer.isActive():
                self._tick()  # the first one at once, the rest on the timer
                self.timer.start()

    @Slot()
    def _tick(self) -> None:
        if self.queue:
            self._draw(self.queue.popleft())
        if not self.queue:
            self.timer.stop()
            if self._job_done:
                self._finished()

    def _flush(self) -> None:
        last = {}
        while self.queue:
            u = self.queue.popleft()
            self._count(u)
            last[u.which] = u
        for u in last.values():
            self.pipeline.seam_updated.emit(u)
        self.timer.stop()
        if self._job_done:
            self._finished()

    def _count(self, update) -> None:
        if not update.final:
            self.drawn += 1
            self.chart.add(update.which, update.seam.criterion)

    def _draw(self, update) -> None:
        self._count(update)
        self.pipeline.seam_updated.emit(update)
        self.label.setText(
            f"improvement {self.drawn}: {SHORT[update.which]} overlap, criterion "
            f"{update.seam.criterion:.3f} ({len(self.queue)} waiting)"
        )

    def _on_done(self, result) -> None:
        self.result = result
        self._job_done = True
        if self._skip:
            self._flush()
        elif not self.queue and not self.timer.isActive():
            self._finished()

    def _finished(self) -> None:
        if self.state != "watching":
            return
        crit = ", ".join(f"{SHORT[k]} {v:.3f}" for k, v in self.result.criterion.items())
        self.label.setText(f"{self.drawn} improvements drawn; criterion {crit}")
        self.label.setToolTip("Keep these seams, or go back to the default seams?")
        self._set_state("finished")

    def _on_error(self, exc) -> None:
        self._finish_watch()
        self.pipeline.message.emit("error", error_text(exc))

    def _on_cancel(self) -> None:
        self._finish_watch()
        self.pipeline.message.emit("info", "Watching the search cancelled.")
