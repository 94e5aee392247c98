"""Watch the search: the published oscillating search drawn one improvement at a time."""

from __future__ import annotations

import numpy as np

from engine.events import drain
from engine.tiles import SeamlessUpdate, iter_make_seamless
from quilt_gui.widgets.watch_search import INTERVAL_MS, MAX_PER_SECOND, describe_seam
from tests.gui.helpers import WAIT_MS, make_window, open_sample, template, wait_idle

RECT = (150, 120, 128, 112)


def engine_improvements(window, spec) -> list:
    """The improvements the engine streams for the watched tile (non-final updates)."""
    args, kwargs, _ = window.pipeline.seamless_request()
    events = []
    drain(iter_make_seamless(*args, **{**kwargs, "seam": spec}), events.append)
    return [e for e in events if isinstance(e, SeamlessUpdate) and not e.final]


def test_watch_mode_draws_every_improvement_then_keeps_or_goes_back(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    template(qtbot, w, RECT)
    watch = w.overlap_panel.watch
    assert INTERVAL_MS * MAX_PER_SECOND >= 1000  # the pace: at most ~30 drawn a second
    default = w.doc.tileset.seamless
    assert "oscillating" not in w.criterion_label.text() or "published" not in (
        w.criterion_label.text()
    )
    drawn = []
    w.pipeline.seam_updated.connect(lambda u: drawn.append(u))
    watch.timer.setInterval(1)  # the test does not wait for a person's pace
    per_tick = []  # drawn by each timer tick (the first after a pause is drawn at once)

    def counted_tick():
        before = watch.drawn
        type(watch)._tick(watch)
        per_tick.append(watch.drawn - before)

    watch.timer.timeout.disconnect(watch._tick)
    watch.timer.timeout.connect(counted_tick)
    watch.watch_button.click()
    assert watch.state == "watching" and watch.skip_button.isVisible()
    assert "published" in w.criterion_label.text()  # the status bar names the variant
    qtbot.waitUntil(lambda: watch.drawn > 50, timeout=WAIT_MS)
    assert per_tick and max(per_tick) == 1  # one per tick
    assert len(drawn) >= 50 and all(isinstance(u, SeamlessUpdate) for u in drawn)
    watch.skip()  # the rest at once
    qtbot.waitUntil(lambda: watch.state == "finished", timeout=WAIT_MS)
    expected = engine_improvements(w, watch.spec)
    assert watch.drawn == len(expected) > 50  # every improvement reached the queue
    crit = [float(u.seam.criterion) for u in drawn[:50]]
    assert crit == [float(e.seam.criterion) for e in expected[:50]]  # in order, one by one
    assert [len(v) for v in watch.chart.series.values()] == [
        sum(e.which == k for e in expected) for k in ("horizontal", "vertical")
    ]
    chart = watch.chart.series["horizontal"]
    assert chart[-1] < chart[0]  # the criterion falls
    # on screen: the last improvement of each overlap, which is the watched result's seam
    for which in ("horizontal", "vertical"):
        shown = w.overlap_panel.views[which].paths[0].points
        np.testing.assert_array_equal(shown, np.asarray(watch.result.paths[which]))
    assert watch.keep_button.isVisible() and watch.back_button.isVisible()
    # back to the default: the document's seams again
    watch.back_button.click()
    assert watch.state == "idle"
    np.testing.assert_array_equal(
        w.overlap_panel.views["horizontal"].paths[0].points,
        np.asarray(default.paths["horizontal"]),
    )
    assert describe_seam(default.seam) in w.criterion_label.text()
    # watch again and keep: the parameters become the paper's and recompute the same seams
    watch.start()
    watch.skip()
    qtbot.waitUntil(lambda: watch.state == "finished", timeout=WAIT_MS)
    watched = watch.result
    watch.keep_button.click()
    wait_idle(qtbot, w)
    kept = w.doc.tileset.seamless
    assert kept.seam.options["variant"] == "faithful" and kept.seam.options["init"] == "argmin"
    for which in ("horizontal", "vertical"):
        np.testing.assert_array_equal(kept.paths[which], watched.paths[which])
    assert "oscillating as published" in w.criterion_label.text()
    w.act_undo.trigger()
    wait_idle(qtbot, w)
    assert w.doc.params["method"] == default.seam.method


def test_an_edit_abandons_the_watch(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    template(qtbot, w, RECT)
    watch = w.overlap_panel.watch
    watch.start()
    assert watch.state == "watching"
    w.doc.tileset.set_template_rect((140, 110, 128, 112))
    assert watch.state == "idle" and not watch.queue
    wait_idle(qtbot, w)


def test_template_search_draws_its_sweep(qtbot):
    from quilt_gui import params

    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_params({"tile_size": params.ANY, "tile_min": 96, "tile_max": 160})
    wait_idle(qtbot, w)
    sweep = w.source_view.sweep
    seen = []

    def look(event) -> None:  # what the canvas holds as the events arrive
        seen.append((event.phase, event.round, sweep.isVisible(), len(sweep.recent)))

    w.pipeline.template_swept.connect(look)
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert len(seen) > 10 and all(visible for *_, visible, _ in seen)
    assert {(p, r) for p, r, *_ in seen} >= {("horizontal", 0), ("vertical", 0), ("horizontal", 1)}
    assert max(n for *_, n in seen) > 24  # the rectangles of several chunks at once
    assert not sweep.isVisible() and not sweep.recent  # gone when the search ends
    w.pipeline.sweep_samples = 0
    seen.clear()
    w.act_find.trigger()
    wait_idle(qtbot, w)
    assert not seen
