"""The preview's tile-set figures and warnings (issue 10): a good set and a warned one.

    xvfb-run -s "-screen 0 1600x1000x24" python tools/screenshots_quality.py

Writes docs/preview_quality.png (the bundled lichen sample, the editor's defaults, all
candidates picked: the figures in one line and no warning; cobblestones, the default sample,
still shows one: frame 1.18 > 1.15) and
docs/preview_warned.png (the evaluation set's procedural bricks under a lighting gradient:
the frame, ring tone and lattice warnings in words) and docs/scale_warning.png (shelves every
64 px searched with 64 px tiles: the banner says the tile cuts the structures, issue 10 item 6).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from PIL import Image

    from benchmarks.evalset import load
    from quilt_gui.responsiveness import wait_until
    from tools.screenshots import open_editor

    app, w, idle = open_editor()
    out = ROOT / "docs"

    def tile_set(name: str) -> None:
        w.act_find.trigger()
        wait_until(idle)
        w.act_generate.trigger()
        wait_until(idle)
        w.doc.tileset.set_picks(list(range(len(w.doc.tileset.candidates))))
        w.tabs.setCurrentWidget(w.preview_view)
        wait_until(lambda: idle() and w.preview_view.quality is not None, timeout_s=180)
        w.message_bar.dismiss()
        w.preview_view.canvas.fit()
        app.processEvents()
        w.grab().save(str(out / name))
        print("wrote", out / name, w.preview_view.quality)

    w.files.open_path(str(ROOT / "resources" / "samples" / "lichen.png"), confirm=False)
    wait_until(idle)
    tile_set("preview_quality.png")
    path = Path(tempfile.mkdtemp(prefix="quilt_shots_")) / "bricks.png"
    Image.fromarray(load("bricks")).save(path)
    w.files.open_path(str(path), confirm=False)
    wait_until(idle)
    tile_set("preview_warned.png")
    path = path.with_name("shelves.png")
    Image.fromarray(load("shelves")).save(path)
    w.files.open_path(str(path), confirm=False)
    wait_until(idle)
    w.doc.set_params({"tile_size": "64"})
    w.tabs.setCurrentWidget(w.source_view)
    w.act_find.trigger()
    wait_until(idle)
    app.processEvents()
    w.grab().save(str(out / "scale_warning.png"))
    print("wrote", out / "scale_warning.png", w.message_bar.label.text()[:80])
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
