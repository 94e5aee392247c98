"""Screenshots of the searches on screen: docs/watch_search.png and docs/template_sweep.png.

    xvfb-run -a -s "-screen 0 1600x1000x24" python tools/screenshots_search.py

``watch_search.png``: *Watch the search* on the bundled sample's tile, mid-way (the paper's
oscillating search drawing its improvements, the criterion falling in the chart).
``template_sweep.png``: *Find best tile* with a tile size range, caught during a horizontal
phase: the rectangles scored so far drawn faintly, the best so far highlighted.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tools")]


def main() -> int:
    from screenshots import open_editor, save_png

    from quilt_gui import params
    from quilt_gui.responsiveness import wait_until

    app, w, idle = open_editor()
    out = ROOT / "docs"
    doc = w.doc

    # -- the template sweep, caught in a horizontal phase with 60 rectangles on screen
    doc.set_params({"tile_size": params.ANY, "tile_min": 96, "tile_max": 256})
    wait_until(idle)
    sweep = w.source_view.sweep
    caught = []

    def catch(event) -> None:
        if not caught and event.phase == "horizontal" and len(sweep.recent) >= 60:
            sweep._rebuild()
            app.processEvents()
            save_png(w.grab(), out / "template_sweep.png")
            caught.append(event)

    w.pipeline.template_swept.connect(catch)
    w.message_bar.dismiss()
    w.source_view.fit()
    w.act_find.trigger()
    wait_until(idle)
    w.pipeline.template_swept.disconnect(catch)
    print("wrote" if caught else "MISSED", out / "template_sweep.png")

    # -- watch the search, mid-way
    watch = w.overlap_panel.watch
    watch.start()
    wait_until(lambda: watch.drawn >= 150 or watch.state == "finished", 120)
    w.message_bar.dismiss()
    app.processEvents()
    save_png(w.grab(), out / "watch_search.png")
    print("wrote", out / "watch_search.png", f"({watch.drawn} improvements drawn)")
    watch.back()
    wait_until(idle)
    w.close()
    app.processEvents()
    return 0 if caught else 1


if __name__ == "__main__":
    raise SystemExit(main())
