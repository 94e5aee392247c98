"""The Wang tab: generate a set, drag an edge sample (its tiles rebuilt), undo, re-roll,
preview, save and reopen, export."""

from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import QPoint, Qt

from engine.tiles.wang_layout import layout_mismatches
from tests.gui.helpers import WAIT_MS, make_window, open_sample


def wait_wang(qtbot, win, timeout=WAIT_MS):
    qtbot.waitUntil(lambda: not win.jobs.busy(), timeout=timeout)


def generate(qtbot, win, **options):
    win.tabs.setCurrentWidget(win.wang_view)
    view = win.wang_view
    view.tile_size.setValue(options.get("tile_size", 48))
    view.colours.setValue(options.get("colours", 2))
    view.generate_button.click()
    wait_wang(qtbot, win)
    return view


def test_generate_streams_a_complete_set_with_a_valid_preview(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win)
    w = win.doc.wang
    assert w.complete and len(w.tiles) == 16 and len(w.samples) == 4
    assert len(view.samples) == 4  # one diamond per edge sample on the source
    img = view.tiles.array
    assert img.shape[:2] == (4 * 48, 4 * 48)  # the canonical 4x4 arrangement
    sigs = [t.signature for t in w.tile_list()]
    assert w.layout.shape == (8, 8) and layout_mismatches(sigs, w.layout) == 0
    assert view.preview.array.shape[:2] == (8 * 48, 8 * 48)
    old = w.layout.copy()
    view.reroll_layout_button.click()
    assert not np.array_equal(old, w.layout) and layout_mismatches(sigs, w.layout) == 0
    win.doc.undo_stack.undo()
    np.testing.assert_array_equal(w.layout, old)
    view.grid_box.setChecked(True)
    assert len(view._grid_items) == 14


def test_dragging_a_sample_rebuilds_its_tiles_and_undo_restores_it(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win)
    w = win.doc.wang
    before = {k: t.tile.copy() for k, t in w.tiles.items()}
    item = view.samples[("h", 1)]
    old = w.sample("h", 1).origin
    canvas = view.source
    canvas.set_zoom(1.0)
    canvas.centerOn(item.polygon().boundingRect().center())
    a = canvas.mapFromScene(item.polygon().boundingRect().center())
    b = a + QPoint(9, 7)
    qtbot.mousePress(canvas.viewport(), Qt.MouseButton.LeftButton, pos=a)
    for k in range(1, 5):
        qtbot.mouseMove(canvas.viewport(), a + (b - a) * (k / 4))
    qtbot.mouseRelease(canvas.viewport(), Qt.MouseButton.LeftButton, pos=b)
    wait_wang(qtbot, win)
    new = w.sample("h", 1).origin
    assert new != old and w.selected == ("h", 1)
    users = set(w.users("h", 1))
    changed = {k for k, t in w.tiles.items() if not np.array_equal(t.tile, before[k])}
    assert changed == users  # exactly the tiles that show the sample were rebuilt
    y, x = new
    for k in users:  # and they show it: a north edge is the sample's source row
        t = w.tiles[k]
        if t.signature[0] == 1:
            np.testing.assert_array_equal(t.tile[0], win.doc.source.main[y, x : x + 48])
    win.doc.undo_stack.undo()
    wait_wang(qtbot, win)
    assert w.sample("h", 1).origin == old
    for k in users:
        np.testing.assert_array_equal(w.tiles[k].tile, before[k])


def test_reroll_a_sample_save_reopen_and_export(qtbot, tmp_path):
    win = make_window(qtbot)
    open_sample(qtbot, win, "gravel")
    view = generate(qtbot, win)
    w = win.doc.wang
    view.select_sample("v", 0)
    old = w.sample("v", 0).origin
    view.reroll_sample_button.click()
    wait_wang(qtbot, win)
    assert w.sample("v", 0).origin != old and w.complete
    path = tmp_path / "w.quiltproj"
    assert win.files.save_to(str(path), wait=True)
    from engine.project import load_project

    p = load_project(path)
    assert p.wang["colours"] == 2 and len(p.wang_tiles) == 16
    win2 = make_window(qtbot)
    with qtbot.waitSignal(win2.doc.source_changed, timeout=WAIT_MS):
        win2.files.open_path(str(path), confirm=False)
    wait_wang(qtbot, win2)
    w2 = win2.doc.wang
    assert w2.complete and w2.samples == w.samples
    np.testing.assert_array_equal(w2.layout, w.layout)
    for k in w.tiles:  # kept at the source's 8 bits
        np.testing.assert_allclose(w2.tiles[k].tile, w.tiles[k].tile, atol=0.51 / 255)
    win2.tabs.setCurrentWidget(win2.wang_view)
    assert win2.wang_view.tiles.array is not None
    win2.export_dialog()
    dlg = win2._export_dialog
    assert dlg.wang and "Wang" in dlg.windowTitle()
    dlg.folder.setText(str(tmp_path / "bundle"))
    dlg.export()
    qtbot.waitUntil(lambda: dlg.manifest is not None, timeout=WAIT_MS)
    name = dlg.manifest["name"]
    man = json.loads((tmp_path / "bundle" / f"{name}.json").read_text())
    assert man["wang"]["colours"] == 2 and len(man["tiles"]) == 16
    assert "<wangset" in (tmp_path / "bundle" / f"{name}.tsx").read_text()


def test_the_wang_tab_shows_only_the_parameters_the_wang_set_uses(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win)
    win.doc.tileset.set_template_rect((150, 120, 128, 112))
    qtbot.waitUntil(lambda: "seam H" in win.criterion_label.text(), timeout=WAIT_MS)
    groups = win.params_panel.groups
    somol = ("Tile", "Candidates", "Preview", "Heal")  # the Somol set's: no say in a Wang set
    assert all(groups[g].isVisible() for g in somol)  # the tile-set tabs
    win.tabs.setCurrentWidget(win.wang_view)
    assert not any(groups[g].isVisible() for g in somol)
    assert groups["Seams"].isVisible() and groups["Exclusion"].isVisible()  # its cuts use them
    assert win.criterion_label.text() == ""  # the template's seams are not the Wang set's
    win.tabs.setCurrentWidget(win.source_view)
    assert all(groups[g].isVisible() for g in somol)
    assert "seam H" in win.criterion_label.text()


def test_the_banner_does_not_cover_the_wang_layout(qtbot):
    win = make_window(qtbot)
    win.tabs.setCurrentWidget(win.wang_view)
    preview, bar = win.wang_view.preview, win.message_bar
    central = bar.parentWidget()

    def bottom() -> int:  # below the layout canvas's last row, in the banner's parent
        return preview.mapTo(central, QPoint(0, preview.height())).y()

    win.show_message("warning", "Wang set: the texture repeats about every 48 px. " * 6)
    assert bar.isVisible() and bar.label.text().count("48 px") == 6
    top = bar.geometry().top()
    qtbot.waitUntil(lambda: bottom() <= top, timeout=WAIT_MS)
    bar.dismiss()  # gone: the canvases take the room back
    qtbot.waitUntil(lambda: bottom() > top, timeout=WAIT_MS)


def test_a_size_that_breaks_the_period_is_offered_a_whole_one_on_the_banner(qtbot, tmp_path):
    from PIL import Image

    from benchmarks.evalset import planks

    path = tmp_path / "planks.png"
    Image.fromarray(planks(256)).save(path)  # boards every 48 px
    win = make_window(qtbot)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(path), confirm=False)
    view = generate(qtbot, win, tile_size=64)  # 1.33 boards per tile
    bar = win.message_bar
    assert bar.level == "warning" and "48 px (Tile size)" in bar.label.text()
    assert "--tile-size" not in bar.label.text()  # the editor's words
    buttons = [bar._actions.itemAt(i).widget() for i in range(bar._actions.count())]
    assert [b.text() for b in buttons] == ["Use 48 px tiles"]
    before = len(win.messages)
    buttons[0].click()
    wait_wang(qtbot, win)
    assert win.doc.wang.complete and win.doc.wang.options["tile_size"] == 48
    assert view.tile_size.value() == 48 and view.tiles.array.shape[:2] == (4 * 48, 4 * 48)
    assert not any("whole periods" in text for _, text in win.messages[before:])


def test_only_the_note_the_engine_names_carries_the_use_size_button(qtbot):
    from types import SimpleNamespace

    win = make_window(qtbot)
    runner, messages, advice = win.wang_runner, [], []
    runner.message.connect(lambda level, text: messages.append(text))
    runner.advice.connect(lambda level, text, actions: advice.append((text, actions)))
    other = "the texture repeats about every 148 px tall: a note that names 148 px"
    named = "the texture repeats about every 32 px wide: 48 px (Tile size)"
    result = SimpleNamespace(
        notes=(other, named), parameters={}, suggested_size=48, suggested_note=named
    )
    runner._on_done(result)
    assert [text for text, _ in advice] == [f"Wang set: {named}"]  # once, "148 px" not taken
    assert [label for label, _ in advice[0][1]] == ["Use 48 px tiles"]
    assert messages == [f"Wang set: {other}"]


def test_tiles_smaller_than_the_structures_are_offered_a_larger_size_on_the_banner(qtbot, tmp_path):
    from PIL import Image

    from tests.engine.helpers import blob_texture

    path = tmp_path / "stones.png"
    Image.fromarray(np.round(blob_texture() * 255).astype(np.uint8)).save(path)  # ~64 px blobs
    win = make_window(qtbot)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(path), confirm=False)
    generate(qtbot, win, tile_size=32)
    text = win.message_bar.label.text()
    assert win.message_bar.level == "warning" and "too large for 32 px Wang tiles" in text
    assert "--tile-size" not in text and "a photo scaled down" in text
    bar = win.message_bar
    buttons = [bar._actions.itemAt(i).widget() for i in range(bar._actions.count())]
    [label] = [b.text() for b in buttons]
    size = int(label.split()[1])
    assert label == f"Use {size} px tiles" and f"at least {size} px (Tile size)" in text
    assert win.doc.wang.complete  # a warning only: the set is made
