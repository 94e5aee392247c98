"""Bhatia's published minimum resistance cut line, against a literal reading of the paper.

:func:`paper_cut` follows Bhatia 2004 §2 step by step in the paper's own frame (x to the right,
y up, origin at the block's bottom-left corner), with plain lists and sets, independently of the
engine's numba kernel; the interpretations it shares with the engine are listed in
:mod:`engine.seams.resistance`.
"""

import json
import math

import numpy as np
import pytest
from scipy import ndimage

from engine.seams import find_seam
from engine.seams.resistance import published_lines

# the paper's neighbours of line 1, in its order: left, top-left, top, top-right, right (dx, dy)
LINE1_STEPS = [(-1, 0), (-1, 1), (0, 1), (1, 1), (1, 0)]
# line 2 does "the same exercise" from the top-left corner towards the bottom right
LINE2_STEPS = [(-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)]


def paper_cut(E, max_run, image=None):
    """(line 1, line 2, meeting index, cut) in image (row, col) coordinates; the cut listed
    from the top row down."""
    h, w = E.shape

    def inside(p):
        return 0 <= p[0] < w and 0 <= p[1] < h

    def cost(cur, nxt):  # "differs the least from the current pixel"
        if image is None:
            return E[h - 1 - nxt[1], nxt[0]]
        a, b = image[h - 1 - cur[1], cur[0]], image[h - 1 - nxt[1], nxt[0]]
        s = 0.0
        for k in range(len(a)):
            s += (float(b[k]) - float(a[k])) ** 2
        return math.sqrt(s)

    def straight(line, nxt, axis):
        """Pixels in one row (axis 1) or column (axis 0) at the line's end if it steps to nxt."""
        n = 1
        for p in reversed(line):
            if p[axis] != nxt[axis]:
                break
            n += 1
        return n

    def step(line, steps):
        cur = line[-1]
        best, pick = None, None
        for dx, dy in steps:
            nxt = (cur[0] + dx, cur[1] + dy)
            if not inside(nxt) or nxt in line:
                continue
            if straight(line, nxt, 1) > max_run or straight(line, nxt, 0) > max_run:
                continue
            c = cost(cur, nxt)
            if best is None or c < best:
                best, pick = c, nxt
        assert pick is not None, "a line got stuck: the paper says nothing about that"
        return pick

    # line 1: from the bottom-left corner until the top row or the right column
    line1 = [(0, 0)]
    while line1[-1][1] < h - 1 and line1[-1][0] < w - 1:
        line1.append(step(line1, LINE1_STEPS))

    # line 2: from the top-left corner until it meets line 1: on it (the intersection point),
    # or beside it (4-adjacent: where 8-connected lines could cross without a common pixel)
    def meets(p):
        if p in line1:
            return line1.index(p)
        beside = [q for q in line1 if abs(q[0] - p[0]) + abs(q[1] - p[1]) == 1]
        return min((line1.index(q) for q in beside), default=None)

    line2 = [(0, h - 1)]
    while meets(line2[-1]) is None:
        assert line2[-1][1] > 0, "line 2 reached the bottom row without meeting line 1"
        line2.append(step(line2, LINE2_STEPS))
    m = meets(line2[-1])

    # line 1 beyond the meeting point is discarded; the cut runs corner to corner
    cut = line1[: m + 1] + [p for p in reversed(line2) if p != line1[m]]

    def image_coords(points):
        return [(h - 1 - y, x) for x, y in points]

    return image_coords(line1), image_coords(line2), m, image_coords(cut)[::-1]


def random_map(shape, seed, smooth):
    rng = np.random.default_rng(seed)
    e = rng.random(shape)
    return ndimage.gaussian_filter(e, 1.0) if smooth else e


CASES = [
    (shape, seed, max_run)
    for shape in [(2, 2), (3, 4), (5, 2), (8, 3), (12, 6), (20, 9), (33, 5), (6, 14)]
    for seed in range(4)
    for max_run in (1, 2, 3, 5, 8)
]


@pytest.mark.parametrize("shape", sorted({c[0] for c in CASES}))
def test_published_cut_equals_the_papers_steps(shape):
    for _, seed, max_run in (c for c in CASES if c[0] == shape):
        e = random_map(shape, seed, smooth=seed % 2 == 1)
        line1, line2, m, cut = paper_cut(e, max_run)
        seam = find_seam(e, method="resistance", max_run=max_run)
        assert seam.method == "resistance"
        assert [tuple(p) for p in seam.path.tolist()] == cut, (shape, seed, max_run)
        l1, l2, mm = published_lines(e, max_run=max_run)
        assert [tuple(p) for p in l1.tolist()] == line1
        assert [tuple(p) for p in l2.tolist()] == line2
        assert mm == m


def test_published_cut_with_the_new_blocks_colours_equals_the_papers_steps():
    for seed in range(12):
        shape = (10 + seed, 3 + seed % 5)
        e = np.ones(shape)  # the colours alone decide
        img = np.random.default_rng(seed).random((*shape, 3))
        for max_run in (2, 5):
            *_, cut = paper_cut(e, max_run, image=img)
            seam = find_seam(e, method="resistance", max_run=max_run, image=img)
            assert [tuple(p) for p in seam.path.tolist()] == cut


def test_line2_stops_on_line1_and_the_tail_is_discarded():
    e = np.ones((6, 5))
    for p in [(4, 1), (3, 2), (2, 3), (1, 4)]:  # a cheap diagonal for line 1
        e[p] = 0.0
    e[1, 0] = e[2, 0] = 0.0  # a cheap start down the left column for line 2
    line1, line2, m = published_lines(e, max_run=5)
    assert line1.tolist() == [[5, 0], [4, 1], [3, 2], [2, 3], [1, 4]]  # ends in the right column
    assert line2.tolist() == [[0, 0], [1, 0], [2, 0], [3, 0], [4, 1]]  # steps onto line 1
    assert m == 1
    seam = find_seam(e, method="resistance")
    assert seam.path.tolist() == [[0, 0], [1, 0], [2, 0], [3, 0], [4, 1], [5, 0]]
    tail = {(3, 2), (2, 3), (1, 4)}
    assert not tail & set(map(tuple, seam.path.tolist()))


def test_line2_meets_line1_beside_it_at_line1s_earliest_pixel():
    e = np.ones((6, 5))
    for p in [(4, 0), (3, 0), (2, 1), (0, 3)]:
        e[p] = 0.0
    e[1, 2] = 0.5
    e[0, 1] = e[0, 2] = 0.2
    line1, line2, m = published_lines(e, max_run=5)
    assert line1.tolist() == [[5, 0], [4, 0], [3, 0], [2, 1], [1, 2], [0, 3]]  # to the top row
    # line 2 runs right along the top row; (0, 2) touches line 1 at (1, 2) and (0, 3)
    assert line2.tolist() == [[0, 0], [0, 1], [0, 2]]
    assert m == 4  # the earlier of the two
    seam = find_seam(e, method="resistance")
    assert seam.path.tolist() == [[0, 0], [0, 1], [0, 2], [1, 2], [2, 1], [3, 0], [4, 0], [5, 0]]


@pytest.mark.parametrize("max_run", [2, 3, 5])
def test_straight_runs_are_limited(max_run):
    e = np.ones((20, 6))
    e[:, 0] = 0.0  # the cheapest line would climb the left column
    line1, line2, _ = published_lines(e, max_run=max_run)
    for line in (line1, line2):
        for axis in (0, 1):
            v = line[:, axis].tolist()
            run = longest = 1
            for a, b in zip(v, v[1:], strict=False):
                run = run + 1 if a == b else 1
                longest = max(longest, run)
            assert longest <= max_run
    assert line1[:max_run, 1].tolist() == [0] * max_run and line1[max_run, 1] == 1
    assert np.array_equal(
        find_seam(e, method="resistance", max_run=max_run).path,
        find_seam(e, method="resistance", max_run=max_run, variant="published").path,
    )


def two_regions(mask):
    """R1 (mask) one 4-connected region holding the left edge; R2 one 4-connected region once
    joined by the column beyond its right edge, where R2 continues (the cut may touch the
    overlap's right column, as any seam's may)."""
    r1 = ndimage.label(mask)[1] == 1 and mask[:, 0].all()
    r2 = np.pad(~mask, ((0, 0), (0, 1)), constant_values=True)
    return r1 and ndimage.label(r2)[1] == 1


def test_the_mask_splits_the_overlap_into_two_connected_regions():
    touching = 0
    for shape in [(8, 3), (16, 4), (32, 8), (48, 8), (24, 24), (64, 16)]:
        for seed in range(6):
            e = random_map(shape, seed, smooth=seed % 2 == 0)
            for max_run in (2, 5):
                seam = find_seam(e, method="resistance", max_run=max_run)
                assert seam.path[0].tolist() == [0, 0] and seam.path[-1].tolist() == [
                    shape[0] - 1,
                    0,
                ]
                assert two_regions(seam.mask), (shape, seed, max_run)
                assert (~seam.mask).any()
                if seam.path[:, 1].max() < shape[1] - 1:
                    assert ndimage.label(~seam.mask)[1] == 1  # R2 in one piece in the overlap
                else:
                    touching += 1
    assert touching < 72  # most cuts stay off the right column


def test_pins_and_waypoints():
    rng = np.random.default_rng(3)
    e = ndimage.gaussian_filter(rng.random((40, 12)), 1.0)
    for start, end in [(None, None), (5, None), (None, 11), (11, 0), (3, 7)]:
        for wps in [(), ((10, 6),), ((12, 0), (25, 11), (26, 10))]:
            s = find_seam(e, method="resistance", start=start, end=end, waypoints=wps)
            p = s.path.tolist()
            assert p[0] == [0, start or 0] and p[-1] == [39, end or 0]
            assert all(list(w) in p for w in wps)
            assert np.all(np.abs(np.diff(s.path, axis=0)).max(axis=1) == 1)
            assert len({tuple(q) for q in p}) == len(p)
            assert [p.index(list(w)) for w in wps] == sorted(p.index(list(w)) for w in wps)


def test_narrow_and_tiny_overlaps():
    for shape in [(1, 1), (1, 5), (2, 1), (9, 1), (3, 2)]:
        e = np.random.default_rng(0).random(shape)
        s = find_seam(e, method="resistance", max_run=2)
        assert s.path[0].tolist() == [0, 0] and s.path[-1].tolist() == [shape[0] - 1, 0]
        assert np.all(np.abs(np.diff(s.path, axis=0)).max(axis=1) <= 1)


def test_variant_is_checked():
    with pytest.raises(ValueError, match="variant"):
        find_seam(np.ones((4, 4)), method="resistance", variant="two-lines")


def test_seam_cli_variants(tmp_path, capsys):
    from engine.cli import main
    from engine.errormap import error_map
    from engine.io import load_image, save_image
    from resources import sample_path

    src = load_image(sample_path("cobblestones")).pixels
    r1 = save_image(tmp_path / "r1.png", src[100:164, 40:56])
    r2 = save_image(tmp_path / "r2.png", src[100:164, 200:216])
    e = error_map(load_image(r1).pixels, load_image(r2).pixels)
    paths = {}
    for extra in ([], ["--seam-option", "variant=walk"], ["--seam-option", "variant=published"]):
        assert main(["seam", str(r1), str(r2), "--method", "resistance", "--json", *extra]) == 0
        paths[tuple(extra)] = json.loads(capsys.readouterr().out)["path"]
    assert paths[()] == find_seam(e, method="resistance").path.tolist()
    assert paths[()] == paths[("--seam-option", "variant=published")]
    assert paths[("--seam-option", "variant=walk")] == (
        find_seam(e, method="resistance", variant="walk").path.tolist()
    )
    assert paths[()] != paths[("--seam-option", "variant=walk")]
