"""Heal: fill a masked region of an image by quilting from the rest of it.

What GIMP's Resynthesizer calls *Heal selection* and Embark's texture-synthesis *inpaint*, done
with the project's own pieces [REC]: blocks searched by masked SSD (:mod:`engine.matching`), cut
against what is already there by minimum-error seams (:func:`engine.quilting.cut.cut_overlap`,
any :mod:`engine.seams` method) and blended (:func:`engine.quilting.cut.blend_alpha`).

Algorithm
    1. Blocks of ``block`` pixels lie on a grid with a step of ``block - overlap`` over the
       mask's bounding box (one ``overlap`` beyond it, clamped inside the image); only blocks
       holding masked pixels are used.
    2. Onion order: the next block is the one whose window is known best (the largest share of
       original or already healed pixels), ties broken by the mean depth of its missing pixels
       in the mask (distance to the mask's edge). So the fill grows from the boundary inwards.
    3. Search: every window of the source lying wholly outside the mask (and the ``excluded``
       pixels) is scored by the SSD over the block's known pixels, for all positions at once by
       FFT; the block is drawn among the windows within ``1 + tolerance`` of the best
       (:func:`engine.matching.select_within_tolerance`, seeded by ``rng``).
    4. Cut: the block's edge strips that are wholly known (the *arms*) are cut by the seam
       method through the error of old against new (the top and left arms as one L joined in
       the corner, bottom and right separately), and blended across the cut (``blend``).
    5. Paste: only masked pixels are written. Every pixel outside the mask keeps its exact
       value; every missing pixel of the block is filled; healed pixels may be re-cut by later
       blocks. Material maps (``maps``) take the same source window, cut and blend.
    6. Refine (``refine=True``): the mask's edge is a cut no seam can move, so the rim of the
       mask (``overlap`` deep) is healed again with blocks a third the size, matched against
       the original outside and the coarse fill inside. Large blocks carry the texture's
       structure into the middle, small ones continue what crosses the edge (on the bundled
       brick and cobblestone samples the circle of a 120 px hole disappears).

``HealBlock.level`` says which pass placed a block (0 coarse, 1 rim).

``iter_heal`` streams a :class:`HealBlock` item per placed block and
:class:`~engine.events.Progress`; ``heal`` drains it and returns the :class:`HealResult`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from engine._validate import as_image, as_rng, non_negative_number, positive_int
from engine.cancel import check
from engine.errormap import error_map
from engine.events import Item, Progress, drain, frozen_array
from engine.matching import (
    ZERO_ERROR_FRACTION,
    SampleSpectrum,
    error_floor,
    select_within_tolerance,
)
from engine.quilting.cut import blend_alpha, cut_overlap
from engine.quilting.layout import arms_of
from engine.seams.spec import SeamSpec, as_seam_spec, check_blend

__all__ = ["HEAL_SEAM", "HealBlock", "HealResult", "default_block", "heal", "iter_heal"]

MIN_BLOCK = 6
#: the default cut: minimum error boundary cut on the squared error, feathered over 4 px
HEAL_SEAM = SeamSpec("dp", metric="ssd", blend="feather", width=4.0)


@dataclass(frozen=True, slots=True)
class HealBlock(Item):
    """One placed block: where it went and where it came from (x, y, w, h / x, y), its cut
    (``path`` (row, col) in image pixels, empty when the block had no known edge strip), and
    the image's pixels of its window after it was pasted (read-only)."""

    index: int
    level: int
    rect: tuple[int, int, int, int]
    source: tuple[int, int]
    arms: tuple[int, int, int, int]
    path: np.ndarray
    criterion: float
    pixels: np.ndarray


@dataclass(frozen=True)
class HealResult:
    """The healed image and material maps (float32, exact outside the mask), the blocks."""

    image: np.ndarray
    maps: dict[str, np.ndarray]
    blocks: tuple[HealBlock, ...]
    block: int
    overlap: int


def default_block(shape, mask) -> int:
    """A block size for healing ``mask`` in an image of ``shape``: about a tenth of the
    image's short side, at most the mask's larger extent plus a margin, 12..48 px."""
    m = np.asarray(mask, bool)
    rows, cols = np.nonzero(m.any(axis=1))[0], np.nonzero(m.any(axis=0))[0]
    extent = max(rows[-1] - rows[0] + 1, cols[-1] - cols[0] + 1) if rows.size else 0
    b = min(min(shape[:2]) // 10, 2 * extent + 8)
    return int(np.clip(b, 12, 48))


def _window_hits(bad: np.ndarray, bh: int, bw: int) -> np.ndarray:
    """(H - bh + 1, W - bw + 1) bool: the window anchored there holds a ``bad`` pixel."""
    s = np.pad(np.cumsum(np.cumsum(bad, axis=0, dtype=np.int64), axis=1), ((1, 0), (1, 0)))
    return (s[bh:, bw:] - s[:-bh, bw:] - s[bh:, :-bw] + s[:-bh, :-bw]) > 0


def _origins(lo: int, hi: int, n: int, b: int, step: int, overlap: int) -> list[int]:
    """Window origins along one axis covering [lo, hi) with an ``overlap`` margin, inside [0, n)."""
    out, p = [], lo - overlap
    while True:
        out.append(min(max(p, 0), n - b))
        if p + b >= hi + overlap or p + b >= n:
            break
        p += step
    return sorted(set(out))


def iter_heal(
    image,
    mask,
    *,
    maps=None,
    block: int | None = None,
    overlap: int | None = None,
    tolerance: float = 0.1,
    seam: SeamSpec | None = None,
    excluded=None,
    refine: bool = True,
    rng=None,
    cancel=None,
    threads: int | None = None,
):
    """Fill the ``mask`` pixels of ``image`` from the rest of it, streaming events.

    Parameters
    ----------
    image : (H, W[, C]) array_like
        The source (any dtype; returned as float32 in [0, 1]).
    mask : (H, W) array_like of bool
        The pixels to replace (a leaf, a logo, a blemish).
    maps : dict of str to (H, W[, C]) array_like, optional
        Material maps of the same size, healed with the same blocks, cuts and blends.
    block : int, optional
        Block size (default :func:`default_block`, made smaller while no window of intact
        source fits).
    overlap : int, optional
        Width of the edge strips cut against known pixels (default block / 4).
    tolerance : float
        Draw among the windows within ``(1 + tolerance)`` of the best match.
    seam : SeamSpec, optional
        The cut: seam method and options, the error map's metric and the blend across it
        (default :data:`HEAL_SEAM`). The search always uses the SSD.
    excluded : (H, W) array_like of bool, optional
        Pixels never to copy from (besides the mask).
    refine : bool
        Re-heal the mask's rim (``overlap`` deep) with blocks a third the size, so structures
        crossing the mask's edge continue (the edge itself is a fixed cut).
    rng : int, Generator or None
        Seed of the choices among near-best windows.
    cancel : CancelToken, optional
        Checked between blocks; raises :class:`engine.cancel.Cancelled`.
    threads : int, optional
        FFT workers.

    Returns
    -------
    generator
        Yields :class:`HealBlock` and :class:`~engine.events.Progress`; returns a
        :class:`HealResult`.
    """
    img = as_image(image, "image")
    H, W = img.shape[:2]
    m = np.asarray(mask)
    if m.shape != (H, W):
        raise ValueError(f"mask must be shaped {(H, W)} like the image, got {m.shape}")
    m = m.astype(bool)
    if not m.any():
        raise ValueError("mask is empty: paint the region to heal")
    if maps is not None and not isinstance(maps, Mapping):
        raise TypeError(f"maps must be a dict of name -> image, got {type(maps).__name__}")
    extra = {str(k): as_image(v, f"maps[{k!r}]") for k, v in (maps or {}).items()}
    for name, a in extra.items():
        if a.shape[:2] != (H, W):
            raise ValueError(f"maps[{name!r}] must be {W}x{H} like the image, got {a.shape[:2]}")
    bad = m.copy()
    if excluded is not None:
        ex = np.asarray(excluded)
        if ex.shape != (H, W):
            raise ValueError(f"excluded must be shaped {(H, W)} like the image, got {ex.shape}")
        bad |= ex.astype(bool)
    spec = check_blend(as_seam_spec(seam, default=HEAL_SEAM), "heal")
    tolerance = non_negative_number(tolerance, "tolerance")
    auto = block is None
    b = default_block((H, W), m) if auto else positive_int(block, "block", minimum=MIN_BLOCK)
    while True:
        fits = b <= min(H, W) and not _window_hits(bad, b, b).all()
        if fits or not auto or b <= MIN_BLOCK:
            break
        b = max(MIN_BLOCK, b * 3 // 4)
    if not fits:
        raise ValueError(
            f"no {b}x{b} window of the image lies outside the region to heal"
            f"{' and the excluded pixels' if excluded is not None else ''}: paint a smaller "
            "region or choose a smaller block"
        )
    ov = max(1, b // 4) if overlap is None else positive_int(overlap, "overlap", minimum=1)
    if ov >= b:
        raise ValueError(f"overlap must be smaller than the block ({b}), got {ov}")
    passes = [(m, b, ov)]
    fine = max(MIN_BLOCK, b // 3)
    if refine and fine < b:  # re-heal the rim with small blocks: the mask's edge is a fixed cut
        rim = m & (ndimage.distance_transform_edt(m) <= ov)
        passes.append((rim, fine, max(1, fine // 4)))
    return _iter_heal(
        img,
        m,
        extra,
        bad,
        passes,
        tolerance,
        spec,
        as_rng(rng),
        cancel,
        1 if threads is None else max(1, int(threads)),
    )


def _cells(fill: np.ndarray, b: int, ov: int) -> list[tuple[int, int]]:
    """Origins (y, x) of the grid blocks holding ``fill`` pixels (step ``b - ov``)."""
    H, W = fill.shape
    rows, cols = np.nonzero(fill.any(axis=1))[0], np.nonzero(fill.any(axis=0))[0]
    ys = _origins(int(rows[0]), int(rows[-1]) + 1, H, b, b - ov, ov)
    xs = _origins(int(cols[0]), int(cols[-1]) + 1, W, b, b - ov, ov)
    return [(y, x) for y in ys for x in xs if fill[y : y + b, x : x + b].any()]


def _iter_heal(img, mask, maps, bad, passes, tolerance, spec, rng, cancel, threads):
    C = img.shape[2]
    canvas = img.copy()
    canvases = {k: v.copy() for k, v in maps.items()}
    depth = ndimage.distance_transform_edt(mask)
    spectrum = SampleSpectrum(np.where(mask[:, :, None], 0.0, img), workers=threads)
    zero = ZERO_ERROR_FRACTION * error_floor(img) * C
    plan = [(level, fill, b, ov, _cells(fill, b, ov)) for level, (fill, b, ov) in enumerate(passes)]
    blocks: list[HealBlock] = []
    total, done = sum(len(p[-1]) for p in plan), 0
    yield Progress(0, total, "blocks")
    for level, fill, b, ov, cells in plan:
        invalid = _window_hits(bad, b, b)
        unknown = fill.copy()
        canvas[unknown] = 0.0
        while cells:
            check(cancel)
            y, x = cells.pop(_next_cell(cells, unknown, depth, b))
            done += 1
            win = (slice(y, y + b), slice(x, x + b))
            missing = unknown[win]
            if not missing.any():
                continue
            known = ~missing
            old = canvas[win]
            arms = tuple(min(a, ov) for a in arms_of(known))
            strips = _strips(known.shape, arms)
            weights = _match_weights(known, mask[win] & ~strips, strips, ov)
            errors = spectrum.ssd(old[None], weights[None])[0]
            errors[invalid] = np.inf
            flat, _, _ = select_within_tolerance(
                errors, tolerance=tolerance, zero_level=zero * weights.sum(), rng=rng
            )
            sy, sx = (int(v) for v in np.unravel_index(flat, errors.shape))
            src = (slice(sy, sy + b), slice(sx, sx + b))
            new = img[src]
            alpha, path, criterion = _cut(old, new, known, arms, strips, spec, cancel)
            write = mask[win][:, :, None]  # only masked pixels change
            a3 = alpha[:, :, None]
            canvas[win] = np.where(write, a3 * old + (1 - a3) * new, old)
            for name, cm in canvases.items():
                mo, mn = cm[win], maps[name][src]
                cm[win] = np.where(write, a3 * mo + (1 - a3) * mn, mo)
            unknown[win] = False
            event = HealBlock(
                index=len(blocks),
                level=level,
                rect=(x, y, b, b),
                source=(sx, sy),
                arms=arms,
                path=frozen_array(path + (y, x)),
                criterion=criterion,
                pixels=frozen_array(canvas[win]),
            )
            blocks.append(event)
            yield event
            yield Progress(done, total, "blocks")
    return HealResult(canvas, canvases, tuple(blocks), passes[0][1], passes[0][2])


def _next_cell(cells, unknown, depth, b) -> int:
    """Index of the best-known cell (onion order), ties to the shallowest missing pixels."""
    best, key = 0, None
    for i, (y, x) in enumerate(cells):
        miss = unknown[y : y + b, x : x + b]
        n = int(miss.sum())
        k = (n, float(depth[y : y + b, x : x + b][miss].mean()) if n else 0.0, i)
        if key is None or k < key:
            best, key = i, k
    return best


def _strips(shape, arms) -> np.ndarray:
    """The block's edge strips of widths ``arms`` (top, left, bottom, right)."""
    t, left, bot, r = arms
    strips = np.zeros(shape, bool)
    strips[:t] = True
    strips[:, :left] = True
    if bot:
        strips[-bot:] = True
    if r:
        strips[:, -r:] = True
    return strips


def _match_weights(known, written, strips, ov) -> np.ndarray:
    """Which known pixels the search compares: those the new block will touch (within
    ``ov`` of the masked pixels it writes outside the strips) and the strips it is cut in."""
    near = ndimage.binary_dilation(written, iterations=ov) if written.any() else written
    return (known & (near | strips)).astype(np.float32)


def _cut(old, new, known, arms, strips, spec: SeamSpec, cancel):
    """Weight of the old content in the block (0 on its missing pixels), the cut's path and
    criterion."""
    if not any(arms):
        return np.zeros(known.shape, np.float32), np.zeros((0, 2), np.intp), 0.0
    err = error_map(old, new, metric=spec.metric)
    err[~known] = 0.0
    cut = cut_overlap(err, arms, seam=spec, cancel=cancel)
    alpha = blend_alpha(cut, err, strips, seam=spec)
    alpha[~known] = 0.0
    return alpha, cut.path, float(cut.criterion)


def heal(image, mask, **options) -> HealResult:
    """Fill the ``mask`` pixels of ``image`` from the rest of it (see :func:`iter_heal`)."""
    return drain(iter_heal(image, mask, **options))
