"""Wang tiles never left from old pixels or old samples (issue 11, mend13): a heal while
Generate chooses its samples, Ctrl+Z to a set made before a heal, a save during a rebuild;
and the Wang history keeps a bounded number of whole sets."""

from __future__ import annotations

from engine.tiles.wang import WangSample
from quilt_gui.wang_doc import KEPT_SETS, NewWangSet
from tests.gui.helpers import WAIT_MS, make_window, open_sample
from tests.gui.test_wang_view import generate, wait_wang


def mismatched(win) -> list[int]:
    """Tiles whose north row is not the row of their h sample in the current source."""
    w, src = win.doc.wang, win.doc.source.main
    T = int(w.options["tile_size"])
    bad = []
    for k, t in sorted(w.tiles.items()):
        y, x = w.sample("h", t.signature[0]).origin
        if not (t.tile[0] == src[y, x : x + T]).all():
            bad.append(k)
    return bad


def heal(win):
    """New pixels for the source, as a heal gives (every pixel moved a little)."""
    healed = 1 - win.doc.source.main
    win.doc.apply_source_maps({**win.doc.source.maps, win.doc.source.main_name: healed})


def test_a_heal_while_generate_chooses_its_samples_makes_the_set_from_the_new_pixels(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    win.tabs.setCurrentWidget(win.wang_view)
    win.wang_view.tile_size.setValue(48)
    win.wang_view.generate_button.click()
    assert win.doc.wang.samples is None  # still choosing them
    heal(win)
    wait_wang(qtbot, win)
    w = win.doc.wang
    assert w.complete and mismatched(win) == []
    assert win.doc.wang.undo_stack.count() == 0  # the restart is no undo step


def test_undo_to_a_set_made_before_a_heal_rebuilds_it_from_the_healed_pixels(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, tile_size=48)
    samples = list(win.doc.wang.samples)
    generate(qtbot, win, tile_size=40)
    heal(win)
    wait_wang(qtbot, win)
    win.doc.undo_stack.undo()  # the 48 px set back...
    wait_wang(qtbot, win)
    w = win.doc.wang
    assert w.options["tile_size"] == 48 and w.samples == samples  # ...with its samples
    assert w.complete and mismatched(win) == []  # and tiles of the healed pixels


def test_a_set_saved_during_a_rebuild_is_rebuilt_when_reopened(qtbot, tmp_path):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    generate(qtbot, win, tile_size=48)
    w = win.doc.wang
    y, x = w.sample("h", 1).origin
    w.set_sample(WangSample("h", 1, (y + 3, x + 2)))  # its tiles are rebuilt...
    win.export_dialog(wang=True)  # (not exported meanwhile: the message says why)
    assert win.messages[-1][1] == f"Wait for the rebuild of {len(w.stale)} Wang tiles."
    path = str(tmp_path / "p.quiltproj")
    assert win.files.save_to(path, wait=True)  # ...and the project saved at once
    wait_wang(qtbot, win)
    other = make_window(qtbot)
    with qtbot.waitSignal(other.doc.path_changed, timeout=WAIT_MS):
        other.files.open_path(path, confirm=False)
    wait_wang(qtbot, other)
    assert other.doc.wang.complete and mismatched(other) == []
    assert other.doc.wang.sample("h", 1).origin == (y + 3, x + 2)


def test_the_wang_history_keeps_a_bounded_number_of_whole_sets(qtbot):
    win = make_window(qtbot)
    open_sample(qtbot, win, "cobblestones")
    w = win.doc.wang
    for seed in range(KEPT_SETS + 3):
        win.wang_view.seed.setValue(seed)
        generate(qtbot, win, tile_size=16, colours=1)
        if seed == 0:  # the first set: its samples, then a sample move (an undo step)
            first = list(w.samples)
            y, x = w.sample("h", 0).origin
            assert win.wang_runner.move_sample("h", 0, (y + 1, x + 1))
            wait_wang(qtbot, win)
            moved = list(w.samples)
    stack = w.undo_stack
    sets = [stack.command(i) for i in range(stack.count())]
    sets = [c for c in sets if isinstance(c, NewWangSet)]
    assert len(sets) == KEPT_SETS + 2 == stack.count() - 1
    assert sum(bool(c.old[2]) for c in sets) == KEPT_SETS  # tiles kept only in the last ones
    while stack.index() > 1:  # back to the first set after its move: its tiles made again
        stack.undo()
        wait_wang(qtbot, win)
    assert w.samples == moved and moved != first and w.complete and mismatched(win) == []
    stack.undo()  # the move, undone on the rebuilt set
    wait_wang(qtbot, win)
    assert w.samples == first and w.complete and mismatched(win) == []


def test_the_waiting_tiles_are_the_documents_own(qtbot):
    """A snapshot keeps the Wang document's waiting tiles without a runner reaching in."""
    from quilt_gui.document import Document

    doc = Document()
    doc.wang.stale = {1, 2}
    assert doc.wang.snapshot()[7] == {1, 2}
