"""The parameters panel as an artist meets it (issue 13 items 8, 9, 10, 12)."""

from __future__ import annotations

import re

import numpy as np
from PIL import Image

from quilt_gui import params
from resources import sample_path
from tests.gui.helpers import WAIT_MS, make_window, open_sample, wait_idle

JARGON = re.compile(r"\b(w_T|w_P|rho|o_max|Max run|Tile min|Tile max|sigma|Alpha)\b|ρ")


def choose(panel, key, value) -> None:
    """Pick ``value`` in the combo box of ``key`` as a user does (by its shown text)."""
    box = panel.widgets[key]
    box.setCurrentIndex(box.findData(value))


def test_the_tile_size_control_gives_square_tiles_and_any_searches_the_range(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)  # 512 x 512
    box = w.params_panel.widgets["tile_size"]
    shown = [box.itemText(i) for i in range(box.count())]
    assert shown[0] == "Auto (square)" and shown[-1] == "Any (search)"
    assert [box.itemData(i) for i in range(1, box.count() - 1)] == list(params.TILE_SIZES)
    assert not w.params_panel.widgets["tile_min"].isEnabled()  # only for Any
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (256, 256)  # Auto: square, a power of two
    choose(w.params_panel, "tile_size", "128")  # choosing a size searches again at once
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (128, 128)
    assert w.doc.tileset.seamless.tile.shape[:2] == (128, 128)
    choose(w.params_panel, "tile_size", "any")
    assert w.params_panel.widgets["tile_min"].isEnabled()
    w.params_panel.widgets["tile_min"].setValue(90)
    w.params_panel.widgets["tile_max"].setValue(140)
    wait_idle(qtbot, w)
    _, _, tw, th = w.doc.tileset.template_rect
    assert 90 <= tw <= 140 and 90 <= th <= 140
    while w.doc.params["tile_size"] != "128":  # undo restores, and searches nothing new
        w.doc.undo_stack.undo()
        wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (128, 128) and w.doc.undo_stack.canRedo()


def test_labels_are_plain_words_with_the_papers_on_the_second_line_and_a_basic_view(qtbot):
    w = make_window(qtbot)
    panel = w.params_panel
    for p in params.PARAMS:
        label = panel.labels[p.key]
        assert not JARGON.search(label.text()), p.key
        first = label.toolTip().split("\n")[0]
        assert not re.search(r"Somol|Efros|Long & Mould|Bhatia|CS194", first), p.key
        if p.paper:
            assert label.toolTip().split("\n")[-1] == p.paper
    assert "w_T" in panel.labels["overlap"].toolTip().split("\n")[1]
    assert panel.labels["overlap"].text() == "Seam search width"
    assert panel.labels["rho"].text() == "Blend softness"
    assert panel.view == "Basic"
    basic = set(panel.shown_keys())
    assert {"tile_size", "overlap", "blend", "rho", "n_candidates"} <= basic
    assert not basic & {"o_max", "max_run", "joint_weight", "patch_overlap", "margin"}
    panel.view_buttons.button(1).click()  # Advanced
    advanced = set(panel.shown_keys())
    assert basic < advanced and {"o_max", "patch_overlap", "joint_weight"} <= advanced
    again = make_window(qtbot)  # the choice is remembered
    assert again.params_panel.view == "Advanced"


def test_reset_to_defaults_and_sizes_that_follow_the_image(qtbot, tmp_path):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"tile_size": "512", "overlap": 40, "n_candidates": 7, "rho": 9})
    wait_idle(qtbot, w)
    steps = w.doc.undo_stack.count()
    w.params_panel.reset_button.click()
    wait_idle(qtbot, w)
    for key in ("tile_size", "overlap", "n_candidates", "rho"):
        assert w.doc.params[key] == params.DEFAULTS[key], key
    assert w.doc.undo_stack.count() == steps + 1  # one undo step
    # sizes of a larger image do not follow a small one
    w.doc.set_params({"tile_size": "256", "overlap": 40})
    small = tmp_path / "small.png"
    rng = np.random.default_rng(0)
    Image.fromarray((rng.random((150, 170, 3)) * 255).astype(np.uint8)).save(small)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(small), confirm=False)
    assert w.doc.params["tile_size"] == "auto" and w.doc.params["overlap"] == 0
    assert w.params_panel.widgets["overlap"].text() == "auto"  # not a bare "0"
    assert "Tile size, Seam search width: too large for this image" in w.last_message()
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert w.doc.tileset.template_rect[2:] == (64, 64) and not w.last_message("error")


def test_the_quilting_output_is_twice_the_source_by_default(qtbot, tmp_path):
    w = make_window(qtbot)
    src = tmp_path / "sample.png"
    rng = np.random.default_rng(1)
    Image.fromarray((rng.random((40, 56, 3)) * 255).astype(np.uint8)).save(src)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(src), confirm=False)
    w.doc.set_param("block", 16)
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    assert w.doc.quilting.output.shape[:2] == (80, 112)
    assert params.output_shape(params.DEFAULTS, (3000, 4000)) == (2048, 2048)  # capped
    assert params.output_shape({"out_height": 300, "out_width": 0}, (100, 100)) == (300, 200)


def test_a_choice_name_too_long_for_its_box_ends_with_an_ellipsis(qtbot, monkeypatch):
    """The panel's own Seam shape box paints the name with "…" where it is too narrow (what
    its painter is asked to draw as the box's label is recorded; no style is swapped: a
    recording QProxyStyle set on the box crashed a later event of the popup's frame)."""
    from PySide6.QtWidgets import QStyle, QStylePainter

    from quilt_gui.widgets.params_panel import ElidingComboBox

    labels: list[str] = []
    draw = QStylePainter.drawControl

    def recording(painter, element, opt):
        if element == QStyle.ControlElement.CE_ComboBoxLabel:
            labels.append(opt.currentText)
        draw(painter, element, opt)

    w = make_window(qtbot)
    box = w.params_panel.widgets["method"]  # Seam shape
    assert isinstance(box, ElidingComboBox)
    assert box.currentText() == "Cut across, row by row"
    monkeypatch.setattr(QStylePainter, "drawControl", recording)
    box.resize(300, box.sizeHint().height())
    box.grab()
    assert labels[-1] == box.shown_text() == "Cut across, row by row"
    box.resize(90, box.sizeHint().height())  # the Advanced panel with its scroll bar
    shown = box.shown_text()
    assert shown.endswith("…") and "Cut across, row by row".startswith(shown[:-1])
    box.grab()
    assert labels[-1] == shown  # painted with it


def test_sizes_made_smaller_for_a_tiny_image_come_back_for_the_next(qtbot, tmp_path):
    """ux13: a 40×30 photo set the block size to 15 px ("back to automatic", though it has no
    automatic value) and the next 512 px photo was quilted with 15 px blocks."""
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"tile_size": "256", "block": 48})
    tiny = tmp_path / "tiny.png"
    rng = np.random.default_rng(0)
    Image.fromarray((rng.random((30, 40, 3)) * 255).astype(np.uint8)).save(tiny)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(tiny), confirm=False)
    assert w.doc.params["block"] == 15 and w.doc.params["tile_size"] == "auto"
    text = w.last_message()
    assert "Tile size: too large for this image, back to automatic" in text
    assert "Block size 15 px: the image is too small for more" in text
    wait_idle(qtbot, w)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(sample_path("brick")), confirm=False)
    assert w.doc.params["block"] == 48 and w.doc.params["tile_size"] == "256"
    assert "Tile size 256, Block size 48 again" in w.last_message()
    wait_idle(qtbot, w)
    # a size changed by hand after the fit is the user's: it stays
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(tiny), confirm=False)
    w.doc.set_param("block", 12)
    wait_idle(qtbot, w)
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(sample_path("brick")), confirm=False)
    assert w.doc.params["block"] == 12 and w.doc.params["tile_size"] == "256"
    wait_idle(qtbot, w)
