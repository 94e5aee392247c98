"""The whole tile-set workflow driven through the editor, as a user would (issue 5)."""

from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import Qt

from engine.project import load_project
from tests.gui.helpers import WAIT_MS, click_candidate, make_window, open_sample, wait_idle


def test_tile_set_workflow_open_to_reopen(qtbot, tmp_path):
    w = make_window(qtbot)
    doc = w.doc
    # -- open: the bundled sample, shown on the canvas
    open_sample(qtbot, w)
    assert doc.source is not None and doc.source.shape == (512, 512)
    assert w.source_view.array is doc.source.main
    assert "Opened cobblestones.png" in w.last_message()

    # -- find template: runs in the background, the rectangle is drawn where the search ended
    w.act_find.trigger()
    wait_idle(qtbot, w)
    x, y, tw, th = doc.tileset.template_rect
    (lo, _), (hi, _) = doc.tileset.settings().tile_range(doc.source.shape)
    assert lo <= tw <= hi and lo <= th <= hi
    assert w.source_view.rect_item.isVisible() and w.source_view.rect_item.rect == (x, y, tw, th)
    assert doc.undo_stack.undoText() == "Find best tile"
    for k, shade in w.source_view.shades.items():
        assert shade.isVisible(), k
    ov = doc.tileset.overlap()
    assert w.source_view.shades["R_R"].rect().getRect() == (x + tw, y, ov, th + ov)

    # -- seamless tile: error maps, seams and the wrapped 3x3 view
    s = doc.tileset.seamless
    assert s is not None and s.tile.shape[:2] == (th, tw)
    assert w.source_view.heat["horizontal"].isVisible()
    seam_pts = w.source_view.seams["horizontal"].points
    assert np.array_equal(seam_pts, s.paths_source["horizontal"])
    assert w.overlap_panel.views["vertical"].frame_shape == s.errors["vertical"].shape
    assert "seam criterion" in w.overlap_panel.labels["horizontal"].text()
    assert w.tile_view.shown_image().shape[:2] == (3 * th, 3 * tw)
    qtbot.waitUntil(lambda: w.tile_view.metrics is not None, timeout=WAIT_MS)
    assert "wrap border ratio" in w.tile_view.info.text()
    assert w.tile_view.metrics["wrap"] < 2.0  # naive crops of this sample score far higher
    assert "seam H" in w.criterion_label.text()

    # -- generate 30 candidates: they stream into the gallery
    inserted = []
    w.gallery.model().rowsInserted.connect(lambda *a: inserted.append(a[1]))
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    assert len(doc.tileset.candidates) == 30 and w.gallery.model().rowCount() == 30
    assert len(inserted) == 30  # one row at a time, as they arrived
    m = doc.params["margin"]
    for e in doc.tileset.candidates:  # every candidate keeps the template's border: they connect
        assert np.array_equal(e.tile[:m], s.tile[:m])
        assert np.array_equal(e.tile[:, -m:], s.tile[:, -m:])
    assert doc.undo_stack.undoText() == "Generate candidates"

    # -- pick 5: click, click, shift+click a range of three
    click_candidate(qtbot, w, 2)
    click_candidate(qtbot, w, 7)
    click_candidate(qtbot, w, 10)
    click_candidate(qtbot, w, 12, Qt.KeyboardModifier.ShiftModifier)
    assert doc.tileset.picks == [2, 7, 10, 11, 12]
    model = w.gallery.model()
    from quilt_gui.widgets.gallery import PICK_ROLE

    assert [model.index(i).data(PICK_ROLE) for i in (2, 7, 10, 11, 12, 0)] == [1, 2, 3, 4, 5, 0]
    click_candidate(qtbot, w, 7)  # toggles off ...
    assert doc.tileset.picks == [2, 10, 11, 12]
    doc.undo_stack.undo()  # ... and undo brings it back
    assert doc.tileset.picks == [2, 7, 10, 11, 12]

    # -- preview: the picked tiles assembled by the layout, with its grid score
    wait_idle(qtbot, w)
    w.tabs.setCurrentWidget(w.preview_view)
    rows, cols = doc.params["preview_rows"], doc.params["preview_cols"]
    assert doc.tileset.layout.shape == (rows, cols) and set(np.unique(doc.tileset.layout)) <= set(
        range(5)
    )
    assert (doc.tileset.layout[:, 1:] != doc.tileset.layout[:, :-1]).all()  # no equal neighbours
    assert doc.tileset.preview.shape[:2] == (rows * th, cols * tw)
    cell = doc.tileset.layout[1, 2]
    tile = doc.tileset.candidates[doc.tileset.picks[cell]].tile
    assert np.array_equal(doc.tileset.preview[th : 2 * th, 2 * tw : 3 * tw], tile)
    assert w.preview_view.canvas.array is doc.tileset.preview
    assert "grid score" in w.preview_view.info.text() and doc.tileset.grid_score is not None
    # the picked set's interior figures (issue 10), measured in the background, and warnings
    qtbot.waitUntil(lambda: w.preview_view.quality is not None, timeout=WAIT_MS)
    q = w.preview_view.quality
    assert {"frame", "ring_tone", "duplicates", "lattice", "template_share"} <= set(q)
    assert f"frame {q['frame']:.2f}" in w.preview_view.info.text()
    assert q["duplicates"] == 0
    assert w.preview_view.warnings.isVisibleTo(w.preview_view) == bool(q["warnings"])
    old_layout = doc.tileset.layout.copy()
    w.act_reroll_layout.trigger()
    wait_idle(qtbot, w)
    assert not np.array_equal(doc.tileset.layout, old_layout)

    # -- export through the dialog, into tmp_path
    w.act_export.trigger()
    dlg = w._export_dialog
    assert dlg.isVisible()
    out = tmp_path / "bundle"
    dlg.folder.setText(str(out))
    dlg.spacing.setValue(2)
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS) as sig:
        dlg.export_button.click()
    manifest = sig.args[0]
    assert len(manifest["tiles"]) == 5
    on_disk = json.loads((out / f"{doc.name}.json").read_text())
    assert on_disk["tiles"] == manifest["tiles"]
    layout = json.loads((out / f"{doc.name}_layout.json").read_text())
    assert np.array_equal(layout["cells"], doc.tileset.layout)
    assert any(out.glob("*.tsx")) and any(out.glob("*.tmx")) and any(out.glob("*.tres"))
    assert len(list(out.glob(f"{doc.name}_0*_albedo.png"))) == 5
    assert "Exported 5 tiles" in dlg.status.text()

    # -- save the project, then reopen it in a fresh window
    path = tmp_path / "session.quiltproj"
    w.files.ask_save_path = lambda: str(path)
    with qtbot.waitSignal(doc.path_changed, timeout=WAIT_MS):
        w.act_save.trigger()
    assert not doc.modified and not w.isWindowModified()
    saved = load_project(path)
    assert saved.picks == [2, 7, 10, 11, 12] and len(saved.candidates) == 30

    w2 = make_window(qtbot)
    with qtbot.waitSignal(w2.doc.path_changed, timeout=WAIT_MS):
        w2.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, w2)
    d2 = w2.doc.tileset
    assert d2.template_rect == doc.tileset.template_rect and d2.picks == doc.tileset.picks
    assert np.array_equal(d2.layout, doc.tileset.layout)
    assert len(d2.candidates) == 30 and w2.gallery.model().rowCount() == 30
    for a, b in zip(d2.candidates, doc.tileset.candidates, strict=True):
        assert np.abs(a.tile - b.tile).max() <= 0.5 / 255 + 1e-6  # 8-bit PNG in the project
    assert d2.seamless is not None and d2.seamless.rect == doc.tileset.seamless.rect  # recomputed
    assert w2.source_view.rect_item.rect == doc.tileset.template_rect
    assert d2.preview is not None and "grid score" in w2.preview_view.info.text()
    assert not w2.doc.modified
