"""Material maps through the editor, per-tile preview weights, persisted options."""

from __future__ import annotations

import numpy as np
from PIL import Image
from PySide6.QtCore import Qt

from engine.materials import decode_normals
from quilt_gui import settings
from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample, wait_idle


def normal_map_of(gray: np.ndarray) -> np.ndarray:
    """A plausible tangent-space normal map (uint8 RGB) from a height field."""
    gy, gx = np.gradient(gray.astype(np.float64) * 4.0)
    n = np.stack([-gx, -gy, np.ones_like(gx)], axis=2)
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    return np.round((n * 0.5 + 0.5) * 255).astype(np.uint8)


def test_attached_normal_map_follows_every_cut_and_exports(qtbot, tmp_path):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    src = w.doc.source.main
    path = tmp_path / "cobbles_normal.png"
    Image.fromarray(normal_map_of(src.mean(axis=2))).save(path)
    with qtbot.waitSignal(w.doc.maps_changed, timeout=WAIT_MS):
        w.files.attach_map(str(path))
    assert list(w.doc.source.maps) == ["albedo", "normal"]
    assert w.doc.source.kinds["normal"] == "normal"
    w.doc.tileset.set_template_rect((150, 120, 128, 112))
    wait_idle(qtbot, w)
    s = w.doc.tileset.seamless
    assert "normal" in s.maps and s.maps["normal"].shape == s.tile.shape
    w.doc.set_param("n_candidates", 4)
    w.act_generate.trigger()
    wait_idle(qtbot, w)
    for e in w.doc.tileset.candidates:
        assert set(e.images("albedo")) == {"albedo", "normal"}
        v = decode_normals(e.maps["normal"])
        assert np.allclose(np.linalg.norm(v, axis=2), 1.0, atol=0.02)
    w.doc.tileset.set_picks([0, 2])
    wait_idle(qtbot, w)
    w.export_dialog()
    dlg = w._export_dialog
    assert dlg.normal.isEnabled()
    dlg.folder.setText(str(tmp_path / "out"))
    with qtbot.waitSignal(dlg.exported, timeout=WAIT_MS):
        dlg.export()
    assert len(list((tmp_path / "out").glob("*_normal.png"))) >= 2
    # a map of the wrong size is refused with a message naming it
    wrong = tmp_path / "wrong_roughness.png"
    Image.fromarray(np.zeros((10, 12), np.uint8)).save(wrong)
    w.files.attach_map(str(wrong))
    qtbot.waitUntil(lambda: "wrong_roughness.png" in w.last_message("error"), timeout=WAIT_MS)
    assert list(w.doc.source.maps) == ["albedo", "normal"]


def test_preview_weight_zero_removes_a_tile_from_the_layout(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 4)
    w.doc.tileset.set_picks([0, 1, 2])
    wait_idle(qtbot, w)
    assert set(np.unique(w.doc.tileset.layout)) == {0, 1, 2}
    w.doc.tileset.set_weight(1, 0.0)  # candidate 1 is the second picked tile (id 1)
    wait_idle(qtbot, w)
    assert 1 not in set(np.unique(w.doc.tileset.layout))
    tip = w.gallery.model().index(1).data(Qt.ItemDataRole.ToolTipRole)
    assert "preview weight 0" in tip  # also drawn as a ×0 tag on the thumbnail


def test_options_persist_between_sessions(qtbot):
    w = make_window(qtbot)
    w.doc.set_param("overlap", 21)
    w.doc.mark_saved()
    w.close()
    assert settings.get("parameters")["overlap"] == 21
    w2 = make_window(qtbot)
    assert w2.doc.params["overlap"] == 21 and w2.params_panel.value("overlap") == 21


def test_seam_weights_of_the_maps_steer_the_cut_undo_and_survive_a_reopen(qtbot, tmp_path):
    from engine.tiles import make_seamless

    w = make_window(qtbot)
    open_sample(qtbot, w)
    box = w.params_panel.materials
    assert not box.isVisible()  # one map: nothing to weigh
    height = np.random.default_rng(3).integers(0, 256, w.doc.source.shape, dtype=np.uint8)
    path = tmp_path / "cobbles_height.png"
    Image.fromarray(height).save(path)
    with qtbot.waitSignal(w.doc.maps_changed, timeout=WAIT_MS):
        w.files.attach_map(str(path))
    assert box.isVisible() and list(box.spins) == ["albedo", "height"]
    assert box.spins["albedo"].value() == 1.0 and box.spins["height"].value() == 0.0
    rect = (150, 120, 128, 112)
    w.doc.tileset.set_template_rect(rect)
    wait_idle(qtbot, w)
    plain = w.doc.tileset.seamless.paths["horizontal"].copy()
    box.spins["height"].setValue(2.0)  # what typing 2 and Enter does
    assert w.doc.undo_stack.undoText() == "Seam weight of height"
    wait_idle(qtbot, w)
    src = w.doc.source
    expected = make_seamless(
        src.main,
        rect,
        overlap=w.doc.tileset.overlap(),
        seam=w.pipeline.seam_spec(),
        maps={"height": src.maps["height"]},
        weights={"main": 1.0, "height": 2.0},
    )
    np.testing.assert_array_equal(
        w.doc.tileset.seamless.paths["horizontal"], expected.paths["horizontal"]
    )
    assert not np.array_equal(plain, expected.paths["horizontal"])
    project = str(tmp_path / "w.quiltproj")
    assert w.files.save_to(project, wait=True)
    w.doc.undo_stack.undo()
    assert box.spins["height"].value() == 0.0 and w.doc.tileset.engine_weights() is None
    with qtbot.waitSignal(w.doc.path_changed, timeout=WAIT_MS):
        w.files.open_path(project, confirm=False)
    assert w.doc.tileset.map_weights == {"height": 2.0} and box.spins["height"].value() == 2.0


def test_quilting_with_material_maps_says_it_makes_the_colour_map_only(qtbot, tmp_path):
    """ux13: with a normal map attached ("it follows every cut"), Synthesize and Save output
    made and wrote the colour map alone without a word."""
    w = make_window(qtbot)
    open_sample(qtbot, w)
    path = tmp_path / "cobbles_normal.png"
    Image.fromarray(normal_map_of(w.doc.source.main.mean(axis=2))).save(path)
    with qtbot.waitSignal(w.doc.maps_changed, timeout=WAIT_MS):
        w.files.attach_map(str(path))
    assert "quilting makes the colour map only" in w.last_message()
    w.doc.set_params({"out_width": 96, "out_height": 96, "block": 32})
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    assert "(the colour map only: the normal map is not quilted)" in w.last_message()
    w.files.save_output(path=str(tmp_path / "out.png"))
    qtbot.waitUntil(lambda: not w.doc.quilting.unsaved, timeout=WAIT_MS)
    text = w.last_message()
    assert text.startswith("Saved the 96×96 output") and "normal map is not quilted" in text
