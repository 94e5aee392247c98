"""Wang tile sets (Cohen, Shade, Hiller & Deussen 2003; ALGORITHMS.md §6).

Every tile edge carries a colour; K colours for the north/south edges (axis ``"h"``) and K for
the east/west edges (axis ``"v"``). Two tiles join wherever their touching edges have the same
colour, because both show the same *edge sample* there: a diamond of the source centred on the
edge, whose halves lie in the two tiles. The complete set has one tile per edge signature
(N, E, S, W), K⁴ tiles (16 for K = 2, 81 for K = 3), optionally several variants each.

1. **Edge samples** (:func:`choose_sample`). Each colour is a source position. In a tile, an
   N/S sample meets an E/W sample along a diagonal, so the samples are chosen by the quilting
   matcher (:class:`engine.matching.SampleSpectrum`, masked SSD by FFT over every source
   position): each new sample is the best match (drawn within ``tolerance``) for the samples of
   the other axis over the four diagonal bands where they meet, at least ``min_distance``
   from every earlier sample (variety: no sample repeats another or continues it). The first
   is drawn at random; after one round each sample of the first axis is chosen again against
   the whole other axis.
2. **The frame** (:mod:`engine.tiles.wang_cut`): the four edge layers joined by four
   minimum-error cuts from the corners to a junction (any seam method), so the tile's edge
   pixels are exactly the edge samples' own.
3. **The interior** (``interior="patch"``, default [REC]): a source window chosen by the same
   matcher against the frame's ring (offsets ``margin .. patch_overlap - 1``), drawn within
   ``tolerance`` and away from the samples and the other tiles' windows, stitched in along a
   closed cut inside that ring (:func:`engine.stitch.patch_cut`; the outer ``margin`` pixels
   stay the frame's). Without it (``interior="diamonds"``, Cohen's construction) every pixel
   of a tile is one of its four samples: a tile repeats a quarter of every tile of the same
   colour, which a large layout shows as a lattice of repeated diamonds. With it only the
   thin ring outside the cut is shared, and ``variants`` tiles per signature differ inside.

Tiles stream as :class:`WangTile` items (after one :class:`WangSamples` item); tile ``k`` is
seeded from ``(seed, k)`` and its interior avoids the windows of tiles ``0 .. k-1`` only, so the
same seed gives the same set on 1 or 2 workers. Material maps follow every cut
(:func:`engine.materials.apply_cut`: normals renormalised); pixels away from the blends are
copies of the source (16-bit values stay exact).
"""

from __future__ import annotations

import numbers
import warnings
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass, field

import numpy as np

from engine._validate import as_image, choice, positive_int
from engine.cancel import AnyCancel, Cancelled, CancelToken, check, is_cancelled
from engine.errormap import colour_channels
from engine.events import Item, Progress, drain, frozen_array
from engine.exclusion import valid_anchors
from engine.matching import ZERO_ERROR_FRACTION, SampleSpectrum, error_floor
from engine.matching import select_within_tolerance as _select
from engine.materials import apply_cut
from engine.seams.spec import as_seam_spec
from engine.stitch import PATCH_SEAM, patch_cut
from engine.tiles.candidates import base_seed, default_patch_overlap
from engine.tiles.seamless import MAIN, as_maps, check_weights, seam_error
from engine.tiles.template import default_overlap, excluded_mask, flat_warning
from engine.tiles.wang_cut import CUTS, frame_cut, frame_reach, ramp_reach

__all__ = [
    "AXES",
    "INTERIORS",
    "WANG_DEFAULTS",
    "WangSample",
    "WangSamples",
    "WangSet",
    "WangTile",
    "canonical_signatures",
    "choose_sample",
    "de_bruijn",
    "from_candidate",
    "iter_wang_set",
    "make_wang_tile",
    "samples_from_record",
    "wang_record",
    "wang_set",
]

AXES = ("h", "v")  # "h": colours of the north/south edges, "v": of the east/west edges
INTERIORS = ("patch", "diamonds")
PATCH_LABEL = 4  # label of the interior patch's pixels (0..3: N, E, S, W; wang_cut.LABELS)
ROLE_AXIS = {"n": "h", "s": "h", "e": "v", "w": "v"}
#: samples and interiors come from the source's windows at least this detailed (quantile)
DETAIL_QUANTILE = 0.25

#: Options of :func:`iter_wang_set` and their defaults.
WANG_DEFAULTS = {
    "colours": 2,
    "band": None,
    "variants": 1,
    "interior": "patch",
    "patch_overlap": None,
    "margin": 1,
    "outward": 1.0,
    "min_distance": None,
    "tolerance": 0.1,
    "seam": PATCH_SEAM,
    "excluded": None,
    "maps": None,
    "weights": None,
}


# --------------------------------------------------------------------------- signatures
def de_bruijn(k: int) -> list[int]:
    """A de Bruijn sequence B(k, 2): every ordered pair of 0..k-1 appears once cyclically.

    >>> de_bruijn(2)
    [0, 0, 1, 1]
    """
    k = positive_int(k, "k")
    a = [0] * (2 * k + 1)
    seq: list[int] = []

    def db(t, p):
        if t > 2:
            if 2 % p == 0:
                seq.extend(a[1 : p + 1])
        else:
            a[t] = a[t - p]
            db(t + 1, p)
            for j in range(a[t - p] + 1, k):
                a[t] = j
                db(t + 1, t)

    db(1, 1)
    return seq


def canonical_signatures(k: int) -> list[tuple[int, int, int, int]]:
    """Every edge signature (N, E, S, W) once, in the row-major order of a k² x k² grid that
    is itself a valid Wang tiling, toroidally (Lagae's packing of a complete set): cell (i, j)
    has N = x[i], S = x[i + 1], W = x[j], E = x[j + 1] for the de Bruijn sequence x."""
    x = de_bruijn(k)
    n = len(x)
    return [(x[i], x[(j + 1) % n], x[(i + 1) % n], x[j]) for i in range(n) for j in range(n)]


# --------------------------------------------------------------------------- results
@dataclass(frozen=True, slots=True)
class WangSample:
    """One edge colour: a source position whose pixels continue across every edge of that
    colour.

    ``origin`` is the source (row, col) of tile pixel (0, 0) when the sample lies on a tile's
    north edge (axis ``"h"``) or west edge (axis ``"v"``); on the south (east) edge it shows
    the source ``tile`` rows (columns) above (left of) that. ``error`` is its matching error
    when chosen (mean squared difference per band pixel and channel).
    """

    axis: str
    colour: int
    origin: tuple[int, int]
    error: float = 0.0

    def offset(self, role: str, tile: int) -> tuple[int, int]:
        """Source (row, col) of tile pixel (0, 0) in ``role`` (n, e, s or w)."""
        oy, ox = self.origin
        return {"n": (oy, ox), "w": (oy, ox), "s": (oy - tile, ox), "e": (oy, ox - tile)}[role]

    def footprint(self, tile: int, reach: int) -> tuple[int, int, int, int]:
        """Source rectangle (x, y, w, h) the sample's layers read."""
        oy, ox = self.origin
        if self.axis == "h":
            return (ox, oy - reach, tile, 2 * reach)
        return (ox - reach, oy, 2 * reach, tile)

    def diamond(self, tile: int) -> list[tuple[float, float]]:
        """The diamond's corners (x, y) in source pixel-edge coordinates: the square rotated
        by 45° whose diagonal is the tile edge."""
        oy, ox = self.origin
        t = tile / 2
        if self.axis == "h":
            return [(ox, oy), (ox + t, oy - t), (ox + tile, oy), (ox + t, oy + t)]
        return [(ox, oy), (ox + t, oy + t), (ox, oy + tile), (ox - t, oy + t)]


@dataclass(frozen=True, slots=True)
class WangSamples(Item):
    """The edge samples of a run (streamed before the tiles): h colours then v colours."""

    samples: tuple


@dataclass(frozen=True, slots=True)
class WangTile(Item):
    """One finished Wang tile.

    Attributes
    ----------
    index : int
        Its slot: ``variant * K**4 + position`` in :func:`canonical_signatures` order.
    signature : (n, e, s, w)
        The colour of each edge (h colours on n and s, v colours on e and w).
    variant : int
    tile : (T, T, C) float32
    maps : dict
        The same tile for every extra material map.
    labels : (T, T) uint8 or None
        Where each pixel comes from: 0 N, 1 E, 2 S, 3 W sample, 4 the interior patch (None
        for a tile read back from a project).
    paths : dict
        The cuts in tile (row, col): ``nw``, ``ne``, ``sw``, ``se`` (corner to junction) and
        ``patch`` (the closed loop, absent without an interior patch).
    junction : (row, col)
    patch_origin : (row, col) or None
        The interior patch's source window (top-left), None without one.
    scores : dict
        ``criterion`` and ``peak`` of the corner cuts (sum, max), ``patch_criterion``,
        ``patch_peak``, ``band_error`` (mean ring error of the patch window).
    seed : int or None
    """

    index: int
    signature: tuple[int, int, int, int]
    variant: int
    tile: np.ndarray
    maps: dict
    labels: np.ndarray | None
    paths: dict
    junction: tuple[int, int]
    patch_origin: tuple[int, int] | None = None
    scores: dict = field(default_factory=dict)
    seed: int | None = None

    @property
    def wang(self) -> dict:
        """The signature as ``{"n": c, "e": c, "s": c, "w": c}`` (the manifest's form)."""
        return dict(zip("nesw", self.signature, strict=True))

    def to_candidate(self):
        """This tile as the project's tile type (:class:`engine.candidate.CandidateTile`): its
        signature, variant and junction in ``params``; :func:`from_candidate` reads it back."""
        from engine.candidate import CandidateTile

        cuts = {k: np.asarray(v).tolist() for k, v in self.paths.items() if k != "patch"}
        return CandidateTile(
            index=self.index,
            tile=self.tile,
            maps=dict(self.maps),
            patch_origin=self.patch_origin,
            loop=self.paths.get("patch"),
            scores={k: float(v) for k, v in self.scores.items()},
            seed=self.seed,
            params={
                "wang": self.wang,
                "variant": self.variant,
                "index": self.index,
                "junction": list(self.junction),
                "cuts": cuts,
            },
        )


def from_candidate(c) -> WangTile:
    """The :class:`WangTile` a project keeps as :meth:`WangTile.to_candidate` wrote it (its
    pixel labels are not kept: ``labels`` is None)."""
    p = c.params
    paths = {k: np.asarray(v, dtype=np.intp).reshape(-1, 2) for k, v in p.get("cuts", {}).items()}
    if c.loop is not None:
        paths["patch"] = np.asarray(c.loop, dtype=np.intp)
    junction = p.get("junction") or (0, 0)
    return WangTile(
        index=int(p.get("index", c.index)),
        signature=tuple(int(p["wang"][k]) for k in "nesw"),
        variant=int(p.get("variant", 0)),
        tile=c.tile,
        maps=dict(c.maps),
        labels=None,
        paths=paths,
        junction=(int(junction[0]), int(junction[1])),
        patch_origin=None if c.patch_origin is None else tuple(c.patch_origin),
        scores=dict(c.scores),
        seed=c.seed,
    )


@dataclass(frozen=True)
class WangSet:
    """A Wang tile set: its samples and tiles (index order; a cancelled run holds fewer)."""

    colours: int
    tile_size: int
    band: int
    variants: int
    samples: tuple[WangSample, ...]
    tiles: tuple[WangTile, ...]
    parameters: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def count(self) -> int:
        """Tiles of the complete set: ``variants * colours**4``."""
        return self.variants * self.colours**4

    @property
    def complete(self) -> bool:
        return [t.index for t in self.tiles] == list(range(self.count))

    def sample(self, axis: str, colour: int) -> WangSample:
        return self.samples[AXES.index(axis) * self.colours + colour]

    @property
    def signatures(self) -> list[tuple[int, int, int, int]]:
        return [t.signature for t in self.tiles]

    def record(self) -> dict:
        """The set's record for manifests and projects (:func:`wang_record`)."""
        return wang_record(self.samples, self.parameters)

    def arrangement(self, variant: int = 0) -> np.ndarray:
        """The K² x K² index matrix of :func:`canonical_signatures` (a valid tiling that also
        wraps) for one variant."""
        n = self.colours**2
        return (variant * n * n + np.arange(n * n)).reshape(n, n)


def wang_record(samples, parameters: dict) -> dict:
    """A Wang set as plain JSON (manifest, project): colours, tile size, variants, band, the
    samples and every parameter of the run; :func:`samples_from_record` reads the samples
    back."""
    return {
        "colours": int(parameters["colours"]),
        "tile_size": int(parameters["tile_size"]),
        "variants": int(parameters.get("variants", 1)),
        "band": parameters.get("band"),
        "samples": [
            {"axis": s.axis, "colour": int(s.colour), "origin": [int(v) for v in s.origin],
             "error": float(s.error)}
            for s in samples
        ],
        "parameters": dict(parameters),
    }  # fmt: skip


def samples_from_record(record: dict) -> list[WangSample]:
    """The :class:`WangSample` list of a :func:`wang_record`."""
    return [
        WangSample(s["axis"], int(s["colour"]), (int(s["origin"][0]), int(s["origin"][1])),
                   float(s.get("error", 0.0)))
        for s in record["samples"]
    ]  # fmt: skip


# --------------------------------------------------------------------------- seeds
def wang_seed(base: int, kind: int, index: int) -> int:
    """Seed of item ``index`` of ``kind`` (0: samples, 1: tiles) in a run seeded ``base``."""
    state = np.random.SeedSequence([int(base), int(kind), int(index)]).generate_state(1, np.uint64)
    return int(state[0]) & (2**63 - 1)


# --------------------------------------------------------------------------- setup
def _nonneg_float(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not value >= 0:
        raise ValueError(f"{name} must be a number >= 0, got {value!r}")
    return float(value)


class WangSetup:
    """Validated inputs and the matcher's spectra, shared by every tile of a run."""

    def __init__(self, source, *, tile_size, **options):
        opts = {**WANG_DEFAULTS, **options}
        colours, band, variants = opts.pop("colours"), opts.pop("band"), opts.pop("variants")
        interior, patch_overlap = opts.pop("interior"), opts.pop("patch_overlap")
        margin, outward = opts.pop("margin"), opts.pop("outward")
        min_distance, tolerance = opts.pop("min_distance"), opts.pop("tolerance")
        seam = opts.pop("seam")
        excluded, maps, weights = opts.pop("excluded"), opts.pop("maps"), opts.pop("weights")
        if opts:
            raise TypeError(f"unexpected option(s): {', '.join(sorted(opts))}")
        self.S = as_image(source, "source")
        H, W = self.S.shape[:2]
        self.K = positive_int(colours, "colours")
        self.T = T = positive_int(tile_size, "tile_size", minimum=8)
        self.band = positive_int(
            max(2, default_overlap(T)) if band is None else band, "band", minimum=1
        )
        if 4 * self.band > T:
            raise ValueError(f"band {self.band} is too wide for {T} px tiles (at most {T // 4})")
        self.variants = positive_int(variants, "variants")
        self.interior = choice(interior, "interior", INTERIORS)
        if self.interior == "diamonds" and self.variants > 1:
            raise ValueError(
                "variants > 1 needs interior='patch' (without a patch every variant of a "
                "signature would be the same tile)"
            )
        self.seam = as_seam_spec(seam, default=PATCH_SEAM)
        self.reach = frame_reach(T, self.band, ramp_reach(self.seam))
        if min(H, W) < max(T, 2 * self.reach):
            need = 2 * self.reach
            raise ValueError(
                f"the {W}x{H} source is too small for {T} px Wang tiles: each edge sample "
                f"needs {need}x{T} px (use a smaller tile_size or band)"
            )
        self.ring = positive_int(
            default_patch_overlap(default_overlap(T)) if patch_overlap is None else patch_overlap,
            "patch_overlap",
            minimum=2,
        )
        self.margin = positive_int(margin, "margin", minimum=1)
        if self.margin >= self.ring:
            raise ValueError(
                f"margin must be smaller than patch_overlap, got margin={self.margin}, "
                f"patch_overlap={self.ring}"
            )
        if 2 * self.ring > T:
            raise ValueError(f"patch_overlap {self.ring} is too wide for {T} px tiles")
        self.min_distance = _nonneg_float(
            T / 2 if min_distance is None else min_distance, "min_distance"
        )
        self.tolerance = _nonneg_float(tolerance, "tolerance")
        extra = as_maps(maps, (H, W))
        self.weights = check_weights(weights, extra)
        self.stack = {MAIN: self.S, **extra}
        self.excluded = excluded_mask(excluded, (H, W))
        self.notes = []
        flat = flat_warning(self.S)
        if flat:
            self.notes.append(flat)
        self.spec = SampleSpectrum(self.S)
        self.zero_level = ZERO_ERROR_FRACTION * error_floor(self.S) * self.S.shape[2]
        self.bands = _band_pixels(T, self.band)
        self._calm: dict[str, np.ndarray] = {}
        self._detail: dict[tuple[int, int], np.ndarray] = {}
        r, c = np.mgrid[0:T, 0:T]
        d = np.minimum.reduce([r, c, T - 1 - r, T - 1 - c])
        self.outward = _nonneg_float(outward, "outward")
        # outward bias of the interior's cut (as the candidates'): 0 at the margin, `outward`
        # x the mean error at the ring's inner edge, added to the map the cut is searched on
        span = max(1, self.ring - 1 - self.margin)
        ring = (d >= self.margin) & (d < self.ring)
        self.depth = np.where(d < self.ring, np.clip((d - self.margin) / span, 0, 1), 0.0)
        # the interior is matched where its cut will run: the ring, the outer part first
        self.ring_mask = np.where(ring, 1 / (1 + self.outward * self.depth), 0).astype(np.float32)

    # ---- geometry
    def window_shape(self, axis: str) -> tuple[int, int]:
        return (2 * self.reach, self.T) if axis == "h" else (self.T, 2 * self.reach)

    def anchor_to_origin(self, axis: str, y: int, x: int) -> tuple[int, int]:
        return (y + self.reach, x) if axis == "h" else (y, x + self.reach)

    def check_origin(self, axis: str, origin) -> tuple[int, int]:
        try:
            oy, ox = (int(v) for v in origin)
        except (TypeError, ValueError):
            raise TypeError(f"a sample origin must be (row, col), got {origin!r}") from None
        H, W = self.S.shape[:2]
        wh, ww = self.window_shape(axis)
        y, x = (oy - self.reach, ox) if axis == "h" else (oy, ox - self.reach)
        if not (0 <= y <= H - wh and 0 <= x <= W - ww):
            raise ValueError(
                f"an {axis!r} sample at origin {(oy, ox)} reads source pixels outside the "
                f"{W}x{H} source (its {ww}x{wh} window would start at x={x}, y={y})"
            )
        return oy, ox

    def layer(self, sample: WangSample, role: str) -> dict[str, np.ndarray]:
        """The sample's pixels in ``role`` as T x T maps (zero outside what the frame reads)."""
        T, h = self.T, self.reach
        y, x = sample.offset(role, T)
        out = {}
        for name, img in self.stack.items():
            a = np.zeros((T, T, img.shape[2]), np.float32)
            if role == "n":
                a[:h] = img[y : y + h, x : x + T]
            elif role == "s":
                a[T - h :] = img[y + T - h : y + T, x : x + T]
            elif role == "w":
                a[:, :h] = img[y : y + T, x : x + h]
            else:
                a[:, T - h :] = img[y : y + T, x + T - h : x + T]
            out[name] = a
        return out

    # ---- sample selection
    def sample_errors(self, axis: str, others: list[WangSample]) -> np.ndarray:
        """Band SSD of an ``axis`` sample at every window anchor against ``others`` (the
        other axis), over the four diagonal bands of every tile where they meet."""
        T = self.T
        wh, ww = self.window_shape(axis)
        C = self.S.shape[2]
        kern = np.zeros((C, wh, ww), np.float32)
        wts = np.zeros((wh, ww), np.float32)
        const = 0.0
        for o in others:
            for name, (rows, cols) in self.bands.items():
                a_role, b_role = CUTS[name][:2]
                mine, theirs = (b_role, a_role) if axis == "h" else (a_role, b_role)
                oy, ox = o.offset(theirs, T)
                target = self.S[oy + rows, ox + cols]  # (n, C)
                wy, wx = _window_coords(mine, rows, cols, T, self.reach)
                np.add.at(wts, (wy, wx), 1.0)
                np.add.at(kern, (slice(None), wy, wx), target.T)
                const += float(np.sum(target.astype(np.float64) ** 2))
        if not others:
            H, W = self.S.shape[:2]
            return np.zeros((H - wh + 1, W - ww + 1), np.float32)
        e = self.spec.ssd_terms(kern[None], wts[None, None], np.array([const]))[0]
        return e

    def forbid_near(self, allowed: np.ndarray, offsets, points, distance: float) -> None:
        """Clear ``allowed`` (window anchors) where an anchor plus any of ``offsets`` lies
        within ``distance`` of any of ``points`` (source (row, col))."""
        if distance <= 0 or not len(points):
            return
        ny, nx = allowed.shape
        gy, gx = np.arange(ny), np.arange(nx)
        d2 = distance * distance
        for dy, dx in offsets:
            for py, px in points:
                ry = (gy + dy - py) ** 2
                rows = np.flatnonzero(ry < d2)
                if rows.size == 0:
                    continue
                rx = (gx + dx - px) ** 2
                allowed[rows] &= ry[rows, None] + rx[None, :] >= d2

    def detailed(self, shape: tuple[int, int]) -> np.ndarray:
        """Window anchors of ``shape`` whose detail (mean squared Laplacian of the luminance)
        is at least :data:`DETAIL_QUANTILE` of the source's windows: a matcher alone
        favours flat regions (they match anything calm), and flat samples or interiors
        read as blurred patches in a layout."""
        if shape not in self._detail:
            lum = colour_channels(self.S).mean(axis=2, dtype=np.float64)
            lap = np.zeros_like(lum)
            lap[1:-1, 1:-1] = (
                lum[:-2, 1:-1]
                + lum[2:, 1:-1]
                + lum[1:-1, :-2]
                + lum[1:-1, 2:]
                - 4 * lum[1:-1, 1:-1]
            )
            sat = np.pad(np.cumsum(np.cumsum(lap * lap, axis=0), axis=1), ((1, 0), (1, 0)))
            h, w = shape
            energy = sat[h:, w:] - sat[:-h, w:] - sat[h:, :-w] + sat[:-h, :-w]
            self._detail[shape] = energy >= np.quantile(energy, DETAIL_QUANTILE)
        return self._detail[shape]

    def calm_joint(self, axis: str) -> np.ndarray:
        """Window anchors whose joint (the source's own step across the tile edge the sample
        lies on) is no rougher than the median, relative to the steps of the sample's whole
        window: a joint along a mortar line or a shelf edge would show at every edge of
        that colour. (Relative to its window, so that calm regions are not preferred.)"""
        if axis not in self._calm:
            S = self.S if axis == "h" else self.S.transpose(1, 0, 2)
            T, h = self.T, self.reach
            d = np.sum(np.diff(S.astype(np.float64), axis=0) ** 2, axis=2)  # d[y] = S[y+1]-S[y]
            run = np.cumsum(np.pad(d, ((0, 0), (1, 0))), axis=1)
            rows = (run[:, T:] - run[:, :-T]) / T  # mean over T columns, by first column
            # window anchor (y, x): joint between source rows y + h - 1 and y + h; the
            # window's own steps are rows y .. y + 2h - 2
            n = S.shape[0] - 2 * h + 1
            joint = rows[h - 1 : h - 1 + n]
            acc = np.cumsum(np.pad(rows, ((1, 0), (0, 0))), axis=0)
            window = (acc[2 * h - 1 : 2 * h - 1 + n] - acc[:n]) / (2 * h - 1)
            ratio = joint / (window + 1e-12)
            calm = ratio <= np.median(ratio)
            self._calm[axis] = calm if axis == "h" else calm.T
        return self._calm[axis]

    def role_anchors(self, samples: list[WangSample]) -> list[tuple[int, int]]:
        """Source position of tile pixel (0, 0) for every role of every sample."""
        pts = []
        for s in samples:
            roles = ("n", "s") if s.axis == "h" else ("w", "e")
            pts += [s.offset(r, self.T) for r in roles]
        return pts

    def choose(self, axis, colour, others, placed, rng) -> WangSample:
        """Sample ``colour`` of ``axis``: best matching ``others`` within tolerance, away from
        ``placed`` (role anchors) by ``min_distance``."""
        e = self.sample_errors(axis, others).astype(np.float64)
        wh, ww = self.window_shape(axis)
        allowed = np.ones(e.shape, bool)
        if self.excluded is not None:
            allowed &= valid_anchors(self.excluded, (wh, ww))
        if not allowed.any():
            raise ValueError(
                f"no {ww}x{wh} edge sample fits outside the excluded region: paint a smaller "
                "exclusion or use a smaller tile_size"
            )
        allowed &= self.calm_joint(axis) & self.detailed((wh, ww))
        h, T = self.reach, self.T
        offs = [(h, 0), (h - T, 0)] if axis == "h" else [(0, h), (0, h - T)]
        dist = self.min_distance
        while True:
            ok = allowed.copy()
            self.forbid_near(ok, offs, placed, dist)
            if ok.any() or dist < 1:
                break
            dist /= 2
        if not ok.any():
            ok = allowed
        if dist < self.min_distance:
            self.notes.append(
                f"the source is too small for {self.K} colours at min_distance "
                f"{self.min_distance:g}: samples are {dist:g} px apart"
            )
        n_px = sum(len(r) for r, _ in self.bands.values()) * max(1, len(others))
        k, _, _ = _select(
            np.where(ok, e, np.inf),
            tolerance=self.tolerance,
            zero_level=self.zero_level * n_px,
            rng=rng,
        )
        y, x = divmod(k, e.shape[1])
        err = float(e[y, x]) / (n_px * self.S.shape[2]) if others else 0.0
        return WangSample(axis, int(colour), self.anchor_to_origin(axis, y, x), err)

    def choose_all(self, base: int, cancel) -> list[WangSample]:
        chosen: dict[tuple[str, int], WangSample] = {}
        order = [(axis, c) for c in range(self.K) for axis in AXES]
        order += [("h", c) for c in range(self.K)]  # each h colour again against every v
        for step, (axis, c) in enumerate(order):
            check(cancel)
            other = "v" if axis == "h" else "h"
            others = [s for (a, _), s in chosen.items() if a == other]
            placed = self.role_anchors([s for key, s in chosen.items() if key != (axis, c)])
            rng = np.random.default_rng(wang_seed(base, 0, step))
            chosen[(axis, c)] = self.choose(axis, c, others, placed, rng)
        return [chosen[(a, c)] for a in AXES for c in range(self.K)]

    # ---- tiles
    def frame(self, samples: list[WangSample], signature, cancel):
        check(cancel)
        layers = {}
        for role, colour in zip("nesw", signature, strict=True):
            layers[role] = self.layer(samples[AXES.index(ROLE_AXIS[role]) * self.K + colour], role)
        errors = {
            name: seam_error(layers[a], layers[b], self.weights, self.seam.metric)
            for name, (a, b, _, _) in CUTS.items()
        }
        fr = frame_cut(errors, band=self.band, seam=self.seam, cancel=cancel)
        return fr, fr.apply(layers)

    def patch_errors(self, framed: dict) -> np.ndarray:
        u = framed[MAIN]
        return self.spec.ssd(u[None], self.ring_mask[None])[0]

    def patch_anchor(self, errors, samples, avoid, rng) -> tuple[tuple[int, int], float, float]:
        """The interior window: within tolerance of the best ring match, away from the
        samples and from ``avoid`` (earlier tiles' windows)."""
        T = self.T
        allowed = np.ones(errors.shape, bool)
        allowed &= self.detailed((T, T))
        if self.excluded is not None:
            allowed &= valid_anchors(self.excluded, (T, T))
        if not allowed.any():
            raise ValueError(
                f"no {T}x{T} interior patch fits outside the excluded region: paint a smaller "
                "exclusion or use interior='diamonds'"
            )
        dist = self.min_distance
        while True:
            ok = allowed.copy()
            self.forbid_near(ok, [(0, 0)], self.role_anchors(samples), dist)
            self.forbid_near(ok, [(0, 0)], avoid, dist)
            if ok.any() or dist < 1:
                break
            dist /= 2
        if not ok.any():
            ok = allowed
        n_px = float(self.ring_mask.sum())
        k, _, _ = _select(
            np.where(ok, errors.astype(np.float64), np.inf),
            tolerance=self.tolerance,
            zero_level=self.zero_level * n_px,
            rng=rng,
        )
        y, x = divmod(k, errors.shape[1])
        return (int(y), int(x)), float(errors[y, x]) / (n_px * self.S.shape[2]), dist

    def finish(self, index, signature, variant, fr, framed, origin, band_error, seed, cancel):
        check(cancel)
        T = self.T
        labels = np.array(fr.labels)
        paths = dict(fr.paths)
        scores = {
            "criterion": float(sum(fr.criterion.values())),
            "peak": float(max(fr.peak.values())),
        }
        out = framed
        if origin is not None:
            y, x = origin
            q = {k: v[y : y + T, x : x + T] for k, v in self.stack.items()}
            err = seam_error(q, framed, self.weights, self.seam.metric)
            bias = self.outward * float(err.mean()) * self.depth if self.outward else None
            cut = patch_cut(
                q[MAIN],
                framed[MAIN],
                ring=self.ring,
                margin=self.margin,
                seam=self.seam,
                error=err,
                bias=bias,
                cancel=cancel,
            )
            check(cancel)
            out = apply_cut(q, framed, cut.alpha)
            labels[cut.mask] = PATCH_LABEL
            paths["patch"] = np.asarray(cut.loop)
            scores.update(
                patch_criterion=float(cut.criterion),
                patch_peak=float(cut.peak),
                band_error=band_error,
            )
        fz = frozen_array
        return WangTile(
            index=int(index),
            signature=tuple(int(v) for v in signature),
            variant=int(variant),
            tile=fz(out[MAIN]),
            maps={k: fz(v) for k, v in out.items() if k != MAIN},
            labels=fz(labels),
            paths={k: fz(v) for k, v in paths.items()},
            junction=fr.junction,
            patch_origin=None if origin is None else (int(origin[0]), int(origin[1])),
            scores=scores,
            seed=seed,
        )

    def parameters(self) -> dict:
        return {
            "colours": self.K,
            "tile_size": self.T,
            "band": self.band,
            "reach": self.reach,
            "variants": self.variants,
            "interior": self.interior,
            "patch_overlap": self.ring,
            "margin": self.margin,
            "outward": self.outward,
            "min_distance": self.min_distance,
            "tolerance": self.tolerance,
            "seam": self.seam.to_dict(),
        }


def _band_pixels(T: int, band: int) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Tile pixels (rows, cols) of each cut's nominal band, for matching samples: within
    ``band`` of the cut's diagonal, upper cuts in rows 1 .. T/2 - 1, lower ones T/2 .. T-2."""
    out = {}
    half = T // 2
    for name, (_, _, fr, fc) in CUTS.items():
        r, c = np.mgrid[1 : T - half, 0:T]  # frame rows 1 .. T - 1 - T/2
        keep = np.abs(c - r) <= band
        r, c = r[keep], c[keep]
        if fr:
            r = T - 1 - r
        if fc:
            c = T - 1 - c
        if not fr:
            keep = r < half
            r, c = r[keep], c[keep]
        out[name] = (r.astype(np.intp), c.astype(np.intp))
    return out


def _window_coords(role: str, rows, cols, T: int, reach: int):
    """Tile pixels of a sample in ``role`` -> coordinates in its selection window."""
    if role == "n":
        return rows + reach, cols
    if role == "s":
        return rows - T + reach, cols
    if role == "w":
        return rows, cols + reach
    return rows, cols - T + reach


# --------------------------------------------------------------------------- API
def _check_samples(setup: WangSetup, samples) -> list[WangSample]:
    K = setup.K
    try:
        samples = list(samples)
    except TypeError:
        raise TypeError("samples must be a list of WangSample") from None
    if len(samples) != 2 * K or not all(isinstance(s, WangSample) for s in samples):
        raise ValueError(f"samples must be {2 * K} WangSample (h colours, then v colours)")
    for i, s in enumerate(samples):
        axis, colour = AXES[i // K], i % K
        if (s.axis, s.colour) != (axis, colour):
            raise ValueError(
                f"samples[{i}] must be the {axis!r} sample of colour {colour}, got "
                f"{(s.axis, s.colour)}"
            )
    for s in samples:
        setup.check_origin(s.axis, s.origin)
    return samples


def _check_indices(indices, count: int) -> list[int]:
    if indices is None:
        return list(range(count))
    out = sorted({int(i) for i in indices})
    if out and (out[0] < 0 or out[-1] >= count):
        raise ValueError(f"tile indices must lie in [0, {count - 1}], got {out}")
    return out


def _signature(K: int, index: int) -> tuple[tuple[int, int, int, int], int]:
    sigs = canonical_signatures(K)
    return sigs[index % len(sigs)], index // len(sigs)


def iter_wang_set(
    source,
    *,
    tile_size: int,
    samples=None,
    tiles=None,
    avoid=(),
    rng=None,
    workers: int = 2,
    cancel=None,
    **options,
):
    """Stream a Wang tile set; the generator's value is the :class:`WangSet`.

    Parameters
    ----------
    source : (H, W[, C]) array
    tile_size : int
        T (square tiles, >= 8).
    samples : list of WangSample or None
        Use these edge samples (h colours 0..K-1 then v colours) instead of choosing them.
    tiles : iterable of int or None
        Build only these tile indices (default all).
    avoid : iterable of (row, col)
        Interior windows (top-left) of tiles kept from elsewhere, which new interiors avoid.
    rng : int, Generator or None
        The run's seed.
    workers : int
        Threads (1 runs in the calling thread).
    cancel : CancelToken or None
        Stops the run; the tiles already finished are kept in the returned set.

    Options (defaults in :data:`WANG_DEFAULTS`)
    -------------------------------------------
    colours : int
        K, colours per edge direction; the set has ``variants * K**4`` tiles.
    band : int or None
        Half-width of the diagonal bands the corner cuts run in (default ≈ T / 10).
    variants : int
        Tiles per edge signature (each with its own interior patch).
    interior : {"patch", "diamonds"}
        A matched source window inside each tile (default) or Cohen's four diamonds alone.
    patch_overlap, margin
        The ring the interior's closed cut runs in (default as the Somol set's w_P for a
        template overlap of T / 10) and the outer pixels that always stay the edge samples'
        (>= 1).
    outward : float
        Bias of the interior's cut towards the margin (its error is weighted
        ``1 + outward`` at the ring's inner edge, 1 at the margin), so the part every tile
        of an edge colour shares stays thin; the interior is matched with the inverse weights.
    min_distance : float or None
        Least distance (px) between samples and interior windows (default T / 2; halved when
        the source cannot hold them, with a note).
    tolerance : float
        Samples and interiors are drawn among the positions within ``(1 + tolerance)`` of
        the best match.
    seam : SeamSpec
        Seam method and options, error metric and blending of every cut (default
        :data:`engine.stitch.PATCH_SEAM`: dp, adaptive blending).
    excluded : (H, W) bool or None
        Source pixels no sample or patch may contain.
    maps, weights
        Extra material maps ({name: image of the source's size}) and the seam error weights.

    Yields :class:`Progress`, one :class:`WangSamples` and the :class:`WangTile` items as they
    finish (any order; each has its ``index``).
    """
    setup = WangSetup(source, tile_size=tile_size, **options)
    given = None if samples is None else _check_samples(setup, samples)
    count = setup.variants * setup.K**4
    indices = _check_indices(tiles, count)
    avoid = [(int(y), int(x)) for y, x in avoid]
    workers = positive_int(workers, "workers")
    base = base_seed(rng)
    for note in setup.notes:
        warnings.warn(note, stacklevel=2)
    return _iter_wang_set(setup, given, indices, avoid, base, workers, cancel)


def _iter_wang_set(setup: WangSetup, samples, indices, avoid, base, workers, cancel):
    n = len(indices)
    yield Progress(0, n, "Wang tiles")
    notes_before = len(setup.notes)
    if samples is None:
        try:
            samples = setup.choose_all(base, cancel)
        except Cancelled:
            yield Progress(0, n, "Wang tiles: cancelled")
            return _result(setup, [], [], {})
    yield WangSamples(tuple(samples))
    made: dict[int, WangTile] = {}
    stop = CancelToken()
    token = AnyCancel(cancel, stop)
    pool = (
        ThreadPoolExecutor(max_workers=workers, thread_name_prefix="wang") if workers > 1 else None
    )

    def submit(fn, *args) -> Future:
        if pool is not None:
            return pool.submit(fn, *args)
        f: Future = Future()
        try:
            f.set_result(fn(*args))
        except BaseException as exc:  # noqa: BLE001 - handed to the consumer like a pool's
            f.set_exception(exc)
        return f

    def stage_a(k):
        sig, _ = _signature(setup.K, k)
        fr, framed = setup.frame(samples, sig, token)
        errs = setup.patch_errors(framed) if setup.interior == "patch" else None
        return fr, framed, errs

    def stage_c(k, fr, framed, origin, band_error):
        sig, variant = _signature(setup.K, k)
        return setup.finish(
            k, sig, variant, fr, framed, origin, band_error, wang_seed(base, 1, k), token
        )

    try:
        ahead = workers  # frames made ahead of the ordered choice (a finish waits behind them)
        firsts: dict[int, Future] = {}
        finishing: dict[Future, int] = {}
        placed = list(avoid)
        nxt = 0

        def fill():
            nonlocal nxt
            while nxt < n and len(firsts) < ahead:
                firsts[indices[nxt]] = submit(stage_a, indices[nxt])
                nxt += 1

        fill()
        for k in indices:
            if is_cancelled(cancel):
                break
            fut = firsts[k]
            while not fut.done():  # hand out finished tiles while tile k's frame is made
                done, _ = wait([fut, *finishing], return_when=FIRST_COMPLETED)
                yield from _collect(done, finishing, made, n)
            try:
                fr, framed, errs = fut.result()
            except Cancelled:
                break
            del firsts[k]
            fill()
            origin, band_error = None, None
            if errs is not None:
                rng = np.random.default_rng(wang_seed(base, 1, k))
                origin, band_error, _ = setup.patch_anchor(errs, samples, placed, rng)
                placed.append(origin)
            finishing[submit(stage_c, k, fr, framed, origin, band_error)] = k
            done = [f for f in finishing if f.done()]
            yield from _collect(done, finishing, made, n)
        while finishing and not is_cancelled(cancel):
            done, _ = wait(list(finishing), return_when=FIRST_COMPLETED)
            yield from _collect(done, finishing, made, n)
    finally:
        stop.cancel()
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
    if len(made) < n:
        yield Progress(len(made), n, "Wang tiles: cancelled")
    for note in setup.notes[notes_before:]:
        warnings.warn(note, stacklevel=2)
    return _result(setup, samples, [made[k] for k in sorted(made)], {})


def _collect(done, finishing: dict, made: dict, n: int):
    for f in sorted(done, key=lambda f: finishing.get(f, -1)):
        k = finishing.pop(f, None)
        if k is None:
            continue
        try:
            t = f.result()
        except Cancelled:
            continue
        made[k] = t
        yield t
        yield Progress(len(made), n, f"Wang tile {k}")


def _result(setup: WangSetup, samples, tiles, extra) -> WangSet:
    return WangSet(
        colours=setup.K,
        tile_size=setup.T,
        band=setup.band,
        variants=setup.variants,
        samples=tuple(samples),
        tiles=tuple(tiles),
        parameters={**setup.parameters(), **extra},
        notes=tuple(dict.fromkeys(setup.notes)),
    )


def wang_set(source, **options) -> WangSet:
    """Drain :func:`iter_wang_set` and return the :class:`WangSet`."""
    return drain(iter_wang_set(source, **options))


def choose_sample(source, samples, axis: str, colour: int, *, tile_size: int, rng=None, **options):
    """Choose edge sample ``colour`` of ``axis`` again (a re-roll): the best match for the
    other axis's samples within tolerance, away from the others. ``samples`` is the current
    list (h colours then v colours); the others stay. Options as :func:`iter_wang_set`."""
    setup = WangSetup(source, tile_size=tile_size, **options)
    current = _check_samples(setup, samples)
    choice(axis, "axis", AXES)
    colour = positive_int(colour, "colour", minimum=0)
    if colour >= setup.K:
        raise ValueError(f"colour must be < {setup.K}, got {colour}")
    other = "v" if axis == "h" else "h"
    others = [s for s in current if s.axis == other]
    placed = setup.role_anchors([s for s in current if (s.axis, s.colour) != (axis, colour)])
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    return setup.choose(axis, colour, others, placed, gen)


def make_wang_tile(
    source,
    samples,
    index: int,
    *,
    tile_size: int,
    patch_origin=None,
    seed: int | None = None,
    avoid=(),
    cancel=None,
    **options,
) -> WangTile:
    """Make tile ``index`` of a set with these ``samples``: its interior from ``patch_origin``
    (row, col) when given, else drawn from ``seed`` away from ``avoid`` (other tiles'
    interior windows). Options as :func:`iter_wang_set`."""
    setup = WangSetup(source, tile_size=tile_size, **options)
    current = _check_samples(setup, samples)
    count = setup.variants * setup.K**4
    (index,) = _check_indices([index], count)
    sig, variant = _signature(setup.K, index)
    fr, framed = setup.frame(current, sig, cancel)
    origin, band_error = None, None
    if setup.interior == "patch":
        T = setup.T
        H, W = setup.S.shape[:2]
        if patch_origin is not None:
            try:
                origin = (int(patch_origin[0]), int(patch_origin[1]))
            except (TypeError, ValueError, IndexError):
                raise TypeError(f"patch_origin must be (row, col), got {patch_origin!r}") from None
            if not (0 <= origin[0] <= H - T and 0 <= origin[1] <= W - T):
                raise ValueError(
                    f"patch_origin {origin} puts the {T}x{T} patch outside the {W}x{H} source"
                )
            errs = setup.patch_errors(framed)
            band_error = float(errs[origin]) / (float(setup.ring_mask.sum()) * setup.S.shape[2])
        else:
            errs = setup.patch_errors(framed)
            rng = np.random.default_rng(seed)
            origin, band_error, _ = setup.patch_anchor(
                errs, current, [(int(y), int(x)) for y, x in avoid], rng
            )
    return setup.finish(index, sig, variant, fr, framed, origin, band_error, seed, cancel)
