"""The shortest paths of issue 13's acceptance, performed exactly as a person would:

* photo -> square 256 px seamless tile exported: 4 actions
  (drop the photo, choose 256 × 256, Ctrl+Shift+E, Save in the file dialog);
* photo -> tile set of 8 picked tiles exported: 7 actions
  (drop the photo, Ctrl+T, Ctrl+G, click the first tile, Shift+click the eighth, Ctrl+E,
  Enter in the export dialog).
"""

from __future__ import annotations

import json

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication

from engine.io import load_image
from engine.metrics import wrap_border_ratio
from resources import sample_path
from tests.gui.helpers import WAIT_MS, click_candidate, drop, make_window, wait_idle

PHOTO = sample_path("grass")  # a photograph (scikit-image's grass, 512 x 512)


def key(qtbot, w, k, mods=Qt.KeyboardModifier.NoModifier) -> None:
    """A key press as the focused window receives it (shortcuts included)."""
    qtbot.keyClick(QApplication.focusWidget() or w, k, mods)


def test_photo_to_a_256_px_seamless_tile_exported_in_4_actions(qtbot, tmp_path):
    w = make_window(qtbot)
    w.activateWindow()
    target = tmp_path / "grass_tile.png"
    dialogs = []
    w.files.ask_image_path = lambda caption, name: dialogs.append(name) or str(target)
    actions = 0
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        drop(w, PHOTO)  # 1: drop the photo on the window
    actions += 1
    wait_idle(qtbot, w)
    box = w.params_panel.widgets["tile_size"]
    box.setCurrentIndex(box.findText("256 × 256"))  # 2: choose the tile size
    actions += 1
    wait_idle(qtbot, w)
    w.source_view.setFocus()
    key(
        qtbot,
        w,
        Qt.Key.Key_E,
        Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier,
    )
    actions += 2  # 3: Ctrl+Shift+E, 4: Save in the file dialog (accepting its name)
    wait_idle(qtbot, w)
    assert actions == 4 and dialogs == ["grass_tile.png"]
    tile = load_image(target).pixels
    assert tile.shape[:2] == (256, 256)
    assert wrap_border_ratio(tile) < 1.3  # it tiles


def test_photo_to_a_set_of_8_picked_tiles_exported_in_7_actions(qtbot, tmp_path):
    w = make_window(qtbot)
    w.activateWindow()
    actions = 0
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        drop(w, PHOTO)  # 1
    actions += 1
    wait_idle(qtbot, w)
    w.source_view.setFocus()
    key(qtbot, w, Qt.Key.Key_T, Qt.KeyboardModifier.ControlModifier)  # 2: Find best tile
    actions += 1
    wait_idle(qtbot, w)
    key(qtbot, w, Qt.Key.Key_G, Qt.KeyboardModifier.ControlModifier)  # 3: Generate
    actions += 1
    wait_idle(qtbot, w)
    click_candidate(qtbot, w, 0)  # 4
    click_candidate(qtbot, w, 7, Qt.KeyboardModifier.ShiftModifier)  # 5
    actions += 2
    assert w.doc.tileset.picks == list(range(8))
    key(qtbot, w, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)  # 6: Export…
    actions += 1
    dlg = w._export_dialog
    qtbot.waitExposed(dlg)
    out = tmp_path / "grass_set"
    dlg.folder.setText(str(out))  # (the test's folder instead of the default beside the photo)
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        qtbot.keyClick(dlg.folder, Qt.Key.Key_Return)  # 7: Enter exports
    actions += 1
    assert actions == 7 <= 8
    manifest = json.loads(next(out.glob("*.json")).read_text())
    assert len(manifest["tiles"]) == 8
    assert len(list(out.glob("*_0*_albedo.png"))) == 8
