"""Responsiveness (issue 5): the GUI thread never stalls while jobs run; Cancel is quick.

The figures are printed (run with ``-s``) for the benchmark table; benchmarks/
gui_responsiveness.py prints the same table and judges the targets (p99 gap <= 50 ms, max gap
<= 150 ms, cancel <= 200 ms). This test shares the machine with the rest of the suite (and CI
with other jobs), so it checks only what holds under any load: the GUI thread kept ticking
while every job ran, no single stall took a quarter of the job's time (work done on the GUI
thread would stall it for the whole job), and Cancel ended each job within 2 s.
"""

from __future__ import annotations

from quilt_gui.responsiveness import format_table, measure_all
from tests.gui.helpers import make_window, open_sample

STALL_SHARE, CANCEL_MS = 0.25, 2000.0


def test_gui_thread_stays_responsive_and_cancel_is_quick(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    rows = measure_all(w, repeats=3)
    print("\n" + format_table(rows))
    for name, s in rows.items():
        if "ms" in s:
            assert s["ms"] <= CANCEL_MS, (name, s)
        elif "p99" in s:
            assert s["n"] > 0, name
            assert s["max"] <= STALL_SHARE * s["seconds"] * 1000.0, (name, s)
        else:  # parameter change -> seamless tile redrawn: reported, not a pass/fail target
            assert 0 < s["recompute_ms"] < 10_000, (name, s)
