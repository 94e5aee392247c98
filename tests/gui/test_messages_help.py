"""Messages that move nothing, and help that stays (issue 13 item 6)."""

from __future__ import annotations

from PySide6.QtCore import QRect
from PySide6.QtWidgets import QToolButton

from tests.gui.helpers import make_window, open_sample


def test_a_message_floats_over_the_canvas_and_moves_nothing(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.message_bar.dismiss()
    qtbot.wait(10)
    before = (w.tabs.geometry(), w.source_view.mapTo(w, w.source_view.rect().topLeft()))
    w.show_message("warning", "Something to read. " * 12, actions=(("OK", lambda: None),))
    qtbot.wait(10)
    after = (w.tabs.geometry(), w.source_view.mapTo(w, w.source_view.rect().topLeft()))
    assert w.message_bar.isVisible() and before == after
    bar = w.message_bar.geometry()
    assert w.centralWidget().rect().contains(bar)
    # it floats at the bottom: the tab bar and the Quilting tab's buttons stay clickable
    w.tabs.setCurrentWidget(w.quilt_view)
    tab_bar = w.tabs.tabBar().geometry()
    assert not bar.intersects(tab_bar)
    synth = next(b for b in w.quilt_view.findChildren(QToolButton) if "Synthesize" in b.text())
    top_left = synth.mapTo(w.centralWidget(), synth.rect().topLeft())
    assert not bar.intersects(QRect(top_left, synth.size()))
    w.message_bar.dismiss()
    assert w.tabs.geometry() == before[0]


def test_help_is_a_shortcut_sheet_and_a_getting_started_that_stay(qtbot):
    w = make_window(qtbot)
    w.message_bar.dismiss()
    help_menu = next(a.menu() for a in w.menuBar().actions() if a.text() == "&Help")
    entries = {a.text(): a for a in help_menu.actions()}
    entries["&Keyboard and mouse"].trigger()
    sheet = w._help["shortcuts"]
    assert sheet.isVisible() and not w.message_bar.isVisible()
    rows = sheet.rows()
    assert ("Keyboard", "Ctrl+T", "Find best tile") in rows
    assert any(r[1] == "Wheel" for r in rows) and len(rows) > 30
    entries["&Getting started"].trigger()
    guide = w._help["getting_started"]
    assert guide.isVisible() and "Export seamless tile" in guide.text.text()
    qtbot.wait(50)
    assert sheet.isVisible() and guide.isVisible()  # dialogs, not a banner that fades


def test_engine_notes_name_the_editors_controls_not_the_command_line(qtbot):
    import numpy as np

    from engine.tiles.stationarity import stationarity_of

    rng = np.random.default_rng(0)
    light = np.linspace(0.4, 1.0, 128, dtype=np.float32)[None, :, None]
    note = stationarity_of(rng.random((128, 128, 3), dtype=np.float32) * light).warnings[0]
    assert "(tileset --flatten)" in note  # the command line's hint, in the engine's note
    w = make_window(qtbot)
    w.show_message("warning", note)
    text = w.message_bar.label.text()
    assert "--flatten" not in text and "try Flatten lighting (Parameters ▸ Advanced ▸ Tile)" in text
    assert w.last_message() == text


def test_a_wang_note_on_a_small_source_names_what_to_change_not_min_distance(qtbot):
    import warnings

    import numpy as np

    from engine.tiles.wang import iter_wang_set

    rng = np.random.default_rng(0)
    src = rng.random((30, 40, 3), dtype=np.float32)  # a 40x30 photo: samples crowd together
    gen = iter_wang_set(src, tile_size=14, colours=2, rng=0)
    with warnings.catch_warnings():  # the engine also warns it on its own
        warnings.simplefilter("ignore")
        while True:
            try:
                next(gen)
            except StopIteration as end:
                notes = end.value.notes
                break
    (note,) = [n for n in notes if "too small for 2 colours" in n]
    assert "min_distance" in note  # the engine's word
    w = make_window(qtbot)
    w.show_message("warning", f"Wang set: {note}")
    text = w.message_bar.label.text()
    assert "min_distance" not in text and "fewer Colours, a smaller Tile size" in text


def test_a_long_message_is_as_tall_as_its_wrapped_text(qtbot):
    w = make_window(qtbot)
    w.show_message("warning", "The lighting varies across the photo, try something. " * 10)
    qtbot.wait(10)
    bar = w.message_bar
    lines = bar.label.heightForWidth(bar.label.width())
    assert lines > 2 * bar.label.fontMetrics().height()  # it wraps
    assert bar.height() <= lines + 16  # the margins (5 + 5 px), not a sizeHint's narrow wrap


def test_the_shortcut_sheet_says_what_ctrl_g_and_ctrl_r_do_on_the_tab_shown(qtbot):
    """polish13b: opened on the Wang tab, the sheet listed neither key for Generate candidates
    nor for Re-roll layout (the Wang tab's buttons take them there, 329559f) and said nothing
    of what they do there; it follows the tabs while it stays open."""
    w = make_window(qtbot)
    w.tabs.setCurrentWidget(w.wang_view)
    sheet = w.show_help()

    def keys(rows):
        return sorted((k, what) for where, k, what in rows if k in ("Ctrl+G", "Ctrl+R"))

    assert keys(sheet.rows()) == [
        ("Ctrl+G", "Generate: make the Wang set from the source"),
        ("Ctrl+R", "Re-roll layout: another valid layout of the Wang tiles"),
    ]
    w.tabs.setCurrentWidget(w.source_view)  # the tile set's actions have them again
    assert keys(sheet.rows()) == [("Ctrl+G", "Generate candidates"), ("Ctrl+R", "Re-roll layout")]
    sheet.close()
