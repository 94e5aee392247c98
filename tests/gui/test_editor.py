"""Editor interactions: canvas, template step, waypoints, supersede, bad input, close, recovery."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image
from PySide6.QtCore import QPoint, QPointF, Qt
from PySide6.QtGui import QWheelEvent
from PySide6.QtWidgets import QPushButton

from quilt_gui import settings
from quilt_gui.imaging import to_uint8
from quilt_gui.widgets.canvas import ImageCanvas
from quilt_gui.widgets.gallery import CandidateModel
from tests.gui.helpers import WAIT_MS, drop, make_window, open_sample, template, wait_idle


@pytest.fixture
def win(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    return w


# ---------------------------------------------------------------------- canvas
def wheel(canvas: ImageCanvas, pos: QPointF, delta: int) -> None:
    ev = QWheelEvent(
        pos,
        canvas.viewport().mapToGlobal(pos.toPoint()).toPointF(),
        QPoint(0, 0),
        QPoint(0, delta),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    canvas.wheelEvent(ev)


def test_wheel_zoom_keeps_the_pixel_under_the_cursor(qtbot):
    c = ImageCanvas()
    qtbot.addWidget(c)
    c.resize(400, 300)
    c.show()
    qtbot.waitExposed(c)
    c.set_image(np.random.default_rng(0).random((64, 80, 3)).astype(np.float32), fit=True)
    pos = QPointF(230, 140)
    before = c.mapToScene(pos.toPoint())
    for _ in range(3):
        wheel(c, pos, 120)
    after = c.mapToScene(pos.toPoint())
    assert c.zoom > 4
    assert abs(before.x() - after.x()) < 1 / c.zoom + 0.3 and abs(before.y() - after.y()) < 0.5
    # nearest neighbour above 100 %, smooth below
    assert c.image_item.transformationMode() == Qt.TransformationMode.FastTransformation
    c.set_zoom(0.5)
    assert c.image_item.transformationMode() == Qt.TransformationMode.SmoothTransformation
    c.actual_size()
    assert c.zoom == 1.0
    c.fit()
    r = c.mapFromScene(c.image_rect()).boundingRect()
    assert c.viewport().rect().contains(r)


def test_a_view_fitted_while_hidden_fits_when_shown_and_on_resize(qtbot):
    from PySide6.QtWidgets import QTabWidget

    tabs = QTabWidget()
    qtbot.addWidget(tabs)
    first, hidden = ImageCanvas(), ImageCanvas()
    tabs.addTab(first, "a")
    tabs.addTab(hidden, "b")
    tabs.resize(500, 400)
    tabs.show()
    qtbot.waitExposed(tabs)
    hidden.set_image(np.zeros((300, 200, 3), np.float32), fit=True)
    tabs.setCurrentWidget(hidden)

    def whole_image_visible() -> bool:
        r = hidden.mapFromScene(hidden.image_rect()).boundingRect()
        return hidden.viewport().rect().contains(r)

    qtbot.waitUntil(whole_image_visible, timeout=WAIT_MS)
    tabs.resize(500, 250)  # smaller: still fitted
    qtbot.waitUntil(whole_image_visible, timeout=WAIT_MS)
    hidden.set_zoom(2.0)  # the user's zoom sticks
    tabs.resize(520, 300)
    qtbot.wait(50)
    assert hidden.zoom == 2.0


def test_zoom_shortcuts_and_pixel_readout(qtbot, win):
    win.source_view.setFocus()
    win.act_100.trigger()
    assert win.source_view.zoom == 1.0
    win.act_zoom_in.trigger()
    assert win.source_view.zoom == 2.0
    pos = win.source_view.view_pos_of_pixel(10, 20)  # exact at an integer zoom
    assert win.source_view.pixel_at(QPointF(pos)) == (10, 20)
    win.act_fit.trigger()
    assert win.source_view.zoom < 2.0
    win._on_hover(win.source_view, (10, 20))
    v = (win.doc.source.main[10, 20] * 255).round().astype(int)
    assert win.pixel_label.text() == f"x 20, y 10 = ({v[0]}, {v[1]}, {v[2]})"


# ---------------------------------------------------------------------- template step
def test_drag_rectangle_is_one_undo_step_and_nudge(qtbot, win):
    template(qtbot, win)
    v = win.source_view
    v.set_zoom(1.0)
    v.center_on_pixel(176, 214)
    x, y, w, h = win.doc.tileset.template_rect
    start = v.view_pos_of_pixel(y + h // 2, x + w // 2).toPoint()
    n0 = win.doc.undo_stack.count()
    qtbot.mousePress(v.viewport(), Qt.MouseButton.LeftButton, pos=start)
    for k in range(1, 11):
        qtbot.mouseMove(v.viewport(), start + QPoint(2 * k, k))
    qtbot.mouseRelease(v.viewport(), Qt.MouseButton.LeftButton, pos=start + QPoint(20, 10))
    assert win.doc.tileset.template_rect == (x + 20, y + 10, w, h)
    assert win.doc.undo_stack.count() == n0 + 1
    # arrow keys nudge by 1 px, Shift by 10
    v.setFocus()
    qtbot.keyClick(v, Qt.Key.Key_Left)
    qtbot.keyClick(v, Qt.Key.Key_Down, Qt.KeyboardModifier.ShiftModifier)
    assert win.doc.tileset.template_rect == (x + 19, y + 20, w, h)
    win.doc.undo_stack.undo()
    win.doc.undo_stack.undo()
    win.doc.undo_stack.undo()
    assert win.doc.tileset.template_rect == (x, y, w, h)
    wait_idle(qtbot, win)
    assert win.doc.tileset.seamless.rect == (x, y, w, h)  # the seams follow the rectangle


def test_resize_handle(qtbot, win):
    template(qtbot, win)
    v = win.source_view
    v.set_zoom(1.0)
    x, y, w, h = win.doc.tileset.template_rect
    v.center_on_pixel(y + h, x + w)
    corner = v.mapFromScene(QPointF(x + w, y + h))
    qtbot.mousePress(v.viewport(), Qt.MouseButton.LeftButton, pos=corner)
    qtbot.mouseMove(v.viewport(), corner + QPoint(-16, -8))
    qtbot.mouseRelease(v.viewport(), Qt.MouseButton.LeftButton, pos=corner + QPoint(-16, -8))
    assert win.doc.tileset.template_rect == (x, y, w - 16, h - 8)


def test_slider_drag_in_parameters_panel_is_one_step(qtbot, win):
    template(qtbot, win)
    slider = win.params_panel.widgets["rho"]
    n0 = win.doc.undo_stack.count()
    slider.sliderPressed.emit()
    for v in (4, 5, 6, 7):
        slider.setValue(v)
    slider.sliderReleased.emit()
    assert win.doc.params["rho"] == 7 and win.doc.undo_stack.count() == n0 + 1
    win.doc.undo_stack.undo()
    assert win.params_panel.value("rho") == 3 == win.doc.params["rho"]


def test_waypoint_click_in_overlap_panel_steers_the_seam(qtbot, win):
    template(qtbot, win)
    view = win.overlap_panel.views["horizontal"]
    h, w = view.frame_shape
    path = {tuple(p) for p in win.doc.tileset.seamless.paths["horizontal"].tolist()}
    row = h // 2
    col = next(c for c in range(2, w - 2) if (row, c) not in path)
    ox, oy = view.offsets[2]  # the error-map panel
    view.set_zoom(2.0)  # an integer zoom: the click lands on exactly this pixel
    view.centerOn(QPointF(ox + col + 0.5, oy + row + 0.5))
    pos = view.mapFromScene(QPointF(ox + col + 0.5, oy + row + 0.5))
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert win.doc.tileset.waypoints["horizontal"] == [(row, col)]
    wait_idle(qtbot, win)
    assert (row, col) in {tuple(p) for p in win.doc.tileset.seamless.paths["horizontal"].tolist()}
    x, y = win.doc.tileset.template_rect[:2]
    src = {tuple(p) for p in win.source_view.seams["horizontal"].points.tolist()}
    assert (y + row, x + col) in src  # drawn on the source too, at the same pixel
    qtbot.mouseClick(view.viewport(), Qt.MouseButton.RightButton, pos=pos)
    assert win.doc.tileset.waypoints["horizontal"] == []


def test_live_seams_of_a_new_rectangle_are_drawn_on_both_its_overlaps(qtbot, win):
    """Before a new rectangle's result exists, each live update draws that rectangle's own
    overlap: the left/right one and the top/bottom one (cut from the left/right stitch),
    from the regions and error map the engine sends with the updates."""
    from quilt_gui.imaging import heat_rgba

    template(qtbot, win, (150, 120, 128, 112))
    panel, ov = win.overlap_panel, win.doc.tileset.overlap()
    old = win.doc.tileset.seamless
    new = (60, 40, 100, 90)
    seen = []

    def record(update):  # runs after the panel's own slot (connected later)
        view = panel.views[update.which]
        seen.append(
            (
                update.which,
                win.doc.tileset.seamless is old,
                view.frame_shape,
                panel.frames[update.which],
                view.array.copy(),
                update,
            )
        )

    win.pipeline.seam_updated.connect(record)
    win.doc.set_param("method", "oscillating")  # streams improvements on both overlaps
    wait_idle(qtbot, win)
    old = win.doc.tileset.seamless
    seen.clear()
    win.doc.tileset.apply_template_rect(new)
    wait_idle(qtbot, win)
    assert win.doc.tileset.seamless is not old and tuple(win.doc.tileset.seamless.rect) == new
    live = [s for s in seen if s[1]]  # delivered while the old result was still shown
    assert {s[0] for s in live} == {"horizontal", "vertical"}, [s[0] for s in seen]
    shapes = {"horizontal": (90 + ov, ov), "vertical": (ov, 100)}
    for which, _, shape, frame, image, update in live:
        assert shape == shapes[which] and frame == (new, ov)
        keys = ("R_R", "R_L") if which == "horizontal" else ("R_B", "R_T")
        h, w = shape
        panels = [to_uint8(update.regions[k])[..., :3] for k in keys]
        panels.append(heat_rgba(update.error)[..., :3])
        for (ox, oy), expected in zip(panel.views[which].offsets, panels, strict=True):
            np.testing.assert_array_equal(image[oy : oy + h, ox : ox + w, :3], expected)
    x, y = new[:2]
    h_update = next(s[5] for s in live if s[0] == "horizontal")
    np.testing.assert_array_equal(  # R_R is the source strip right of the new rectangle
        h_update.regions["R_R"], win.doc.source.main[y : y + 90 + ov, x + 100 : x + 100 + ov]
    )
    assert panel.views["vertical"].paths[0].isVisible()


def test_changing_a_parameter_supersedes_and_no_stale_result_is_drawn(qtbot, win):
    template(qtbot, win, (60, 60, 300, 300))
    applied, live = [], []
    win.doc.tileset.seamless_changed.connect(
        lambda: applied.append(
            (
                win.doc.tileset.seamless and win.doc.tileset.seamless.seam.method,
                win.doc.params["method"],
            )
        )
    )
    win.pipeline.seam_updated.connect(
        lambda u: live.append((u.seam.method, win.doc.params["method"]))
    )
    superseded = []
    for method in ("oscillating", "dp", "oscillating-optimal", "oscillating"):
        with qtbot.waitSignal(
            win.jobs.started, timeout=WAIT_MS, check_params_cb=lambda j: j.key == "seamless"
        ) as sig:
            win.doc.set_param("method", method)
        old = sig.args[0]
        win.doc.set_param("rho", win.doc.params["rho"] + 1)  # a change while it runs
        assert not old.alive  # superseded at once
        superseded.append(old)
    win.doc.set_param("method", "dp")
    win.doc.set_param("rho", 5)
    wait_idle(qtbot, win)
    qtbot.waitUntil(lambda: all(j.state == "aborted" for j in superseded), timeout=WAIT_MS)
    assert applied and all(m is None or m == cur for m, cur in applied)
    assert all(m == cur for m, cur in live)
    assert win.doc.tileset.seamless.seam.method == "dp" and win.doc.tileset.seamless.seam.rho == 5


# ---------------------------------------------------------------------- gallery model
def test_candidate_model_passes_qtmodeltester(qtbot, qtmodeltester, win):
    template(qtbot, win)
    model = CandidateModel(win.doc)
    qtmodeltester.check(model)
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    qtmodeltester.check(model)
    assert model.rowCount() == 30
    win.doc.tileset.toggle_pick(3)
    win.doc.tileset.set_locked(3, True)
    win.doc.undo_stack.undo()
    qtmodeltester.check(model)


def test_lock_reroll_and_patch_drag(qtbot, win):
    template(qtbot, win)
    win.doc.set_param("n_candidates", 6)
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    before = [e.tile for e in win.doc.tileset.candidates]
    win.doc.tileset.set_locked(1, True)
    win.reroll_candidate(2)
    wait_idle(qtbot, win)
    assert not np.array_equal(win.doc.tileset.candidates[2].tile, before[2])
    assert win.doc.undo_stack.undoText() == "Re-roll candidate #3"
    # dragging the patch source rectangle rebuilds that candidate from the new place
    win.gallery.setCurrentIndex(win.gallery.model().index(4))
    item = win.source_view.patch_item
    assert item.isVisible() and item.rect == win.doc.tileset.candidates[4].patch_rect
    px, py, pw, ph = item.rect
    H, W = win.doc.source.shape
    new = (min(px + 15, W - pw), min(py + 9, H - ph))
    item.set_rect((new[0], new[1], pw, ph))
    item.drag_finished.emit()
    wait_idle(qtbot, win)
    assert win.doc.tileset.candidates[4].patch_origin == (new[1], new[0])
    # generating again keeps the locked candidate (and its pick)
    win.doc.tileset.toggle_pick(1)
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    assert len(win.doc.tileset.candidates) == 6 and np.array_equal(
        win.doc.tileset.candidates[0].tile, before[1]
    )
    assert win.doc.tileset.picks == [0]
    dlg = win.open_candidate(0)
    assert dlg.isVisible() and dlg.lock_button.text() == "Unlock"
    assert dlg.loop_item.isVisible()
    dlg.close()


# ---------------------------------------------------------------------- bad input
def test_corrupt_file_dropped_shows_message_and_keeps_editor_usable(qtbot, win, tmp_path):
    bad = tmp_path / "broken.png"
    bad.write_bytes(b"\x89PNG\r\n\x1a\n" + b"garbage" * 50)
    source = win.doc.source
    drop(win, bad)
    qtbot.waitUntil(lambda: win.last_message("error") != "", timeout=WAIT_MS)
    text = win.last_message("error")
    assert "broken.png" in text and ("corrupt" in text or "not an image" in text)
    assert win.message_bar.isVisible() and win.message_bar.level == "error"
    assert win.doc.source is source  # nothing lost
    win.act_find.trigger()  # still usable
    wait_idle(qtbot, win)
    assert win.doc.tileset.seamless is not None


def test_drop_opens_an_image_and_remembers_it(qtbot, win, tmp_path):
    good = tmp_path / "small texture.png"
    pixels = np.random.default_rng(1).integers(0, 256, (90, 120, 3), dtype=np.uint8)
    Image.fromarray(pixels).save(good)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        drop(win, good)
    assert win.doc.source.shape == (90, 120) and win.doc.name == "small_texture"
    assert settings.get("recent_files")[0] == str(good.resolve())
    win._fill_recent_menu()
    assert "small texture.png" in win.recent_menu.actions()[0].text()


@pytest.mark.parametrize(
    ("mode", "shown"),
    [
        ("L", "8-bit gray"),
        ("P", "8-bit palette"),
        ("RGBA", "8-bit RGB + alpha"),
        ("I;16", "16-bit gray"),
    ],
)
def test_opened_message_names_the_colour_model_in_words(qtbot, win, tmp_path, mode, shown):
    path = tmp_path / "t.png"
    rgb = np.random.default_rng(2).integers(0, 256, (40, 50, 3), dtype=np.uint8)
    im = Image.fromarray(rgb)
    if mode == "I;16":
        im = Image.fromarray(rgb[:, :, 0].astype(np.uint16) * 257)
    else:
        im = im.convert(mode)
    im.save(path)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(path), confirm=False)
    assert f"50×40, {shown}." in win.last_message()


def test_files_dropped_on_any_image_view_reach_the_window(win):
    # Qt delivers a drag to the innermost widget that accepts drops; a QGraphicsView does
    # by default and ignores files, so a drop on the source image did nothing
    assert win.acceptDrops()
    for canvas in win.canvases():
        assert not canvas.acceptDrops() and not canvas.viewport().acceptDrops(), canvas


def test_image_too_small_for_the_tile(qtbot, win, tmp_path):
    tiny = tmp_path / "tiny.png"
    Image.fromarray(np.zeros((24, 24, 3), np.uint8) + 100).save(tiny)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(tiny), confirm=False)
    win.doc.set_params({"tile_size": "any", "tile_min": 64, "tile_max": 64})
    win.act_find.trigger()
    wait_idle(qtbot, win)
    error = win.last_message("error")
    assert "smaller than the minimum tile" in error and "tile_min" not in error
    assert win.doc.tileset.template_rect is None
    win.doc.set_params({"tile_min": 0, "tile_max": 0})  # automatic: scaled to the image
    win.act_find.trigger()
    wait_idle(qtbot, win)
    assert win.doc.tileset.template_rect is not None and win.doc.tileset.seamless is not None
    win.doc.set_param("overlap", 8)
    win.doc.tileset.set_template_rect((0, 0, 10, 10))  # a hand-drawn rectangle too small for w_T
    wait_idle(qtbot, win)
    assert "at least 2*overlap" in win.last_message("error") and win.doc.tileset.seamless is None
    win.doc.set_param("overlap", 4)  # fixing the parameter recovers
    wait_idle(qtbot, win)
    assert win.doc.tileset.seamless is not None


def test_unwritable_folder_for_export_and_save(qtbot, win, tmp_path):
    template(qtbot, win)
    win.doc.set_param("n_candidates", 3)
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    win.export_dialog()
    dlg = win._export_dialog
    dlg.folder.setText("/sys/fs/quilt_bundle")
    dlg.export()
    wait_idle(qtbot, win)
    assert "Export failed" in dlg.status.text() and "/sys/fs/quilt_bundle" in dlg.status.text()
    assert "Export failed" in win.last_message("error")
    win.files.save_to("/sys/fs/quilt_session.quiltproj")
    wait_idle(qtbot, win)
    assert "The project was not saved" in win.last_message("error")
    assert win.doc.modified  # still unsaved, nothing lost
    dlg.folder.setText(str(tmp_path / "ok"))
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        dlg.export()
    # again into the same folder: the dialog names its own check box, not an API keyword
    assert dlg.export() is None
    assert "not empty: tick “Overwrite an existing bundle”" in dlg.status.text()
    a_file = tmp_path / "ok" / next(p.name for p in (tmp_path / "ok").iterdir())
    dlg.folder.setText(str(a_file / "sub"))
    assert dlg.export() is None and "is a file, not a folder" in dlg.status.text()
    dlg.overwrite.setChecked(True)
    dlg.folder.setText(str(tmp_path / "ok"))
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        dlg.export()


# ---------------------------------------------------------------------- closing and recovery
def test_close_while_jobs_run_does_not_hang(qtbot, win):
    template(qtbot, win)
    win.doc.set_param("n_candidates", 500)
    win.act_generate.trigger()
    win.doc.set_param("method", "oscillating")
    qtbot.waitUntil(lambda: len(win.doc.tileset.candidates) > 0, timeout=WAIT_MS)
    assert win.jobs.running()
    assert win.close()  # returns once every job stopped (500 candidates would take minutes)
    assert not win.isVisible()


def test_unsaved_changes_prompt_on_close(qtbot, win, tmp_path):
    win.doc.set_param("overlap", 12)
    assert win.doc.modified and win.isWindowModified()
    win.files.ask_save_changes = lambda: "cancel"
    assert not win.close() and win.isVisible()
    target = tmp_path / "kept.quiltproj"
    win.files.ask_save_changes = lambda: "save"
    win.files.ask_save_path = lambda: str(target)
    assert win.close()
    assert target.is_file()


def test_autosave_and_recovery_after_a_crash(qtbot, win):
    template(qtbot, win)
    win.doc.set_param("n_candidates", 4)
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    win.doc.tileset.toggle_pick(1)
    job = win.files.autosave_now()
    wait_idle(qtbot, win)
    assert job.state == "done" and win.files.recovery_file().is_file()
    # "crash": the first window never closes; a new session starts
    w2 = make_window(qtbot)
    open_sample(qtbot, w2)
    assert "did not close normally" in w2.message_bar.label.text()
    restore = next(b for b in w2.message_bar.findChildren(QPushButton) if b.text() == "Restore")
    restore.click()
    wait_idle(qtbot, w2)
    assert (
        w2.doc.tileset.template_rect == win.doc.tileset.template_rect
        and w2.doc.tileset.picks == [1]
    )
    assert len(w2.doc.tileset.candidates) == 4 and w2.doc.modified
    win.doc.mark_saved()


def test_light_theme_on_request(qtbot, win):
    from PySide6.QtWidgets import QApplication

    label = win.params_panel.widgets["rho"]._label  # a style-sheeted superqt label

    def text_lightness() -> int:
        return label.palette().color(label.foregroundRole()).lightness()

    win.set_theme("light")
    assert QApplication.palette().window().color().lightness() > 128
    assert text_lightness() < 128  # dark numbers on the light background
    win.set_theme("dark")
    assert QApplication.palette().window().color().lightness() < 128
    assert text_lightness() > 128
    assert settings.get("theme") == "dark"


def test_preview_grid_toggles_with_g_and_stays_in_step(qtbot, win):
    assert win.act_preview_grid.shortcut().toString() == "G"
    box = win.preview_view.grid_box
    assert not box.isChecked()
    win.act_preview_grid.trigger()  # what the G key does
    assert box.isChecked() and win.preview_view.grid and settings.get("preview_grid")
    box.setChecked(False)
    assert not win.act_preview_grid.isChecked()


def test_window_fits_a_1280_px_screen_whatever_the_labels_say(qtbot, win):
    from tests.gui.helpers import generate

    generate(qtbot, win, 4)
    win.doc.tileset.set_picks([0, 1, 2])
    wait_idle(qtbot, win)
    win.show_message("info", "A long message. " * 30)  # a long banner
    for tab in (win.source_view, win.preview_view, win.quilt_view):
        win.tabs.setCurrentWidget(tab)
        assert win.minimumSizeHint().width() <= 1100, tab


def test_only_the_options_of_the_seam_method_in_use_are_editable(qtbot, win):
    wid = win.params_panel.widgets
    assert not wid["o_max"].isEnabled() and not wid["max_run"].isEnabled()  # dp
    win.doc.set_param("method", "oscillating")
    assert wid["o_max"].isEnabled() and wid["osc_init"].isEnabled()
    assert not wid["max_run"].isEnabled() and not wid["levels"].isEnabled()
    win.doc.set_param("q_method", "resistance")
    win.tabs.setCurrentWidget(win.quilt_view)  # quilting: its own seam method counts
    assert wid["max_run"].isEnabled() and not wid["o_max"].isEnabled()
    win.tabs.setCurrentWidget(win.source_view)
    assert wid["o_max"].isEnabled()
    assert wid["rho"].isEnabled() and not wid["width"].isEnabled()  # adaptive blending
    win.doc.set_param("blend", "feather")
    assert wid["width"].isEnabled() and not wid["rho"].isEnabled()
    assert "only for adaptive blending" in wid["rho"].toolTip()


def test_open_dialog_lists_images_and_projects_together(win, monkeypatch):
    asked = []
    monkeypatch.setattr(
        win.files, "ask_open_path", lambda caption, filters, key: asked.append(filters)
    )
    win.files.open_dialog()
    first = asked[0].split(";;")[0]
    assert "*.png" in first and "*.quiltproj" in first
