"""Drawing the tile rectangle on the source; Space+drag and middle-drag pan (issue 13 item 2)."""

from __future__ import annotations

from PySide6.QtCore import QPoint, Qt

from tests.gui.helpers import make_window, open_sample, wait_idle


def drag(qtbot, view, a: QPoint, b: QPoint, button=Qt.MouseButton.LeftButton) -> None:
    qtbot.mousePress(view.viewport(), button, Qt.KeyboardModifier.NoModifier, a)
    for k in range(1, 6):
        qtbot.mouseMove(view.viewport(), a + (b - a) * (k / 5))
    qtbot.mouseRelease(view.viewport(), button, Qt.KeyboardModifier.NoModifier, b)


def scroll(view) -> tuple[int, int]:
    return view.horizontalScrollBar().value(), view.verticalScrollBar().value()


def test_a_plain_drag_draws_the_tile_rectangle_and_space_or_middle_drag_pans(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    v, ts = w.source_view, w.doc.tileset
    v.set_zoom(1.0)
    v.center_on_pixel(200, 200)
    assert ts.template_rect is None
    steps, before = w.doc.undo_stack.count(), scroll(v)
    a, b = v.view_pos_of_pixel(150, 120).toPoint(), v.view_pos_of_pixel(229, 259).toPoint()
    (r0, c0), (r1, c1) = v.pixel_at(a.toPointF()), v.pixel_at(b.toPointF())
    assert (r1 - r0, c1 - c0) == (79, 139)
    drag(qtbot, v, a, b)  # 140 wide, 80 high
    assert scroll(v) == before  # it did not pan
    assert ts.template_rect == (c0, r0, 140, 140)  # square: the tile size is Auto (square)
    assert w.doc.undo_stack.count() == steps + 1 and w.act_undo.text().endswith("rectangle")
    wait_idle(qtbot, w)
    assert ts.seamless is not None and ts.seamless.tile.shape[:2] == (140, 140)
    w.doc.set_param("tile_size", "any")  # any size: the rectangle drawn, as drawn
    a, b = v.view_pos_of_pixel(60, 300).toPoint(), v.view_pos_of_pixel(119, 389).toPoint()
    r0, c0 = v.pixel_at(a.toPointF())
    drag(qtbot, v, a, b)
    assert ts.template_rect == (c0, r0, 90, 60)
    wait_idle(qtbot, w)
    rect = ts.template_rect
    v.set_zoom(3.0)
    v.setFocus()
    qtbot.keyPress(v, Qt.Key.Key_Space)  # Space+drag pans
    start = scroll(v)
    drag(qtbot, v, QPoint(200, 200), QPoint(120, 150))
    qtbot.keyRelease(v, Qt.Key.Key_Space)
    assert scroll(v) == (start[0] + 80, start[1] + 50) and ts.template_rect == rect
    start = scroll(v)
    drag(qtbot, v, QPoint(100, 100), QPoint(140, 130), Qt.MouseButton.MiddleButton)
    assert scroll(v) == (start[0] - 40, start[1] - 30) and ts.template_rect == rect


def test_a_smaller_rectangle_leaves_waypoints_outside_it_unused_and_kept(qtbot):
    """A waypoint below a shrunk rectangle's overlap is not sent (the engine refuses it: no
    seamless tile and an error, as before) nor drawn; it is kept for an undo."""
    w = make_window(qtbot)
    open_sample(qtbot, w)
    t = w.doc.tileset
    t.set_template_rect((150, 120, 128, 112))
    t.add_waypoint("horizontal", (100, 4))
    wait_idle(qtbot, w)
    assert t.waypoints_in_use()["horizontal"] == [(100, 4)]
    t.set_template_rect((150, 120, 64, 64))
    wait_idle(qtbot, w)
    assert t.seamless is not None and t.seamless.tile.shape[:2] == (64, 64)
    assert w.message_bar.level != "error"
    assert t.waypoints["horizontal"] == [(100, 4)] and t.waypoints_in_use()["horizontal"] == []
    assert w.source_view._waypoint_items == []
    assert w.overlap_panel.views["horizontal"].waypoints == []
    t.undo_stack.undo()  # the larger rectangle again: the waypoint is used again
    wait_idle(qtbot, w)
    assert t.waypoints_in_use()["horizontal"] == [(100, 4)]
    assert len(w.source_view._waypoint_items) == 1
