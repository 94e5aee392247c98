"""Bhatia's minimum resistance cut line (Bhatia 2004 §2, ALGORITHMS §4), two variants.

Both run in the canonical seam frame of :mod:`engine.seams` (rows top to bottom, R1 kept on the
left, R2 on the right) and pick each step by a *step cost*: given the new block's colours
``image``, the colour distance between the current pixel and the candidate ("a pixel that
differs the least from the current pixel ... in a selected color space", the paper's rule);
without it, the error of the pixel stepped on (the error map is all a seam method is given).
A straight run is at most ``max_run`` consecutive pixels in one row or one column.

``variant="published"`` (default): the paper's two-line construction
    The paper's cut "along the left edge" runs between the block's bottom-left and top-left
    corners; here those are the overlap's pixels (h - 1, 0) and (0, 0), or (h - 1, end) and
    (0, start) when pinned.

    1. *Line 1* starts at the bottom-left corner and steps "towards the top right" to the
       cheapest of its left, top-left, top, top-right and right neighbours ("the pixels below
       the current pixel are ignored"); it stops on reaching the top row or the right column
       ("the last pixel on the texture toward top or right edge").
    2. *Line 2* starts at the top-left corner and does "the same exercise ... moving toward
       bottom right": the mirrored neighbours left, bottom-left, bottom, bottom-right, right.
       It stops where it meets line 1.
    3. Line 1's part beyond the meeting point is discarded; the cut is line 1 from the
       bottom-left corner to the meeting point joined to line 2 back to the top-left corner
       (listed here from the top row down). R1's territory (:attr:`Seam.mask`) is the region
       between the overlap's left edge and the cut, the cut included.

    The bottom edge ("created in a similar manner") is the same construction on the transposed
    block; :mod:`engine.quilting` does that, and orients both bands so that line 1 starts at
    the corner the block shares with the blocks already placed, as the paper's blocks grow
    from their bottom-left corner. The blend "of the pixels around the cut line" is the
    caller's (quilting's territory blend, or :func:`engine.blend.blend_weights`).

    Where the text had to be interpreted (each choice is ours):

    * *Step cost*: see above; the paper has no error map, its cut is traced in the new block.
    * *Run limit*: "no more than a predefined number of pixels in a given row or column" and
      "the maximum length of the straight lines ... in vertical or horizontal direction"
      (5 in its Figure 3) are read as *consecutive* pixels: a line may hold at most
      ``max_run`` pixels in a row before leaving it, and at most ``max_run`` in a column; a
      diagonal step ends both runs. (Read as a total per row and column, a line climbing h
      rows would need h / max_run columns, which contradicts "a smaller length will bring
      the cut line closer to the edge".)
    * *No turning back*: a line never steps onto its own pixels (with no downward step for
      line 1 that only forbids reversing along a row); the text does not say so, but a
      "line" that doubles back on itself is no line.
    * *Ties*: the first of the neighbours in the paper's order (left, top-left, top,
      top-right, right; mirrored for line 2).
    * *Meeting*: 8-connected lines can cross diagonally without sharing a pixel, so line 2
      meets line 1 on the first pixel that lies on line 1 *or is 4-adjacent to it*
      (one cannot cross the other without such a pixel). The meeting point is that pixel
      when it is on line 1, else the earliest pixel of line 1 4-adjacent to it.
    * *The block*: the seam method sees only the overlap it is given (quilting gives the band
      of ``overlap`` pixels along the edge), so "the top or right edge" is the overlap's.
    * *Stuck lines*: with the corners as ends a line always has an allowed step (this is
      checked by the literal re-implementation in the tests). With pinned ends, waypoints or
      a one-pixel-wide overlap it may not: line 1 then steps up (up-left, up-right) or ends,
      line 2 steps down; a line 2 that reaches the bottom row before meeting line 1 walks
      along that row to it.

    Waypoints (our extension) split the rows into segments between consecutive anchors;
    each segment is built as above (its top anchor starts line 2, its bottom anchor line 1),
    off the pixels of the segments above it.

``variant="walk"``: one greedy walk from the top row down
    From the start pixel (the cheapest of row 0 unless pinned) the walk repeatedly steps to
    the cheapest allowed neighbour among down, down-left, down-right, left and right (never
    up): inside the map, not visited before, within the run limit, and — towards a pinned
    point (end or waypoint) — inside the cone of pixels from which it stays reachable. When
    nothing is allowed it steps down (diagonally towards a pinned point when the cone demands
    it). It ends on reaching the bottom row or the pinned end point. An overlap strip's ends
    are free in this variant; ``start`` / ``end`` pin a corner-to-corner cut.
"""

from __future__ import annotations

import numpy as np

from engine._jit import njit

# walk: down, down-left, down-right, left, right
_DR = np.array([1, 1, 1, 0, 0], dtype=np.int64)
_DC = np.array([0, -1, 1, -1, 1], dtype=np.int64)
# published, in the paper's order: left, top-left, top, top-right, right (line 1; line 2 mirrors
# the rows: left, bottom-left, bottom, bottom-right, right)
_PR = np.array([0, -1, -1, -1, 0], dtype=np.int64)
_PC = np.array([-1, -1, 0, 1, 1], dtype=np.int64)
_PR2 = -_PR


@njit(cache=True, nogil=True)
def _step_cost(error, image, use_image, r, c, nr, nc):
    if not use_image:
        return error[nr, nc]
    s = 0.0
    for k in range(image.shape[2]):
        d = image[nr, nc, k] - image[r, c, k]
        s += d * d
    return np.sqrt(s)


@njit(cache=True, nogil=True)
def _runs_after(dr, dc, row_run, col_run):
    """(row run, column run) after a step (dr, dc): a sideways step extends the row run, an
    upright one the column run, a diagonal one ends both."""
    if dr == 0:
        return row_run + 1, 1
    if dc == 0:
        return 1, col_run + 1
    return 1, 1


# ----------------------------------------------------------------------------- walk
@njit(cache=True, nogil=True)
def _walk(error, image, use_image, start, trow, tcol, max_run, path):
    """Walk through the targets (trow[k], tcol[k]); tcol = -1 means any pixel of that row.

    ``start`` < 0 picks the cheapest pixel of row 0 inside the first target's cone.
    Writes the pixels to ``path`` and returns their number.
    """
    h, w = error.shape
    visited = np.zeros((h, w), dtype=np.bool_)
    r = 0
    c = start
    if c < 0:
        best = np.inf
        for i in range(w):
            if tcol[0] >= 0 and abs(i - tcol[0]) > trow[0]:
                continue
            if error[0, i] < best:
                best = error[0, i]
                c = i
    n = 0
    path[n, 0] = r
    path[n, 1] = c
    n += 1
    visited[r, c] = True
    row_run = 1
    col_run = 1
    for k in range(trow.shape[0]):
        tr = trow[k]
        tc = tcol[k]
        while not (r == tr and (tc < 0 or c == tc)):
            best = np.inf
            pick = -1
            for d in range(5):
                nr = r + _DR[d]
                nc = c + _DC[d]
                if nr > tr or nc < 0 or nc >= w or visited[nr, nc]:
                    continue
                rr, cr = _runs_after(_DR[d], _DC[d], row_run, col_run)
                if rr > max_run or cr > max_run:
                    continue
                outside = tc >= 0 and (tr - nr) < abs(nc - tc)
                # outside the target's cone only a sideways step that gets closer is allowed
                if outside and not (_DR[d] == 0 and abs(nc - tc) < abs(c - tc)):
                    continue
                v = _step_cost(error, image, use_image, r, c, nr, nc)
                if v < best:
                    best = v
                    pick = d
            if pick >= 0:
                nr = r + _DR[pick]
                nc = c + _DC[pick]
            elif r < tr:
                nr = r + 1
                nc = c
                if tc >= 0 and (tr - nr) < abs(tc - c):
                    nc = c + (1 if tc > c else -1)
            else:
                nr = r
                nc = c + (1 if tc > c else -1)
            row_run, col_run = _runs_after(nr - r, nc - c, row_run, col_run)
            r = nr
            c = nc
            visited[r, c] = True
            path[n, 0] = r
            path[n, 1] = c
            n += 1
    return n


# ----------------------------------------------------------------------------- published
@njit(cache=True, nogil=True)
def _cheapest(error, image, use_image, r, c, drs, dcs, taken, blocked, row_run, col_run, max_run):
    """The cheapest allowed step (drs[d], dcs[d]) from (r, c), the first of equals; -1 if none.

    Allowed: inside the map, not on the line itself (``taken``) nor ``blocked``, and both
    straight runs within ``max_run``."""
    h, w = error.shape
    best = np.inf
    pick = -1
    for d in range(drs.shape[0]):
        nr = r + drs[d]
        nc = c + dcs[d]
        if nr < 0 or nr >= h or nc < 0 or nc >= w or taken[nr, nc] > 0 or blocked[nr, nc]:
            continue
        rr, cr = _runs_after(drs[d], dcs[d], row_run, col_run)
        if rr > max_run or cr > max_run:
            continue
        v = _step_cost(error, image, use_image, r, c, nr, nc)
        if v < best:
            best = v
            pick = d
    return pick


@njit(cache=True, nogil=True)
def _line1(error, image, use_image, ra, rb, cb, blocked, max_run, on1, line):
    """Line 1 of the segment rows ra..rb from (rb, cb) towards the top right; stops on row ra or
    the right column. Marks ``on1`` with 1-based indices; returns its length."""
    w = error.shape[1]
    r = rb
    c = cb
    n = 0
    line[n, 0] = r
    line[n, 1] = c
    n += 1
    on1[r, c] = n
    row_run = 1
    col_run = 1
    while r > ra and c < w - 1:
        pick = _cheapest(
            error, image, use_image, r, c, _PR, _PC, on1, blocked, row_run, col_run, max_run
        )
        if pick < 0:  # stuck: up, up-left, up-right, or end here
            for d in (2, 1, 3):
                nc = c + _PC[d]
                if 0 <= nc < w and not blocked[r - 1, nc]:
                    pick = d
                    break
            if pick < 0:
                break
        row_run, col_run = _runs_after(_PR[pick], _PC[pick], row_run, col_run)
        r += _PR[pick]
        c += _PC[pick]
        line[n, 0] = r
        line[n, 1] = c
        n += 1
        on1[r, c] = n
    return n


@njit(cache=True, nogil=True)
def _touch(on1, r, c):
    """1-based index of the line-1 pixel that (r, c) meets: itself, else the earliest of its
    4-neighbours on line 1; 0 if none."""
    h, w = on1.shape
    if on1[r, c] > 0:
        return on1[r, c]
    m = 0
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        nr = r + dr
        nc = c + dc
        if 0 <= nr < h and 0 <= nc < w:
            k = on1[nr, nc]
            if k > 0 and (m == 0 or k < m):
                m = k
    return m


@njit(cache=True, nogil=True)
def _line2(error, image, use_image, ra, ca, rb, cb, blocked, max_run, on1, line):
    """Line 2 from (ra, ca) towards the bottom right until it meets line 1 (``on1``).

    Returns (length, meeting index into line 1, 0-based). A line that reaches row rb before
    meeting walks along it towards (rb, cb), which is on line 1."""
    h, w = error.shape
    visited = np.zeros((h, w), dtype=np.bool_)
    r = ra
    c = ca
    n = 0
    row_run = 1
    col_run = 1
    while True:
        line[n, 0] = r
        line[n, 1] = c
        n += 1
        visited[r, c] = True
        m = _touch(on1, r, c)
        if m > 0:
            return n, m - 1
        if r == rb:  # bottom row without meeting: along it to line 1's start
            c += 1 if cb > c else -1
            continue
        pick = _cheapest(
            error, image, use_image, r, c, _PR2, _PC, visited, blocked, row_run, col_run, max_run
        )
        if pick < 0:
            pick = 2  # stuck: down (rows below ra are never blocked nor visited)
        row_run, col_run = _runs_after(_PR2[pick], _PC[pick], row_run, col_run)
        r += _PR2[pick]
        c += _PC[pick]


@njit(cache=True, nogil=True)
def _published(error, image, use_image, anchors, max_run, path, line1, line2, meet):
    """The cut through the anchors (k, 2), top to bottom, one segment per consecutive pair.

    Writes the cut to ``path`` and returns its length; ``line1`` / ``line2`` / ``meet`` receive
    the last segment's lines and meeting index (for :func:`published_lines`)."""
    h, w = error.shape
    blocked = np.zeros((h, w), dtype=np.bool_)
    n = 0
    for s in range(anchors.shape[0] - 1):
        ra, ca = anchors[s, 0], anchors[s, 1]
        rb, cb = anchors[s + 1, 0], anchors[s + 1, 1]
        on1 = np.zeros((h, w), dtype=np.int64)
        n1 = _line1(error, image, use_image, ra, rb, cb, blocked, max_run, on1, line1)
        n2, m = _line2(error, image, use_image, ra, ca, rb, cb, blocked, max_run, on1, line2)
        meet[0] = n1
        meet[1] = n2
        meet[2] = m
        first = 1 if s > 0 else 0  # the anchor closing the previous segment
        k2 = n2
        if line2[n2 - 1, 0] == line1[m, 0] and line2[n2 - 1, 1] == line1[m, 1]:
            k2 = n2 - 1  # line 2 ends on the meeting point: list it once
        for i in range(first, k2):
            path[n, 0] = line2[i, 0]
            path[n, 1] = line2[i, 1]
            n += 1
        for i in range(m, -1, -1):
            path[n, 0] = line1[i, 0]
            path[n, 1] = line1[i, 1]
            n += 1
        for i in range(n):
            blocked[path[i, 0], path[i, 1]] = True
    return n


_NO_IMAGE = np.zeros((1, 1, 1))


def _anchors(pins: np.ndarray) -> np.ndarray:
    """Segment ends for the published variant: the corners (or pinned ends) and waypoints."""
    h = pins.shape[0]
    rows = [0, *(int(r) for r in np.flatnonzero(pins >= 0) if 0 < r < h - 1), h - 1]
    rows = sorted(set(rows))
    return np.array([(r, max(int(pins[r]), 0)) for r in rows], dtype=np.int64).reshape(-1, 2)


def _published_arrays(error, pins, max_run, image):
    h, w = error.shape
    anchors = _anchors(pins)
    use_image = image is not None
    img = _NO_IMAGE if image is None else image
    path = np.empty((h * w + h, 2), dtype=np.int64)
    line1 = np.empty((h * w, 2), dtype=np.int64)
    line2 = np.empty((h * w, 2), dtype=np.int64)
    meet = np.zeros(3, dtype=np.int64)
    if anchors.shape[0] == 1:  # one row: both corners are the same pixel
        path[0] = anchors[0]
        line1[0] = line2[0] = anchors[0]
        meet[:] = (1, 1, 0)
        return path[:1].copy(), line1, line2, meet
    n = _published(error, img, use_image, anchors, max_run, path, line1, line2, meet)
    return path[:n].copy(), line1, line2, meet


def published_lines(error: np.ndarray, *, max_run: int = 5, image=None):
    """The published construction's parts on a whole map, corner to corner (no pins).

    Returns ``(line1, line2, meeting)``: line 1 from the bottom-left corner as built (its
    discarded tail included), line 2 from the top-left corner up to where it met line 1, and the
    index into ``line1`` of the meeting point. For drawing and for tests; the cut itself is
    ``line2`` (without a last pixel equal to the meeting point) followed by
    ``line1[meeting::-1]``.
    """
    e = np.ascontiguousarray(error, dtype=np.float64)
    pins = np.full(e.shape[0], -1, dtype=np.int64)
    _, line1, line2, meet = _published_arrays(e, pins, int(max_run), image)
    n1, n2, m = (int(v) for v in meet)
    return line1[:n1].copy(), line2[:n2].copy(), m


def resistance_path(
    error: np.ndarray, pins: np.ndarray, *, max_run: int, image=None, variant: str = "published"
):
    """The cut's pixels ((N, 2) intp, top to bottom) honouring the pinned rows of ``pins``."""
    if variant == "published":
        return _published_arrays(error, pins, max_run, image)[0]
    h, w = error.shape
    trow = np.flatnonzero(pins[1:] >= 0) + 1  # pinned rows below the top, in order
    tcol = pins[trow]
    if pins[h - 1] < 0 or h == 1:  # end free: stop anywhere in the bottom row
        trow, tcol = np.append(trow, h - 1), np.append(tcol, -1)
    start = int(pins[0])
    use_image = image is not None
    img = _NO_IMAGE if image is None else image
    path = np.empty((h * w, 2), dtype=np.int64)
    n = _walk(
        error, img, use_image, start, trow.astype(np.int64), tcol.astype(np.int64), max_run, path
    )
    return path[:n].copy()
