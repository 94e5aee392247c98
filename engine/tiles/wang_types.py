"""The values of a Wang tile set (:mod:`engine.tiles.wang`): edge samples, tiles, the set,
its edge signatures in their canonical order, and the plain-JSON record manifests and projects
keep."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine._validate import positive_int
from engine.events import Item
from engine.stitch import PATCH_SEAM

__all__ = [
    "AXES",
    "INTERIORS",
    "INTERIOR_BLENDS",
    "WANG_DEFAULTS",
    "WangSample",
    "WangSamples",
    "WangSet",
    "WangTile",
    "canonical_signatures",
    "de_bruijn",
    "from_candidate",
    "samples_from_record",
    "wang_record",
    "wang_seed",
]

AXES = ("h", "v")  # "h": colours of the north/south edges, "v": of the east/west edges
INTERIORS = ("patch", "diamonds")
PATCH_LABEL = 4  # label of the interior patch's pixels (0..3: N, E, S, W; wang_cut.LABELS)
ROLE_AXIS = {"n": "h", "s": "h", "e": "v", "w": "v"}
#: samples and interiors come from the source's windows at least this detailed (quantile)
DETAIL_QUANTILE = 0.25
#: h samples come from the positions whose corner steps (where four tiles meet) are no rougher
#: than CORNER_STEPS x the source's own mean squared step, or from the CORNER_QUANTILE of
#: positions with the least when fewer are; measured with ``python -m benchmarks.wang
#: --quality public`` (corner border ratio 1.6 -> 0.8 on cobblestones, lattice unchanged
#: within its spread over seeds, but on the periodic weave)
CORNER_STEPS = 2.0
CORNER_QUANTILE = 0.05
#: on a periodic texture whose period the tile holds k times, samples and interiors keep to
#: the first sample's phase modulo T / k within this many px (see WangSetup.keep_phase): 0.5 =
#: the whole pixel nearest to the phase. 1.0 (until session 7) let two windows lie 2 px apart,
#: so shelves' boards stepped by 1-2 px at the tile lines (frame 1.215 -> 1.085, seeds 0-2)
PHASE_SLACK = 0.5
#: v samples (the E/W edges) come from the positions whose edge band (the ring's width either
#: side of the edge line, along the tile), relative to their window, is at least this quantile
#: of the source's by detail (see WangSetup.edge_band): the calm-joint rule alone put every E/W
#: edge line mid-way between a texture's lines parallel to it (brick's mortar 12-16 px inside
#: every tile's W/E edges: frame 1.188, seeds 0-2). h samples keep without it (coins 1.18 ->
#: 1.52, brick 1.22: their rows then run along the coins and the brick ends), and so do the v
#: samples of a texture periodic along x (planks 1.36 -> 1.52: beside one board gap, the next
#: lies a period away in every tile; coins 1.18 -> 1.16-1.33 over four seed triples)
EDGE_BAND_QUANTILE = 0.5
#: the gradient-domain interior's correction is screened at this many rings' widths (32 px at
#: 128 px tiles; the candidates' :data:`engine.tiles.patch_stitch.POISSON_REACH` is 2): the
#: step between a window and the shared ring beside its cut (1-3 px from the edge) is spread
#: over twice the depth, so the frame's peak at the cut falls (retina's pooled profile at 2 px
#: 1.11 -> 1.06; its frame over four seed triples 1.116 / 1.115 / 1.097 / 1.138 -> 1.066 /
#: 1.058 / 1.047 / 1.094, this change alone). README "Session 12"
INTERIOR_REACH = 4.0

#: How the interior patch is blended (``interior_blend``): "auto" = gradient domain unless the
#: seam's blend is "none" (hard cuts asked for: every pixel stays a source copy), or one of
#: :data:`engine.seams.spec.TILE_BLEND_MODES` for the interior alone.
INTERIOR_BLENDS = ("auto", "none", "feather", "adaptive", "poisson")

#: Options of :func:`iter_wang_set` and their defaults.
WANG_DEFAULTS = {
    "colours": 2,
    "band": None,
    "variants": 1,
    "interior": "patch",
    "interior_blend": "auto",
    "patch_overlap": None,
    "margin": 1,
    "outward": 1.0,
    "min_distance": None,
    "tolerance": 0.1,
    "corner_match": True,
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
    #: a tile size near ``tile_size`` that holds whole periods of the source where
    #: ``tile_size`` does not (:func:`engine.tiles.wang_size.whole_period_size`; a note says so),
    #: or that holds its structures where they are too large for ``tile_size``
    #: (:func:`engine.tiles.wang_size.large_structure_note`)
    suggested_size: int | None = None
    #: the one of ``notes`` that names ``suggested_size`` (None without a suggestion)
    suggested_note: str | None = None

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
