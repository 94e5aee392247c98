"""Quality measures of tiles, joints and synthesized images (DESIGN.md "Quality").

All measures work on the colour channels in [0, 1] (alpha dropped, gray kept as one
channel); absolute differences are averaged over channels.

* :func:`border_ratio` — mean |A's last column − B's first column| over the mean |difference
  of adjacent columns| inside A and B (B right of A; ``direction="vertical"``: B below A,
  rows instead of columns). 1.0: the joint is as smooth as the texture itself.
* :func:`wrap_border_ratio` — a tile against itself across its wrap.
* :func:`grid_border_ratio` — the same ratio along the lines of a block grid.
* :func:`block_grid_border_ratio` — the same along a quilted image's grid, where its cuts run.
* :func:`corner_border_ratio` — the same near the grid's crossings, where four tiles meet.
* :func:`corner_energy` — all steps (across, along and off the lines) in windows around the
  crossings over the image's mean step, with its profile by distance from the crossing.
* :func:`detail_ratio` — variance of the Laplacian of a tile over that of the source
  (:func:`laplacian_variance`).
* :func:`grid_score` — normalised autocorrelation at a lag of one tile period minus the
  source's own at the same lag (a repeated tile scores about 1.0).
* :func:`seam_stats` — criterion (sum) and peak (max) of the error along a seam.

Interior metrics of a tile set (issue 10; exact definitions in the README, "Interior
metrics"), which see what joint metrics cannot, live in :mod:`engine.tileset_metrics` and are
re-exported here: :func:`frame` (gradient of the blurred luminance by distance to the tile
edge, over reference crops of the source), :func:`ring_tone`, :func:`duplicates`,
:func:`lattice` (tile-period harmonics of random layouts over the power between them, minus a
margin-sharing crops floor) and :func:`template_share`.

A ratio whose denominator is zero (a perfectly flat texture) is 1.0 when the numerator is
also zero and ``inf`` otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine._metric_base import colour as _colour
from engine._metric_base import pair as _period
from engine._metric_base import ratio as _ratio
from engine._validate import as_error_map, as_image, choice, positive_int
from engine.errormap import colour_channels

DIRECTIONS = ("horizontal", "vertical")
WRAP_DIRECTIONS = ("both", "horizontal", "vertical")

__all__ = [
    "DUPLICATE_LEVEL",
    "FRAME_SIGMA",
    "LATTICE_LAYOUTS",
    "LUMA",
    "REFERENCE_CROPS",
    "SHARE_LEVEL",
    "Duplicates",
    "Frame",
    "Lattice",
    "CornerEnergy",
    "block_grid_border_ratio",
    "corner_border_ratio",
    "corner_energy",
    "mean_step",
    "step_windows",
    "border_ratio",
    "duplicates",
    "edge_distance",
    "frame",
    "lattice",
    "lattice_db",
    "layout_frame",
    "luminance",
    "ring_tone",
    "QUALITY_LIMITS",
    "command_advice",
    "quality_warnings",
    "template_share",
    "tile_line_distance",
    "tileset_quality",
    "detail_ratio",
    "grid_border_ratio",
    "grid_score",
    "laplacian_variance",
    "seam_stats",
    "wrap_border_ratio",
]


def _col_steps(x: np.ndarray) -> np.ndarray:
    """|x[:, i+1] − x[:, i]| averaged over channels, (H, W−1) float64 (summed channel by
    channel: ``.mean(axis=2)``'s values, 3x faster)."""
    d = np.abs(np.diff(x.astype(np.float64, copy=False), axis=1))
    return sum(d[..., c] for c in range(d.shape[2])) / d.shape[2]


def border_ratio(a, b, *, direction: str = "horizontal") -> float:
    """Border ratio of ``b`` placed right of (``"horizontal"``) or below (``"vertical"``) ``a``.

    ``a`` and ``b`` must have the same height (horizontal) or width (vertical).

    Examples
    --------
    >>> t = np.tile(np.arange(8.0) / 8, (4, 1))  # a ramp: every step 1/8
    >>> round(border_ratio(t, t), 3)  # the joint jumps 7/8 back to 0
    7.0
    """
    choice(direction, "direction", DIRECTIONS)
    x = _colour(a, "a")
    y = _colour(b, "b")
    if direction == "vertical":
        x, y = x.transpose(1, 0, 2), y.transpose(1, 0, 2)
    if x.shape[0] != y.shape[0] or x.shape[2] != y.shape[2]:
        side = "height" if direction == "horizontal" else "width"
        raise ValueError(
            f"a and b must have the same {side} and channels for a {direction} joint, "
            f"got shapes {np.shape(a)} and {np.shape(b)}"
        )
    joint = np.abs(x[:, -1].astype(np.float64) - y[:, 0]).mean()
    sa, sb = _col_steps(x), _col_steps(y)
    n = sa.size + sb.size
    inner = (sa.sum() + sb.sum()) / n if n else 0.0
    return _ratio(joint, inner)


def wrap_border_ratio(tile, *, direction: str = "both") -> float:
    """Border ratio of ``tile`` against itself across its wrap.

    ``"horizontal"``: the last column against the first (the tile repeated left-right);
    ``"vertical"``: the last row against the first; ``"both"`` (default): the mean of the two.
    """
    choice(direction, "direction", WRAP_DIRECTIONS)
    t = as_image(tile, "tile")
    if direction == "both":
        return 0.5 * (border_ratio(t, t) + border_ratio(t, t, direction="vertical"))
    return border_ratio(t, t, direction=direction)


def grid_border_ratio(image, period, *, offset=(0, 0), direction: str = "both") -> float:
    """Border ratio measured along the lines of a block grid in ``image``.

    Grid lines run between pixel ``k - 1`` and ``k`` for every ``k = offset + n * period``
    strictly inside the image (per axis; ``period`` and ``offset`` are (rows, cols)). The ratio
    is mean |difference across grid lines| / mean |difference of adjacent columns (rows)
    elsewhere|: vertical lines use column steps, horizontal lines row steps. ``"both"``
    (default) returns the mean of the two directions that have lines.
    """
    choice(direction, "direction", WRAP_DIRECTIONS)
    x = _colour(image, "image")
    return _grid_ratio(_grid_steps(x, direction), x.shape, period, offset)


def _grid_steps(x: np.ndarray, direction: str) -> dict[int, np.ndarray]:
    """The steps of columns (key 1) and rows (key 0) that ``direction`` reads."""
    axes = (1, 0) if direction == "both" else (1 - DIRECTIONS.index(direction),)
    return {a: _col_steps(x if a else x.transpose(1, 0, 2)) for a in axes}


def _grid_ratio(steps_of: dict, shape, period, offset) -> float:
    ph, pw = _period(period)
    oy, ox = (int(v) for v in offset)
    ratios = []
    for axis, step, off in ((1, pw, ox), (0, ph, oy)):
        if (steps := steps_of.get(axis)) is None:
            continue
        k = np.arange(1, steps.shape[1] + 1)  # the line between k-1 and k
        on = (k - off) % step == 0
        if on.any() and (~on).any():
            ratios.append(_ratio(steps[:, on].mean(), steps[:, ~on].mean()))
    if not ratios:
        raise ValueError(
            f"no grid line of period {(ph, pw)} and offset {(oy, ox)} lies inside the "
            f"{shape[1]}x{shape[0]} image"
        )
    return float(np.mean(ratios))


def corner_border_ratio(image, period, *, radius: int = 2) -> float:
    """:func:`grid_border_ratio` measured only within ``radius`` pixels of the points where
    grid lines cross: where four tiles meet (Wang tiles' corner problem, whose diagonal
    neighbours share no edge). The steps across the lines there over the steps off the lines;
    mean of both directions. Grid lines as in :func:`grid_border_ratio` (offset 0).
    """
    x = _colour(image, "image")
    ph, pw = _period(period)
    r = positive_int(radius, "radius")
    ratios = []
    for axis, step, other in ((1, pw, ph), (0, ph, pw)):
        steps = _col_steps(x if axis == 1 else x.transpose(1, 0, 2))  # (along, across - 1)
        k = np.arange(1, steps.shape[1] + 1)
        on = k % step == 0
        along = np.arange(steps.shape[0])
        # distance of each position along a line to the nearest crossing line (between
        # pixels m * other - 1 and m * other)
        d = np.minimum(along % other, other - 1 - along % other)
        near = (d < r) & (along >= other - r) & (along < steps.shape[0] - other + r)
        if on.any() and (~on).any() and near.any():
            ratios.append(_ratio(steps[near][:, on].mean(), steps[:, ~on].mean()))
    if not ratios:
        raise ValueError(
            f"no crossing of grid lines of period {(ph, pw)} lies inside the "
            f"{x.shape[1]}x{x.shape[0]} image"
        )
    return float(np.mean(ratios))


def step_windows(image, points, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """The steps of ``image`` in square windows around pixel-corner ``points``.

    ``points`` is an (n, 2) array of (row, col) corners: (y, x) lies between pixels y − 1 and
    y and x − 1 and x, so a tile crossing at (m·T, n·T) is a point. Every column step
    (|x[i, j+1] − x[i, j]|, averaged over channels; at row centre i + ½, on the line j + 1)
    and every row step whose Chebyshev distance to the point is below ``radius`` is read.
    Returns the steps (n, m) and each step's ring, floor(distance), 0 .. radius − 1 (m,).
    Every point must satisfy radius <= y <= H − radius and radius <= x <= W − radius.
    """
    x = _colour(image, "image")
    r = positive_int(radius, "radius")
    p = np.asarray(points, dtype=np.intp).reshape(-1, 2)
    H, W = x.shape[:2]
    if p.size and not (
        (p[:, 0] >= r).all()
        and (p[:, 0] <= H - r).all()
        and (p[:, 1] >= r).all()
        and (p[:, 1] <= W - r).all()
    ):
        raise ValueError(f"every point needs {r} px around it inside the {W}x{H} image")
    a = np.arange(-r, r)  # across the point's row: row centres y + a + 1/2
    b = np.arange(-(r - 1), r)  # the line j + 1 = x + b
    aa, bb = np.meshgrid(a, b, indexing="ij")
    ring = np.maximum(np.where(aa >= 0, aa, -aa - 1), np.abs(bb)).ravel()
    cols = _col_steps(x)  # (H, W - 1)
    rows = _col_steps(x.transpose(1, 0, 2))  # (W, H - 1): row steps, transposed
    vc = cols[p[:, 0, None] + aa.ravel(), p[:, 1, None] - 1 + bb.ravel()]
    vr = rows[p[:, 1, None] + aa.ravel(), p[:, 0, None] - 1 + bb.ravel()]
    return np.concatenate([vc, vr], axis=1), np.concatenate([ring, ring])


def mean_step(image) -> float:
    """The image's mean step (column and row steps pooled): what :func:`step_windows` reads
    on average at uniformly random points."""
    x = _colour(image, "image")
    c, r = _col_steps(x), _col_steps(x.transpose(1, 0, 2))
    return float((c.sum() + r.sum()) / (c.size + r.size))


@dataclass(frozen=True)
class CornerEnergy:
    """:func:`corner_energy`'s result: means over ``level``, the image's mean step."""

    value: float  #: the steps within ``radius`` of the crossings
    lines: float  #: the same around the midpoints of the tile edges (a joint, no crossing)
    profile: np.ndarray  #: the crossings' steps by ring (floor of the distance), 0 .. r − 1
    level: float  #: the image's mean step (random points)
    count: int  #: crossings read


def corner_energy(image, period, *, radius: int = 4) -> CornerEnergy:
    """Step energy where four tiles meet: the mean step (all column and row steps, across,
    along and off the tile lines: :func:`step_windows`) within ``radius`` px of the interior
    crossings of the grid of ``period`` (offset 0), over the image's mean step (what random
    points read). 1.0: the crossings are as smooth as anywhere; a tile construction whose
    corners break (unrelated pixels meeting, cuts converging, blend blobs) reads above, a
    blurred corner below. ``lines``: the same at the midpoints of the tile edges, to tell a
    corner's own excess from the joints'. A layout of crops of one continuous image (the
    image itself) reads about 1.
    """
    x = _colour(image, "image")
    ph, pw = _period(period)
    r = positive_int(radius, "radius")
    H, W = x.shape[:2]
    ys, xs = np.arange(ph, H - r + 1, ph), np.arange(pw, W - r + 1, pw)
    ys, xs = ys[ys >= r], xs[xs >= r]
    if not (len(ys) and len(xs)):
        raise ValueError(
            f"no crossing of grid lines of period {(ph, pw)} lies {r} px inside the {W}x{H} image"
        )
    level = mean_step(x)
    cross = np.stack(np.meshgrid(ys, xs, indexing="ij"), -1).reshape(-1, 2)
    steps, ring = step_windows(x, cross, r)
    profile = np.array([_ratio(steps[:, ring == k].mean(), level) for k in range(r)])
    mids = [(y, m) for y in ys for m in xs - pw // 2 if m >= r]
    mids += [(m, xx) for m in ys - ph // 2 for xx in xs if m >= r]
    line = step_windows(x, mids, r)[0].mean() if mids else np.nan
    return CornerEnergy(
        _ratio(steps.mean(), level), _ratio(line, level), profile, level, len(cross)
    )


def block_grid_border_ratio(result, *, reduce: str = "max") -> float:
    """Border ratio of a quilted image along its block grid, where the cuts run.

    ``result`` is an :class:`engine.quilting.QuiltResult` or anything with its ``image``,
    ``step`` (the grid's period), ``band`` (the width of the strip after each grid line in which
    the cuts run) and, for an output that wraps, ``torus_lines`` (row and column positions where
    its blocks start; None or absent otherwise).

    The joints are not straight lines after a cut, so the ratio is measured on the grid lines
    shifted by every offset 0..band and the largest (``"max"``) or the mean (``"mean"``) is
    returned; a straight overlap's joint lies at offset 0. A tileable output is measured as the
    torus it is (the image tiled 2 × 2): at the real block positions, the wrap line included.
    """
    choice(reduce, "reduce", ("max", "mean"))
    lines = getattr(result, "torus_lines", None)
    vals = []
    x = _colour(result.image, "image")
    steps = _grid_steps(x, "both") if lines is None else None  # once for every offset
    for k in range(result.band + 1):
        if lines is not None:
            vals.append(_torus_grid_ratio(result.image, lines, k))
            continue
        try:
            vals.append(_grid_ratio(steps, x.shape, result.step, (k, k)))
        except ValueError:  # no grid line inside the image at this offset
            continue
    if not vals:
        raise ValueError("the output has no block grid line inside it")
    return float(max(vals) if reduce == "max" else np.mean(vals))


def _torus_grid_ratio(image: np.ndarray, lines, offset: int) -> float:
    """Mean |step| across the lines ``lines + offset`` (rows, cols; modulo the size, so the
    wrap joint counts) over the mean |step| between every other pair of neighbours."""
    x = colour_channels(image).astype(np.float64)
    ratios = []
    for a, starts in ((x, lines[1]), (x.transpose(1, 0, 2), lines[0])):
        n = a.shape[1]
        steps = np.abs(np.roll(a, -1, axis=1) - a).mean(axis=2)  # i: column i -> (i + 1) % n
        on = np.zeros(n, dtype=bool)
        on[(starts + offset - 1) % n] = True
        if on.any() and (~on).any():
            den = steps[:, ~on].mean()
            ratios.append(steps[:, on].mean() / den if den > 0 else 1.0)
    return float(np.mean(ratios))


#: Values (rows x columns x channels) of one strip of :func:`laplacian_variance`.
_STRIP_VALUES = 1 << 20


def laplacian_variance(image) -> float:
    """Variance of the 4-neighbour Laplacian of ``image`` over its interior pixels, averaged
    over the colour channels (alpha dropped): the detail measure of :func:`detail_ratio`.

    Computed in float32 strips of rows with float64 accumulation (per-strip mean and sum of
    squared deviations, merged exactly), so a large source costs little memory beyond itself
    (about 16 MB more at any size) and is never copied whole; a caller comparing many
    tiles with one source can compute the source's figure once.

    Examples
    --------
    >>> laplacian_variance(np.zeros((8, 8)))
    0.0
    """
    return _laplacian_variance(image, "image")


def _laplacian_variance(image, name: str) -> float:
    a = np.asarray(image)
    as_image(a[:3], name)  # dtype and shape checks on three rows (no full copy)
    if a.shape[0] < 3 or a.shape[1] < 3:
        raise ValueError(f"{name} must be at least 3x3 pixels, got {a.shape[1]}x{a.shape[0]}")
    H, W = a.shape[:2]
    channels = a.shape[2] if a.ndim == 3 else 1
    step = max(1, _STRIP_VALUES // (W * channels))
    count = 0
    mean = M2 = None
    for r0 in range(1, H - 1, step):  # interior rows r0 .. r1 - 1
        r1 = min(H - 1, r0 + step)
        x = colour_channels(as_image(a[r0 - 1 : r1 + 1], name))
        c = x[1:-1, 1:-1]
        lap = x[:-2, 1:-1] - c  # neighbour differences first: exact for close values, so
        tmp = np.empty_like(lap)  # float32 loses nothing on a bright, low-contrast image
        for nb in (x[2:, 1:-1], x[1:-1, :-2], x[1:-1, 2:]):
            lap += np.subtract(nb, c, out=tmp)
        v = lap.reshape(-1, x.shape[2])
        n = v.shape[0]
        m = v.mean(axis=0, dtype=np.float64)
        v -= m.astype(np.float32)
        q = np.einsum("ij,ij->j", v, v, dtype=np.float64)
        if mean is None:
            count, mean, M2 = n, m, q
            continue
        delta = m - mean  # Chan et al.: merge two (count, mean, M2) summaries
        total = count + n
        mean = mean + delta * (n / total)
        M2 = M2 + q + delta**2 * (count * n / total)
        count = total
    return float((M2 / count).mean())


def detail_ratio(tile, source) -> float:
    """Variance of the Laplacian of ``tile`` over that of ``source`` (interior pixels).

    Blurring (cross-fading) lowers it below 1; a cut-based tile keeps it near 1. See
    :func:`laplacian_variance` (to compute the source's figure once for many tiles).
    """
    vt = _laplacian_variance(tile, "tile")
    vs = _laplacian_variance(source, "source")
    if vs == 0:
        raise ValueError("source has no detail (its Laplacian is zero everywhere)")
    return vt / vs


def _autocorrelation(x: np.ndarray, lag: tuple[int, int]) -> float:
    """Pearson correlation of ``x`` with itself shifted by ``lag``, averaged over channels."""
    dy, dx = lag
    h, w = x.shape[:2]
    p = x[: h - dy, : w - dx].reshape(-1, x.shape[2]).astype(np.float64)
    q = x[dy:, dx:].reshape(-1, x.shape[2]).astype(np.float64)
    p -= p.mean(axis=0)
    q -= q.mean(axis=0)
    num = (p * q).sum(axis=0)
    den = np.sqrt((p * p).sum(axis=0) * (q * q).sum(axis=0))
    flat = den == 0
    r = np.where(flat, 0.0, num / np.where(flat, 1.0, den))
    r[flat & np.all(p == q, axis=0)] = 1.0  # a flat image repeats itself exactly
    return float(r.mean())


def grid_score(image, period, *, source) -> float:
    """Grid visibility of ``image`` synthesized from tiles (or blocks) of ``period`` (ph, pw).

    The normalised autocorrelation of ``image`` at lags (ph, 0) and (0, pw), minus the
    source's own at the same lags, averaged over the lags that fit in both images. One
    tile repeated scores about 1.0; a synthesis as varied as its source scores about 0.
    """
    x = _colour(image, "image")
    s = _colour(source, "source")
    ph, pw = _period(period)
    scores = [
        _autocorrelation(x, lag) - _autocorrelation(s, lag)
        for lag in ((ph, 0), (0, pw))
        if all(lag[0] < a.shape[0] and lag[1] < a.shape[1] for a in (x, s))
    ]
    if not scores:
        raise ValueError(
            f"period {(ph, pw)} must be smaller than the image ({x.shape[1]}x{x.shape[0]}) and "
            f"the source ({s.shape[1]}x{s.shape[0]}) along at least one axis"
        )
    return float(np.mean(scores))


def seam_stats(seam, error=None) -> tuple[float, float]:
    """(criterion, peak): sum and maximum of the error along a seam.

    ``seam`` is an :class:`engine.seams.Seam` (its own figures are returned) or an (N, 2)
    (row, col) path; with ``error`` the figures are measured on that map instead (e.g. the
    seam of one metric judged by another).
    """
    path = getattr(seam, "path", seam)
    if error is None:
        if not hasattr(seam, "criterion"):
            raise TypeError("seam_stats needs an error map when seam is a plain path")
        return float(seam.criterion), float(seam.peak)
    e = as_error_map(error)
    p = np.asarray(path, dtype=np.intp).reshape(-1, 2)
    if p.size == 0:
        raise ValueError("seam has no path pixels")
    if (p < 0).any() or (p[:, 0] >= e.shape[0]).any() or (p[:, 1] >= e.shape[1]).any():
        raise ValueError(f"seam path leaves the {e.shape[1]}x{e.shape[0]} error map")
    v = e[p[:, 0], p[:, 1]]
    return float(v.sum()), float(v.max())


# Issue 10's interior metrics (engine/tileset_metrics.py), re-exported.
from engine.tileset_metrics import (  # noqa: E402
    DUPLICATE_LEVEL,
    FRAME_SIGMA,
    LATTICE_LAYOUTS,
    LUMA,
    QUALITY_LIMITS,
    REFERENCE_CROPS,
    SHARE_LEVEL,
    Duplicates,
    Frame,
    Lattice,
    command_advice,
    duplicates,
    edge_distance,
    frame,
    lattice,
    lattice_db,
    layout_frame,
    luminance,
    quality_warnings,
    ring_tone,
    template_share,
    tile_line_distance,
    tileset_quality,
)
