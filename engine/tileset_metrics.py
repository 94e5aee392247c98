"""Interior metrics of a tile set (issue 10; exact definitions in the README, "Interior
metrics"), re-exported by :mod:`engine.metrics`.

Joint metrics are blind inside a tile (every candidate of a Somol-Haindl set shares the
template's ring, so every joint *is* the template's joint). These measure what a person sees in
a layout: :func:`frame` (gradient of the blurred luminance by distance to the tile edge, over
reference crops of the source), :func:`ring_tone`, :func:`duplicates`, :func:`lattice`
(tile-period harmonics of random layouts over the power between them, minus a floor of crops
that share the template's margin) and :func:`template_share`.

The reference crops are random crops of the source of the tile's size; with a template, they
are drawn in its phase along the axes where the texture is periodic and the tile holds whole
periods (:mod:`engine.reference_crops`: against random-phase crops an aligned set of a periodic
texture — whose layout is the texture itself — read as a frame and a lattice).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from engine._metric_base import colour as _colour
from engine._metric_base import pair as _period
from engine._metric_base import ratio as _ratio
from engine._validate import as_rng, non_negative_number, positive_int
from engine.reference_crops import ReferenceCrops

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
    "QUALITY_LIMITS",
    "command_advice",
    "duplicates",
    "edge_distance",
    "frame",
    "lattice",
    "layout_frame",
    "lattice_db",
    "luminance",
    "quality_warnings",
    "frame_profiles",
    "ring_reference",
    "ring_steps",
    "ring_tone",
    "template_share",
    "tile_line_distance",
    "tileset_quality",
]

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


def _reference(source_lum, size, template, in_phase) -> ReferenceCrops:
    """Where the reference crops come from: in ``template``'s phase (when given and
    ``in_phase``) along the axes where the texture is periodic, else anywhere."""
    t = None
    if template is not None and in_phase:
        t = luminance(getattr(template, "tile", template))
        if t.shape != tuple(size):
            raise ValueError(
                f"template is {t.shape[1]}x{t.shape[0]}, the tiles {size[1]}x{size[0]}"
            )
    return ReferenceCrops.build(source_lum, size, t)


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
    blurred luminance at distance d from the tile edge over that of the reference crops;
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
    template=None,
    in_phase: bool = True,
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
    template : (h, w[, C]) image, optional
        The set's template: the crops are drawn in its phase along the axes where the texture
        is periodic and the tile holds whole periods (:mod:`engine.reference_crops`; with
        ``in_phase=False`` or without a template, at random phases everywhere).
    rng : seed or Generator
        The crops' positions.

    The crops' gradient is taken from the blurred *source* (reflected at its border), so a
    crop's edge pixels see their real neighbours.

    Examples
    --------
    Crops of a periodic texture — a seamless tile repeated — are tiles that continue across
    every joint: no frame.

    >>> rng = np.random.default_rng(0)
    >>> src = np.tile(rng.random((32, 32)), (4, 4))
    >>> crops = [src[y : y + 32, x : x + 32] for y, x in rng.integers(0, 96, (40, 2))]
    >>> 0.9 < frame(crops, src, limit=8).value < 1.1
    True
    """
    stack = _tile_stack(tiles)
    S = luminance(source)
    g, dist, lim, sig = _tile_gradients(stack, limit, sigma, "wrap" if wrap else "reflect")
    k = positive_int(crops, "crops")
    prof = _profile(g, dist, lim)
    ref = _source_profile(S, stack.shape[1:], sig, lim, template, in_phase, k, rng)
    return _frame_of(prof, ref)


def _tile_gradients(stack: np.ndarray, limit, sigma, mode: str):
    """The tiles' side of :func:`frame` and :func:`frame_profiles`: the gradient magnitude
    (n, h, w) of every tile blurred by ``sigma`` (``mode`` "wrap" or "reflect"), the tile's
    edge distance, ``limit`` at most half the tile, and ``sigma`` checked."""
    h, w = stack.shape[1:]
    lim = min(positive_int(limit, "limit"), (min(h, w) + 1) // 2)
    sig = non_negative_number(sigma, "sigma")
    g = np.stack([_gradient_magnitude(t, sig, mode) for t in stack])
    return g, edge_distance((h, w)), lim, sig


def _source_profile(S, size, sig, lim, template, in_phase, k, rng) -> np.ndarray:
    """The reference profile: the gradient of the blurred *source* (reflected at its border,
    so a crop's edge pixels see their real neighbours) over ``k`` crops (in ``template``'s
    phase), by distance to the crop's edge."""
    h, w = size
    gs = _gradient_magnitude(S, sig, "reflect")
    org = _reference(S, (h, w), template, in_phase).origins(k, rng)
    return _profile(np.stack([gs[y : y + h, x : x + w] for y, x in org]), edge_distance(size), lim)


def _frame_of(prof: np.ndarray, ref: np.ndarray) -> Frame:
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(ref > 0, prof / np.where(ref > 0, ref, 1), np.where(prof > 0, np.inf, 1))
    i = int(np.argmax(ratio))
    return Frame(float(ratio[i]), i, float(ratio.min()), ratio, prof, ref)


def tile_line_distance(shape, tile, offset=(0, 0)) -> np.ndarray:
    """(H, W) int: distance of every pixel of an image of ``shape`` to the nearest *interior*
    line of a grid of cells ``tile`` (h, w) whose lines lie at ``offset`` (y, x) modulo the
    cell size (a line at p lies between pixels p - 1 and p; the pixels either side are at
    distance 0, as :func:`edge_distance` counts inside one cell). The image's own border is
    no line: a pixel with no line along either axis gets ``H + W``."""
    H, W = _period(shape, "shape")
    out = []
    for n, t, o in zip((H, W), _period(tile, "tile"), offset, strict=True):
        lines = np.arange(int(o) % t, n, t)
        lines = lines[lines > 0]
        r = np.arange(n)[:, None]
        if len(lines) == 0:
            out.append(np.full(n, H + W))
            continue
        d = np.where(r >= lines[None, :], r - lines[None, :], lines[None, :] - 1 - r)
        out.append(d.min(axis=1))
    return np.minimum(out[0][:, None], out[1][None, :])


def layout_frame(
    layouts,
    source,
    *,
    tile,
    limit: int,
    offset=(0, 0),
    sigma: float = FRAME_SIGMA,
    crops: int = REFERENCE_CROPS,
    template=None,
    in_phase: bool = True,
    rng=0,
) -> Frame:
    """Frame score of tiles *inside their layouts*: every tile with its real neighbours.

    ``layouts``: images (H, W[, C]) whose tile lines lie at ``offset`` modulo ``tile`` (h, w)
    (assembled layouts: offset 0). Their luminance is blurred by ``sigma`` and differentiated
    as :func:`frame` does, and the gradient magnitude profiled by distance to the nearest
    *interior* tile line (:func:`tile_line_distance`) over every cell, up to ``limit``; the
    pixels within reach of the image's border (the blur's radius + 1) are left out, so no
    reflected pixel is read. The reference is :func:`frame`'s: the source's own gradient over
    ``crops`` crops (cells of the same grid at random offsets; in ``template``'s phase along
    the axes where the texture is periodic and the tile holds whole periods), by distance to
    the crop's edge. ``value`` etc. as :class:`Frame`.

    Unlike :func:`frame` with ``wrap=False``, a structure cut by the tile line (a grout line
    across the edge) is read with the pixels that really lie beyond it, as a person sees it
    in the layout; the genuine source cut into a grid reads 1 up to the crops' noise.

    >>> rng = np.random.default_rng(0)
    >>> src = rng.random((256, 256))
    >>> 0.9 < layout_frame([src], src, tile=32, limit=8, offset=(5, 11)).value < 1.1
    True
    """
    h, w = _period(tile, "tile")
    S = luminance(source)
    lim = min(positive_int(limit, "limit"), (min(h, w) + 1) // 2)
    sig = non_negative_number(sigma, "sigma")
    k = positive_int(crops, "crops")
    pad = int(4 * sig + 0.5) + 1  # scipy's Gaussian reaches 4 sigma; the gradient one more
    s = np.zeros(lim)
    c = np.zeros(lim)
    for image in layouts:
        L = luminance(image)
        g = _gradient_magnitude(L, sig, "reflect")
        d = tile_line_distance(L.shape, (h, w), offset)
        d[:pad], d[-pad:], d[:, :pad], d[:, -pad:] = lim, lim, lim, lim
        keep = d < lim
        s += np.bincount(d[keep], weights=g[keep], minlength=lim)[:lim]
        c += np.bincount(d[keep], minlength=lim)[:lim]
    if not c.all():
        raise ValueError("the layouts hold no interior tile line within the limit")
    ref = _source_profile(S, (h, w), sig, lim, template, in_phase, k, rng)
    return _frame_of(s / c, ref)


def _ring_centre_steps(stack: np.ndarray, width: int) -> np.ndarray:
    """|mean luminance of the ring (distance < width) − of the centre| per tile."""
    dist = edge_distance(stack.shape[1:])
    ring = dist < width
    if ring.all():
        raise ValueError(
            f"ring width {width} leaves no centre in a {stack.shape[2]}x{stack.shape[1]} tile"
        )
    return np.abs(stack[:, ring].mean(axis=1) - stack[:, ~ring].mean(axis=1))


def ring_tone(
    tiles,
    source,
    *,
    width: int,
    crops: int = REFERENCE_CROPS,
    template=None,
    in_phase: bool = True,
    rng=0,
) -> float:
    """Ring tone of a tile set: mean over the tiles of |mean luminance of the ring (pixels
    closer than ``width`` to the tile edge, w_P for Somol-Haindl candidates) − mean luminance
    of the centre (the rest)|, over the same mean for reference crops of the source (1 = the
    ring is no more set off than anywhere in the photo; crops in ``template``'s phase as in
    :func:`frame`). 1.0 when both are 0, ``inf`` when only the crops' is."""
    stack = _tile_stack(tiles)
    wd = positive_int(width, "width")
    opts = dict(crops=crops, template=template, in_phase=in_phase, rng=rng)
    ref = ring_reference(source, stack.shape[1:], width=wd, **opts)
    return _ratio(float(_ring_centre_steps(stack, wd).mean()), ref)


def ring_steps(tiles, *, width: int) -> np.ndarray:
    """(n,) float: per tile |mean luminance of the ring (pixels closer than ``width`` to the
    tile edge) − mean luminance of the centre|; :func:`ring_tone` is their mean over
    :func:`ring_reference`."""
    return _ring_centre_steps(_tile_stack(tiles), positive_int(width, "width"))


def ring_reference(
    source,
    size,
    *,
    width: int,
    crops: int = REFERENCE_CROPS,
    template=None,
    in_phase: bool = True,
    rng=0,
) -> float:
    """The mean :func:`ring_steps` of ``crops`` crops of ``size`` (h, w) of the source, in
    ``template``'s phase as in :func:`frame`: the reference of :func:`ring_tone`."""
    S = luminance(source)
    h, w = _period(size, "size")
    wd = positive_int(width, "width")
    org = _reference(S, (h, w), template, in_phase).origins(positive_int(crops, "crops"), rng)
    return float(_ring_centre_steps(np.stack([S[y : y + h, x : x + w] for y, x in org]), wd).mean())


def frame_profiles(tiles, *, limit: int, sigma: float = FRAME_SIGMA) -> np.ndarray:
    """(n, limit) float: per tile (blurred and differentiated as repeated) its mean gradient
    magnitude at each distance 0 .. ``limit`` - 1 from its edge (``limit`` at most half the
    tile, as in :func:`frame`, whose ``profile`` with ``wrap`` is their mean up to rounding)."""
    g, dist, lim, _ = _tile_gradients(_tile_stack(tiles), limit, sigma, "wrap")
    return np.stack([_profile(t[None], dist, lim) for t in g])


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
    in_phase: bool = True,
    rng=0,
) -> Lattice:
    """Lattice score of a tile set: in random ``grid`` layouts of the tiles, 10·log10 of the
    mean spectral power on the harmonics of the tile period (DC excluded) over the mean power
    half-way between them (offsets of half a harmonic spacing along rows, columns and both),
    minus the same for layouts of random source crops that carry the template's outer
    ``margin`` pixels (the floor of any set that shares a border; the crops in the
    template's phase along the axes where the texture is periodic and the tile holds whole
    periods, as in :func:`frame`, unless ``in_phase`` is False). Mean over ``layouts``
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
    where = _reference(S, (h, w), template, in_phase)
    vals, floors = [], []
    for i in range(count):
        # fresh crops per layout: one set's floor is off by dB on uneven sources
        org = where.origins(k, g)
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
    fr = frame(tiles, source, limit=2 * ring, template=template, rng=rng)
    lat = lattice(tiles, source, template=template, margin=margin, rng=rng)
    return {
        "frame": fr.value,
        "frame_low": fr.low,
        "frame_distance": fr.distance,
        "ring_tone": ring_tone(tiles, source, width=ring, template=template, rng=rng),
        "duplicates": duplicates(tiles, template).count,
        "lattice": lat.above,
        "lattice_floor": lat.floor,
        "template_share": float(template_share(tiles, template).mean()),
    }


def command_advice(flattened: bool = False) -> dict[str, str]:
    """Per figure of :func:`tileset_quality`: what exceeding its limit means and what to try,
    in the command line's words; Flatten lighting is suggested only while it is off
    (``flattened`` False), else said to be on (as the editor's texts do)."""
    if flattened:
        tone, frame_try, ring_try = " although Flatten lighting is on", "", ""
    else:
        tone, frame_try, ring_try = "", "Flatten lighting, ", "Flatten lighting or "
    return {
        "frame": f"the tiles show a frame (frame {{v:.2f}} > {{lim}}){tone}: try {frame_try}a "
        "wider patch search or a smaller patch ring",
        "ring_tone": "the shared ring differs in tone from the patches (ring tone {v:.2f} > "
        f"{{lim}}){tone}: try {ring_try}another template position",
        "duplicates": "{v} candidate(s) repeat the template or each other: use a larger source, "
        "smaller tiles or fewer candidates",
        "lattice": "a layout shows a lattice at the tile period ({v:+.1f} dB above the floor of "
        "a shared border): structured textures may need smaller patch rings, larger tiles or a "
        "Wang set",
    }


def quality_warnings(
    q: dict, advice: dict[str, str] | None = None, *, flattened: bool = False
) -> list[str]:
    """What :func:`tileset_quality`'s figures mean for a person, in words (empty: none of
    issue 10's limits is exceeded); ``advice`` replaces the texts (``{v}`` the figure, ``{lim}``
    its limit), e.g. in the editor's words; without it, :func:`command_advice` of
    ``flattened`` (whether the set was made with Flatten lighting on)."""
    advice = command_advice(flattened) if advice is None else advice
    return [advice[k].format(v=q[k], lim=lim) for k, lim in QUALITY_LIMITS.items() if q[k] > lim]
