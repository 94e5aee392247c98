"""Heal in the editor (issue 13 item 15): paint a region, Heal, undo; the healed source is what
the template search uses."""

from __future__ import annotations

import numpy as np
from PIL import Image
from PySide6.QtCore import Qt

from tests.engine.helpers import smooth_texture
from tests.gui.helpers import WAIT_MS, drag, make_window, wait_idle

LOGO = (1.0, 0.0, 1.0)  # magenta: found nowhere in the texture


def magenta(img) -> np.ndarray:
    return (img[..., 0] > 0.8) & (img[..., 2] > 0.8) & (img[..., 1] < 0.2)


def test_paint_heal_undo_and_the_healed_source_feeds_the_template_search(qtbot, tmp_path):
    tex = (smooth_texture((160, 176), 3, seed=5, sigma=1.5) * 0.7).astype(np.float32)
    tex[70:90, 80:100] = LOGO
    path = tmp_path / "logo.png"
    Image.fromarray((tex * 255 + 0.5).astype(np.uint8)).save(path)
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, w)
    doc, v = w.doc, w.source_view
    original = doc.source.main.copy()
    assert magenta(original).sum() == 400
    v.set_zoom(2.0)
    v.center_on_pixel(80, 90)
    w.doc.set_param("brush", 15)
    w.act_heal_brush.trigger()  # the Heal brush: a plain drag paints the region
    steps = doc.undo_stack.count()
    a, b = v.view_pos_of_pixel(80, 72).toPoint(), v.view_pos_of_pixel(80, 108).toPoint()
    drag(qtbot, v, a, b, modifier=Qt.KeyboardModifier.NoModifier)
    mask = doc.heal_mask
    assert mask is not None and mask[magenta(original)].all() and mask.sum() < 2000
    assert doc.tileset.template_rect is None  # painting did not draw a rectangle
    assert doc.undo_stack.count() == steps + 1 and w.heal_tool.brush.overlay.isVisible()
    w.act_heal.trigger()
    wait_idle(qtbot, w)
    healed = doc.source.main
    assert not magenta(healed).any()
    np.testing.assert_array_equal(healed[~mask], original[~mask])  # only the region changed
    assert doc.heal_mask is None and any(t.startswith("Healed") for _, t in w.messages)
    assert doc.undo_stack.undoText() == "Heal" and doc.modified
    w.act_undo.trigger()  # one step brings back the source and the region
    assert magenta(doc.source.main).sum() == 400 and doc.heal_mask is not None
    w.act_redo.trigger()
    assert not magenta(doc.source.main).any()
    w.act_heal_brush.trigger()  # off
    w.doc.set_param("tile_size", "64")
    w.act_find.trigger()  # the search and the seamless tile use the healed source
    wait_idle(qtbot, w)
    x, y, tw, th = doc.tileset.template_rect
    assert not magenta(np.asarray(doc.tileset.seamless.tile)).any()
    np.testing.assert_array_equal(w.source_view.array, doc.source.main)  # shown healed


def test_a_heal_says_which_candidates_still_show_the_healed_pixels(qtbot):
    """ux13: candidates cut from the pixels a heal replaced kept them without a word (13 of 30
    here, 3 of them picked, on the cobblestones): the message names them."""
    from tests.gui.helpers import generate, open_sample

    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, n=6, rect=(150, 120, 128, 112))
    doc = w.doc
    w.doc.tileset.set_picks([0, 1])
    x0, y0, tw, th = doc.tileset.template_rect
    # a 12 px square of candidate #1's patch outside the tile rectangle
    x, y, pw, ph = doc.tileset.candidates[0].patch_rect
    spot = next(
        (c, r)
        for r in range(y, y + ph - 12, 4)
        for c in range(x, x + pw - 12, 4)
        if r + 12 <= y0 or r >= y0 + th or c + 12 <= x0 or c >= x0 + tw
    )
    mask = np.zeros(doc.source.shape, bool)
    mask[spot[1] : spot[1] + 12, spot[0] : spot[0] + 12] = True
    hit = [
        e.index + 1
        for e in doc.tileset.candidates
        if mask[e.patch_rect[1] : e.patch_rect[1] + e.patch_rect[3]][
            :, e.patch_rect[0] : e.patch_rect[0] + e.patch_rect[2]
        ].any()
    ]
    doc.set_heal_mask(mask, text="Paint region to heal")
    w.act_heal.trigger()
    wait_idle(qtbot, w)
    text = w.last_message()
    assert text.startswith("Healed") and 1 in hit
    assert "still show" in text and "the unhealed pixels" in text
    # every candidate hit named, then which of them are picked (mend15a: "2 candidates (1 of
    # them picked: #1, #6)" listed the unpicked #6 as picked)
    picked = [f"#{i}" for i in hit if i - 1 in doc.tileset.picks]
    names = ", ".join(f"#{i}" for i in hit)
    assert f"({names}; {len(picked)} of them picked: {', '.join(picked)})" in text, text
    assert "#1" in text and "R in the gallery" in text
    assert w.messages[-1][0] == "warning"


def test_undoing_the_stroke_while_heal_runs_stops_it(qtbot, monkeypatch):
    """ux13: Ctrl+Z right after Heal took the painted stroke back, but the heal went on and
    replaced the pixels anyway ("Healed 0 pixels"), over the stroke's redo."""
    import threading

    import engine.heal
    from tests.gui.helpers import open_sample

    def slow(*_args, cancel=None, **_options):  # as a long heal: nothing until cancelled
        stop = threading.Event()
        for _ in range(12_000):  # at most 120 s
            if cancel is None or cancel.cancelled:
                return None
            stop.wait(0.01)
        return None
        yield

    w = make_window(qtbot)
    open_sample(qtbot, w)
    doc = w.doc
    original = doc.source.main.copy()
    mask = np.zeros(doc.source.shape, bool)
    mask[100:130, 200:240] = True
    doc.set_heal_mask(mask, text="Paint region to heal")
    monkeypatch.setattr(engine.heal, "iter_heal", slow)
    job = w.heal_tool.run()
    assert job is not None and job.alive
    w.act_undo.trigger()  # the stroke goes
    assert doc.heal_mask is None and not job.alive
    assert "Heal stopped: the region to heal changed" in w.last_message()
    wait_idle(qtbot, w)
    np.testing.assert_array_equal(doc.source.main, original)
    assert doc.undo_stack.canRedo() and doc.undo_stack.redoText() == "Paint region to heal"
