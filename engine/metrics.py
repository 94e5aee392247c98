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
* :func:`detail_ratio` — variance of the Laplacian of a tile over that of the source
  (:func:`laplacian_variance`).
* :func:`grid_score` — normalised autocorrelation at a lag of one tile period minus the
  source's own at the same lag (a repeated tile scores about 1.0).
* :func:`seam_stats` — criterion (sum) and peak (max) of the error along a seam.

Interior metrics of a tile set (issue 10; exact definitions in the README, "Interior
metrics"), which see what joint metrics cannot: :func:`frame` (gradient of the blurred
luminance by distance to the tile edge, over random source crops), :func:`ring_tone`,
:func:`duplicates`, :func:`lattice` (tile-period harmonics of random layouts over the
power between them, minus a margin-sharing crops floor) and :func:`template_share`.

A ratio whose denominator is zero (a perfectly flat texture) is 1.0 when the numerator is
also zero and ``inf`` otherwise.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from engine._validate import (
    as_error_map,
    as_image,
    as_rng,
    choice,
    non_negative_number,
    positive_int,
)
from engine.errormap import colour_channels

DIRECTIONS = ("horizontal", "vertical")
WRAP_DIRECTIONS = ("both", "horizontal", "vertical")

__all__ = [
    "Duplicates",
    "Frame",
    "Lattice",
    "block_grid_border_ratio",
    "corner_border_ratio",
    "border_ratio",
    "duplicates",
    "edge_distance",
    "frame",
    "lattice",
    "lattice_db",
    "luminance",
    "ring_tone",
    "QUALITY_LIMITS",
    "quality_warnings",
    "template_share",
    "tileset_quality",
    "detail_ratio",
    "grid_border_ratio",
    "grid_score",
    "laplacian_variance",
    "seam_stats",
    "wrap_border_ratio",
]


def _colour(image, name: str, *, min_size: int = 1) -> np.ndarray:
    return colour_channels(as_image(image, name, min_size=min_size))


def _ratio(num: float, den: float) -> float:
    if den > 0:
        return float(num / den)
    return 1.0 if num == 0 else float("inf")


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


def _period(period, name: str = "period") -> tuple[int, int]:
    if isinstance(period, numbers.Integral) and not isinstance(period, bool):
        period = (period, period)
    try:
        ph, pw = (int(v) for v in period)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an int or a (ph, pw) pair, got {period!r}") from None
    if ph < 1 or pw < 1:
        raise ValueError(f"{name} must be positive, got {(ph, pw)}")
    return ph, pw


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


# =========================================================================== interior metrics
# Issue 10: joint metrics are blind inside a tile (every candidate of a Somol-Haindl set shares
# the template's ring, so every joint *is* the template's joint). These measure what a person
# sees in a layout: a frame along the tile edges, a ring of another tone, repeated tiles and a
# lattice at the tile period. Definitions are in the README ("Interior metrics").

#: Gaussian σ (px) of the blurred luminance whose gradient the frame profile measures.
FRAME_SIGMA = 1.0
#: Random source crops that make a reference profile / tone / lattice floor.
REFERENCE_CROPS = 256
#: Two tiles are duplicates below this mean absolute luminance difference.
DUPLICATE_LEVEL = 1.0 / 255.0
#: A pixel "is the template's" when every channel is within this of the template's.
SHARE_LEVEL = 0.5 / 255.0
#: Random 8x8 layouts averaged by :func:`lattice`, each with its own crops (README: 4 layouts
#: sharing one set of crops moved retina's figure from +1.4 to +9.1 dB with the seed).
LATTICE_LAYOUTS = 16
#: Luminance weights (ITU-R BT.709, as ``skimage.color.rgb2gray``).
LUMA = (0.2125, 0.7154, 0.0721)


def luminance(image) -> np.ndarray:
    """(H, W) float64 luminance of an image in [0, 1]: BT.709 weights of R, G, B
    (:data:`LUMA`, as ``skimage.color.rgb2gray``); a gray image is its own luminance and
    alpha is dropped."""
    x = _colour(image, "image").astype(np.float64)
    if x.shape[2] == 1:
        return x[:, :, 0]
    return x[:, :, 0] * LUMA[0] + x[:, :, 1] * LUMA[1] + x[:, :, 2] * LUMA[2]


def edge_distance(shape) -> np.ndarray:
    """(h, w) int: distance of every pixel to the nearest tile edge, ``min(r, c, h-1-r,
    w-1-c)`` (0 on the outermost ring)."""
    h, w = _period(shape, "shape")
    r = np.arange(h)[:, None]
    c = np.arange(w)[None, :]
    return np.minimum(np.minimum(r, h - 1 - r), np.minimum(c, w - 1 - c))


def _tile_stack(tiles, name: str = "tiles") -> np.ndarray:
    """(n, h, w) float64 luminance of a non-empty sequence of equally sized tiles."""
    ts = [getattr(t, "tile", t) for t in tiles]
    if not ts:
        raise ValueError(f"{name} must not be empty")
    lum = [luminance(t) for t in ts]
    if len({v.shape for v in lum}) != 1:
        raise ValueError(f"{name} must all have one size, got {sorted({v.shape for v in lum})}")
    return np.stack(lum)


def _crop_origins(shape, size, count: int, rng) -> np.ndarray:
    """(count, 2) random top-left corners of ``size`` crops inside a source of ``shape``."""
    H, W = shape
    h, w = size
    if h > H or w > W:
        raise ValueError(f"tiles ({w}x{h}) are larger than the source ({W}x{H}): no crop fits")
    g = as_rng(rng)
    return np.column_stack([g.integers(0, H - h + 1, count), g.integers(0, W - w + 1, count)])


def _gradient_magnitude(lum: np.ndarray, sigma: float, mode: str) -> np.ndarray:
    """|∇ G_σ * L| with central differences; ``mode`` "wrap" (a tile as repeated) or
    "reflect" (a source: one-sided differences on its border)."""
    from scipy import ndimage

    b = ndimage.gaussian_filter(lum, sigma, mode=mode)
    if mode == "wrap":
        gy = (np.roll(b, -1, axis=-2) - np.roll(b, 1, axis=-2)) / 2
        gx = (np.roll(b, -1, axis=-1) - np.roll(b, 1, axis=-1)) / 2
    else:
        gy, gx = np.gradient(b)
    return np.hypot(gy, gx)


def _profile(values: np.ndarray, dist: np.ndarray, limit: int) -> np.ndarray:
    """Mean of ``values`` (n, h, w) over every tile and pixel at each distance 0..limit-1."""
    d = np.broadcast_to(dist, values.shape).ravel()
    keep = d < limit
    s = np.bincount(d[keep], weights=values.ravel()[keep], minlength=limit)
    c = np.bincount(d[keep], minlength=limit)
    return s[:limit] / np.maximum(c[:limit], 1)


@dataclass(frozen=True, slots=True)
class Frame:
    """Result of :func:`frame`.

    ``value``: max over distances 0 .. ``limit`` - 1 of ``ratio`` (1 = no frame);
    ``ratio[d]`` = ``profile[d] / reference[d]``, the tiles' mean gradient magnitude of the
    blurred luminance at distance d from the tile edge over that of random source crops;
    ``distance``: where the maximum lies; ``low``: the minimum of ``ratio`` (a ring that is
    *flatter* than the crops, e.g. blurred, reads below 1).
    """

    value: float
    distance: int
    low: float
    ratio: np.ndarray
    profile: np.ndarray
    reference: np.ndarray


def frame(
    tiles,
    source,
    *,
    limit: int,
    sigma: float = FRAME_SIGMA,
    crops: int = REFERENCE_CROPS,
    wrap: bool = True,
    rng=0,
) -> Frame:
    """Frame score of a tile set against its source.

    Parameters
    ----------
    tiles : sequence of (h, w[, C]) images (or objects with a ``tile`` attribute)
        The candidates (not the template).
    source : (H, W[, C]) image
    limit : int
        Distances 0 .. limit - 1 from the tile edge are compared: where the cut can lie,
        ``2 * w_P`` for Somol-Haindl candidates.
    sigma : float
        Gaussian blur of the luminance (px) before its gradient.
    crops : int
        Random crops of the source (the tiles' size) in the reference profile.
    wrap : bool
        Blur and differentiate every tile as repeated (True: a seamless tile, what a layout
        of tiles sharing its border shows); False: reflect at the tile's border.
    rng : seed or Generator
        The crops' positions.

    The crops' gradient is taken from the blurred *source* (reflected at its border), so a
    crop's edge pixels see their real neighbours.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> src = rng.random((128, 128))
    >>> crops = [src[y : y + 32, x : x + 32] for y, x in rng.integers(0, 96, (40, 2))]
    >>> 0.9 < frame(crops, src, limit=8, wrap=False).value < 1.1  # doctest: +SKIP
    True
    """
    stack = _tile_stack(tiles)
    S = luminance(source)
    n, h, w = stack.shape
    lim = positive_int(limit, "limit")
    lim = min(lim, (min(h, w) + 1) // 2)
    sig = non_negative_number(sigma, "sigma")
    k = positive_int(crops, "crops")
    dist = edge_distance((h, w))
    if wrap:
        g = np.stack([_gradient_magnitude(t, sig, "wrap") for t in stack])
    else:
        g = np.stack([_gradient_magnitude(t, sig, "reflect") for t in stack])
    prof = _profile(g, dist, lim)
    gs = _gradient_magnitude(S, sig, "reflect")
    org = _crop_origins(S.shape, (h, w), k, rng)
    ref = _profile(np.stack([gs[y : y + h, x : x + w] for y, x in org]), dist, lim)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(ref > 0, prof / np.where(ref > 0, ref, 1), np.where(prof > 0, np.inf, 1))
    i = int(np.argmax(ratio))
    return Frame(float(ratio[i]), i, float(ratio.min()), ratio, prof, ref)


def _ring_centre_steps(stack: np.ndarray, width: int) -> np.ndarray:
    """|mean luminance of the ring (distance < width) − of the centre| per tile."""
    dist = edge_distance(stack.shape[1:])
    ring = dist < width
    if ring.all():
        raise ValueError(
            f"ring width {width} leaves no centre in a {stack.shape[2]}x{stack.shape[1]} tile"
        )
    return np.abs(stack[:, ring].mean(axis=1) - stack[:, ~ring].mean(axis=1))


def ring_tone(tiles, source, *, width: int, crops: int = REFERENCE_CROPS, rng=0) -> float:
    """Ring tone of a tile set: mean over the tiles of |mean luminance of the ring (pixels
    closer than ``width`` to the tile edge, w_P for Somol-Haindl candidates) − mean luminance
    of the centre (the rest)|, over the same mean for random crops of the source (1 = the
    ring is no more set off than anywhere in the photo). 1.0 when both are 0, ``inf`` when
    only the crops' is."""
    stack = _tile_stack(tiles)
    S = luminance(source)
    wd = positive_int(width, "width")
    h, w = stack.shape[1:]
    org = _crop_origins(S.shape, (h, w), positive_int(crops, "crops"), rng)
    ref = _ring_centre_steps(np.stack([S[y : y + h, x : x + w] for y, x in org]), wd)
    return _ratio(float(_ring_centre_steps(stack, wd).mean()), float(ref.mean()))


@dataclass(frozen=True, slots=True)
class Duplicates:
    """Result of :func:`duplicates`: tile indices equal to the template, and index pairs
    (i < j) equal to each other; ``count`` is their total."""

    of_template: tuple[int, ...]
    pairs: tuple[tuple[int, int], ...]

    @property
    def count(self) -> int:
        return len(self.of_template) + len(self.pairs)


def duplicates(tiles, template=None, *, level: float = DUPLICATE_LEVEL) -> Duplicates:
    """Tiles equal to ``template`` or to each other: mean absolute luminance difference below
    ``level`` (default 1/255). No tiles: none."""
    if len(tiles) == 0:
        return Duplicates((), ())
    stack = _tile_stack(tiles).astype(np.float32)
    lev = non_negative_number(level, "level")
    of_t: list[int] = []
    if template is not None:
        t = luminance(getattr(template, "tile", template)).astype(np.float32)
        if t.shape != stack.shape[1:]:
            raise ValueError(
                f"template is {t.shape[1]}x{t.shape[0]}, the tiles "
                f"{stack.shape[2]}x{stack.shape[1]}"
            )
        of_t = [int(i) for i in np.flatnonzero(np.abs(stack - t).mean(axis=(1, 2)) < lev)]
    pairs = []
    for i in range(len(stack) - 1):
        d = np.abs(stack[i + 1 :] - stack[i]).mean(axis=(1, 2))
        pairs += [(i, i + 1 + int(j)) for j in np.flatnonzero(d < lev)]
    return Duplicates(tuple(of_t), tuple(pairs))


def template_share(tiles, template, *, level: float = SHARE_LEVEL) -> np.ndarray:
    """Per tile: the fraction of its pixels that are the template's (every colour channel
    within ``level``, default half a step of 8 bits)."""
    t = _colour(getattr(template, "tile", template), "template")
    lev = non_negative_number(level, "level")
    out = []
    for k, tile in enumerate(tiles):
        x = _colour(getattr(tile, "tile", tile), f"tiles[{k}]")
        if x.shape != t.shape:
            raise ValueError(f"tiles[{k}] is shaped {x.shape}, the template {t.shape}")
        out.append(float(np.all(np.abs(x - t) <= lev, axis=2).mean()))
    return np.asarray(out)


def _harmonic_spectra(stack, layout) -> tuple[float, float]:
    """(mean power on the tile-period harmonics, mean power half-way between them) of the
    luminance image assembled from ``stack`` (n, h, w) by ``layout`` (R, C), R and C even.

    Computed exactly from tile-sized transforms: bin (R i + a, C j + b) of the assembled
    image's DFT is bin (i, j) of the h x w DFT of ``Σ_cells (−1)^(ty [a>0] + tx [b>0]) T_cell``
    modulated by ``exp(−iπ (r/h [a>0] + c/w [b>0]))`` (a ∈ {0, R/2}, b ∈ {0, C/2})."""
    R, C = layout.shape
    n, h, w = stack.shape
    ty, tx = np.arange(R)[:, None], np.arange(C)[None, :]
    r, c = np.arange(h)[:, None], np.arange(w)[None, :]
    pairs = [(a, b) for a in (0, 1) for b in (0, 1)]
    weights = np.zeros((4, n), dtype=stack.dtype)
    for k, (a, b) in enumerate(pairs):
        np.add.at(weights[k], layout.ravel(), ((-1.0) ** (ty * a + tx * b)).ravel())
    sums = (weights @ stack.reshape(n, h * w)).reshape(4, h, w)
    power = {}
    for k, (a, b) in enumerate(pairs):
        mod = np.exp(-1j * np.pi * (a * r / h + b * c / w))
        power[a, b] = np.abs(np.fft.fft2(sums[k] * mod)) ** 2
    harm = power[0, 0].copy()
    harm[0, 0] = np.nan  # the DC bin is no harmonic
    mid = np.concatenate([power[1, 0].ravel(), power[0, 1].ravel(), power[1, 1].ravel()])
    return float(np.nanmean(harm)), float(mid.mean())


def lattice_db(image, period) -> float:
    """Spectral power of ``image``'s luminance on the harmonics of ``period`` (ph, pw) over
    the power half-way between them, in dB (the brute-force form of the lattice measure: one
    2-D DFT of the whole image, whose size must be an even multiple of the period)."""
    L = luminance(image)
    ph, pw = _period(period)
    H, W = L.shape
    if H % (2 * ph) or W % (2 * pw):
        raise ValueError(f"the image ({W}x{H}) must be an even number of periods {(ph, pw)}")
    R, C = H // ph, W // pw
    P = np.abs(np.fft.fft2(L)) ** 2
    harm = P[::R, ::C].copy()
    harm[0, 0] = np.nan
    mid = np.concatenate(
        [
            P[R // 2 :: R, ::C].ravel(),
            P[::R, C // 2 :: C].ravel(),
            P[R // 2 :: R, C // 2 :: C].ravel(),
        ]
    )
    return float(10 * np.log10(np.nanmean(harm) / mid.mean()))


@dataclass(frozen=True, slots=True)
class Lattice:
    """Result of :func:`lattice`, in dB: ``value`` of the tiles' layouts, ``floor`` of the
    margin-carrying crops' layouts (same index matrices), ``above`` = value − floor."""

    value: float
    floor: float
    above: float


def lattice(
    tiles,
    source,
    *,
    template=None,
    margin: int,
    grid=(8, 8),
    layouts=LATTICE_LAYOUTS,
    crops: int | None = None,
    rng=0,
) -> Lattice:
    """Lattice score of a tile set: in random ``grid`` layouts of the tiles, 10·log10 of the
    mean spectral power on the harmonics of the tile period (DC excluded) over the mean power
    half-way between them (offsets of half a harmonic spacing along rows, columns and both),
    minus the same for layouts of random source crops that carry the template's outer
    ``margin`` pixels (the floor of any set that shares a border). Mean over ``layouts``
    random index matrices (uniform, equal neighbours allowed); the crops use the same
    matrices (``crops`` of them, default as many as tiles).

    ``template=None``: every tile has its own border (a Wang set, whose edges come from its
    edge samples): crop k carries the outer ``margin`` pixels of tile k (``crops`` must then
    be None). ``layouts`` may also be a sequence of (R, C) index matrices to use instead of
    random ones (e.g. valid Wang layouts; ``grid`` is then their shape)."""
    stack = _tile_stack(tiles)
    n, h, w = stack.shape
    m = positive_int(margin, "margin", minimum=0)
    ring = edge_distance((h, w)) < m
    if template is None:
        if crops is not None:
            raise ValueError("crops must be None when every tile carries its own border")
        border = stack[:, ring]  # crop k carries tile k's own
    else:
        t = luminance(getattr(template, "tile", template))
        if t.shape != (h, w):
            raise ValueError(f"template is {t.shape[1]}x{t.shape[0]}, the tiles {w}x{h}")
        border = t[ring]
    if isinstance(layouts, numbers.Integral) and not isinstance(layouts, bool):
        R, C = _period(grid, "grid")
        matrices = None
        count = positive_int(layouts, "layouts")
    else:
        matrices = [np.asarray(x, dtype=np.int64) for x in layouts]
        if not matrices or any(x.ndim != 2 or x.shape != matrices[0].shape for x in matrices):
            raise ValueError("layouts must be an int or a non-empty list of equal 2-D matrices")
        if any(x.min() < 0 or x.max() >= n for x in matrices):
            raise ValueError(f"layouts must hold tile indices 0..{n - 1}")
        (R, C), count = matrices[0].shape, len(matrices)
    if R % 2 or C % 2:
        raise ValueError(f"grid must have an even number of rows and columns, got {(R, C)}")
    k = n if crops is None else positive_int(crops, "crops")
    g = as_rng(rng)
    S = luminance(source)
    vals, floors = [], []
    for i in range(count):
        # fresh crops per layout: one set's floor is off by dB on uneven sources
        org = _crop_origins(S.shape, (h, w), k, g)
        ref = np.stack([S[y : y + h, x : x + w] for y, x in org])
        ref[:, ring] = border
        idx = g.integers(0, n, (R, C)) if matrices is None else matrices[i]
        hv, mv = _harmonic_spectra(stack, idx)
        hf, mf = _harmonic_spectra(ref, idx % k)
        vals.append(10 * np.log10(hv / mv))
        floors.append(10 * np.log10(hf / mf))
    v, f = float(np.mean(vals)), float(np.mean(floors))
    return Lattice(v, f, v - f)


#: Issue 10's acceptance limits of a tile set, by figure of :func:`tileset_quality`.
QUALITY_LIMITS = {"frame": 1.15, "ring_tone": 1.3, "duplicates": 0, "lattice": 1.5}


def tileset_quality(tiles, source, *, template, ring: int, margin: int, rng=0) -> dict:
    """Every interior figure of a candidate set as plain numbers: ``frame`` (and
    ``frame_low``, ``frame_distance``), ``ring_tone``, ``duplicates``, ``lattice`` (dB above
    its floor; ``lattice_floor``), ``template_share`` (mean over the tiles). ``ring`` is w_P
    (frame up to 2·w_P, ring tone over w_P), ``margin`` the border the tiles share."""
    fr = frame(tiles, source, limit=2 * ring, rng=rng)
    lat = lattice(tiles, source, template=template, margin=margin, rng=rng)
    return {
        "frame": fr.value,
        "frame_low": fr.low,
        "frame_distance": fr.distance,
        "ring_tone": ring_tone(tiles, source, width=ring, rng=rng),
        "duplicates": duplicates(tiles, template).count,
        "lattice": lat.above,
        "lattice_floor": lat.floor,
        "template_share": float(template_share(tiles, template).mean()),
    }


#: Per figure of :func:`tileset_quality`: what exceeding its limit means, in words.
_ADVICE = {
    "frame": "the tiles show a frame (frame {v:.2f} > {lim}): try Flatten lighting, a wider "
    "patch search or a smaller patch ring",
    "ring_tone": "the shared ring differs in tone from the patches (ring tone {v:.2f} > {lim}): "
    "try Flatten lighting or another template position",
    "duplicates": "{v} candidate(s) repeat the template or each other: use a larger source, "
    "smaller tiles or fewer candidates",
    "lattice": "a layout shows a lattice at the tile period ({v:+.1f} dB above the floor of a "
    "shared border): structured textures may need smaller patch rings, larger tiles or a Wang "
    "set",
}


def quality_warnings(q: dict) -> list[str]:
    """What :func:`tileset_quality`'s figures mean for a person, in words (empty: none of
    issue 10's limits is exceeded)."""
    return [_ADVICE[k].format(v=q[k], lim=lim) for k, lim in QUALITY_LIMITS.items() if q[k] > lim]
