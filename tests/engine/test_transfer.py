import numpy as np
import pytest

from engine import quilting
from engine.cancel import Cancelled, CancelToken
from engine.quilting import BlockPlaced, quilt
from engine.transfer import (
    IterationDone,
    correspondence_map,
    iter_transfer,
    transfer,
    transfer_schedule,
)


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
    """Default schedule: blocks 30, 20, 13 and α 0.1, 0.5, 0.9."""
    res = transfer(cobbles, target, block=30, iterations=3, correspondence=kind, rng=0)
    errs = [it.correspondence_error for it in res.iterations]
    assert len(errs) == 3
    assert errs[0] > errs[1] > errs[2]
    # and transfer follows the target far better than plain synthesis does
    plain = quilt(cobbles, target.shape, block=30, rng=0).image
    cs = correspondence_map(target, kind=kind)
    assert errs[-1] < 0.6 * np.mean((correspondence_map(plain, kind=kind) - cs) ** 2)


def test_same_seed_same_transfer_for_any_thread_count(cobbles, monkeypatch):
    monkeypatch.setattr(quilting, "POOL_MIN_SAMPLE_AREA", 0)
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
    with pytest.raises(ValueError, match="correspondence"):
        iter_transfer(cobbles, disc(), block=24, correspondence="edges")
    with pytest.raises(ValueError, match="larger than the output"):
        iter_transfer(cobbles, disc(10, 10), block=24)
