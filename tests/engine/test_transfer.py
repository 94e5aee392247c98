import numpy as np
import pytest

from engine.cancel import Cancelled, CancelToken
from engine.io import load_image
from engine.quilting import BlockPlaced, quilt, scheduler
from engine.transfer import (
    IterationDone,
    correspondence_map,
    iter_transfer,
    transfer,
    transfer_schedule,
)
from resources import SAMPLE_NAMES, sample_path


@pytest.fixture(scope="module")
def cobbles():
    from engine.io import load_image
    from resources import sample_path

    return load_image(sample_path("cobblestones")).pixels[:80, :80].copy()


def disc(h=72, w=84):
    yy, xx = np.mgrid[0:h, 0:w]
    return np.where((xx - w / 2) ** 2 + (yy - h / 2) ** 2 < (h / 3) ** 2, 0.9, 0.1).astype(
        np.float32
    )


def gradient(h=72, w=84):
    return np.tile(np.linspace(0, 1, w, dtype=np.float32), (h, 1))


def test_alpha_one_reduces_to_plain_synthesis(cobbles):
    target = disc()
    q = quilt(cobbles, target.shape, block=18, overlap=3, rng=11)
    t = transfer(cobbles, target, block=18, overlap=3, alpha=1.0, iterations=1, rng=11)
    np.testing.assert_array_equal(q.image, t.image)
    assert [r.source for r in q.blocks] == [r.source for r in t.blocks]


@pytest.mark.parametrize("target", [disc(120, 120), gradient(120, 120)], ids=["disc", "gradient"])
@pytest.mark.parametrize("kind", ["luminance", "blurred"])
def test_correspondence_error_falls_with_each_iteration(cobbles, target, kind):
    """Default schedule (blocks 30, 20, 13; α 0.1, 0.5, 0.9) on cobblestones, 120 px targets:
    the error falls at every pass (seeds 0..7 of every case here, measured when this was
    written; the test runs seed 0). Not a law of the method: the last pass weighs texture 9:1
    against correspondence and often raises the error a little on other settings (next test)."""
    res = transfer(cobbles, target, block=30, iterations=3, correspondence=kind, rng=0)
    errs = [it.correspondence_error for it in res.iterations]
    assert len(errs) == 3
    assert errs[0] > errs[1] > errs[2]
    # and transfer follows the target far better than plain synthesis does
    plain = quilt(cobbles, target.shape, block=30, rng=0).image
    cs = correspondence_map(target, kind=kind)
    assert errs[-1] < 0.6 * np.mean((correspondence_map(plain, kind=kind) - cs) ** 2)


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_correspondence_error_falls_on_every_sample_while_alpha_stays_moderate(name):
    """On every bundled sample the error falls at each of N = 3 passes with α rising 0.1 → 0.7
    (seeds 0..7, disc and gradient: 80 of 80 cases, measured; the test runs seed 1). With the
    default ramp to α = 0.9 the same runs fail in 40 of 80 cases, always on the last pass
    (+0.1 to +6.4 %), as do 6 of 8 seeds with N = 4 on the 120 px disc: the last pass trades
    correspondence for texture coherence. That is the α schedule's nature (ending at 0.7 removes
    it), so the acceptance line holds for moderate final α, not for the paper's 0.9 in general."""
    px = load_image(sample_path(name)).pixels[:80, :80]
    s = np.repeat(px, 3, axis=2) if px.shape[2] == 1 else px[..., :3]
    for target in (disc(96, 96), gradient(96, 96)):
        res = transfer(s, target, block=24, iterations=3, alpha=(0.1, 0.7), rng=1)
        errs = [it.correspondence_error for it in res.iterations]
        assert errs[0] > errs[1] > errs[2], errs


def test_same_seed_same_transfer_for_any_thread_count(cobbles, monkeypatch):
    monkeypatch.setattr(scheduler, "POOL_MIN_SAMPLE_AREA", 0)
    kw = dict(block=20, iterations=2, rng=4)
    a = transfer(cobbles, disc(), threads=1, **kw)
    b = transfer(cobbles, disc(), threads=2, **kw)
    np.testing.assert_array_equal(a.image, b.image)


def test_schedule_does_not_compound():
    sched = transfer_schedule(30, 3)
    assert [b for b, _, _ in sched] == [30, 20, 13]  # 30·(2/3)^i, not 30·2^i//3^i chained
    assert [ov for _, ov, _ in sched] == [5, 3, 2]
    np.testing.assert_allclose([a for _, _, a in sched], [0.1, 0.5, 0.9])
    assert [a for *_, a in transfer_schedule(30, 2, alpha=0.3)] == [0.3, 0.3]
    np.testing.assert_allclose(
        [a for *_, a in transfer_schedule(30, 3, alpha=(0.2, 0.6))], [0.2, 0.4, 0.6]
    )
    assert [ov for _, ov, _ in transfer_schedule(30, 2, overlap=9)] == [9, 6]


def test_costs_are_normalised_terms_checked_by_brute_force(cobbles):
    """First block: only the correspondence term (exact minimum over all windows); second block:
    overlap SSD + r · correspondence SSD with r = ((1-α)/(h w)) / (α/(|M| C))."""
    sample = cobbles[:40, :40]
    target = gradient(30, 30)
    alpha, b, ov = 0.4, 12, 3
    gen = iter_transfer(
        sample, target, block=b, overlap=ov, alpha=alpha, iterations=1, rng=2, threads=1
    )
    placed = [e for e in gen if isinstance(e, BlockPlaced)]
    cs, ct = correspondence_map(sample), correspondence_map(target)
    n = 40 - b + 1
    corr = np.array(
        [[((cs[y : y + b, x : x + b] - ct[:b, :b]) ** 2).sum() for x in range(n)] for y in range(n)]
    )
    first = placed[0].record
    assert first.best_error == pytest.approx(corr.min(), rel=1e-4, abs=1e-4)
    x, y = first.source[:2]
    assert corr[y, x] <= 1.1 * corr.min() + 1e-4
    second = placed[1].record
    assert second.position == (0, b - ov)
    old = placed[0].pixels[:, b - ov :]
    ct2 = ct[:b, b - ov : 2 * b - ov]
    m = second.overlap
    r = ((1 - alpha) / (b * b)) / (alpha / (m.sum() * 3))
    cost = np.array(
        [
            [
                ((sample[yy : yy + b, xx : xx + b][:, :ov] - old) ** 2).sum()
                + r * ((cs[yy : yy + b, xx : xx + b] - ct2) ** 2).sum()
                for xx in range(n)
            ]
            for yy in range(n)
        ]
    )
    assert second.best_error == pytest.approx(cost.min(), rel=1e-4, abs=1e-3)
    x2, y2 = second.source[:2]
    assert second.match_error == pytest.approx(cost[y2, x2], rel=1e-4, abs=1e-3)


def test_previous_iteration_is_frozen_and_matched(cobbles):
    target = disc()
    events = list(iter_transfer(cobbles, target, block=24, iterations=2, alpha=1.0, rng=3))
    its = [e for e in events if isinstance(e, IterationDone)]
    assert [it.iteration for it in its] == [1, 2]
    assert not its[0].image.flags.writeable
    assert its[0].image is not its[1].image
    # with α = 1 the second pass is pulled toward the first by the previous-iteration term
    d_prev = np.mean(np.abs(its[1].image - its[0].image))
    fresh = quilt(cobbles, target.shape, block=16, rng=3).image
    assert d_prev < 0.7 * np.mean(np.abs(fresh - its[0].image))


def test_transfer_cancel_and_errors(cobbles):
    token = CancelToken()
    gen = iter_transfer(cobbles, disc(), block=24, iterations=2, rng=0, cancel=token)
    next(gen)
    token.cancel()
    with pytest.raises(Cancelled):
        list(gen)
    with pytest.raises(ValueError, match="alpha"):
        iter_transfer(cobbles, disc(), block=24, alpha=1.5)
    with pytest.raises(ValueError, match="iterations"):
        iter_transfer(cobbles, disc(), block=12, iterations=6)
    with pytest.raises(ValueError, match="overlap 11 to 5 px at iteration 3.*smaller overlap"):
        iter_transfer(cobbles, disc(), block=12, overlap=11, iterations=3)
    with pytest.raises(ValueError, match="correspondence"):
        iter_transfer(cobbles, disc(), block=24, correspondence="edges")
    with pytest.raises(ValueError, match="larger than the output"):
        iter_transfer(cobbles, disc(10, 10), block=24)


def test_second_iteration_cost_with_the_previous_term_by_brute_force(cobbles):
    """Iteration 2: cost = α (overlap SSD / (|M| C) + SSD to iteration 1's output / (h w C))
    + (1 − α) SSD(correspondence) / (h w), for every window; the records hold it divided by
    the overlap term's weight (the largest weight when a block has no overlap)."""
    sample = cobbles[:36, :36].astype(np.float64)
    target = disc(26, 26)
    events = list(
        iter_transfer(
            cobbles[:36, :36],
            target,
            block=12,
            overlap=3,
            alpha=(0.3, 0.6),
            iterations=2,
            rng=5,
            threads=1,
        )
    )
    done = [i for i, e in enumerate(events) if isinstance(e, IterationDone)]
    prev = events[done[0]].image.astype(np.float64)
    placed = [e.record for e in events[done[0] + 1 :] if isinstance(e, BlockPlaced)]
    b, a, c = 8, 0.6, 3
    cs, ct = correspondence_map(sample), correspondence_map(target)
    n = 36 - b + 1
    win = np.lib.stride_tricks.sliding_window_view(sample, (b, b, c))[:, :, 0]  # (n, n, b, b, c)
    cwin = np.lib.stride_tricks.sliding_window_view(cs, (b, b))
    assert win.shape[:2] == (n, n)
    canvas = np.zeros((26, 26, 3))
    filled = np.zeros((26, 26), bool)
    for r in placed[:3]:
        (y0, x0), (h, w) = r.position, r.size
        assert (h, w) == (b, b)
        m = filled[y0 : y0 + h, x0 : x0 + w]
        old = canvas[y0 : y0 + h, x0 : x0 + w]
        ssd_prev = ((win - prev[y0 : y0 + h, x0 : x0 + w]) ** 2).sum(axis=(2, 3, 4))
        ssd_corr = ((cwin - ct[y0 : y0 + h, x0 : x0 + w]) ** 2).sum(axis=(2, 3))
        w_prev, w_corr = a / (h * w * c), (1 - a) / (h * w)
        cost = w_prev * ssd_prev + w_corr * ssd_corr
        ref = max(w_prev, w_corr)
        if m.any():
            cost += a / (m.sum() * c) * ((win - old) ** 2)[:, :, m].sum(axis=(2, 3))
            ref = a / (m.sum() * c)
        assert r.best_error * ref == pytest.approx(cost.min(), rel=1e-4)
        assert (w_prev * ssd_prev).mean() > 0.05 * cost.mean()  # the term is not negligible
        x, y = r.source[:2]
        assert r.match_error * ref == pytest.approx(cost[y, x], rel=1e-4)
        canvas[y0 : y0 + h, x0 : x0 + w][~r.keep_old if r.keep_old is not None else ...] = sample[
            y : y + h, x : x + w
        ][~r.keep_old if r.keep_old is not None else ...]
        filled[y0 : y0 + h, x0 : x0 + w] = True


def test_large_sample_transfer_takes_the_pyramid_identically_on_any_thread_count(monkeypatch):
    """A sample over 256² in fast mode: the coarse-to-fine search with the correspondence map as
    one more channel; every pass's cost re-ranked exactly, the same output on 1 and 2 threads,
    and the correspondence improves as on the exact search."""
    from engine.quilting import Estimated
    from engine.transfer import iter_transfer
    from tests.engine.helpers import events_and_result, smooth_texture

    monkeypatch.setattr(scheduler, "POOL_MIN_SAMPLE_AREA", 0)
    s = smooth_texture((320, 320), seed=2, sigma=3.0)
    target = disc(90, 90)
    kw = dict(block=24, iterations=2, rng=5, mode="fast")
    events, a = events_and_result(iter_transfer(s, target, threads=1, **kw))
    assert events[0].plan.search == "pyramid" and isinstance(events[0], Estimated)
    b = transfer(s, target, threads=2, **kw)
    np.testing.assert_array_equal(a.image, b.image)
    exact = transfer(s, target, block=24, iterations=2, rng=5, mode="exact")
    err = [it.correspondence_error for it in a.iterations]
    assert err[-1] <= 1.25 * exact.iterations[-1].correspondence_error
