"""Excluded source pixels in the tile-set workflow (issue 3 item 4), the seam-kernel warm-up
at start-up and the seamless tile's 1x1 / 3x3 / 5x5 keys."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from PySide6.QtCore import QPointF, Qt

from quilt_gui import main_window
from quilt_gui.job_bodies import excluded_mask
from tests.gui.helpers import WAIT_MS, drag, make_window, open_sample, template, wait_idle


@pytest.fixture
def win(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    return w


def footprint(rect, overlap):
    x, y, w, h = rect
    return slice(y, y + h + overlap), slice(x, x + w + overlap)


def test_the_status_bar_follows_the_brush_and_keeps_no_stale_pixel(qtbot, win):
    v = win.source_view
    v.set_zoom(1.0)
    v.center_on_pixel(256, 256)
    a = v.view_pos_of_pixel(220, 200).toPoint()
    b = v.view_pos_of_pixel(240, 300).toPoint()
    (ra, ca), (rb, cb) = v.pixel_at(QPointF(a)), v.pixel_at(QPointF(b))
    qtbot.mouseMove(v.viewport(), a)
    assert win.pixel_label.text().startswith(f"x {ca}, y {ra} =")
    drag(qtbot, v, a, b, modifier=Qt.KeyboardModifier.ShiftModifier)
    assert win.doc.exclude_painted[rb, cb]
    assert win.pixel_label.text().startswith(f"x {cb}, y {rb} =")  # where the brush is, not was


def test_shift_drag_on_the_source_paints_one_undoable_exclusion(qtbot, win):
    v = win.source_view
    assert win.params_panel.groups["Exclusion"].isVisible()  # shown in the tile-set mode
    v.set_zoom(1.0)
    v.center_on_pixel(256, 256)
    win.doc.set_param("brush", 5)
    n0 = win.doc.undo_stack.count()
    a = v.view_pos_of_pixel(220, 200).toPoint()
    b = v.view_pos_of_pixel(240, 300).toPoint()
    shift = Qt.KeyboardModifier.ShiftModifier
    drag(qtbot, v, a, b, modifier=shift)
    mask = win.doc.exclude_painted
    assert win.doc.undo_stack.count() == n0 + 1
    assert mask[220, 200] and mask[240, 300] and mask[230, 250] and not mask[100, 100]
    assert v.painter.overlay.isVisible() and win.quilt_view.excluded.isVisible()  # one mask
    assert win.doc.tileset.template_rect is None  # painting did not draw a rectangle
    # Shift+right-drag erases; Ctrl+Shift+click excludes the colour under the cursor
    qtbot.mousePress(v.viewport(), Qt.MouseButton.RightButton, shift, a)
    qtbot.mouseRelease(v.viewport(), Qt.MouseButton.RightButton, shift, a)
    assert not win.doc.exclude_painted[220, 200] and win.doc.exclude_painted[240, 300]
    ctrl_shift = Qt.KeyboardModifier.ControlModifier | shift
    qtbot.mouseClick(v.viewport(), Qt.MouseButton.LeftButton, ctrl_shift, b)
    px = win.doc.source.main[v.pixel_at(QPointF(b))]
    assert win.doc.params["exclude_color"] == "#" + "".join(
        f"{round(float(c) * 255):02x}" for c in px[:3]
    )
    assert win.doc.params["exclude_tolerance"] > 0
    win.doc.undo_stack.undo()
    win.doc.undo_stack.undo()
    win.doc.undo_stack.undo()
    assert win.doc.exclude_painted is None and not v.painter.overlay.isVisible()


def test_template_search_and_candidates_avoid_the_excluded_pixels(qtbot, win):
    doc = win.doc
    doc.set_params({"tile_size": "any", "tile_min": 96, "tile_max": 128, "n_candidates": 6})
    win.act_find.trigger()
    wait_idle(qtbot, win)
    first = doc.tileset.template_rect
    ov = doc.tileset.overlap()
    painted = np.zeros(doc.source.shape, bool)
    painted[footprint(first, ov)] = True  # exactly where the best tile was
    doc.set_painted(painted)
    win.act_find.trigger()
    wait_idle(qtbot, win)
    assert doc.tileset.template_rect != first
    assert not painted[footprint(doc.tileset.template_rect, ov)].any()
    # a colour range too: the candidates' patches avoid both
    src = doc.source.main
    row, col = np.unravel_index(np.argmin(src.sum(axis=2)), src.shape[:2])
    win.source_view.painter.pick_colour((int(row), int(col)))
    mask = excluded_mask(src, doc.params["exclude_color"], doc.params["exclude_tolerance"], painted)
    assert mask.sum() > painted.sum()
    win.act_generate.trigger()
    wait_idle(qtbot, win)
    assert len(doc.tileset.candidates) == 6
    for e in doc.tileset.candidates:
        x, y, w, h = e.patch_rect
        assert not mask[y : y + h, x : x + w].any(), e.patch_rect
    win.reroll_candidate(2)
    wait_idle(qtbot, win)
    x, y, w, h = doc.tileset.candidates[2].patch_rect
    assert not mask[y : y + h, x : x + w].any()
    # dragging a patch onto the excluded region is refused with a message, not a crash
    win.pipeline.remake_candidate(0, origin=(first[1], first[0]))
    wait_idle(qtbot, win)
    assert "excluded" in win.last_message("error")


def test_painted_exclusion_is_saved_in_the_project(qtbot, win, tmp_path):
    painted = np.zeros(win.doc.source.shape, bool)
    painted[10:40, 300:333] = True
    painted[500, 7] = True
    win.doc.set_painted(painted)
    template(qtbot, win)
    path = str(tmp_path / "p.quiltproj")
    assert win.files.save_to(path, wait=True)
    w2 = make_window(qtbot)
    with qtbot.waitSignal(w2.doc.exclusion_changed, timeout=WAIT_MS):
        w2.files.open_path(path, confirm=False)
    wait_idle(qtbot, w2)
    np.testing.assert_array_equal(w2.doc.exclude_painted, painted)
    assert w2.source_view.painter.overlay.isVisible()
    assert not w2.doc.modified


def test_seam_kernels_warm_up_once_in_a_worker(qtbot, monkeypatch):
    import engine.seams

    calls = []
    monkeypatch.setattr(main_window, "_warmup_started", False)
    monkeypatch.setattr(engine.seams, "warmup", lambda: calls.append(threading.current_thread()))
    w = make_window(qtbot)
    qtbot.waitUntil(lambda: bool(calls), timeout=WAIT_MS)
    assert calls[0] is not threading.main_thread()
    make_window(qtbot)
    wait_idle(qtbot, w)
    assert len(calls) == 1


def test_number_keys_switch_the_seamless_tile_repeats(qtbot, win):
    template(qtbot, win)
    tv = win.tile_view
    for n, key in ((1, Qt.Key.Key_1), (5, Qt.Key.Key_5), (3, Qt.Key.Key_3)):
        action = win.act_repeats[n]
        assert action.shortcut().toString() == str(n)
        assert f"({n})" in tv.repeat_buttons.button(n).toolTip()
        win.source_view.setFocus()
        qtbot.keyClick(win.source_view, key)
        assert tv.repeats == n and action.isChecked()
        assert tv.canvas.array.shape[:2] == (n * tv.tile.shape[0], n * tv.tile.shape[1])
    view_menu = next(a.menu() for a in win.menuBar().actions() if a.text() == "&View")
    assert set(win.act_repeats.values()) <= set(view_menu.actions())
    tv.repeat_buttons.button(5).click()  # the buttons keep the menu in step
    assert win.act_repeats[5].isChecked()
    # digits typed into a spin box stay there
    spin = win.params_panel.widgets["n_candidates"]
    spin.setFocus()
    spin.lineEdit().selectAll()
    qtbot.keyClick(spin.lineEdit(), Qt.Key.Key_1)
    assert tv.repeats == 5 and spin.lineEdit().text() == "1"
