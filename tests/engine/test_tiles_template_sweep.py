"""The template search streams a sample of the rectangles it scores (``sweep``)."""

import numpy as np

from engine.tiles import TemplateSweep, TemplateUpdate, find_template, iter_find_template
from engine.tiles.detail import DETAIL_WEIGHT
from tests.engine.helpers import events_and_result
from tests.engine.test_tiles_template import brute_detail_penalty, dist, periodic


def phase_cost(S, rect, w, phase, lam):
    """The cost a phase gives ``rect``: its strip mismatch and wrap-joint step over the
    phase's rows (horizontal) or the rectangle's footprint columns (vertical), and the detail
    term of its footprint."""
    detail = brute_detail_penalty(S, rect, w, DETAIL_WEIGHT)
    x, y, a, b = rect
    if phase == "vertical":
        S = S[:, x : x + a + w].transpose(1, 0, 2)
        x, y, a, b = y, 0, b, a
    rows = slice(y, y + b + w)
    d = dist(S[rows, x : x + w], S[rows, x + a : x + a + w]).mean()
    return d + lam * dist(S[rows, x + a - 1], S[rows, x + a]).mean() + detail


def test_sweep_events_sample_the_scored_rectangles():
    S = periodic(shape=(90, 100))
    kw = dict(tile_min=20, tile_max=40, overlap=4, joint_weight=0.5)
    plain_events, plain = events_and_result(iter_find_template(S, **kw))
    events, tmpl = events_and_result(iter_find_template(S, sweep=12, **kw))
    assert not any(isinstance(e, TemplateSweep) for e in plain_events)
    assert tmpl == plain  # the sweep only watches
    updates = [e for e in events if isinstance(e, TemplateUpdate)]
    assert updates == [e for e in plain_events if isinstance(e, TemplateUpdate)]
    sweeps = [e for e in events if isinstance(e, TemplateSweep)]
    assert {e.phase for e in sweeps} == {"horizontal", "vertical"}
    assert {e.round for e in sweeps} >= {0, 1}  # the search and a refinement round
    H, W = S.shape[:2]
    for e in sweeps:
        assert 1 <= len(e.rects) <= 13 and e.rects.shape[1] == 4 and not e.rects.flags.writeable
        assert e.overlap == 4 and not e.coarse
        x, y, a, b = e.rects.T
        assert (x >= 0).all() and (y >= 0).all() and (x + a + 4 <= W).all()
        assert (y + b + 4 <= H).all()
        for rect, cost in zip(e.rects.tolist(), e.costs, strict=True):
            assert np.isclose(cost, phase_cost(S, rect, 4, e.phase, 0.5))
        assert e.best_cost <= e.costs.min() + 1e-12
    # within a phase the best so far only improves
    for a, b in zip(sweeps, sweeps[1:], strict=False):
        if (a.phase, a.round) == (b.phase, b.round):
            assert b.best_cost <= a.best_cost
    # each phase ends with its own best, the search's choice (here the first one's columns)
    first = [e for e in sweeps if (e.phase, e.round) == ("horizontal", 0)][-1]
    assert first.best[0] == updates[0].rect[0] and first.best[2] == updates[0].rect[2]


def test_coarse_sweep_is_scaled_to_the_source():
    S = periodic(shape=(160, 180))
    events, tmpl = events_and_result(
        iter_find_template(S, tile_min=40, tile_max=70, overlap=6, coarse=2, sweep=8)
    )
    sweeps = [e for e in events if isinstance(e, TemplateSweep)]
    coarse = [e for e in sweeps if e.coarse]
    assert coarse and [e for e in sweeps if not e.coarse]
    for e in coarse:
        assert (e.rects % 2 == 0).all() and e.overlap == 6
        assert (e.rects[:, 0] + e.rects[:, 2] + e.overlap <= 180 + 2).all()
    assert tmpl == find_template(S, tile_min=40, tile_max=70, overlap=6, coarse=2)
