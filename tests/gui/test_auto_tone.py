"""Flatten lighting's Auto in the editor (issue 10): the banner says it, Off switches it off."""

from PIL import Image

from benchmarks.evalset import bricks
from tests.gui.helpers import WAIT_MS, make_window, wait_idle


def test_uneven_lighting_is_flattened_said_on_the_banner_and_can_be_switched_off(qtbot, tmp_path):
    path = tmp_path / "bricks.png"
    Image.fromarray(bricks(256, seed=3)).save(path)  # a lighting gradient of ±22 %
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    w.doc.set_params({"tile_size": "64"})
    s = w.pipeline.settings()
    assert s.flatten is True and s.seam.blend == "poisson"
    assert w.pipeline.flatten_scale() is not None
    w.act_find.trigger()
    wait_idle(qtbot, w)
    banner = w.message_bar.label.text()
    assert "lighting varies" in banner and "automatic" in banner
    assert "Flatten lighting: Off keeps" in banner and "--no-flatten" not in banner  # UI words
    panel, hint = w.params_panel, w.params_panel.tone_hint
    assert panel.value("blend") == "adaptive"  # the choice is kept; the hint says what Auto uses
    assert hint.isVisibleTo(panel) and "Gradient domain" in hint.text()
    w.tabs.setCurrentWidget(w.wang_view)  # Auto tone leaves a Wang set alone: no hint there
    assert not hint.isVisibleTo(panel)
    w.tabs.setCurrentWidget(w.source_view)
    assert hint.isVisibleTo(panel)
    w.doc.set_params({"flatten": "off"})
    s = w.pipeline.settings()
    assert s.flatten is False and s.seam.blend == "adaptive"
    assert w.pipeline.flatten_scale() is None and w.doc.tileset.tone_note is None
    assert not hint.isVisibleTo(panel)


def _lit_bricks_window(qtbot, tmp_path):
    """A window with a 256 px bricks photo open and 64 px tiles (the Flattened lighting view's
    tests)."""
    path = tmp_path / "bricks.png"
    Image.fromarray(bricks(256, seed=3)).save(path)
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    w.doc.set_params({"tile_size": "64"})
    return w


def test_flattened_lighting_before_and_after_on_the_source_canvas(qtbot, tmp_path):
    import numpy as np

    from engine.tone import flatten_lighting

    w = _lit_bricks_window(qtbot, tmp_path)
    photo, canvas, act = w.doc.source.main, w.source_view, w.flatten_compare.action
    assert act in w.actions() and act.shortcut().toString() == "F"
    act.trigger()  # after: the source as the tiles are made from it
    qtbot.waitUntil(lambda: w.flatten_compare.shown is not None, timeout=WAIT_MS)
    scale = w.pipeline.flatten_scale()
    want = flatten_lighting(photo, scale=scale)
    np.testing.assert_array_equal(canvas.image_item.array, want)
    assert "lighting flattened" in w.messages[-1][1]
    for said in (w.messages[-1][1], act.toolTip()):  # true on the Wang tab too
        assert "the tile set's tiles are made from it" in said
        assert "a Wang set uses the photo as it is" in said
    w.doc.set_params({"tile_size": "128"})  # another scale: flattened again
    qtbot.waitUntil(lambda: w.flatten_compare.shown == w.pipeline.flatten_scale(), timeout=WAIT_MS)
    assert w.flatten_compare.shown != scale
    act.trigger()  # before: the photo
    assert canvas.image_item.array is photo
    w.doc.set_params({"flatten": "off"})
    act.trigger()  # nothing to compare: said, and switched back
    assert not act.isChecked() and canvas.image_item.array is photo
    assert "Flatten lighting is off for this photo" in w.messages[-1][1]


def test_a_new_photo_with_flattened_lighting_shown_is_flattened_once(qtbot, tmp_path, monkeypatch):
    """Deciding Auto for the new photo says so (tone_changed), which asked for the flattened view
    again while it was being asked for: two flatten jobs, the first run to the end for nothing."""
    w = make_window(qtbot)
    paths = []
    for seed in (3, 4):
        paths.append(tmp_path / f"bricks{seed}.png")
        Image.fromarray(bricks(256, seed=seed)).save(paths[-1])
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(paths[0]), confirm=False)
    w.doc.set_params({"tile_size": "64"})
    w.flatten_compare.action.trigger()
    qtbot.waitUntil(lambda: w.flatten_compare.shown is not None, timeout=WAIT_MS)
    jobs, starts = w.pipeline.jobs, []
    real_start = jobs.start

    def spy(key, *args, **kwargs):
        starts.append(key)
        return real_start(key, *args, **kwargs)

    monkeypatch.setattr(jobs, "start", spy)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(paths[1]), confirm=False)
    qtbot.waitUntil(lambda: w.flatten_compare.shown is not None, timeout=WAIT_MS)
    assert w.flatten_compare.action.isChecked()
    assert starts.count("flatten-view") == 1
    wait_idle(qtbot, w)


def test_a_tile_size_changed_and_back_while_flattening_shows_the_scale_asked(qtbot, tmp_path):
    """The size changed back before the other scale's job ended: that job's image (at the scale
    no longer asked) was shown over the right one, and said to be of that scale."""
    import numpy as np

    from engine.tone import flatten_lighting

    w = _lit_bricks_window(qtbot, tmp_path)
    view, photo = w.flatten_compare, w.doc.source.main
    view.action.trigger()
    qtbot.waitUntil(lambda: view.shown is not None, timeout=WAIT_MS)
    scale = view.shown
    w.doc.set_params({"tile_size": "128"})  # another scale: its job starts...
    other = w.jobs.get("flatten-view")
    assert w.pipeline.flatten_scale() != scale and other is not None
    w.doc.set_params({"tile_size": "64"})  # ...and the size is back before it ends
    qtbot.waitUntil(lambda: other.state != "running", timeout=WAIT_MS)  # (its image delivered)
    wait_idle(qtbot, w)
    assert w.pipeline.flatten_scale() == scale and view.shown == scale
    want = flatten_lighting(photo, scale=scale)
    np.testing.assert_array_equal(w.source_view.image_item.array, want)
