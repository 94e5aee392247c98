"""Candidates gallery: double-click opens without picking, stable order, stopped generation."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QMouseEvent

from engine.tiles.candidates import candidate_seed
from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample, template, wait_idle


def _mouse(view, kind, row) -> None:
    ix = view.model().index(row, 0)
    view.scrollTo(ix)
    pos = QPointF(view.visualRect(ix).center())
    ev = QMouseEvent(
        kind,
        pos,
        view.viewport().mapToGlobal(pos),
        Qt.MouseButton.LeftButton,
        Qt.MouseButton.LeftButton
        if kind != QEvent.Type.MouseButtonRelease
        else Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
    )
    {
        QEvent.Type.MouseButtonPress: view.mousePressEvent,
        QEvent.Type.MouseButtonRelease: view.mouseReleaseEvent,
        QEvent.Type.MouseButtonDblClick: view.mouseDoubleClickEvent,
    }[kind](ev)


def test_double_click_opens_the_candidate_and_leaves_no_pick_or_undo_step(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 6)
    g = w.gallery
    steps = w.doc.undo_stack.count()
    # a real double-click: press, release, double-click, release
    T = QEvent.Type
    for kind in (T.MouseButtonPress, T.MouseButtonRelease, T.MouseButtonDblClick):
        _mouse(g, kind, 2)
    _mouse(g, T.MouseButtonRelease, 2)
    assert 2 in w._dialogs and w._dialogs[2].isVisible()
    assert w.doc.tileset.picks == [] and w.doc.undo_stack.count() == steps
    assert not w.doc.undo_stack.canRedo()
    # QTest's double-click sends the double-click event alone
    qtbot.mouseDClick(
        g.viewport(), Qt.MouseButton.LeftButton, pos=g.visualRect(g.model().index(4)).center()
    )
    assert 4 in w._dialogs and w.doc.tileset.picks == []
    # a plain click still picks
    _mouse(g, T.MouseButtonPress, 1)
    _mouse(g, T.MouseButtonRelease, 1)
    assert w.doc.tileset.picks == [1]


def test_candidates_are_numbered_by_their_seed_and_a_stop_says_so(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 12)
    seed = int(w.doc.params["seed"])
    assert [e.seed for e in w.doc.tileset.candidates] == [
        candidate_seed(seed, k) for k in range(12)
    ]
    w.doc.set_param("n_candidates", 400)
    w.act_generate.trigger()
    qtbot.waitUntil(lambda: len(w.doc.tileset.candidates) >= 4, timeout=WAIT_MS)
    w.act_cancel.trigger()
    wait_idle(qtbot, w)
    n = len(w.doc.tileset.candidates)
    assert n < 400
    assert w.last_message().startswith(f"Generation stopped: {n} of 400 new candidates made")
    assert w.doc.undo_stack.undoText() == "Generate candidates"


def test_candidate_dialog_shows_seam_on_tile_and_patch_source_and_keeps_it_in_projects(
    qtbot, tmp_path
):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    e = w.doc.tileset.candidates[1]
    dlg = w.open_candidate(1)
    h, w_ = e.tile.shape[:2]
    dlg.view.repeat_buttons.button(1).click()  # 1x1: the seam sits on the only tile
    assert dlg.loop_item.sceneBoundingRect().right() <= w_ + 1
    dlg.view.repeat_buttons.button(3).click()
    assert dlg.loop_item.sceneBoundingRect().left() >= w_ - 1
    x, y, pw, ph = e.patch_rect
    np.testing.assert_array_equal(dlg.patch_view.array, w.doc.source.main[y : y + ph, x : x + pw])
    tx, ty = e.target_rect[:2]
    inside = dlg.patch_loop.points
    assert inside.min() >= 0 and (inside[:, 0] < ph).all() and (inside[:, 1] < pw).all()
    np.testing.assert_array_equal(inside, e.loop - (ty, tx))
    assert "Pixels that differ from the template" in dlg.info.text()
    assert "re-blended in the gradient domain (its step showed): " in dlg.info.text()
    assert "gradient_blend" not in dlg.info.text()  # words, not the engine's key
    dlg.close()
    path = str(tmp_path / "p.quiltproj")
    assert w.files.save_to(path, wait=True)
    with qtbot.waitSignal(w.doc.path_changed, timeout=WAIT_MS):
        w.files.open_path(path, confirm=False)
    wait_idle(qtbot, w)
    back = w.doc.tileset.candidates[1]
    np.testing.assert_array_equal(back.loop, e.loop)
    assert back.target_rect == e.target_rect
    assert w.open_candidate(1).loop_item.isVisible()


def test_candidates_from_an_earlier_template_are_marked_until_regenerated(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 4)
    title = w.docks["gallery"].windowTitle
    assert not w.doc.tileset.candidates_outdated and "earlier template" not in title()
    x, y, tw, th = w.doc.tileset.template_rect
    w.doc.tileset.set_template_rect((x + 4, y + 2, tw - 6, th))
    wait_idle(qtbot, w)
    assert w.doc.tileset.candidates_outdated and "earlier template" in title()
    assert (
        len(w.doc.tileset.candidates) == 4
    )  # kept (they still connect to each other), not dropped
    generate(qtbot, w, 4)
    assert not w.doc.tileset.candidates_outdated and "earlier template" not in title()


def test_fewer_candidates_than_asked_says_why_on_the_banner(qtbot, tmp_path):
    """The engine makes fewer candidates when a small source has no more distinct patch
    positions; the banner gives its reason as a warning (not "Generation stopped")."""
    from PIL import Image

    from resources import sample_path

    small = np.asarray(Image.open(sample_path("cobblestones")))[:180, :180]
    path = tmp_path / "small.png"
    Image.fromarray(small).save(path)
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, w)
    template_rect = (20, 24, 96, 96)
    w.doc.tileset.set_template_rect(template_rect)
    wait_idle(qtbot, w)
    w.doc.set_param("n_candidates", 100)
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    n = len(w.doc.tileset.candidates)
    assert 1 <= n < 100
    assert w.message_bar.level == "warning"
    text = w.message_bar.label.text()
    assert text.startswith(f"Made {n} of 100 candidates: the source has no more patch positions")
    assert "Generation stopped" not in text


def test_a_stop_before_the_first_candidate_does_not_say_click_to_pick(qtbot, monkeypatch):
    """ux13: Esc right after Ctrl+G said "0 candidates. Click to pick the tiles to keep"."""
    import engine.tiles

    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    w.doc.set_param("n_candidates", 30)

    def none_made(*_args, **_options):  # as a run stopped before its first candidate
        return
        yield

    monkeypatch.setattr(engine.tiles, "iter_candidates", none_made)
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    text = w.last_message()
    assert text.startswith("Generation stopped: 0 of 30 new candidates made, 0 candidates.")
    assert "Click to pick" not in text and text.endswith("Generate candidates (Ctrl+G) makes them.")


def test_undoing_the_template_while_generate_runs_stops_it_and_keeps_the_history(
    qtbot, monkeypatch
):
    """ux13: Ctrl+Z during Generate took back the tile rectangle, but the run went on, showed
    30 candidates of a template no longer there and pushed its step over the undone one's
    redo."""
    import threading

    import engine.tiles

    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    before = list(w.doc.tileset.candidates)
    w.doc.set_param("n_candidates", 5)
    w.doc.tileset.set_template_rect((140, 110, 128, 112))
    wait_idle(qtbot, w)
    steps = w.doc.undo_stack.count()

    def slow(*_args, cancel=None, **_options):  # one candidate, then as a long run would
        yield before[0]
        stop = threading.Event()
        for _ in range(12_000):  # at most 120 s
            if cancel is None or cancel.cancelled:
                return
            stop.wait(0.01)

    monkeypatch.setattr(engine.tiles, "iter_candidates", slow)
    w.act_generate.trigger()
    qtbot.waitUntil(lambda: len(w.doc.tileset.candidates) == 1, timeout=WAIT_MS)
    job = w.jobs.get("candidates")
    w.act_undo.trigger()  # the rectangle moves back
    assert w.doc.tileset.template_rect == (150, 120, 128, 112)
    assert not job.alive
    assert w.doc.tileset.candidates == before  # what the gallery held before Generate
    assert "Generation stopped: the tile rectangle changed" in w.last_message()
    wait_idle(qtbot, w)
    assert w.doc.undo_stack.count() == steps and w.doc.undo_stack.canRedo()
    assert w.doc.undo_stack.redoText() == "Move tile rectangle"


def test_undoing_generate_while_a_candidate_is_re_rolled_drops_the_re_roll(qtbot, monkeypatch):
    """ux13: R (re-roll) then Ctrl+Z (undo Generate): the re-rolled tile landed as #k of the
    set Undo brought back (made for the other set), with an undo step over Generate's redo."""
    import threading

    import engine.tiles

    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    first = [id(e) for e in w.doc.tileset.candidates]  # the very entries
    w.doc.set_param("seed", 7)
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    second = list(w.doc.tileset.candidates)
    assert [id(e) for e in second] != first
    release = threading.Event()

    def slow(*_args, cancel=None, index=0, **_options):  # a re-roll of a large tile
        release.wait(120)
        return second[index].replace(seed=12345)

    monkeypatch.setattr(engine.tiles, "make_candidate", slow)
    job = w.pipeline.remake_candidate(1)
    assert job is not None and job.alive
    w.act_undo.trigger()  # the second Generate taken back: the first set in the gallery
    assert [id(e) for e in w.doc.tileset.candidates] == first and not job.alive
    release.set()  # the re-roll finishes
    wait_idle(qtbot, w)
    assert [id(e) for e in w.doc.tileset.candidates] == first
    assert w.doc.undo_stack.canRedo() and w.doc.undo_stack.redoText() == "Generate candidates"


def test_undoing_the_only_template_while_generate_runs_names_what_comes_first(qtbot, monkeypatch):
    """ux13: Ctrl+Z took the template away during Generate, and the banner offered "Generate
    candidates (Ctrl+G)", disabled until there is a tile rectangle again."""
    import threading

    import engine.tiles

    w = make_window(qtbot)
    open_sample(qtbot, w)
    assert w.doc.tileset.template_rect is None
    template(qtbot, w)
    w.doc.set_param("n_candidates", 3)
    wait_idle(qtbot, w)

    def slow(*_args, cancel=None, **_options):  # as a long run would, until cancelled
        stop = threading.Event()
        for _ in range(12_000):  # at most 120 s
            if cancel is None or cancel.cancelled:
                return
            yield from ()
            stop.wait(0.01)

    monkeypatch.setattr(engine.tiles, "iter_candidates", slow)
    w.act_generate.trigger()
    job = w.jobs.get("candidates")
    assert job is not None and job.alive
    for _ in range(3):  # the parameter's step (if it is one), then the template
        if w.doc.tileset.template_rect is not None:
            w.act_undo.trigger()
    assert w.doc.tileset.template_rect is None
    assert not job.alive
    wait_idle(qtbot, w)
    text = w.last_message()
    assert text.startswith("Generation stopped: the tile rectangle was taken away")
    assert "Find best tile (Ctrl+T)" in text and not w.act_generate.isEnabled()
    assert "makes them again" not in text
