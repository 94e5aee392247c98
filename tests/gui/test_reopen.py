"""A reopened or recovered project keeps its candidates current (issue 13 item 3)."""

from __future__ import annotations

from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample, wait_idle


def gallery_title(w) -> str:
    return w.docks["gallery"].windowTitle()


def test_reopened_and_recovered_candidates_are_not_called_outdated(qtbot, tmp_path):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 4, rect=(150, 120, 128, 128))
    w.doc.tileset.set_picks([1, 3])
    wait_idle(qtbot, w)
    assert not w.doc.tileset.candidates_outdated
    path = tmp_path / "p.quiltproj"
    assert w.files.save_to(str(path), wait=True)
    again = make_window(qtbot)
    with qtbot.waitSignal(again.doc.path_changed, timeout=WAIT_MS):
        again.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, again)
    assert again.doc.tileset.seamless is not None  # recomputed from the saved rectangle
    assert not again.doc.tileset.candidates_outdated
    assert "earlier template" not in gallery_title(again)
    assert again.doc.tileset.picks == [1, 3] and "2 of 4 picked" in gallery_title(again)
    # a recovered file too
    w.doc.tileset.set_picks([0])
    job = w.files.autosave_now()
    qtbot.waitUntil(lambda: not job.running, timeout=WAIT_MS)
    third = make_window(qtbot)
    third.files.restore_recovery(w.files.recovery_file())
    wait_idle(qtbot, third)
    assert not third.doc.tileset.candidates_outdated and third.doc.tileset.picks == [0]
    # a real change of the template still marks them
    x, y, tw, th = again.doc.tileset.template_rect
    again.doc.tileset.set_template_rect((x + 9, y + 5, tw, th))
    wait_idle(qtbot, again)
    assert again.doc.tileset.candidates_outdated and "earlier template" in gallery_title(again)
