"""The Wang set's history (ux12): a new set is one undo step, a cancel says what it left."""

from __future__ import annotations

import numpy as np

from engine.tiles.wang import WangSample
from tests.gui.helpers import make_window, open_sample
from tests.gui.test_wang_view import generate, wait_wang


def test_a_new_set_is_undone_to_the_last_one_with_its_edits(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    w = win.doc.wang
    y, x = w.sample("v", 1).origin
    w.set_sample(WangSample("v", 1, (y + 3, x + 2)))  # as a drag does
    wait_wang(qtbot, win)
    moved = w.sample("v", 1).origin
    tiles = {k: t.tile.copy() for k, t in w.tiles.items()}
    generate(qtbot, win, colours=1)  # the new set replaces it...
    assert w.colours == 1 and w.complete and len(w.samples) == 2
    win.doc.undo_stack.undo()  # ...and Ctrl+Z brings it back, as it was
    wait_wang(qtbot, win)
    assert w.colours == 2 and w.complete and w.sample("v", 1).origin == moved
    assert view.colours.value() == 2
    for k, t in w.tiles.items():
        np.testing.assert_array_equal(t.tile, tiles[k])
    win.doc.undo_stack.undo()  # the move before it
    wait_wang(qtbot, win)
    assert w.sample("v", 1).origin == (y, x) and w.complete
    win.doc.undo_stack.redo()
    win.doc.undo_stack.redo()
    wait_wang(qtbot, win)
    assert w.colours == 1 and w.complete and len(w.samples) == 2


def test_cancelling_a_new_set_says_so_and_undo_brings_the_last_one_back(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, colours=2)
    w = win.doc.wang
    old = list(w.samples)
    win.wang_view.colours.setValue(3)
    win.wang_view.generate().stop()  # the status bar's Cancel, before the engine's first check
    wait_wang(qtbot, win)
    assert w.colours == 3 and not w.complete
    level, text = win.messages[-1]
    assert "stopped" in text and f"of {w.count} tiles" in text and "Ctrl+Z" in text
    win.export_dialog()  # an incomplete set is not exported, and the message says why
    assert win.messages[-1][1].startswith("Nothing to export yet: generate the Wang set")
    win.doc.undo_stack.undo()
    assert w.colours == 2 and w.complete and w.samples == old


def test_a_tiny_source_takes_the_wang_tiles_that_fit_and_says_which(qtbot, tmp_path):
    import imageio.v3 as iio

    from resources import sample_path
    from tests.gui.helpers import WAIT_MS

    path = tmp_path / "tiny.png"
    iio.imwrite(path, iio.imread(sample_path("lichen"))[:30, :40, :3])
    win = make_window(qtbot)
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(path), confirm=False)
    view = win.wang_view
    top = view.tile_size.maximum()
    assert 8 <= top < 16  # 40x30: an edge sample needs about twice the tile
    assert win.wang_runner.generate({"tile_size": top + 1}) is None
    assert f"{top} px tiles fit" in win.messages[-1][1]
    view.tile_size.setValue(128)  # clamped to what fits
    assert view.tile_size.value() == top
    view.generate_button.click()
    wait_wang(qtbot, win)
    assert win.doc.wang.complete and len(win.doc.wang.tiles) == 16


def test_a_sample_dragged_past_the_border_stops_at_it(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, colours=2)
    w = win.doc.wang
    for axis in ("h", "v"):
        old = w.sample(axis, 0).origin
        assert win.wang_runner.move_sample(axis, 0, (-500, -500))  # as a drag off the corner
        wait_wang(qtbot, win)
        new = w.sample(axis, 0).origin
        assert new != old and min(new) >= 0
        # the corner: one pixel further up or left does not fit
        for d in ((-1, 0), (0, -1)):
            assert win.wang_runner.move_sample(axis, 0, (new[0] + d[0], new[1] + d[1]))
            assert w.sample(axis, 0).origin == new
    assert w.complete


def test_the_layout_title_stays_above_its_empty_canvas_while_the_set_is_made(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    win.tabs.setCurrentWidget(win.wang_view)
    view = win.wang_view
    title = view.preview.parentWidget().layout().itemAt(0).widget()
    assert view.preview.array is None and view.preview.isVisible()
    assert title.geometry().bottom() < view.preview.geometry().top()


def test_a_sample_is_named_in_white_on_a_chip_of_its_colour(qtbot):
    from quilt_gui.widgets.wang_view import colour_of

    win = make_window(qtbot)
    open_sample(qtbot, win, "brick")
    view = generate(qtbot, win, colours=2)
    item = view.samples[("h", 0)]  # red: on red bricks its red name could not be read
    assert item.label.brush().color().rgb() == colour_of(0).rgb()
    (text,) = item.label.childItems()
    assert text.text() == "h0" and text.brush().color().name() == "#ffffff"


def test_a_sample_moved_while_the_set_is_made_shows_on_every_tile_that_uses_it(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    win.tabs.setCurrentWidget(win.wang_view)
    view, w, runner = win.wang_view, win.doc.wang, win.wang_runner
    view.tile_size.setValue(48)
    moved = []

    def move_once():  # as a drag as soon as the diamonds show, the tiles still streaming
        if not moved:
            y, x = w.sample("h", 1).origin
            moved.append((y + 5, x + 4))
            w.set_sample(WangSample("h", 1, moved[0]))

    w.samples_changed.connect(move_once)
    view.generate_button.click()
    wait_wang(qtbot, win)
    w.samples_changed.disconnect(move_once)
    assert w.complete and w.layout is not None and w.sample("h", 1).origin == moved[0]
    y, x = moved[0]
    row = win.doc.source.main[y, x : x + 48]
    north = [k for k in w.users("h", 1) if w.tiles[k].signature[0] == 1]
    for k in north:  # the moved sample's pixels on every north edge that shows it
        np.testing.assert_array_equal(w.tiles[k].tile[0], row, err_msg=f"tile {k}")
    # the same, whatever the timing: a tile of a job started before a move is dropped
    old_version, k = runner._version, north[0]
    late = w.tiles[k]
    w.set_sample(WangSample("h", 1, (y + 2, x + 1)))
    runner._on_event(old_version, late)  # it arrives after the move
    assert w.tiles[k] is late and k in runner.stale  # not taken as made with the new sample
    wait_wang(qtbot, win)
    assert w.tiles[k] is not late and not runner.stale


def test_a_map_attached_after_the_set_says_the_set_lacks_it(qtbot, tmp_path):
    import imageio.v3 as iio

    from tests.gui.helpers import WAIT_MS

    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, colours=2)
    path = tmp_path / "cobblestones_roughness.png"
    iio.imwrite(path, (win.doc.source.main.mean(axis=2) * 255).astype(np.uint8))
    with qtbot.waitSignal(win.doc.maps_changed, timeout=WAIT_MS):
        win.files.attach_map(str(path))
    level, text = win.messages[-1]
    assert level == "warning" and "The 16 Wang tiles made before lack it" in text
    assert win.files.save_to(str(tmp_path / "p.quiltproj"), wait=True)
    from engine.project import load_project

    assert load_project(tmp_path / "p.quiltproj").wang is None  # what the message warns of


def test_healing_the_source_makes_the_wang_set_again_from_the_healed_pixels(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, colours=2)
    w = win.doc.wang
    y, x = w.sample("h", 0).origin
    healed = win.doc.source.main.copy()
    healed[y - 2 : y + 3, x : x + 48] = 1 - healed[y - 2 : y + 3, x : x + 48]  # on the sample
    win.doc.apply_source_maps({**win.doc.source.maps, win.doc.source.main_name: healed})
    wait_wang(qtbot, win)
    assert w.complete and "healed source" in win.messages[-1][1]
    for k, t in w.tiles.items():  # every tile shows the healed pixels on its h0 edges
        if t.signature[0] == 0:
            np.testing.assert_array_equal(t.tile[0], healed[y, x : x + 48], err_msg=f"tile {k}")


def test_a_set_put_back_by_undo_rebuilds_the_tiles_its_last_move_left_waiting(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    view = generate(qtbot, win, colours=2)
    w, runner = win.doc.wang, win.wang_runner
    y, x = w.sample("h", 0).origin
    w.set_sample(WangSample("h", 0, (y + 3, x + 3)))  # its rebuild starts...
    users = set(w.users("h", 0))
    assert runner.stale == users
    view.colours.setValue(1)
    view.generate()  # ...and a new set replaces it at once
    wait_wang(qtbot, win)
    win.doc.undo_stack.undo()  # the K = 2 set back: its waiting tiles are made again
    wait_wang(qtbot, win)
    assert w.colours == 2 and w.complete and not runner.stale
    row = win.doc.source.main[y + 3, x + 3 : x + 3 + 48]
    for k in users:
        if w.tiles[k].signature[0] == 0:
            np.testing.assert_array_equal(w.tiles[k].tile[0], row, err_msg=f"tile {k}")
