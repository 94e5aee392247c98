"""A quilting run that cannot start (ux13): the finished output stays, nothing asks to
discard it, the message uses the panel's words, and no stale "quilting…" or block remains."""

from __future__ import annotations

import numpy as np

from tests.gui.helpers import WAIT_MS, make_window, open_sample, wait_idle


def test_options_that_cannot_run_keep_the_output_and_say_so_in_the_panels_words(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"out_width": 128, "out_height": 128, "block": 32})
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    kept = w.doc.quilting.output.copy()
    assert w.doc.quilting.unsaved
    asked = []
    w.files.ask_discard_output = lambda: asked.append(1) or True
    # Bhatia's random blocks with extensions need a cut: "No cut (straight)" cannot run; the
    # parameter change itself restarts the shown output's run, then Synthesize is pressed
    w.doc.set_params({"select": "bhatia", "q_method": "straight"})
    wait_idle(qtbot, w)
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    assert asked == []  # nothing to discard for a run that cannot start
    assert w.doc.quilting.result is not None
    assert np.array_equal(w.doc.quilting.output, kept)  # was a black, empty output
    text = w.last_message("error")
    assert "“Block choice: Random with extensions” needs a cut" in text
    assert "“Cut between blocks”" in text and "select=" not in text
    assert "quilting…" not in w.quilt_view.counter.text()
    # a run the options allow replaces it after asking
    w.doc.set_param("q_method", "resistance")
    wait_idle(qtbot, w)
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    assert asked == [1] and w.doc.quilting.result.select == "bhatia"


def test_a_run_failing_in_its_job_leaves_no_empty_output_saying_quilting(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"out_width": 128, "out_height": 128, "block": 32})
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    w.quilt_view.select(len(w.doc.quilting.blocks) - 1)
    assert w.quilt_view.block_rect.isVisible()
    w.files.ask_discard_output = lambda: True
    # every colour excluded: the job's mask check refuses (the option check cannot see it)
    w.doc.set_params({"exclude_color": "#808080", "exclude_tolerance": 0.5})
    wait_idle(qtbot, w)
    assert "excluded" in w.last_message("error")
    assert w.doc.quilting.output is None and w.quilt_view.counter.text() == ""
    assert not w.quilt_view.block_rect.isVisible()
    assert "Block #" not in w.quilt_view.info.text()  # no caption of a block now gone


def test_opening_another_image_drops_the_output_and_starts_no_quilting(qtbot):
    """ux13: with an output shown, opening another photo quilted the new one at once (its
    cleared exclusion restarted the run: a 2048² job for a large photo nobody asked for) and
    the fresh photo counted as modified; Save output wrote that unasked result."""
    from resources import sample_path

    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"out_width": 96, "out_height": 96, "block": 32})
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    assert w.doc.quilting.result is not None
    started = []
    w.doc.quilting.reset.connect(lambda: started.append(w.doc.quilting.output is not None))
    with qtbot.waitSignal(w.doc.source_changed, timeout=WAIT_MS):
        w.files.open_path(str(sample_path("gravel")), confirm=False)
    wait_idle(qtbot, w)
    assert started == [False] and w.jobs.get("quilt") is None  # one reset: the output dropped
    q = w.doc.quilting
    assert q.output is None and q.result is None and not q.unsaved
    assert not w.doc.modified and not w.act_save_output.isEnabled()
    assert w.quilt_view.output.array is None and w.quilt_view.counter.text() == ""


def test_the_overlap_views_read_out_the_overlap_not_the_composites_display_colours(qtbot):
    """ux13: hovering an error map read "x 77, y 99 = (0, 0, 1020, 65025)": the display
    composite's 8-bit RGBA scaled as if it were [0, 1] pixels."""
    from tests.gui.helpers import template

    w = make_window(qtbot)
    open_sample(qtbot, w)
    template(qtbot, w, rect=(150, 120, 128, 112))
    view = w.overlap_panel.views["horizontal"]
    r1, r2, error = view.panels
    h, wd = view.frame_shape
    (ox1, _), (ox2, _) = view.offsets[1:]
    w._on_hover(view, (5, ox2 + 3))  # the error map's row 5, column 3
    assert w.pixel_label.text() == f"error x 3, y 5: {float(error[5, 3]):.4g}"
    w._on_hover(view, (7, ox1 + 2))  # R_L's pixel, in the file's range
    v = (r2[7, 2] * 255).round().astype(int)
    assert w.pixel_label.text() == f"R_L x 2, y 7 = ({v[0]}, {v[1]}, {v[2]})"
    vertical = w.overlap_panel.views["vertical"]
    w._on_hover(vertical, (1, 1))
    assert w.pixel_label.text().startswith("R_B x 1, y 1 = (")
    w._on_hover(view, None)
    assert w.pixel_label.text() == ""


def test_a_transfer_that_cannot_run_keeps_its_output_and_says_so_in_the_panels_words(
    qtbot, tmp_path
):
    """mend15a: a block overlap as wide as the block restarted the shown transfer, which
    failed in its job: the output went (None), the message in the engine's words
    ("iterations=1 shrinks block 16 to 16 px ..."); pressing Transfer again left it None."""
    from PIL import Image

    from quilt_gui.params import quilt_words

    w = make_window(qtbot)
    open_sample(qtbot, w)
    path = tmp_path / "gray.png"
    Image.fromarray(np.full((48, 64), 128, np.uint8)).save(path)
    with qtbot.waitSignal(w.doc.quilting.target_changed, timeout=WAIT_MS):
        w.files.load_target(str(path))
    w.doc.set_params({"block": 16, "iterations": 1})
    w.act_transfer.trigger()
    wait_idle(qtbot, w)
    kept = w.doc.quilting.output.copy()
    asked = []
    w.files.ask_discard_output = lambda: asked.append(1) or True
    w.doc.set_param("q_overlap", 16)  # restarts the shown transfer: it cannot run
    wait_idle(qtbot, w)
    w.act_transfer.trigger()
    wait_idle(qtbot, w)
    assert asked == []  # nothing to discard for a run that cannot start
    assert w.doc.quilting.result is not None
    assert np.array_equal(w.doc.quilting.output, kept)
    text = w.last_message("error")
    assert "a “Block overlap” of 16 px does not fit a “Block size” of 16 px" in text, text
    assert "iterations=" not in text and "block 16" not in text
    later = (
        "iterations=3 shrinks block 16 to 7 px at iteration 3: use fewer iterations, a larger block"
    )
    assert quilt_words(later) == (
        "“Passes” 3 shrinks the “Block size” 16 to 7 px in pass 3: use fewer “Passes”, a larger "
        "“Block size”"
    )
    w.doc.set_param("q_overlap", 4)  # a transfer the options allow replaces it after asking
    wait_idle(qtbot, w)
    w.act_transfer.trigger()
    wait_idle(qtbot, w)
    assert asked == [1] and len(w.doc.quilting.result.iterations) == 1
