"""Responsiveness (issue 5): the GUI thread never stalls while jobs run; Cancel stops a job.

The figures are printed (run with ``-s -n0``) for the benchmark table; benchmarks/
gui_responsiveness.py prints the same table and judges the targets (p99 gap <= 50 ms, max gap
<= 150 ms, cancel <= 200 ms). This test shares the machine with the rest of the suite (and CI
with other jobs), so it checks only what holds under any load: the GUI thread kept ticking
while every job ran and no single stall took a quarter of the job's time (work done on the GUI
thread would stall it for the whole job). Cancel is checked on jobs that cannot end soon (500
candidates of the local patch search, which makes as many as asked; a 2048 px quilt, about
2 000 blocks): the job was still running when Cancel was clicked, it stopped because of the
Cancel (not because it was done) and the window took it back; its latency is only printed.
"""

from __future__ import annotations

from quilt_gui.responsiveness import (
    CANCEL_CANDIDATES,
    cancel_candidates,
    cancel_quilting,
    format_table,
    measure_all,
    wait_until,
)
from tests.gui.helpers import make_window, open_sample, template, wait_idle

STALL_SHARE = 0.25
WAIT_S = 300.0  # a margin for a loaded machine, never reached when all is well


def test_gui_thread_stays_responsive(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    rows = measure_all(w, repeats=3, cancel=False)
    print("\n" + format_table(rows))
    for name, s in rows.items():
        if "p99" in s:
            assert s["n"] > 0, name
            assert s["max"] <= STALL_SHARE * s["seconds"] * 1000.0, (name, s)
        else:  # parameter change -> seamless tile redrawn: reported, not a pass/fail target
            assert 0 < s["recompute_ms"] < 10_000, (name, s)


def _taken_back(w, action) -> None:
    """The window is idle again: no job, no progress bar, and the job's action works."""
    assert not w.jobs.busy()
    assert not w.job_status.isVisible()
    assert action.isEnabled()


def test_cancel_stops_generating_candidates(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    template(qtbot, w)
    out = cancel_candidates(w, WAIT_S)
    print(f"\ncancel candidates: {out['ms']:.0f} ms, {out['made']} of {out['asked']} made")
    job = out["job"]
    assert out["running"], "the job was over before Cancel: nothing was cancelled"
    assert job.token.cancelled and job.state == "done"  # anytime: it keeps what it made
    assert 3 <= out["made"] < CANCEL_CANDIDATES, out  # stopped by Cancel, not done
    assert f"Generation stopped: {out['made']} of {CANCEL_CANDIDATES}" in w.last_message()
    _taken_back(w, w.act_generate)
    assert w.gallery.model().rowCount() == out["made"]
    w.doc.set_param("n_candidates", 4)  # the next run makes all it is asked for
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    assert len(w.doc.tileset.candidates) == 4
    assert not w.last_message().startswith("Generation stopped")


def test_cancel_stops_quilting(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    out = cancel_quilting(w, WAIT_S)
    print(f"\ncancel quilting: {out['ms']:.0f} ms, {len(w.doc.quilting.blocks)} blocks placed")
    job = out["job"]
    assert out["running"], "the quilt was over before Cancel: nothing was cancelled"
    assert job.state == "cancelled", job.state  # the engine stopped; no result came
    assert w.doc.quilting.result is None and w.doc.quilting.finished_output is None
    n = len(w.doc.quilting.blocks)
    assert n >= 3
    assert w.last_message() == f"Quilting cancelled after {n} blocks."
    _taken_back(w, w.act_quilt)
    assert not w.act_save_output.isEnabled()  # nothing finished to save
    w.doc.set_params({"out_width": 128, "out_height": 128})  # the next quilt finishes
    w.act_quilt.trigger()
    assert wait_until(lambda: w.doc.quilting.result is not None and not w.pipeline.busy(), WAIT_S)
    assert w.act_save_output.isEnabled()
