"""Measure how responsive the editor stays while background jobs run.

A precise QTimer on the GUI thread ticks every few milliseconds; the gaps between its ticks
show how long the event loop was blocked (by our own slots, or by a worker holding the GIL).
Used by ``tests/gui/test_responsiveness.py`` and ``benchmarks/gui_responsiveness.py``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QEventLoop, QObject, Qt, QTimer, Slot

from quilt_gui import params

TICK_MS = 5


class GapMeter(QObject):
    """Records the time between ticks of a GUI-thread timer."""

    def __init__(self, interval_ms: int = TICK_MS, parent=None) -> None:
        super().__init__(parent)
        self.timer = QTimer(self)
        self.timer.setTimerType(Qt.TimerType.PreciseTimer)
        self.timer.setInterval(interval_ms)
        self.timer.timeout.connect(self._tick)
        self.ticks: list[float] = []

    def start(self) -> None:
        self.ticks = [time.perf_counter()]
        self.timer.start()

    def stop(self) -> np.ndarray:
        """Stop; the gaps (ms) between consecutive ticks."""
        self.timer.stop()
        self._tick()
        return np.diff(np.asarray(self.ticks)) * 1000.0

    @Slot()
    def _tick(self) -> None:
        self.ticks.append(time.perf_counter())


def gap_stats(gaps) -> dict:
    """Count, p50 / p99 / max (ms) of tick gaps, and their total duration (s)."""
    gaps = np.asarray(gaps, dtype=np.float64)
    if gaps.size == 0:
        return {"n": 0, "p50": 0.0, "p99": 0.0, "max": 0.0, "seconds": 0.0}
    return {
        "n": int(gaps.size),
        "p50": float(np.percentile(gaps, 50)),
        "p99": float(np.percentile(gaps, 99)),
        "max": float(gaps.max()),
        "seconds": float(gaps.sum() / 1000.0),
    }


def wait_until(cond: Callable[[], bool], timeout_s: float = 120.0) -> bool:
    """Run the event loop (without spinning) until ``cond()`` or the timeout."""
    if cond():
        return True
    loop = QEventLoop()
    poll = QTimer()
    poll.setInterval(10)
    deadline = time.perf_counter() + timeout_s

    def check() -> None:
        if cond() or time.perf_counter() > deadline:
            loop.quit()

    poll.timeout.connect(check)
    poll.start()
    loop.exec()
    poll.stop()
    return cond()


def gaps_during(window, start: Callable[[], object], timeout_s: float = 120.0) -> np.ndarray:
    """Tick gaps (ms) from ``start()`` until the pipeline is idle again."""
    meter = GapMeter()
    meter.start()
    start()
    if not wait_until(lambda: not window.pipeline.busy(), timeout_s):
        raise TimeoutError(f"the job did not finish within {timeout_s} s")
    return meter.stop()


def measure_candidates(window, repeats: int = 3) -> dict:
    """Gap statistics while ``n_candidates`` candidates generate, ``repeats`` runs pooled."""
    runs = []
    for k in range(repeats):
        window.doc.set_param("seed", 1000 + k)
        runs.append(gaps_during(window, window.pipeline.generate_candidates))
    return gap_stats(np.concatenate(runs))


def measure_quilting(window) -> dict:
    """Gap statistics while the quilting job runs with the current parameters."""
    return gap_stats(gaps_during(window, window.run_quilt))


def cancel_running(
    window,
    key: str,
    start: Callable[[], object],
    started: Callable[[], bool],
    timeout_s: float = 300.0,
) -> dict:
    """Start the job ``key`` with ``start()``, wait until ``started()`` and the status bar shows
    it, click Cancel and wait until every job has ended.

    Returns ``ms`` (from the click until every job ended), ``job`` and ``running``: whether the
    job was still running when Cancel was clicked (a cancel of a job already over measures
    nothing). Raises TimeoutError when a wait takes longer than ``timeout_s`` (a margin)."""
    start()
    job = window.jobs.get(key)
    if job is None:
        raise RuntimeError(f"no {key} job started")
    if not wait_until(lambda: started() and window.job_status.isVisible(), timeout_s):
        raise TimeoutError(f"the job did not show progress within {timeout_s} s")
    running = job.running
    t0 = time.perf_counter()
    window.job_status.cancel_button.click()
    if not wait_until(lambda: not window.jobs.busy(), timeout_s):
        raise TimeoutError(f"the jobs did not end within {timeout_s} s of Cancel")
    return {"ms": (time.perf_counter() - t0) * 1000.0, "job": job, "running": running}


#: the long jobs :func:`measure_cancel` cancels: candidates (the local patch search makes as
#: many as asked, whatever the source) and a quilt (about 2 000 blocks, 20 s on a quiet machine)
CANCEL_CANDIDATES, CANCEL_QUILT_SIDE = 500, 2048


def cancel_candidates(window, timeout_s: float = 300.0) -> dict:
    """:func:`cancel_running` on the generation of :data:`CANCEL_CANDIDATES` candidates (the
    template must be found), cancelled once 3 of them are shown. Adds ``made`` (new candidates
    kept) and ``asked``; the parameters are restored afterwards."""
    doc = window.doc
    kept = doc.params.get(params.KEPT)
    n = doc.params["n_candidates"]
    doc.apply_params({params.KEPT: {**(kept or {}), "patch_search": "local"}})
    doc.set_param("n_candidates", CANCEL_CANDIDATES)
    wait_until(lambda: not window.pipeline.busy(), timeout_s)
    try:
        out = cancel_running(
            window,
            "candidates",
            window.act_generate.trigger,
            lambda: len(doc.tileset.candidates) >= 3,
            timeout_s,
        )
    finally:
        doc.apply_params({params.KEPT: kept})
        doc.set_param("n_candidates", n)
    out.update(made=len(doc.tileset.candidates), asked=CANCEL_CANDIDATES)
    return out


def cancel_quilting(window, timeout_s: float = 300.0) -> dict:
    """:func:`cancel_running` on a :data:`CANCEL_QUILT_SIDE` px square quilt, cancelled once 3
    blocks are placed; the output size is restored afterwards. No quilt may be shown (the
    size change would re-run it)."""
    doc = window.doc
    if doc.quilting.result is not None or window.jobs.get("quilt") is not None:
        raise RuntimeError("cancel_quilting needs a window without a quilt shown or running")
    size = {k: doc.params[k] for k in ("out_width", "out_height")}
    doc.set_params({"out_width": CANCEL_QUILT_SIDE, "out_height": CANCEL_QUILT_SIDE})
    try:
        return cancel_running(
            window,
            "quilt",
            window.act_quilt.trigger,
            lambda: len(doc.quilting.blocks) >= 3,
            timeout_s,
        )
    finally:
        doc.set_params(size)


def recompute_latency(window, method: str, repeats: int = 3) -> float:
    """Median ms from a parameter change (rho) until the seamless tile of ``method`` is shown."""
    doc = window.doc
    doc.set_param("method", method)
    wait_until(lambda: not window.pipeline.busy())
    times = []
    for k in range(repeats):
        rho = 3 + (k + 1) % 2
        t0 = time.perf_counter()
        doc.set_param("rho", rho)

        def shown(rho=rho) -> bool:
            s = doc.tileset.seamless
            return s is not None and s.seam.rho == rho and not window.pipeline.busy()

        if not wait_until(shown, 60):
            raise TimeoutError(f"no seamless tile for method {method}")
        times.append((time.perf_counter() - t0) * 1000.0)
    return float(np.median(times))


def measure_watch(window, improvements: int = 240) -> dict:
    """Gap statistics while *Watch the search* draws its first ``improvements`` at its own pace
    (about 8 s at 30 a second), then skips to the end and goes back to the default seams.
    Adds ``drawn`` and ``rate`` (drawn improvements per second)."""
    watch = window.overlap_panel.watch
    meter = GapMeter()
    meter.start()
    watch.start()
    wait_until(lambda: watch.drawn >= improvements or watch.state == "finished", 120)
    gaps = meter.stop()
    out = gap_stats(gaps)
    out.update(drawn=watch.drawn, rate=watch.drawn / max(out["seconds"], 1e-9))
    watch.skip()
    wait_until(lambda: watch.state == "finished", 60)
    watch.back()
    wait_until(lambda: not window.pipeline.busy())
    return out


def measure_all(
    window, *, repeats: int = 3, heavy: bool = False, watch: bool = False, cancel: bool = True
) -> dict[str, dict]:
    """The figures of the benchmark table (the window must have the sample open).

    ``heavy`` adds runs of several seconds (300 candidates; a 1536x1536 quilt), so the
    percentiles rest on thousands of ticks rather than a few dozen; ``watch`` the animation of
    *Watch the search* (:func:`measure_watch`, about 8 s); ``cancel`` the latency of Cancel on
    two long jobs (:func:`cancel_candidates`, :func:`cancel_quilting`)."""
    doc = window.doc
    window.pipeline.find_template()
    wait_until(lambda: not window.pipeline.busy())
    rows = {f"{doc.params['n_candidates']} candidates": measure_candidates(window, repeats)}
    if cancel:  # before any quilt is shown (a size change would re-run a shown one)
        rows["cancel candidates"] = {"ms": cancel_candidates(window)["ms"]}
        rows["cancel quilting"] = {"ms": cancel_quilting(window)["ms"]}
    rows["quilting (best match)"] = measure_quilting(window)
    if watch:
        rows["watch the search (paced)"] = measure_watch(window)
    if heavy:
        n, size = doc.params["n_candidates"], (doc.params["out_width"], doc.params["out_height"])
        doc.set_param("n_candidates", 300)
        rows["300 candidates"] = measure_candidates(window, 1)
        doc.set_params({"n_candidates": n, "out_width": 1536, "out_height": 1536})
        rows["quilting 1536x1536 (best match)"] = measure_quilting(window)
        doc.set_params({"out_width": size[0], "out_height": size[1]})
    method = doc.params["method"]
    for m in ("dp", "oscillating", "oscillating-optimal"):  # the methods with a cyclic seam
        rows[f"seamless tile, {m}"] = {"recompute_ms": recompute_latency(window, m)}
    doc.set_param("method", method)
    return rows


def format_table(rows: dict[str, dict]) -> str:
    lines = [
        "| job | duration (s) | ticks | gap p50 (ms) | gap p99 (ms) | gap max (ms) |",
        "|---|---|---|---|---|---|",
    ]
    for name, s in rows.items():
        if "ms" in s or "recompute_ms" in s:
            continue
        lines.append(
            f"| {name} | {s['seconds']:.2f} | {s['n']} | {s['p50']:.1f} | "
            f"{s['p99']:.1f} | {s['max']:.1f} |"
        )
    lines += ["", "| cancel | latency (ms) |", "|---|---|"]
    lines += [f"| {name} | {s['ms']:.0f} |" for name, s in rows.items() if "ms" in s]
    lines += ["", "| parameter change -> redrawn | median (ms) |", "|---|---|"]
    lines += [
        f"| {name} | {s['recompute_ms']:.0f} |" for name, s in rows.items() if "recompute_ms" in s
    ]
    return "\n".join(lines)
