"""Quilting mode: blocks stream onto the canvas, inspection, supersede, exclusion."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, Qt

from tests.gui.helpers import WAIT_MS, drag, make_window, open_sample, wait_idle


def small(w, **extra):
    w.doc.set_params({"out_width": 160, "out_height": 128, "block": 32, **extra})


def test_blocks_stream_in_and_a_click_inspects_one(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    small(w)
    placed = []
    w.doc.quilting.block_placed.connect(placed.append)
    w.act_quilt.trigger()
    assert w.tabs.currentWidget() is w.quilt_view
    assert w.params_panel.groups["Quilting"].isVisible()
    assert not w.params_panel.groups["Tile"].isVisible()
    wait_idle(qtbot, w)
    res = w.doc.quilting.result
    assert res is not None and res.image.shape[:2] == (128, 160)
    assert placed == list(range(len(res.blocks)))  # one event per block, in order
    assert np.array_equal(w.quilt_view.output.array, res.image)
    # click on a block of the output (a click, not a drag)
    rec = res.blocks[7]
    (r, c), (h, wd) = rec.position, rec.size
    out = w.quilt_view.output
    out.fit()
    pos = out.mapFromScene(QPointF(c + wd - 3.5, r + h - 3.5))
    qtbot.mouseClick(out.viewport(), Qt.MouseButton.LeftButton, pos=pos)
    assert w.quilt_view.selected == w.doc.quilting.block_at(r + h - 4, c + wd - 4)
    sel = res.blocks[w.quilt_view.selected]
    assert w.quilt_view.inspector.frame_shape == tuple(sel.size)
    assert f"Block #{sel.index + 1}" in w.quilt_view.info.text()
    assert w.quilt_view.source_rect.rect().getRect() == tuple(float(v) for v in sel.source)
    # the status bar's seam criterion is the inspected block's here, the template's elsewhere
    cut = next(b for b in res.blocks if len(b.path))
    w.quilt_view.select(cut.index)
    assert w.criterion_label.text() == f"block #{cut.index + 1} seam {cut.criterion:.3f}"
    w.tabs.setCurrentWidget(w.source_view)
    assert "block" not in w.criterion_label.text()


def test_parameter_change_restarts_quilting_without_stale_blocks(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    small(w, out_width=256, out_height=256)
    w.act_quilt.trigger()
    qtbot.waitUntil(lambda: len(w.doc.quilting.blocks) >= 2, timeout=WAIT_MS)
    first = w.jobs.get("quilt")
    w.doc.set_param("block", 24)
    assert not first.alive
    wait_idle(qtbot, w)
    res = w.doc.quilting.result
    assert res.block == (24, 24)
    assert all(max(b.size) <= 24 for b in w.doc.quilting.blocks)
    assert np.array_equal(w.doc.quilting.output, res.image)


def test_excluded_colour_is_never_copied(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    small(w, select="random")
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    sample = w.quilt_view.sample
    src = w.doc.source.main
    row, col = np.unravel_index(np.argmin(src.sum(axis=2)), src.shape[:2])  # the darkest pixel
    w.quilt_view._on_sample_clicked((int(row), int(col)), Qt.KeyboardModifier.ControlModifier)
    assert w.doc.params["exclude_color"].startswith("#") and w.doc.params["exclude_tolerance"] > 0
    assert w.quilt_view.excluded.isVisible()
    wait_idle(qtbot, w)  # the change restarted the synthesis
    from quilt_gui.job_bodies import excluded_mask

    mask = excluded_mask(src, w.doc.params["exclude_color"], w.doc.params["exclude_tolerance"])
    assert mask.any()
    for b in w.doc.quilting.result.blocks:
        x, y, bw, bh = b.source
        assert not mask[y : y + bh, x : x + bw].any()
    assert sample.array is src


def test_texture_transfer_streams_passes_and_follows_the_target(qtbot, tmp_path):
    from PIL import Image

    w = make_window(qtbot)
    open_sample(qtbot, w)
    yy, xx = np.mgrid[0:96, 0:128]
    target = np.where((xx - 64) ** 2 + (yy - 48) ** 2 < 30**2, 230, 25).astype(np.uint8)
    path = tmp_path / "disc.png"
    Image.fromarray(target).save(path)
    with qtbot.waitSignal(w.doc.quilting.target_changed, timeout=WAIT_MS):
        w.files.load_target(str(path))
    assert w.quilt_view.target.array.shape[:2] == (96, 128)
    w.doc.set_params({"block": 24, "iterations": 2})
    passes = []
    w.doc.quilting.iteration_finished.connect(passes.append)
    w.act_transfer.trigger()
    wait_idle(qtbot, w)
    res = w.doc.quilting.result
    assert passes == [1, 2] and len(res.iterations) == 2
    assert res.image.shape[:2] == (96, 128)
    lum = res.image[:, :, :3].mean(axis=2)
    inside = (xx - 64) ** 2 + (yy - 48) ** 2 < 20**2
    outside = (xx - 64) ** 2 + (yy - 48) ** 2 > 40**2
    assert lum[inside].mean() > lum[outside].mean() + 0.1  # the disc shows through
    assert "transfer passes" in w.quilt_view.counter.text()
    w.doc.set_param("alpha_ramp", False)  # a parameter change re-runs the transfer
    wait_idle(qtbot, w)
    assert w.doc.quilting.result is not res and len(w.doc.quilting.result.iterations) == 2
    w.doc.quilting.set_target(w.doc.source.main)  # 512 px: long enough to stop midway
    w.doc.set_params({"iterations": 3, "block": 32})
    running = lambda: w.jobs.get("quilt") is not None and len(w.doc.quilting.blocks) > 0  # noqa: E731
    qtbot.waitUntil(running, timeout=WAIT_MS)
    w.act_cancel.trigger()
    wait_idle(qtbot, w)
    assert w.last_message().startswith("Texture transfer cancelled after")


def test_painted_exclusion_is_one_undo_step_and_never_copied(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    small(w, select="random")
    w.tabs.setCurrentWidget(w.quilt_view)
    s = w.quilt_view.sample
    s.set_zoom(1.0)
    s.center_on_pixel(256, 256)
    w.doc.set_param("brush", 6)
    n0 = w.doc.undo_stack.count()
    a = s.view_pos_of_pixel(200, 150).toPoint()
    b = s.view_pos_of_pixel(260, 330).toPoint()
    drag(qtbot, s, a, b, steps=7)  # Shift+drag paints
    mask = w.doc.exclude_painted
    assert w.doc.undo_stack.count() == n0 + 1
    assert mask[200, 150] and mask[260, 330] and mask[230, 240] and not mask[100, 100]
    assert w.quilt_view.excluded.isVisible()
    w.act_quilt.trigger()
    wait_idle(qtbot, w)
    for blk in w.doc.quilting.result.blocks:
        x, y, bw, bh = blk.source
        assert not mask[y : y + bh, x : x + bw].any()
    w.doc.undo_stack.undo()
    assert w.doc.exclude_painted is None and not w.quilt_view.excluded.isVisible()


def test_quilting_job_carries_the_engine_estimate_for_the_status_bar(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    small(w)
    w.act_quilt.trigger()
    job = w.jobs.get("quilt")
    assert job is not None
    qtbot.waitUntil(lambda: job.estimate != "", timeout=WAIT_MS)
    # the plan's words (search, time, memory) are what the status bar shows until a rate is known
    assert job.estimate.startswith("estimate: ") and "search" in job.estimate
    assert "about" in job.estimate and "peak memory" in job.estimate
    wait_idle(qtbot, w)


def test_the_inspector_says_why_a_block_has_no_cut():
    """A block that continues its neighbours' sample exactly gets no cut from the engine: the
    caption says so instead of calling it a straight overlap."""
    from types import SimpleNamespace

    from quilt_gui.widgets.quilt_view import seam_text

    zero, some = np.zeros((4, 4), np.float32), np.ones((4, 4), np.float32)
    keep = np.zeros((4, 4), bool)
    block = SimpleNamespace(path=(), arms=(2, 2, 0, 0), error=zero, keep_old=keep)
    assert seam_text(block).startswith("no cut needed")
    assert seam_text(SimpleNamespace(**{**vars(block), "error": some})) == (
        "straight overlap (no cut)"
    )
    first = SimpleNamespace(path=(), arms=(0, 0, 0, 0), error=None, keep_old=None)
    assert seam_text(first) == "no overlap (first block)"
    cut = SimpleNamespace(**{**vars(block), "path": [(0, 1)], "criterion": 1.5, "peak": 0.25})
    assert seam_text(cut) == "seam criterion 1.500, peak 0.250"
