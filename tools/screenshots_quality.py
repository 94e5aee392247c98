"""The tile-set and Wang workflows' figures and warnings on screen (issues 10 and 11).

    xvfb-run -s "-screen 0 1600x1000x24" python tools/screenshots_quality.py

Writes into docs/ (each PNG at most tools/screenshots.MAX_BYTES):
- preview_quality.png: the bundled lichen sample, the editor's defaults, all candidates picked:
  the figures in one line and no warning;
- preview_warned.png: the evaluation set's procedural planks (Auto tone flattens their
  lighting: the line under Seam blending says so): the frame and lattice warnings in words;
- template_warned.png: scikit-image's page after Find best tile: the stationarity check's
  warnings (uneven lighting, uneven sharpness) on the banner;
- candidates_fewer.png: page's candidates: fewer than asked, and why (positions too calm for
  the tiles' shared joint, the minimum distance), on the banner;
- scale_warning.png: shelves every 64 px searched with 64 px tiles: the banner says the tile
  cuts the structures (issue 10 item 6);
- wang_warned.png: the Wang tab, planks (boards every 48 px) with 128 px tiles: the banner
  says the tiles do not hold whole periods, so every tile line breaks the boards, and offers
  "Use 144 px tiles" (three boards; session 11).
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
    from tools.screenshots import open_editor, save_png

    app, w, idle = open_editor()
    out = ROOT / "docs"
    folder = Path(tempfile.mkdtemp(prefix="quilt_shots_"))

    def shot(name: str) -> None:
        for _ in range(5):
            app.processEvents()
        save_png(w.grab(), out / name)
        print("wrote", out / name, "|", w.message_bar.text[:160].replace("\n", " / "))

    def open_evalset(name: str) -> None:
        path = folder / f"{name}.png"
        Image.fromarray(load(name)).save(path)
        w.files.open_path(str(path), confirm=False)
        wait_until(idle)
        w.tabs.setCurrentWidget(w.source_view)

    def find() -> None:
        w.act_find.trigger()
        wait_until(idle, timeout_s=300)

    def generate() -> None:
        w.act_generate.trigger()
        wait_until(idle, timeout_s=300)

    def tile_set(name: str) -> None:
        find()
        generate()
        w.doc.tileset.set_picks(list(range(len(w.doc.tileset.candidates))))
        w.tabs.setCurrentWidget(w.preview_view)
        wait_until(lambda: idle() and w.preview_view.quality is not None, timeout_s=300)
        w.message_bar.dismiss()
        w.preview_view.canvas.fit()
        shot(name)
        print("   ", w.preview_view.quality)

    w.files.open_path(str(ROOT / "resources" / "samples" / "lichen.png"), confirm=False)
    wait_until(idle)
    tile_set("preview_quality.png")
    open_evalset("planks")
    tile_set("preview_warned.png")

    open_evalset("page")
    find()
    shot("template_warned.png")
    generate()
    w.gallery.scrollToTop()
    shot("candidates_fewer.png")

    open_evalset("shelves")
    w.doc.set_params({"tile_size": "64"})
    find()
    shot("scale_warning.png")

    open_evalset("planks")
    w.tabs.setCurrentWidget(w.wang_view)
    wv = w.wang_view
    wv.tile_size.setValue(128)
    wv.generate_button.click()
    wait_until(lambda: not w.jobs.busy(), timeout_s=300)
    wv.grid_box.setChecked(True)
    wv.tiles.fit()
    wv.preview.fit()
    shot("wang_warned.png")
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
