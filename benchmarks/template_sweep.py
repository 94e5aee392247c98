"""What showing the template search's sweep costs the search (issue 17: at most 10 %).

Usage: ``python benchmarks/template_sweep.py [--repeats 7]`` (offscreen by default).

1. Engine: :func:`engine.tiles.find_template` with ``sweep=0`` (no events) and ``sweep=24`` (the
   editor's :data:`quilt_gui.pipeline.SWEEP_SAMPLES`) on the bundled cobblestones sample and on
   it enlarged 2x, tile sizes searched over a range (the editor's "Any" tile size).
2. Editor: the *Find best tile* job from start to end with the sweep streamed and drawn on the
   source (:class:`quilt_gui.widgets.template_sweep.SweepItem`) and with it off.

Runs alternate (off, on, off, on ...) and medians are compared, so load from other processes
hits both alike; the table is printed and saved to ``benchmarks/results/template_sweep.txt``.
"""

from __future__ import annotations

import argparse
import datetime
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks._util import format_table  # noqa: E402

TARGET = 10.0  # % slower at most


def _alternating(run_off, run_on, repeats: int) -> tuple[float, float]:
    """Median seconds of ``run_off`` and ``run_on``, called in turns after one warm-up each."""
    import numpy as np

    run_off(), run_on()
    off, on = [], []
    for _ in range(repeats):
        off.append(run_off())
        on.append(run_on())
    return float(np.median(off)), float(np.median(on))


def engine_rows(repeats: int, samples: int) -> list:
    import numpy as np

    from engine.events import drain
    from engine.io import load_image, to_rgb
    from engine.tiles import iter_find_template
    from resources import sample_path

    S = to_rgb(load_image(sample_path("cobblestones")).pixels)
    rows, events = [], []
    for label, src, lo, hi in (
        ("512x512, tiles 96..256", S, 96, 256),
        ("1024x1024, tiles 192..512", np.repeat(np.repeat(S, 2, 0), 2, 1), 192, 512),
    ):

        def run(sweep, src=src, lo=lo, hi=hi, events=events):
            events.clear()
            t0 = time.perf_counter()
            drain(iter_find_template(src, tile_min=lo, tile_max=hi, sweep=sweep), events.append)
            return time.perf_counter() - t0

        off, on = _alternating(lambda: run(0), lambda: run(samples), repeats)
        n = sum(type(e).__name__ == "TemplateSweep" for e in events)
        rows.append(_row(f"engine, {label}", off, on, n))
    return rows


def editor_rows(repeats: int) -> list:
    from PySide6.QtCore import QSettings

    from quilt_gui import params
    from quilt_gui.app import make_app

    app = make_app()
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    QSettings.setPath(
        QSettings.Format.IniFormat, QSettings.Scope.UserScope, tempfile.mkdtemp(prefix="qs_")
    )
    from quilt_gui.main_window import MainWindow
    from quilt_gui.pipeline import SWEEP_SAMPLES
    from quilt_gui.responsiveness import wait_until

    w = MainWindow()
    w.files.ask_save_changes = lambda: "discard"
    w.files.ask_discard_output = lambda: True  # a new quilt replaces the last
    w.resize(1400, 900)
    w.show()
    w.open_initial(None)
    wait_until(lambda: w.doc.has_source and not w.pipeline.busy())
    w.doc.set_params({"tile_size": params.ANY, "tile_min": 96, "tile_max": 256})
    wait_until(lambda: not w.pipeline.busy())
    drawn = []
    w.pipeline.template_swept.connect(drawn.append)

    def run(sweep: int) -> float:
        w.pipeline.sweep_samples = sweep
        drawn.clear()
        t0 = time.perf_counter()
        w.pipeline.find_template()
        wait_until(lambda: w.jobs.get("template") is None)
        t = time.perf_counter() - t0
        wait_until(lambda: not w.pipeline.busy())  # the seamless tile after it, not timed
        return t

    off, on = _alternating(lambda: run(0), lambda: run(SWEEP_SAMPLES), repeats)
    row = _row("editor: Find best tile, 512x512, tiles 96..256", off, on, len(drawn))
    w.close()
    app.processEvents()
    return [row]


def _row(label, off, on, events) -> tuple:
    over = 100.0 * (on / off - 1.0)
    ok = "yes" if over <= TARGET else "NO"
    return (label, f"{off:.3f}", f"{on:.3f}", f"{over:+.1f} %", str(events), ok)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="alternating runs (default 7)")
    ap.add_argument("--samples", type=int, default=24, help="engine: sweep per chunk")
    args = ap.parse_args(argv)
    rows = engine_rows(args.repeats, args.samples) + editor_rows(args.repeats)
    table = format_table(
        ("search", "no sweep s", "sweep s", "overhead", "sweep events", f"<= {TARGET:g} %"),
        rows,
    )
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    load = os.getloadavg()[0]
    head = (
        f"# measured {datetime.date.today()} on this {os.cpu_count()}-core machine at commit "
        f"{commit}, load average {load:.1f}; medians of {args.repeats} alternating runs"
    )
    print(head)
    print(table)
    out = ROOT / "benchmarks" / "results" / "template_sweep.txt"
    out.write_text(head + "\n" + table + "\n")
    print("wrote", out)
    return 0 if all(r[-1] == "yes" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
