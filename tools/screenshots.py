"""Drive the editor through the tile-set workflow and quilting, saving screenshots to docs/.

Run under Xvfb so real window-system rendering is used:

    xvfb-run -s "-screen 0 1600x1000x24" python tools/screenshots.py

Writes docs/template.png, docs/template_400.png, docs/candidates.png, docs/candidate.png,
docs/preview.png, docs/quilting.png, docs/quilting_inspect.png, docs/wang.png,
docs/wang_tiles.png, docs/export.png and docs/exclusion.png.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: docs/ stays small: a screenshot PNG larger than this is saved in 256 colours (no
#: dithering, so the interface's text stays sharp), then also scaled down until it fits
MAX_BYTES = 300_000


def save_png(image, path) -> Path:
    """Save ``image`` (a QPixmap or QImage: a grab) as the PNG ``path``, at most
    :data:`MAX_BYTES` (also tools/screenshots_*.py)."""
    import io

    from PIL import Image
    from PySide6.QtCore import QBuffer, QIODevice

    buf = QBuffer()
    buf.open(QIODevice.OpenModeFlag.WriteOnly)
    image.save(buf, "PNG")
    full = Image.open(io.BytesIO(bytes(buf.data()))).convert("RGB")
    data = bytes(buf.data())
    for scale in (1.0, 0.9, 0.8, 0.7, 0.6):
        if len(data) <= MAX_BYTES:
            break
        im = full
        if scale < 1:
            size = (round(full.width * scale), round(full.height * scale))
            im = full.resize(size, Image.Resampling.LANCZOS)
        im = im.quantize(256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE)
        out = io.BytesIO()
        im.save(out, "PNG", optimize=True)
        data = out.getvalue()
    path = Path(path)
    path.write_bytes(data)
    return path


def open_editor():
    """(app, window, idle) with the bundled sample open in a 1600x1000 dark window, settings
    in a temporary folder; ``idle()`` is true once no job runs (also tools/screenshots_search)."""
    from PySide6.QtCore import QSettings

    from quilt_gui.app import make_app

    app = make_app(theme="dark")
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    QSettings.setPath(
        QSettings.Format.IniFormat,
        QSettings.Scope.UserScope,
        tempfile.mkdtemp(prefix="quilt_shots_"),
    )
    from quilt_gui.main_window import MainWindow
    from quilt_gui.responsiveness import wait_until

    w = MainWindow()
    w.files.ask_save_changes = lambda: "discard"
    w.files.ask_discard_output = lambda: True  # a new quilt replaces the last
    w.resize(1600, 1000)
    w.show()
    w.open_initial(None)
    idle = lambda: w.doc.has_source and not w.pipeline.busy()  # noqa: E731
    wait_until(idle)
    return app, w, idle


def main() -> int:
    from quilt_gui.responsiveness import wait_until

    app, w, idle = open_editor()
    out = ROOT / "docs"
    out.mkdir(exist_ok=True)
    doc = w.doc

    def shot(widget, name: str) -> None:
        app.processEvents()
        save_png(widget.grab(), out / name)
        print("wrote", out / name)

    # -- template step: rectangle, shaded overlaps, heat overlays, seams, a waypoint
    w.act_find.trigger()
    wait_until(idle)
    x, y, tw, th = doc.tileset.template_rect
    ov = doc.params["overlap"]
    doc.tileset.add_waypoint("horizontal", (th // 2, ov // 2))
    wait_until(idle)
    w.message_bar.dismiss()
    v = w.source_view
    v.set_zoom(2.0)
    v.center_on_pixel(y + th / 2 + ov / 2, x + tw / 2 + ov / 2)
    w.overlap_panel.views["horizontal"].fit()
    w.overlap_panel.views["vertical"].fit()
    shot(w, "template.png")
    v.set_zoom(4.0)  # pixel alignment of the overlays at 400 %
    v.center_on_pixel(y + th // 2, x + ov // 2)
    shot(v.viewport(), "template_400.png")
    v.fit()

    # -- candidates gallery with picks
    w.act_generate.trigger()
    wait_until(idle)
    doc.tileset.set_picks([1, 4, 6, 9, 13])
    w.gallery.setCurrentIndex(w.gallery.model().index(4))
    w.open_candidate(4).move(w.geometry().right() - 660, w.geometry().top() + 60)
    wait_until(idle)
    w.message_bar.dismiss()
    shot(w, "candidates.png")
    shot(w._dialogs[4], "candidate.png")
    w._dialogs[4].close()

    # -- preview
    w.tabs.setCurrentWidget(w.preview_view)
    w.preview_view.set_grid(True)
    wait_until(idle)
    w.preview_view.canvas.fit()
    shot(w, "preview.png")
    w.preview_view.set_grid(False)

    # -- quilting, caught in progress
    doc.set_params({"out_width": 768, "out_height": 512, "block": 48})
    w.act_quilt.trigger()
    wait_until(lambda: len(doc.quilting.blocks) >= 60)
    shot(w, "quilting.png")
    wait_until(idle)
    w.quilt_view.select(min(57, len(doc.quilting.blocks) - 1))
    w.message_bar.dismiss()
    shot(w, "quilting_inspect.png")

    # -- Wang tab: edge samples on the source, the 16 tiles with their edge colours and cuts,
    # a random valid layout with the grid
    w.tabs.setCurrentWidget(w.wang_view)
    wv = w.wang_view
    wv.tile_size.setValue(128)
    wv.generate_button.click()
    wait_until(lambda: not w.jobs.busy())
    wv.select_sample("h", 1)
    wv.grid_box.setChecked(True)
    w.message_bar.dismiss()
    w.statusBar().clearMessage()  # the quilting's message is not the Wang tab's
    wv.tiles.fit()
    wv.preview.fit()
    shot(w, "wang.png")
    wv.tiles.set_zoom(2.0)
    wv.tiles.center_on_pixel(128, 128)
    shot(wv.tiles.viewport(), "wang_tiles.png")

    # -- export dialog
    w.tabs.setCurrentWidget(w.source_view)
    w.export_dialog()
    dlg = w._export_dialog
    dlg.folder.setText(os.path.join(tempfile.gettempdir(), "cobblestones_export"))
    shot(dlg, "export.png")
    dlg.close()

    # -- excluded source pixels (painted + a colour range) and the tile found around them
    import numpy as np

    H, W = doc.source.shape
    yy, xx = np.mgrid[0:H, 0:W]
    doc.set_painted((yy - H * 0.45) ** 2 + (xx - W * 0.5) ** 2 < (min(H, W) * 0.22) ** 2)
    src = doc.source.main
    w.source_view.painter.pick_colour(np.unravel_index(np.argmin(src.sum(axis=2)), (H, W)))
    w.act_find.trigger()
    wait_until(idle)
    w.message_bar.dismiss()
    w.source_view.show_patch(None)
    w.source_view.fit()
    w.params_panel.scroll.ensureWidgetVisible(w.params_panel.groups["Exclusion"])
    shot(w, "exclusion.png")
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
