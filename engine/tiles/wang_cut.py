"""The Cohen frame of a Wang tile: four edge layers joined by four corner-to-junction cuts.

ALGORITHMS.md §6. A Wang tile with edge colours (N, E, S, W) shows, near each edge, that
edge's colour sample (a *layer*: the source window whose pixels continue across the edge into
the neighbouring tile). The four layers meet along the tile's diagonals; the boundary between
two layers is a minimum-error cut from the tile corner they share to a junction ``J`` near the
centre where all four cuts end:

* ``nw``: W | N, from the top-left corner;   ``ne``: E | N, from the top-right corner;
* ``sw``: W | S, from the bottom-left corner; ``se``: E | S, from the bottom-right corner.

[REC] Each cut is solved in its own frame, flipped so that its corner is the top-left one
(``nw`` as is, ``ne`` mirrored left-right, ``sw`` upside down, ``se`` both), with the A layer
(W or E) on the left and B (N or S) on the right. In that frame the cut runs in a band of
``band`` pixels either side of the diagonal ``r = c``; *shearing* the band row by row
(column ``d = c - r + band``) makes it a rectangle, pixel for pixel (no resampling), so every
seam method of :mod:`engine.seams` runs on it unchanged, pinned at both ends:

* start: frame row 1 at column 0 (row 0 is the B layer's edge, column 0 the A layer's edge);
* end: the junction. ``J`` is the pixel of least total cost of the four dp cuts that reach it
  (the meeting point of :func:`engine.stitch.l_cut`, with four arms).

So the tile's edge pixels are the edge layers' own: row 0 is N and row T-1 is S in full
(corners included), column 0 is W and column T-1 is E in rows 1..T-2. Blending (none, feather,
adaptive) ramps across each cut within the band and never reaches those edge pixels.

The four regions are composited as three two-way cuts, so material maps (normals renormalised)
follow with :func:`engine.materials.apply_cut`: ``left = W|S`` (by ``sw``), ``right = N|E``
(by ``ne``), ``tile = left|right`` (by ``nw`` above the junction row and ``se`` from it down).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from engine.blend import adaptive_half_widths, blend_weights, clamped_half_widths, cut_columns
from engine.cancel import check
from engine.materials import apply_cut
from engine.seams.search import find_seam
from engine.seams.spec import POISSON, SeamSpec

__all__ = ["CUTS", "Frame", "frame_cut", "frame_reach", "ramp_reach"]

#: name -> (A role, B role, flip rows, flip columns)
CUTS = {
    "nw": ("w", "n", False, False),
    "ne": ("e", "n", False, True),
    "sw": ("w", "s", True, False),
    "se": ("e", "s", True, True),
}
ROLES = ("n", "e", "s", "w")
LABELS = {"n": 0, "e": 1, "s": 2, "w": 3}


def ramp_reach(seam: SeamSpec) -> int:
    """How far (px) the blend ramp of ``seam`` can reach past its cut."""
    if seam.blend in ("none", POISSON):  # the frame's cuts stay hard with "poisson"
        return 0
    if seam.blend == "feather":
        return math.ceil(seam.width / 2) + 1
    return 2 * seam.rho + 1


def frame_reach(tile: int, band: int, reach: int) -> int:
    """Rows (columns) of an edge layer the frame can read: from its edge to the junction's
    band, plus the ramp."""
    return min(int(tile), int(tile) // 2 + 2 * int(band) + int(reach) + 2)


def _flip(a: np.ndarray, rows: bool, cols: bool) -> np.ndarray:
    if rows:
        a = a[::-1]
    if cols:
        a = a[:, ::-1]
    return a


def _shear(e: np.ndarray, n_rows: int, band: int) -> tuple[np.ndarray, np.ndarray]:
    """Frame rows 1..n_rows of the band around ``r = c`` as an (n_rows, 2 band + 1) rectangle;
    also the mask of cells inside the tile."""
    T = e.shape[1]
    r = np.arange(1, n_rows + 1)[:, None]
    c = r + np.arange(2 * band + 1)[None, :] - band
    inside = (c >= 0) & (c < T)
    out = np.where(inside, e[r, np.clip(c, 0, T - 1)], 0.0)
    return out, inside


def _pinned_costs(e: np.ndarray, start: int) -> np.ndarray:
    """cost[i, d]: least sum of ``e`` over a one-pixel-per-row 8-connected path from (0, start)
    to (i, d)."""
    n, w = e.shape
    cost = np.full((n, w), np.inf)
    cost[0, start] = e[0, start]
    for i in range(1, n):
        prev = cost[i - 1]
        best = prev.copy()
        best[1:] = np.minimum(best[1:], prev[:-1])
        best[:-1] = np.minimum(best[:-1], prev[1:])
        cost[i] = e[i] + best
    return cost


@dataclass(frozen=True)
class Frame:
    """How a Wang tile's four edge layers are cut and blended (see the module docstring).

    Attributes
    ----------
    junction : (row, col)
        Where the four cuts end.
    alphas : dict
        ``main`` (weight of the W|S side), ``left`` (weight of W within W|S), ``right``
        (weight of N within N|E), each (T, T) float32.
    labels : (T, T) uint8
        Hard label of every pixel: 0 N, 1 E, 2 S, 3 W (:data:`LABELS`).
    paths : dict
        Each cut's pixels (row, col) in tile coordinates, from its corner to the junction.
    criterion, peak : dict
        Per cut: sum and maximum of the error on its path.
    """

    junction: tuple[int, int]
    alphas: dict
    labels: np.ndarray
    paths: dict
    criterion: dict
    peak: dict

    def apply(self, layers: dict) -> dict:
        """Composite ``layers`` ({role: {map name: (T, T, C) image}}) into {map name: tile}."""
        left = apply_cut(layers["w"], layers["s"], self.alphas["left"])
        right = apply_cut(layers["n"], layers["e"], self.alphas["right"])
        return apply_cut(left, right, self.alphas["main"])

    def weights(self) -> dict:
        """Weight of every layer per pixel ({role: (T, T) float32}; they sum to 1)."""
        m, lf, rt = self.alphas["main"], self.alphas["left"], self.alphas["right"]
        return {"w": m * lf, "s": m * (1 - lf), "n": (1 - m) * rt, "e": (1 - m) * (1 - rt)}


def _junction(costs: dict, T: int, band: int) -> tuple[int, int]:
    """The pixel (r, c) of least total cost of the four cuts (ties: nearest the centre)."""
    rows = np.arange(max(2, T // 2 - band), min(T - 2, T // 2 + band + 1))
    cols = np.arange(max(0, T // 2 - 2 * band), min(T - 1, T // 2 + 2 * band + 1))
    r, c = np.meshgrid(rows, cols, indexing="ij")
    total = np.zeros(r.shape)
    for name, cost in costs.items():
        _, _, fr, fc = CUTS[name]
        rr = T - 1 - r if fr else r  # frame row
        cc = T - 2 - c if fc else c  # frame column of the cut's last A pixel
        d = cc - rr + band
        ok = (d >= 0) & (d <= 2 * band) & (rr >= 1) & (rr <= cost.shape[0])
        v = np.full(r.shape, np.inf)
        v[ok] = cost[rr[ok] - 1, d[ok]]
        total += v
    if not np.isfinite(total).any():  # pragma: no cover - the centre is always reachable
        raise RuntimeError("no junction reachable by all four cuts")
    centre = np.abs(r - (T - 1) / 2) + np.abs(c - (T - 1) / 2)
    k = np.lexsort((centre.ravel(), total.ravel()))[0]
    return int(r.ravel()[k]), int(c.ravel()[k])


def _cut_alpha(seam, e, inside, band: int, T: int, spec: SeamSpec) -> np.ndarray:
    """Weight of A over the sheared band (n_rows, 2 band + 1), 0 and 1 exactly at the tile's
    edge pixels (frame column 0 and T - 1, and within the band's own edge columns)."""
    n = e.shape[0]
    filled = np.where(inside, e, e[inside].mean() if inside.any() else 0.0)
    cols = cut_columns(seam.mask)
    if spec.blend in ("none", POISSON) or cols is None:
        alpha = blend_weights(seam, filled, spec=spec)
    else:
        b = (
            np.full(n, spec.width / 2.0)
            if spec.blend == "feather"
            else adaptive_half_widths(seam, filled, rho=spec.rho)
        )
        b = clamped_half_widths(cols, b, 2 * band + 1)
        tile_col = np.arange(1, n + 1) + cols - band  # the cut's last A column in the frame
        b = np.maximum(np.minimum.reduce([b, tile_col + 0.5, T - 1.5 - tile_col]), 0.0)
        i = np.arange(2 * band + 1)[None, :]
        hard = i <= cols[:, None]
        bb = b[:, None]
        safe = np.where(bb > 0, bb, 1.0)
        alpha = np.where(bb > 0, np.clip(0.5 - (i - cols[:, None] - 0.5) / (2 * safe), 0, 1), hard)
    alpha = np.asarray(alpha, dtype=np.float32).copy()
    # the tile's edge pixels stay exact (winding ramps may reach them)
    r = np.arange(1, n + 1)[:, None]
    c = r + np.arange(2 * band + 1)[None, :] - band
    alpha[c == 0] = 1.0
    alpha[c == T - 1] = 0.0
    return alpha


def _unshear(band_values: np.ndarray, n_rows: int, band: int, T: int, left, right) -> np.ndarray:
    """Frame rows 1..n_rows as (n_rows, T): the band's values, ``left`` / ``right`` beside it."""
    r = np.arange(1, n_rows + 1)[:, None]
    c = np.arange(T)[None, :]
    d = c - r + band
    out = np.where(d < 0, left, right).astype(band_values.dtype)
    inb = (d >= 0) & (d <= 2 * band)
    rr, cc = np.nonzero(inb)
    out[rr, cc] = band_values[rr, d[rr, cc]]
    return out


def frame_cut(errors: dict, *, band: int, seam: SeamSpec, cancel=None) -> Frame:
    """Cut a T x T Wang tile between its four edge layers.

    Parameters
    ----------
    errors : dict
        The error map (T, T) between the two layers of every cut, in tile coordinates:
        ``{"nw": d(W, N), "ne": d(E, N), "sw": d(W, S), "se": d(E, S)}``; only the band
        around each cut's diagonal is read.
    band : int
        Half-width of the band around the diagonals in which the cuts run (>= 1).
    seam : SeamSpec
        Any seam method of :mod:`engine.seams` with its options, and the blending across
        each cut (the metric is the caller's, in ``errors``).
    """
    T = next(iter(errors.values())).shape[0]
    rows_max = min(T - 2, T // 2 + band)
    framed, costs = {}, {}
    for name, (_, _, fr, fc) in CUTS.items():
        check(cancel)
        e = np.ascontiguousarray(_flip(np.asarray(errors[name], dtype=np.float64), fr, fc))
        sheared, inside = _shear(e, rows_max, band)
        big = float(sheared.sum()) + 1.0
        sheared = np.where(inside, sheared, big)
        framed[name] = (sheared, inside)
        costs[name] = _pinned_costs(sheared, band - 1)
    jr, jc = _junction(costs, T, band)
    alphas_f, masks_f, paths, crit, peak = {}, {}, {}, {}, {}
    for name, (_, _, fr, fc) in CUTS.items():
        check(cancel)
        sheared, inside = framed[name]
        n = T - 1 - jr if fr else jr
        end_col = T - 2 - jc if fc else jc
        e = np.ascontiguousarray(sheared[:n])
        cut = find_seam(e, seam=seam, start=band - 1, end=end_col - n + band, cancel=cancel)
        alpha = _cut_alpha(cut, e, inside[:n], band, T, seam)
        alphas_f[name] = _unshear(alpha, n, band, T, np.float32(1), np.float32(0))
        masks_f[name] = _unshear(np.asarray(cut.mask), n, band, T, True, False)
        p = np.asarray(cut.path)
        r = p[:, 0] + 1
        c = r + p[:, 1] - band
        if fr:
            r = T - 1 - r
        if fc:
            c = T - 1 - c
        paths[name] = np.column_stack([r, c]).astype(np.intp)
        crit[name] = float(cut.criterion)
        peak[name] = float(cut.peak)

    def tile_rows(name, values):
        """A cut's frame rows 1..n back in tile coordinates (rows and columns unflipped)."""
        _, _, fr, fc = CUTS[name]
        v = values[:, ::-1] if fc else values
        return v[::-1] if fr else v

    main = np.zeros((T, T), np.float32)
    left = np.ones((T, T), np.float32)
    right = np.zeros((T, T), np.float32)
    main[T - 1] = 1.0
    left[T - 1] = 0.0
    right[0] = 1.0
    main[1:jr] = alphas_f["nw"][: jr - 1]
    main[jr : T - 1] = 1.0 - tile_rows("se", alphas_f["se"])
    left[jr : T - 1] = tile_rows("sw", alphas_f["sw"])
    right[1:jr] = 1.0 - tile_rows("ne", alphas_f["ne"])[: jr - 1]

    hm = np.zeros((T, T), bool)  # hard: W|S side
    hl = np.ones((T, T), bool)  # hard: W within W|S
    hr = np.zeros((T, T), bool)  # hard: N within N|E
    hm[T - 1] = True
    hl[T - 1] = False
    hr[0] = True
    hm[1:jr] = masks_f["nw"][: jr - 1]
    hm[jr : T - 1] = ~tile_rows("se", masks_f["se"])
    hl[jr : T - 1] = tile_rows("sw", masks_f["sw"])
    hr[1:jr] = ~tile_rows("ne", masks_f["ne"])[: jr - 1]
    labels = np.where(
        hm, np.where(hl, LABELS["w"], LABELS["s"]), np.where(hr, LABELS["n"], LABELS["e"])
    ).astype(np.uint8)
    for a in (main, left, right, labels):
        a.setflags(write=False)
    return Frame((jr, jc), {"main": main, "left": left, "right": right}, labels, paths, crit, peak)
