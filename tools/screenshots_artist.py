"""Screenshots of issue 13's artist-facing screens, at the screen size Xvfb gives:

    xvfb-run -s "-screen 0 1600x1000x24" python tools/screenshots_artist.py
    xvfb-run -s "-screen 0 1366x768x24" python tools/screenshots_artist.py

The window is placed as the editor places it on that screen (it must fit). Writes, with a
``_1366`` suffix on the small screen, into docs/: tile_size.png (the Tile size control, 256 ×
256 chosen), basic_panel.png (the parameter panel's Basic view), heal_before.png /
heal_after.png (a painted region over a logo, then healed), wrap_around.png (the seamless tile
repeated at 100 % with its borders) and save_output.png (the quilting output's context menu
with Save output…; a grab of the whole screen, so the menu shows).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def logo_photo(folder: Path) -> Path:
    """The grass sample with a logo drawn on it: the thing an artist heals away."""
    from PIL import Image, ImageDraw, ImageFont

    from resources import sample_path

    img = Image.open(sample_path("grass")).convert("RGB")
    draw = ImageDraw.Draw(img)
    draw.rounded_rectangle((180, 200, 330, 260), radius=12, fill=(235, 235, 240))
    try:
        font = ImageFont.load_default(size=40)
    except TypeError:  # Pillow < 10.1
        font = ImageFont.load_default()
    draw.text((196, 208), "LOGO", fill=(200, 30, 40), font=font)
    path = folder / "grass_logo.png"
    img.save(path)
    return path


def main() -> int:
    from PySide6.QtCore import QPoint, QSettings
    from PySide6.QtGui import QGuiApplication

    from quilt_gui.app import make_app

    app = make_app(theme="dark")
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    tmp = Path(tempfile.mkdtemp(prefix="quilt_shots_"))
    QSettings.setPath(QSettings.Format.IniFormat, QSettings.Scope.UserScope, str(tmp))
    from quilt_gui.main_window import MainWindow
    from quilt_gui.responsiveness import wait_until
    from tools.screenshots import save_png

    screen = QGuiApplication.primaryScreen().geometry()
    suffix = "" if screen.width() >= 1600 else f"_{screen.width()}"
    out = ROOT / "docs"
    w = MainWindow()
    w.files.ask_save_changes = lambda: "discard"
    w.files.ask_discard_output = lambda: True  # a new quilt replaces the last
    w.show()  # placed by quilt_gui.window_geometry for this screen
    photo = logo_photo(tmp)
    w.files.open_path(str(photo), confirm=False)
    idle = lambda: w.doc.has_source and not w.pipeline.busy() and not w.jobs.busy()  # noqa: E731
    wait_until(idle)
    doc = w.doc
    frame = w.frameGeometry()
    print(f"screen {screen.width()}x{screen.height()}, window {frame.width()}x{frame.height()}")

    def shot(widget, name: str) -> None:
        for _ in range(5):
            app.processEvents()
        path = out / name.replace(".png", f"{suffix}.png")
        save_png(widget.grab(), path)
        print("wrote", path)

    def screen_shot(name: str) -> None:
        for _ in range(5):
            app.processEvents()
        path = out / name.replace(".png", f"{suffix}.png")
        save_png(QGuiApplication.primaryScreen().grabWindow(0), path)
        print("wrote", path)

    # -- Heal: the painted region over the logo, then healed
    import numpy as np

    H, W = doc.source.shape
    mask = np.zeros((H, W), bool)
    mask[194:267, 174:337] = True
    doc.set_heal_mask(mask)
    w.act_heal_brush.setChecked(True)
    w.source_view.fit()
    w.message_bar.dismiss()
    shot(w, "heal_before.png")
    w.act_heal.trigger()
    wait_until(idle)
    w.act_heal_brush.setChecked(False)
    w.message_bar.dismiss()
    shot(w, "heal_after.png")

    # -- the tile size control: 256 x 256 chosen, the tile found and made seamless
    w.params_panel.set_view("Basic")
    box = w.params_panel.widgets["tile_size"]
    box.setCurrentIndex(box.findText("256 × 256"))
    wait_until(idle)
    w.message_bar.dismiss()
    shot(w, "tile_size.png")
    shot(w.params_panel, "basic_panel.png")

    # -- the wrap-around view of the seamless tile at 100 %, borders on
    w.tabs.setCurrentWidget(w.wrap_view)
    w.wrap_view.borders.setChecked(True)
    w.act_100.trigger()
    c = w.wrap_view.canvas
    c.horizontalScrollBar().setValue(c.horizontalScrollBar().value() + 128)
    c.verticalScrollBar().setValue(c.verticalScrollBar().value() + 128)
    w.message_bar.dismiss()
    shot(w, "wrap_around.png")

    # -- quilting: the finished output and its context menu with Save output…
    w.tabs.setCurrentWidget(w.quilt_view)
    w.act_quilt.trigger()
    wait_until(idle)
    w.message_bar.dismiss()
    view = w.quilt_view.output
    from PySide6.QtWidgets import QMenu

    menu = QMenu(view)
    menu.addActions(view.actions())
    menu.popup(view.mapToGlobal(QPoint(view.width() // 3, view.height() // 3)))
    menu.setActiveAction(w.act_save_output)
    screen_shot("save_output.png")
    menu.close()
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
