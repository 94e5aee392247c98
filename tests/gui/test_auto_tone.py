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
