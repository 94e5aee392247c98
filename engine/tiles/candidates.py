"""Mutually connectable candidate tiles (ALGORITHMS.md §1.5, §1.8).

Each candidate is the seamless template with one patch from another source position stitched
in along a closed minimum-error path whose four corner points are pinned and which never
enters the outer ``margin`` pixels, so every candidate keeps the template's border exactly and
connects to every other.

**Where the patch comes from** (``patch_search``):

* ``"global"`` (default, issue 10 [REC]): the error of the ring's outer band (offsets
  ``margin .. margin + SEARCH_BAND - 1``, where the outward-drawn cut runs) between every source
  window and the template is computed at once by FFT (masked SSD,
  :class:`engine.matching.SampleSpectrum`). Candidate ``k`` is drawn (seeded)
  among the positions within ``1 + tolerance`` of the best remaining one, so structure (brick
  courses, shelves) lines up across the closed cut — ranked, on non-periodic textures, with a
  ``spread`` term against windows that resemble the template and the earlier patches (else
  every tile keeps the template's structure near its edges: the lattice;
  :mod:`engine.tiles.patch_plan`). The template's own position and every
  earlier candidate's are excluded within ``min_distance`` px (Chebyshev), so no two
  candidates repeat; positions worse than ``1 + quality`` times the source's best match are
  never used: when the source cannot give ``n`` such positions, fewer candidates are made and
  a :class:`CandidatesNotice` (and a warning) says why.
* ``"local"`` (the paper's rule): ``s0`` uniform over the valid positions, refined to the best
  ring-band match within ``s0 + [-n, n]^2`` (``neighbourhood``).

Then :func:`engine.stitch.patch_cut` gives the closed cut — searched on the error plus a bias
that makes cuts nearer the outer margin cheaper (``outward``), so the part every tile repeats
(the template share) stays thin — and :func:`engine.materials.apply_cut` applies it to every
map. The ring width w_P defaults to :func:`default_patch_overlap` of the template's w_T.

Cuts run on a thread pool (``workers``) and candidates are yielded as they finish (each carries
its ``index``); the returned list is in index order. Candidate ``k`` is seeded from
``(seed, k)`` and (global search) the positions of candidates ``0 .. k-1`` only, so the same
seed gives identical tiles whatever the worker count or the number of candidates asked for.
"""

from __future__ import annotations

import math
import numbers
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from engine._validate import as_image, choice, non_negative_number, positive_int
from engine.cancel import AnyCancel, Cancelled, CancelToken, check, is_cancelled
from engine.candidate import CandidateTile
from engine.completions import Completions
from engine.errormap import colour_channels
from engine.events import Item, Progress, drain, frozen_array
from engine.exclusion import valid_anchors
from engine.matching import SampleSpectrum
from engine.seams.spec import POISSON, SeamSpec, as_seam_spec
from engine.stitch import PATCH_SEAM
from engine.tiles import patch_plan
from engine.tiles.candidate_kernels import (
    band_costs,
    coarse_interior_means,
    count_changed,
    cut_shows,
    natural_step,
    true_runs,
)
from engine.tiles.patch_phase import SCALE_CROP
from engine.tiles.patch_plan import SPREAD, SPREAD_MAX_POSITIONS
from engine.tiles.patch_stitch import check_ring, gradient_blend, stitch_patch
from engine.tiles.scale import Scale, structure_scale
from engine.tiles.seamless import MAIN, SeamlessTile, as_maps, check_weights
from engine.tiles.template import as_size, excluded_mask, flat_warning

__all__ = [
    "PATCH_SEARCHES",
    "CandidateSetup",
    "CandidateTile",
    "CandidatesNotice",
    "candidate_seed",
    "candidates",
    "default_min_distance",
    "default_patch_overlap",
    "iter_candidates",
    "make_candidate",
]

MARGIN = 1  # px every candidate keeps from the template (default of ``margin``)
PATCH_SEARCHES = ("global", "local")
TOLERANCE = 0.25  # global search: draw within (1 + TOLERANCE) x the best remaining ring match
#: global search: never use a ring match worse than (1 + QUALITY) x the best. 3.0 (was 2.0
#: with the whole ring matched): the outer band's error varies more from window to window,
#: and at 2.0 retina kept 25 candidates of 30, coins 13
QUALITY = 3.0
#: global search: the ring match is measured on the ring's outer SEARCH_BAND px only (offsets
#: margin .. margin + SEARCH_BAND - 1). The outward-drawn cut runs there (at d = 1-2 px for
#: 70-85 % of its length), so that is where the patch must fit; matching the whole ring also
#: made every patch resemble the template 3-9 px in from the edge, a part all tiles then
#: share: on the public evaluation set (seeds 0-2, median; with QUALITY 3) lattice cell
#: +4.29 -> +2.83 dB, retina +6.56 -> +5.71, text +2.36 -> +1.88, moon +1.49 -> +1.19,
#: coins +6.6 -> +6.2, brick +6.5 -> +5.7, gravel, grass, lichen, cobblestones within 0.1;
#: frame within +-0.1 (coins 1.77 -> 1.64)
SEARCH_BAND = 2
#: bias of the closed cut toward the outer margin, in units of the mean error. 1.0 (was 0.5)
#: on the public evaluation set: lattice grass +1.65 -> +1.10 dB, lichen +2.03 -> +1.21,
#: gravel +2.08 -> +1.56, cobblestones +1.17 -> +0.65 for frame 1.06 -> 1.14 (1.25 pushes
#: cobblestones' frame to 1.17, moon's to 1.16: the cut hugs the edge and reads as straight).
#: 0.7 since the cut beside the margin is judged by how the patch continues the margin
#: (:mod:`engine.tiles.patch_stitch`), which pulls it outward by itself: at 1.0 cobblestones'
#: frame read 1.17 (README, "The cut beside the margin")
OUTWARD = 0.7
#: blend "adaptive" (the default): a candidate whose cut shows — the mean step across it of the
#: luminance blurred as the frame metric blurs it, above SEAM_SHOWS x the source's own mean
#: step (:func:`engine.tiles.candidate_kernels.cut_shows`) — is blended in the gradient domain
#: instead (as blend "poisson"). Smooth sources have no match good enough for a hard cut near
#: the margin: median step across the cut / the source's, public set: retina 3.2, coins 2.6,
#: moon 1.5, brick 1.5, cobblestones 1.35, text, cell, gravel 1.2-1.3, grass, lichen 1.1.
#: Measured: moon frame 1.17 -> 0.99 and lattice +1.17 -> +0.99 dB; retina frame 2.33 -> 1.21
#: (tone blocks and hard tile edges gone) but lattice +5.0 -> +8.4 dB; coins frame 2.02 ->
#: 1.07; the others unchanged. 0 turns it off.
SEAM_SHOWS = 1.75
#: ... but only for patch windows of at most this many pixels: one solve of a 1024 x 1024 window
#: costs about a second, and the upsampled 4096 px stand-in photo of the speed benchmark has
#: cuts that show, so 30 such candidates took 4x the 10 s of issue 10's speed line (measured:
#: 4 candidates 3.5 -> 8.9 s under load). Larger tiles keep the hard cut unless
#: ``--blend poisson`` is asked for.
SEAM_SHOWS_MAX_PIXELS = 512 * 512
#: global patch search: a window's cost is its ring band's mean squared error against the
#: template's plus TONE x (mean luminance of its interior − of the template's ring)². All
#: candidates share the template's ring, so a patch whose interior is lighter or darker than
#: that ring makes a tone block with a step at its cut even when the cut itself matches; the
#: source's own windows differ that much (a random layout of plain crops of text shows the
#: same blocks), so the ring-band error alone cannot avoid them. 4 = an interior off by Δ
#: costs as a ring band off by 2Δ. Public text: ring tone 1.24 -> 0.68, lattice +1.25 ->
#: +1.14 dB, the tone blocks of its layout gone (README, "Tone in the patch choice").
TONE = 4.0
PATCH_RING_FLOOR = 8  # px: narrower rings leave the closed cut no room (default_patch_overlap)


def default_patch_overlap(overlap: int) -> int:
    """The default patch ring w_P for a template overlap w_T: ``min(w_T, max(8, w_T // 2))``.

    [REC] The paper only says w_P is tuned per texture (ALGORITHMS §1.8). Everything outside
    a candidate's closed cut is the template, the same in every tile, so a ring narrower
    than w_T shows less of a grid in a synthesized layout, but below about 8 px the cut has
    no room to avoid the texture's features: its error per pixel and the tile's excess
    detail (cut artefacts) climb. Measured on the five bundled samples with
    ``python -m benchmarks.tileset --patch-rings w_T,w_T/2,8 --ring-tiles 64,128,256``:
    at 256 px tiles (w_T 26) w_T // 2 = 13 cuts the grid score of 30 candidates from 0.18 to
    0.12 for 19 % more seam error per pixel (a fixed 8 px: 0.085, +46 %); at 128 px (w_T 13)
    8 px gives 0.20 -> 0.14 for +21 % (6 px: 0.12 but +38 % and detail 1.22 vs 1.13); at
    64 px (w_T 6) a ring wider than w_T shows *more* grid, so w_T stays. Connectability
    (pair border ratios) is the same for all of them.
    """
    w = positive_int(overlap, "overlap")
    return min(w, max(PATCH_RING_FLOOR, w // 2))


def default_min_distance(tile_shape, positions: int) -> int:
    """Default minimum distance (px, Chebyshev) between candidates' patch sources and from
    the template's own position: a quarter of the tile's shorter side, or an eighth of the
    span of the patch positions (the square root of their number ``positions``, e.g.
    ``(H - h + 1) * (W - w + 1)`` without exclusions) when that is smaller, so that a source
    holds about 30 such positions; at least 4."""
    h, w = tile_shape[:2]
    return max(4, min(min(int(h), int(w)) // 4, int(math.sqrt(max(1, positions))) // 8))


@dataclass(frozen=True, slots=True)
class CandidatesNotice(Item):
    """Something the user must be told about a candidate run (e.g. fewer candidates than
    asked, and why); the same text is also issued as a warning."""

    message: str


# --------------------------------------------------------------------------- seeds
def candidate_seed(base: int, index: int) -> int:
    """The seed of candidate ``index`` in a run seeded with ``base`` (63-bit int)."""
    state = np.random.SeedSequence([int(base), int(index)]).generate_state(1, np.uint64)[0]
    return int(state) & (2**63 - 1)


def base_seed(rng) -> int:
    """The run's base seed from ``rng`` (a seed, a Generator or None: a fresh one)."""
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool):
        if rng < 0:
            raise ValueError(f"rng must be a non-negative seed, got {rng}")
        return int(rng)
    if rng is None or isinstance(rng, np.random.Generator):
        gen = rng if rng is not None else np.random.default_rng()
        return int(gen.integers(2**63))
    raise TypeError(f"rng must be an int, a numpy Generator or None, got {type(rng).__name__}")


# --------------------------------------------------------------------------- setup
class CandidateSetup:
    """Validated inputs shared by every candidate of one run (:meth:`make` makes one at a
    given position: the benchmarks measure every position this way)."""

    def __init__(
        self,
        source,
        template,
        *,
        patch_size,
        patch_overlap,
        margin,
        neighbourhood,
        seam,
        excluded,
        maps,
        weights,
        patch_search="global",
        tolerance=TOLERANCE,
        quality=QUALITY,
        min_distance=None,
        outward=OUTWARD,
        seam_shows=SEAM_SHOWS,
        spread=SPREAD,
        scale=None,
    ):
        if not isinstance(template, SeamlessTile):
            raise TypeError(
                "template must be a SeamlessTile (from make_seamless), got "
                f"{type(template).__name__}"
            )
        self.S = as_image(source, "source")
        H, W = self.S.shape[:2]
        th, tw = template.tile.shape[:2]
        if self.S.shape[2] != template.tile.shape[2]:
            raise ValueError(
                f"source has {self.S.shape[2]} channels, the template tile "
                f"{template.tile.shape[2]}: use the source the template was made from"
            )
        self.ring, self.margin = check_ring(
            default_patch_overlap(template.overlap) if patch_overlap is None else patch_overlap,
            margin,
        )
        ph, pw = (th, tw) if patch_size is None else as_size(patch_size, "patch_size")
        if ph > th or pw > tw:
            raise ValueError(f"patch_size {(ph, pw)} must not exceed the tile size {(th, tw)}")
        if ph > H or pw > W:
            raise ValueError(f"patch_size {(ph, pw)} does not fit the {W}x{H} source")
        if min(ph, pw) < 2 * self.ring:
            raise ValueError(
                f"patch_size {(ph, pw)} must be at least 2 * patch_overlap = {2 * self.ring} px "
                "per side"
            )
        self.ph, self.pw = ph, pw
        self.ty, self.tx = (th - ph) // 2, (tw - pw) // 2
        self.n = positive_int(neighbourhood, "neighbourhood", minimum=0)
        self.seam = as_seam_spec(seam, default=PATCH_SEAM)
        self.search = choice(patch_search, "patch_search", PATCH_SEARCHES)
        self.tolerance = non_negative_number(tolerance, "tolerance")
        self.quality = non_negative_number(quality, "quality")
        self._min_distance = min_distance
        self.outward = non_negative_number(outward, "outward")
        self.seam_shows = non_negative_number(seam_shows, "seam_shows")
        self.spread = non_negative_number(spread, "spread")
        if scale is not None and not isinstance(scale, Scale):
            raise TypeError(f"scale must be a Scale, got {type(scale).__name__}")
        self.scale = scale
        tx0, ty0 = template.rect[:2]
        self.template_origin = (ty0 + (th - ph) // 2, tx0 + (tw - pw) // 2)
        self._costs = None
        extra = as_maps(maps, (H, W))
        if set(extra) != set(template.maps):
            raise ValueError(
                f"maps {sorted(extra)} must be the material maps the template was made with "
                f"{sorted(template.maps)}"
            )
        self.weights = check_weights(weights, extra)
        self.stack = {MAIN: self.S, **extra}
        tmaps = {
            MAIN: np.asarray(template.tile),
            **{k: np.asarray(v) for k, v in template.maps.items()},
        }
        self.tmaps = tmaps
        win = (slice(self.ty, self.ty + ph), slice(self.tx, self.tx + pw))
        self.U = {k: v[win] for k, v in tmaps.items()}
        self.U_main = self.U[MAIN]
        ex = excluded_mask(excluded, (H, W))
        self.valid = None if ex is None else valid_anchors(ex, (ph, pw))
        positions = (H - ph + 1) * (W - pw + 1) if self.valid is None else self.valid.sum()
        self.min_distance = positive_int(
            default_min_distance((th, tw), int(positions))
            if self._min_distance is None
            else self._min_distance,
            "min_distance",
            minimum=0,
        )
        if self.valid is not None and not self.valid.any():
            raise ValueError(
                f"no {pw}x{ph} patch fits outside the excluded region: paint a smaller "
                "exclusion or use a smaller patch_size"
            )
        if self.seam.blend == POISSON and self.margin == 0:
            raise ValueError(
                "blend 'poisson' keeps the outer margin fixed: margin must be at least 1"
            )
        self.notes = []
        if self.margin == 0 and (ph, pw) == (th, tw):
            self.notes.append(
                "margin 0 with a patch as large as the tile: cuts may reach the tile border, "
                "so candidates may not connect to each other"
            )
        flat = flat_warning(self.S)
        self.flat = bool(flat)  # every window is the same: no content check (warned)
        if flat:
            self.notes.append(flat)
        # ring band for the position refinement (offsets margin .. ring-1)
        r, c = np.mgrid[0:ph, 0:pw]
        d = np.minimum.reduce([r, c, ph - 1 - r, pw - 1 - c])
        self.band = (d >= self.margin) & (d < self.ring)
        self.band_runs = true_runs(self.band)
        self.search_band = self.band & (d < self.margin + SEARCH_BAND)
        # outward bias of the cut: 0 at the margin, `outward` x the mean error at the ring's
        # inner edge (added to the error map the cut is searched on)
        depth = np.clip((d - self.margin) / max(1, self.ring - 1 - self.margin), 0, 1)
        self.bias = np.where(d < self.ring, depth, 0.0)
        reblend = (
            self.seam_shows > 0
            and self.seam.blend == "adaptive"
            and self.margin > 0
            and ph * pw <= SEAM_SHOWS_MAX_PIXELS
        )
        y, x = max(0, (H - 1024) // 2), max(0, (W - 1024) // 2)  # a central crop is enough
        crop = self.S[y : y + 1024, x : x + 1024]
        self.natural = natural_step(self.lum(crop)) if reblend else None
        self.Sc = np.ascontiguousarray(colour_channels(self.S))
        self.Up = np.ascontiguousarray(colour_channels(self.U[MAIN]).transpose(2, 0, 1))

    # ---- positions
    def ring_costs(self) -> np.ndarray:
        """Mean squared error (per pixel and channel) of every source window's outer ring band
        (:data:`SEARCH_BAND`) against the template's, plus the tone term (:data:`TONE`);
        ``inf`` where the patch would hold excluded pixels. Computed once."""
        if self._costs is None:
            band = self.search_band.astype(np.float32)
            spec = SampleSpectrum(self.Sc)
            e = spec.ssd(self.Up.transpose(1, 2, 0)[None], band[None])[0]
            e /= band.sum() * self.Sc.shape[2]
            if TONE > 0:
                e += TONE * self._tone_costs()
            if self.valid is not None:
                e[~self.valid] = np.inf
            self._costs = e
        return self._costs

    def _tone_costs(self) -> np.ndarray:
        """(mean luminance of every window's interior − of the template's ring)², the
        interior being the pixels at least the patch ring w_P in (the ring is where the cut
        runs; on blocks of :attr:`stride` px): the tone step a patch would leave at its
        cut (:data:`TONE`)."""
        r = self.ring
        u = self.lum(self.U[MAIN])
        inner = np.zeros(u.shape, dtype=bool)
        inner[r:-r, r:-r] = True
        ring = float(u[~inner].mean())
        m = coarse_interior_means(self.S, (self.ph, self.pw), r, self.stride)
        return (m - ring) ** 2

    def keep_away(self, allowed: np.ndarray, origin) -> None:
        """Clear ``allowed`` within ``min_distance`` (Chebyshev) of ``origin``."""
        d = self.min_distance
        if d <= 0:
            return
        y, x = origin
        allowed[max(0, y - d + 1) : y + d, max(0, x - d + 1) : x + d] = False

    def plan(self, seeds, avoid=()) -> tuple[list[tuple[int, int]], str | None]:
        """Global search: the patch origins of candidates with these ``seeds`` (in order)
        and a note when fewer could be given (:func:`engine.tiles.patch_plan.plan`)."""
        return patch_plan.plan(self, seeds, avoid)

    def spread_term(self) -> patch_plan.Spread | None:
        """The global search's resemblance term (:mod:`engine.tiles.patch_plan`), or None when
        ``spread`` is 0, the source has more than :data:`SPREAD_MAX_POSITIONS` patch positions
        or the texture is periodic (its patches must keep the template's phase)."""
        H, W = self.S.shape[:2]
        if self.spread == 0 or (H - self.ph + 1) * (W - self.pw + 1) > SPREAD_MAX_POSITIONS:
            return None
        if any(self.texture_scale().periodic):
            return None
        return patch_plan.Spread(self.lum(self.S), (self.ph, self.pw), self.spread)

    def texture_scale(self) -> Scale:
        """The texture's structure scale: the one given, else measured once on a central crop
        of at most :data:`engine.tiles.patch_phase.SCALE_CROP` px (as the phase class is)."""
        if self.scale is None:
            H, W = self.S.shape[:2]
            c = SCALE_CROP
            y, x = max(0, (H - c) // 2), max(0, (W - c) // 2)
            self.scale = structure_scale(self.S[y : y + c, x : x + c])
        return self.scale

    def lum(self, window: np.ndarray) -> np.ndarray:
        """Luminance (float32) of an image."""
        from engine.metrics import luminance

        return luminance(window).astype(np.float32)

    @property
    def stride(self) -> int:
        """Every k-th pixel of a window is enough to compare contents (~128 per side)."""
        return max(1, min(self.ph, self.pw) // 128)

    def window_lum(self, origin) -> np.ndarray:
        """Luminance of the patch window at ``origin``, every :attr:`stride`-th pixel."""
        y, x = origin
        k = self.stride
        return self.lum(self.S[y : y + self.ph : k, x : x + self.pw : k])

    def random_origin(self, gen: np.random.Generator) -> tuple[int, int]:
        H, W = self.S.shape[:2]
        if self.valid is None:
            return int(gen.integers(0, H - self.ph + 1)), int(gen.integers(0, W - self.pw + 1))
        flat = np.flatnonzero(self.valid)
        k = int(flat[int(gen.integers(0, flat.size))])
        return divmod(k, self.valid.shape[1])

    def refine(self, origin, n: int) -> tuple[tuple[int, int], float]:
        """Best position in origin + [-n, n]^2 by the mean ring-band error."""
        H, W = self.S.shape[:2]
        y0, x0 = origin
        ylo, yhi = max(0, y0 - n), min(H - self.ph, y0 + n)
        xlo, xhi = max(0, x0 - n), min(W - self.pw, x0 + n)
        out = np.empty((yhi - ylo + 1, xhi - xlo + 1), dtype=np.float64)
        band_costs(self.Sc, self.Up, self.band_runs, ylo, xlo, out)
        if self.valid is not None:
            out[~self.valid[ylo : yhi + 1, xlo : xhi + 1]] = np.inf
        if not np.isfinite(out).any():  # the given origin itself must be valid
            raise ValueError(f"patch_origin {origin} lies on the excluded region")
        # ties -> the position nearest the drawn one (stable for flat sources)
        yy, xx = np.mgrid[ylo : yhi + 1, xlo : xhi + 1]
        order = np.lexsort(((np.abs(yy - y0) + np.abs(xx - x0)).ravel(), out.ravel()))
        k = int(order[0])
        return (int(yy.ravel()[k]), int(xx.ravel()[k])), float(out.ravel()[k])

    # ---- one candidate
    def make(self, index: int, seed: int | None, origin, n: int, cancel) -> CandidateTile:
        check(cancel)
        if origin is None:
            origin = self.random_origin(np.random.default_rng(seed))
        (sy, sx), band_error = self.refine(origin, n)
        check(cancel)
        win = (slice(sy, sy + self.ph), slice(sx, sx + self.pw))
        Q = {k: v[win] for k, v in self.stack.items()}
        out, cut = stitch_patch(
            Q,
            self.U,
            ring=self.ring,
            margin=self.margin,
            seam=self.seam,
            weights=self.weights,
            outward=self.outward,
            depth=self.bias,
            continue_margin=True,
            cancel=cancel,
        )
        reblended = self.natural is not None and cut_shows(
            self.lum(out[MAIN]), cut.mask, self.natural, self.seam_shows
        )
        if reblended:
            out = gradient_blend(Q, self.U, cut, ring=self.ring, margin=self.margin)
        ty, tx, ph, pw = self.ty, self.tx, self.ph, self.pw
        tiles = {}
        for k, v in self.tmaps.items():
            t = v.copy()
            t[ty : ty + ph, tx : tx + pw] = out[k]
            tiles[k] = t
        tile = tiles[MAIN]
        m = self.margin
        if m and not _ring_equal(tile, self.tmaps[MAIN], m):  # pragma: no cover - invariant
            raise RuntimeError("a candidate changed the template's outer margin")
        th, tw = tile.shape[:2]
        mask = np.zeros((th, tw), dtype=bool)
        mask[ty : ty + ph, tx : tx + pw] = cut.mask
        alpha = np.zeros((th, tw), dtype=np.float32)
        alpha[ty : ty + ph, tx : tx + pw] = cut.alpha
        changed = count_changed(tile, self.tmaps[MAIN]) / (th * tw)
        scores = {
            "criterion": float(cut.criterion),
            "peak": float(cut.peak),
            "band_error": band_error,
            "changed": changed,
            "coverage": float(mask.mean()),
            "gradient_blend": float(reblended),
        }
        fr = frozen_array
        return CandidateTile(
            index=int(index),
            tile=fr(tile),
            maps={k: fr(v) for k, v in tiles.items() if k != MAIN},
            patch_rect=(sx, sy, pw, ph),
            patch_origin=(sy, sx),
            target_rect=(tx, ty, pw, ph),
            loop=fr(np.asarray(cut.loop) + (ty, tx)),
            mask=fr(mask),
            alpha=fr(alpha),
            scores=scores,
            seed=seed,
        )


def _ring_equal(a: np.ndarray, b: np.ndarray, m: int) -> bool:
    return bool(
        np.array_equal(a[:m], b[:m])
        and np.array_equal(a[-m:], b[-m:])
        and np.array_equal(a[:, :m], b[:, :m])
        and np.array_equal(a[:, -m:], b[:, -m:])
    )


# --------------------------------------------------------------------------- API
def iter_candidates(
    source,
    template: SeamlessTile,
    n: int = 30,
    *,
    patch_size=None,
    patch_overlap=None,
    margin: int = MARGIN,
    patch_search: str = "global",
    neighbourhood: int = 5,
    tolerance: float = TOLERANCE,
    quality: float = QUALITY,
    min_distance: int | None = None,
    outward: float = OUTWARD,
    seam_shows: float = SEAM_SHOWS,
    spread: float = SPREAD,
    scale: Scale | None = None,
    seam: SeamSpec | None = None,
    excluded=None,
    maps=None,
    weights=None,
    rng=None,
    workers: int = 2,
    cancel=None,
):
    """Stream ``n`` connectable variants of ``template``; the generator's value is their list.

    Parameters
    ----------
    source : (H, W[, C]) array
        The source the template was made from.
    template : SeamlessTile
    n : int
        Number of candidates.
    patch_size : int or (h, w) or None
        Patch window size (default: the tile size); centred in the tile.
    patch_overlap : int or None
        w_P, the ring in which the closed cut runs (default: :func:`default_patch_overlap`
        of the template's w_T, ``min(w_T, max(8, w_T // 2))``).
    margin : int
        Outer pixels that always stay the template (default :data:`MARGIN`, 1).
    patch_search : {"global", "local"}
        Where patches come from (module docstring): the best ring matches over the whole
        source (default) or the paper's random position refined within ``neighbourhood``.
    neighbourhood : int
        n of the local search (s0 + [-n, n]^2); unused by the global search.
    tolerance, quality : float
        Global search: draw among positions within ``1 + tolerance`` of the best remaining
        ring match; never use one worse than ``1 + quality`` times the source's best.
    min_distance : int or None
        Global search: px (Chebyshev) between any two candidates' patch sources and from
        the template's position (default :func:`default_min_distance`).
    outward : float
        Bias of the closed cut toward the outer margin (0 = none), in units of the mean
        error; thinner shared rings repeat less of the template in a layout.
    seam_shows : float
        With the default blend "adaptive": a candidate whose cut's step is above this
        multiple of the source's own step is blended in the gradient domain instead
        (:data:`SEAM_SHOWS`; 0 = never; its ``scores["gradient_blend"]`` is 1); patches
        larger than :data:`SEAM_SHOWS_MAX_PIXELS` never are.
    spread : float
        Global search: weight of a window's resemblance to the template and the patches
        already chosen in the draw's rank (:mod:`engine.tiles.patch_plan`; :data:`SPREAD`;
        0 = the band match alone); off on periodic textures.
    scale : engine.tiles.scale.Scale or None
        The structure scale, if known (the template search's; None: measured on a central
        crop): on a periodic texture the global search draws from the template's phase class
        first (:mod:`engine.tiles.patch_phase`) and without the spread term.
    seam : SeamSpec, optional
        Seam method and options, error metric and blending of the patch cuts (default
        :data:`engine.stitch.PATCH_SEAM`: dp with adaptive blending).
    excluded : (H, W) bool or None
        Source pixels no patch may contain.
    maps, weights
        The template's material maps (same names) and the seam error weights.
    rng : int, Generator or None
        The run's seed; candidate k uses :func:`candidate_seed` (seed, k).
    workers : int
        Threads (1 runs in the calling thread).
    cancel : CancelToken or None
        Stops the run; the candidates already finished are kept and returned.

    Yields :class:`CandidateTile` items as they finish (any order; each has its ``index``),
    :class:`Progress` and, when fewer candidates than asked can be made, one
    :class:`CandidatesNotice` (also issued as a warning).
    """
    setup = CandidateSetup(
        source,
        template,
        patch_size=patch_size,
        patch_overlap=patch_overlap,
        margin=margin,
        neighbourhood=neighbourhood,
        seam=seam,
        excluded=excluded,
        maps=maps,
        weights=weights,
        patch_search=patch_search,
        tolerance=tolerance,
        quality=quality,
        min_distance=min_distance,
        outward=outward,
        seam_shows=seam_shows,
        spread=spread,
        scale=scale,
    )
    n = positive_int(n, "n")
    workers = positive_int(workers, "workers")
    base = base_seed(rng)
    for note in setup.notes:
        warnings.warn(note, stacklevel=2)
    return _iter_candidates(setup, n, base, workers, cancel)


def _iter_candidates(setup: CandidateSetup, n: int, base: int, workers: int, cancel):
    seeds = [candidate_seed(base, k) for k in range(n)]
    made: dict[int, CandidateTile] = {}
    yield Progress(0, n, "candidates")
    origins: list = [None] * n
    if setup.search == "global":
        check(cancel)
        origins, note = setup.plan(seeds)
        if note:
            warnings.warn(note, stacklevel=2)
            yield CandidatesNotice(note)
        n = len(origins)
    step = 0 if setup.search == "global" else setup.n
    if workers == 1:
        for k in range(n):
            if is_cancelled(cancel):
                break
            try:
                c = setup.make(k, seeds[k], origins[k], step, cancel)
            except Cancelled:
                break
            made[k] = c
            yield c
            yield Progress(len(made), n, f"candidate {k}")
    else:
        stop = CancelToken()
        token = AnyCancel(cancel, stop)
        pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="candidates")
        completions = Completions()  # a Ctrl+C while waiting never wedges a worker
        try:
            pending = {}
            for k in range(n):
                fut = pool.submit(setup.make, k, seeds[k], origins[k], step, token)
                pending[fut] = k
                completions.watch(fut)
            while pending:
                finished = completions.wait(pending)
                for fut in sorted(finished, key=pending.get):
                    k = pending.pop(fut)
                    if fut.cancelled():
                        continue
                    try:
                        c = fut.result()
                    except Cancelled:
                        continue
                    made[k] = c
                    yield c
                    yield Progress(len(made), n, f"candidate {k}")
                if is_cancelled(cancel):
                    for fut in pending:
                        fut.cancel()
        finally:
            stop.cancel()
            pool.shutdown(wait=True, cancel_futures=True)
    if len(made) < n:
        yield Progress(len(made), n, "candidates: cancelled")
    elif n < len(seeds):
        yield Progress(n, n, f"candidates: {n} of {len(seeds)}")
    return [made[k] for k in sorted(made)]


def candidates(source, template: SeamlessTile, n: int = 30, **options) -> list[CandidateTile]:
    """Drain :func:`iter_candidates` and return the candidates in index order."""
    return drain(iter_candidates(source, template, n, **options))


def make_candidate(
    source,
    template: SeamlessTile,
    *,
    patch_origin=None,
    index: int = 0,
    seed: int | None = None,
    rng=None,
    neighbourhood: int | None = None,
    patch_search: str = "global",
    avoid=(),
    tolerance: float = TOLERANCE,
    quality: float = QUALITY,
    min_distance: int | None = None,
    outward: float = OUTWARD,
    seam_shows: float = SEAM_SHOWS,
    spread: float = SPREAD,
    scale: Scale | None = None,
    patch_size=None,
    patch_overlap=None,
    margin: int = MARGIN,
    seam: SeamSpec | None = None,
    excluded=None,
    maps=None,
    weights=None,
    cancel=None,
) -> CandidateTile:
    """Make one candidate: from a user-given ``patch_origin`` (row, col) or from a seed.

    With ``patch_origin`` the patch is taken exactly there (``neighbourhood`` defaults to 0;
    give one to let the position settle nearby). Without it the position is drawn from
    ``seed`` (a candidate's own seed, to rebuild it) or, if that is None too, from ``rng``
    (a re-roll): by the global search (away from the template's position and from the
    patch origins in ``avoid``, e.g. the other candidates') or the local one. Raises
    :class:`engine.cancel.Cancelled` when cancelled, ``ValueError`` when the global search
    finds no position.
    """
    setup = CandidateSetup(
        source,
        template,
        patch_size=patch_size,
        patch_overlap=patch_overlap,
        margin=margin,
        neighbourhood=0 if neighbourhood is None else neighbourhood,
        seam=seam,
        excluded=excluded,
        maps=maps,
        weights=weights,
        patch_search=patch_search,
        tolerance=tolerance,
        quality=quality,
        min_distance=min_distance,
        outward=outward,
        seam_shows=seam_shows,
        spread=spread,
        scale=scale,
    )
    if isinstance(index, bool) or not isinstance(index, numbers.Integral) or index < 0:
        raise ValueError(f"index must be a non-negative integer, got {index!r}")
    origin = None
    if patch_origin is not None:
        try:
            origin = (int(patch_origin[0]), int(patch_origin[1]))
        except (TypeError, ValueError, IndexError):
            raise TypeError(f"patch_origin must be (row, col), got {patch_origin!r}") from None
        H, W = setup.S.shape[:2]
        if not (0 <= origin[0] <= H - setup.ph and 0 <= origin[1] <= W - setup.pw):
            raise ValueError(
                f"patch_origin {origin} puts the {setup.pw}x{setup.ph} patch outside the "
                f"{W}x{H} source"
            )
        n = setup.n
        seed = None
    else:
        if seed is None:
            seed = candidate_seed(base_seed(rng), index)
        n = 5 if neighbourhood is None else setup.n
        if setup.search == "global":
            found, note = setup.plan([seed], avoid=[tuple(int(v) for v in o) for o in avoid])
            if not found:
                raise ValueError(note)
            origin, n = found[0], 0
    return setup.make(index, seed, origin, n, cancel)
