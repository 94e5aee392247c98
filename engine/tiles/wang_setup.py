"""The validated inputs of a Wang set run and its steps (:mod:`engine.tiles.wang`): choosing
the edge samples with the quilting matcher, cutting a tile's frame between its four edge
layers, choosing and stitching its interior."""

from __future__ import annotations

import math
import numbers

import numpy as np

from engine._validate import as_image, choice, positive_int
from engine.cancel import check
from engine.errormap import colour_channels
from engine.events import frozen_array
from engine.exclusion import valid_anchors
from engine.matching import ZERO_ERROR_FRACTION, SampleSpectrum, box_sums_float, error_floor
from engine.matching import select_within_tolerance as _select
from engine.seams.spec import POISSON, as_seam_spec
from engine.stitch import PATCH_SEAM
from engine.tiles.candidates import check_ring, default_patch_overlap, stitch_patch
from engine.tiles.seamless import MAIN, as_maps, check_weights, seam_error
from engine.tiles.template import default_overlap, excluded_mask, flat_warning
from engine.tiles.wang_cut import CUTS, frame_cut, frame_reach, ramp_reach
from engine.tiles.wang_types import (
    AXES,
    CORNER_QUANTILE,
    CORNER_STEPS,
    DETAIL_QUANTILE,
    EDGE_BAND_QUANTILE,
    INTERIOR_BLENDS,
    INTERIOR_REACH,
    INTERIORS,
    PATCH_LABEL,
    PHASE_SLACK,
    ROLE_AXIS,
    WANG_DEFAULTS,
    WangSample,
    WangTile,
    wang_seed,
)

__all__ = ["WangSetup"]


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
        interior_blend = opts.pop("interior_blend")
        margin, outward = opts.pop("margin"), opts.pop("outward")
        min_distance, tolerance = opts.pop("min_distance"), opts.pop("tolerance")
        seam, corner_match = opts.pop("seam"), opts.pop("corner_match")
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
        #: the size checks' options as given (None where defaulted: they scale with the size)
        self._fit_options = dict(band=band, patch_overlap=patch_overlap, seam=self.seam)
        self.interior_blend = choice(interior_blend, "interior_blend", INTERIOR_BLENDS)
        if self.interior_blend == "auto":
            blend = "none" if self.seam.blend == "none" else POISSON
        else:
            blend = self.interior_blend
        #: the interior patch's cut: the seam with the interior's blend
        self.interior_seam = self.seam.replace(blend=blend)
        self.reach = frame_reach(T, self.band, ramp_reach(self.seam))
        if min(H, W) < max(T, 2 * self.reach):
            need = 2 * self.reach
            raise ValueError(
                f"the {W}x{H} source is too small for {T} px Wang tiles: each edge sample "
                f"needs {need}x{T} px (use a smaller tile_size or band)"
            )
        self.ring, self.margin = check_ring(
            default_patch_overlap(default_overlap(T)) if patch_overlap is None else patch_overlap,
            margin,
            min_margin=1,
        )
        if 2 * self.ring > T:
            raise ValueError(f"patch_overlap {self.ring} is too wide for {T} px tiles")
        self.min_distance = _nonneg_float(
            T / 2 if min_distance is None else min_distance, "min_distance"
        )
        self.tolerance = _nonneg_float(tolerance, "tolerance")
        self.corner_match = bool(corner_match)
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
        self._energy_sat: np.ndarray | None = None
        self._window_energy: np.ndarray | None = None
        self._squares: np.ndarray | None = None
        self._corner: tuple | None = None
        self._phase: tuple | None = None
        self._periodic = (False, False)
        #: a tile size near T that holds whole periods where T does not, or a larger one that
        #: holds structures too large for T (:meth:`phase`)
        self.suggested_size: int | None = None
        #: the note (in :attr:`notes`) that names :attr:`suggested_size`
        self.suggested_note: str | None = None
        step = np.diff(colour_channels(self.S), axis=1)
        #: mean squared colour step between horizontally adjacent source pixels
        self.natural_step = float(np.einsum("yxc,yxc->", step, step, dtype=np.float64)) / (
            step.shape[0] * step.shape[1]
        )
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

    def origin_to_anchor(self, axis: str, oy: int, ox: int) -> tuple[int, int]:
        return (oy - self.reach, ox) if axis == "h" else (oy, ox - self.reach)

    def nearest_origin(self, axis: str, origin) -> tuple[int, int]:
        """The origin nearest ``origin`` whose window lies in the source (an edge sample
        dragged past the border stops at it; :meth:`check_origin` still refuses a source
        smaller than the window)."""
        (wh, ww), (H, W) = self.window_shape(axis), self.S.shape[:2]
        y, x = self.origin_to_anchor(axis, *(int(v) for v in origin))
        return self.anchor_to_origin(axis, min(max(y, 0), H - wh), min(max(x, 0), W - ww))

    def check_origin(self, axis: str, origin) -> tuple[int, int]:
        try:
            oy, ox = (int(v) for v in origin)
        except (TypeError, ValueError):
            raise TypeError(f"a sample origin must be (row, col), got {origin!r}") from None
        H, W = self.S.shape[:2]
        wh, ww = self.window_shape(axis)
        y, x = self.origin_to_anchor(axis, oy, ox)
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
                wts[wy, wx] += 1.0  # a band's pixels are distinct: no repeated index
                kern[:, wy, wx] += target.T
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

    def _laplacian_sat(self) -> np.ndarray:
        """Summed-area table of the luminance's squared Laplacian (once per run)."""
        if self._energy_sat is None:
            lum = colour_channels(self.S).mean(axis=2, dtype=np.float32)
            lap = np.zeros(lum.shape, np.float64)
            lap[1:-1, 1:-1] = (
                lum[:-2, 1:-1]
                + lum[2:, 1:-1]
                + lum[1:-1, :-2]
                + lum[1:-1, 2:]
                - 4 * lum[1:-1, 1:-1]
            )
            np.square(lap, out=lap)
            self._energy_sat = np.pad(lap.cumsum(axis=0).cumsum(axis=1), ((1, 0), (1, 0)))
        return self._energy_sat

    def detailed(self, shape: tuple[int, int]) -> np.ndarray:
        """Window anchors of ``shape`` whose detail (mean squared Laplacian of the luminance)
        is at least :data:`DETAIL_QUANTILE` of the source's windows: a matcher alone
        favours flat regions (they match anything calm), and flat samples or interiors
        read as blurred patches in a layout."""
        if shape not in self._detail:
            energy = box_sums_float(self._laplacian_sat(), shape)
            self._detail[shape] = energy >= np.quantile(energy, DETAIL_QUANTILE)
        return self._detail[shape]

    def detail_half(self, placed) -> np.ndarray | None:
        """Interior window anchors on the side of the source's median window detail (mean
        squared Laplacian of the luminance, as :meth:`detailed`) that ``placed`` (earlier
        tiles' windows) hold fewer of; None when they hold as many.

        Keeps a set's windows as detailed as random crops are, half above the median and
        half below: the matcher alone draws from one side (calm rings match calm windows on
        page, whose tiles were 0.90 of its crops' detail; the flattest-quarter rule pushes
        the other way, 10-13 of 16 windows above the median on a test source), and a set
        busier than its crops near the edges reads as a frame."""
        T = self.T
        if self._window_energy is None:
            self._window_energy = box_sums_float(self._laplacian_sat(), (T, T))
        energy = self._window_energy
        med = np.median(energy)
        above = sum(1 for y, x in placed if energy[y, x] >= med)
        below = len(placed) - above
        if above == below:
            return None
        return energy >= med if below > above else energy < med

    def calm_joint(self, axis: str) -> np.ndarray:
        """Window anchors whose joint (the source's own step across the tile edge the sample
        lies on) is no rougher than the median, relative to the steps of the sample's whole
        window: a joint along a mortar line or a shelf edge would show at every edge of
        that colour. (Relative to its window, so that calm regions are not preferred.)"""
        if axis not in self._calm:
            S = self.S if axis == "h" else self.S.transpose(1, 0, 2)
            T, h = self.T, self.reach
            step = S[1:] - S[:-1]
            d = np.einsum("yxc,yxc->yx", step, step)  # d[y] = |S[y+1] - S[y]|²
            run = np.pad(d.cumsum(axis=1, dtype=np.float64), ((0, 0), (1, 0)))
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

    def edge_band(self, axis: str) -> np.ndarray:
        """Window anchors of an ``axis`` sample whose edge band (the ring's width either side
        of the edge line, along the tile) is no calmer than the median, relative to the
        sample's whole window (detail: the luminance's squared Laplacian, as :meth:`detailed`;
        the quantile is :data:`EDGE_BAND_QUANTILE`).

        The calm-joint rule keeps edge lines off a texture's lines; alone, on lines parallel
        to the edge (brick's mortar) it puts the edge line mid-way between two, the same in
        every sample, so every tile had a calm band along its W/E edges and the mortar
        12-16 px inside them. A band as detailed as its window puts the edge line beside a
        line instead, at varying distances. (Relative to the window, as the calm joint, so
        that detailed regions are not preferred: the absolute band moved moon's E/W edges
        into its craters, frame 0.99 -> 1.14.)"""
        key = f"band-{axis}"
        if key not in self._calm:
            sat = self._laplacian_sat()
            T, h, r = self.T, self.reach, self.ring
            window = box_sums_float(sat, self.window_shape(axis))
            # anchor (y, x) of an h sample: the edge line between rows y + h - 1 and y + h
            box, at = ((2 * r, T), (h - r, 0)) if axis == "h" else ((T, 2 * r), (0, h - r))
            band = box_sums_float(sat, box, at, window.shape)
            ratio = (band / (2 * r)) / (window / (2 * h) + 1e-12)
            self._calm[key] = ratio >= np.quantile(ratio, EDGE_BAND_QUANTILE)
        return self._calm[key]

    def phase(self) -> tuple[float | None, float | None]:
        """Per axis (y, x): T / k where the texture is periodic and the tile holds k whole
        periods (:func:`engine.reference_crops.phase_axes`), else None.

        Along such an axis a Wang set can be the texture itself, every course, shelf or
        board continuing across every joint *and* through every tile, only when all its
        layers and interiors lie in one phase of the texture modulo T / k; the matcher
        alone, within its tolerance and kept apart by ``min_distance``, picks windows a few
        px out of phase (shelf boards stepping inside the tiles)."""
        if self._phase is None:
            from engine.reference_crops import phase_axes
            from engine.tiles.scale import structure_scale
            from engine.tiles.wang_size import large_structure_note, source_fits, whole_period_size

            scale = structure_scale(self.S)
            self._periodic = (bool(scale.periodic[0]), bool(scale.periodic[1]))
            axes = phase_axes(scale, (self.T, self.T))
            self._phase = tuple(
                self.T / round(self.T / scale.size[i]) if axes[i] else None for i in range(2)
            )
            fits = lambda n: source_fits(self.S.shape, n, **self._fit_options)  # noqa: E731
            self.suggested_size = whole_period_size(scale, self.T, fits)
            note = broken_period_note(scale, self.T, axes, self.suggested_size)
            if note:
                self.notes.append(note)
                self.suggested_note = note if self.suggested_size else None
            note, size = large_structure_note(scale, self.T, self.S.shape, fits)
            if note:  # the larger fault: its size replaces a whole-period one
                self.notes.append(note)
                self.suggested_size, self.suggested_note = size, note if size else None
        return self._phase

    def periodic(self) -> tuple[bool, bool]:
        """Per axis (y, x): whether the texture is periodic along it (its structure scale's
        autocorrelation, as :meth:`phase`; the tile need not hold whole periods)."""
        self.phase()
        return self._periodic

    def keep_phase(self, allowed: np.ndarray, offset, point) -> None:
        """Clear ``allowed`` (window anchors) where anchor + ``offset`` (the source position
        of tile pixel (0, 0)) is out of the phase of ``point`` along the axes of
        :meth:`phase`, by more than :data:`PHASE_SLACK` px; unchanged if nothing would be
        left."""
        keep = allowed.copy()
        for i, p in enumerate(self.phase()):
            if p is None:
                continue
            g = np.arange(keep.shape[i]) + offset[i] - point[i]
            near = np.abs(g - np.round(g / p) * p) <= PHASE_SLACK
            keep &= near[:, None] if i == 0 else near[None, :]
        if keep.any():
            allowed &= keep

    def tile_origin(self, sample: WangSample) -> tuple[int, int]:
        """Source position of tile pixel (0, 0) in the sample's N (h) or W (v) layer."""
        return sample.offset("n" if sample.axis == "h" else "w", self.T)

    def role_anchors(self, samples: list[WangSample]) -> list[tuple[int, int]]:
        """Source position of tile pixel (0, 0) for every role of every sample."""
        pts = []
        for s in samples:
            roles = ("n", "s") if s.axis == "h" else ("w", "e")
            pts += [s.offset(r, self.T) for r in roles]
        return pts

    def corner_errors(self, same: list[WangSample]) -> np.ndarray:
        """Squared colour steps where four tiles meet, for an ``h`` sample at every window
        anchor, with itself and with the other ``h`` samples ``same``.

        A tile's rows 0 and T-1 are its N and S samples' in full, corners included, so at a
        crossing the east end of one h sample's two edge rows (the tile on the left) touches
        the west end of another's (the tile on the right): two pixel rows per crossing where
        the step across the vertical tile line joins two unrelated source pixels (the
        corner problem; every pairing of the colours occurs, a colour with itself too)."""
        T, h = self.T, self.reach
        S = colour_channels(self.S)
        if self._corner is None:  # once per run: the edge rows' ends at every anchor
            ny, nx = S.shape[0] - 2 * h + 1, S.shape[1] - T + 1
            rows = S[h - 1 : h + ny]  # anchor y's edge rows are rows[y] and rows[y + 1]
            first = np.ascontiguousarray(rows[:, :nx])
            last = np.ascontiguousarray(rows[:, T - 1 : T - 1 + nx])
            d = np.einsum("yxc,yxc->yx", last - first, last - first)
            norms = [np.einsum("yxc,yxc->yx", a, a) for a in (first, last)]
            self._corner = (first, last, *norms, d[:-1] + d[1:])
        first, last, n_first, n_last, e = self._corner
        e = e.copy()  # summed over the two edge rows (and the channels)
        for o in same:
            oy, ox = o.origin  # its edge rows are source rows oy - 1 and oy
            for mine, norm, theirs in (
                (last, n_last, S[oy - 1 : oy + 1, ox]),  # o to the right of this sample
                (first, n_first, S[oy - 1 : oy + 1, ox + T - 1]),  # o to its left
            ):
                for r in (0, 1):  # |a - b|² = |a|² - 2 a.b + |b|², b one pixel
                    part = slice(r, r + e.shape[0])
                    e += norm[part] - 2 * (mine[part] @ theirs[r]) + float(theirs[r] @ theirs[r])
        return e

    def hv_corner_errors(self, vs: list[WangSample]) -> np.ndarray:
        """Squared colour steps of the v samples' end pixels at the tile corners, for an ``h``
        sample at every window anchor (as :meth:`corner_errors`), summed over ``vs``.

        A tile's rows 0 and T-1 are its N and S samples' and its columns 0 and T-1 its W and
        E samples' in rows 1..T-2; the corner cuts start below the corner, so at every corner
        the edge column's end pixel (row 1 or T-2) sits between two pixels of the h layer: the
        edge row's corner pixel beside it along the edge and the layer's pixel diagonally
        inward beside it across the cut (the dots where four tiles meet). Each v sample's four
        end pixels (W and E roles, top and bottom) against this h sample's two neighbours."""
        T, h = self.T, self.reach
        S = colour_channels(self.S)
        ny, nx = S.shape[0] - 2 * h + 1, S.shape[1] - T + 1
        e = np.zeros((ny, nx))
        # (v pixel offset from the v origin, [h layer pixels' offsets from the h origin])
        corners = (
            ((1, 0), ((0, 0), (1, 1))),  # NW: W(1, 0) below N(0, 0), left of N(1, 1)
            ((1, -1), ((0, T - 1), (1, T - 2))),  # NE: E(1, T-1)
            ((T - 2, 0), ((-1, 0), (-2, 1))),  # SW: W(T-2, 0) above S(T-1, 0)
            ((T - 2, -1), ((-1, T - 1), (-2, T - 2))),  # SE: E(T-2, T-1)
        )
        # per h pixel (its offset from the h origin) the v end pixels beside it, summed:
        # sum |q - p|² = n |q|² - 2 q.(sum p) + sum |p|² (one pass per h pixel, not per v)
        near: dict[tuple[int, int], list] = {}
        for v in vs:
            vy, vx = v.origin
            for (py, px), nbrs in corners:
                for nb in nbrs:
                    near.setdefault(nb, []).append(S[vy + py, vx + px].astype(np.float64))
        if self._squares is None:  # once per run: |q|² of every source pixel
            self._squares = np.einsum("yxc,yxc->yx", S, S, dtype=np.float64)
        for (dy, dx), ps in near.items():  # the h origin of anchor (y, x) is (y + h, x)
            rows, cols = slice(h + dy, h + dy + ny), slice(dx, dx + nx)
            q, p = S[rows, cols], np.sum(ps, axis=0)
            e += len(ps) * self._squares[rows, cols] + sum(float(a @ a) for a in ps)
            for c in range(S.shape[2]):
                e -= (2 * p[c]) * q[..., c]
        return e

    def choose(self, axis, colour, others, placed, rng, same=()) -> WangSample:
        """Sample ``colour`` of ``axis``: best matching ``others`` within tolerance, away from
        ``placed`` (role anchors) by ``min_distance``; an ``h`` sample also with corner steps
        (:meth:`corner_errors`, with itself and ``same``, the other h samples) no rougher
        than :data:`CORNER_STEPS` x the source's own, or among the :data:`CORNER_QUANTILE`
        of positions with the least."""
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
        if axis == "v" and not self.periodic()[1] and (allowed & self.edge_band(axis)).any():
            allowed &= self.edge_band(axis)
        h, T = self.reach, self.T
        if others or same:  # the phase of the samples chosen first
            ref = self.tile_origin([*others, *same][0])
            self.keep_phase(allowed, (h, 0) if axis == "h" else (0, h), ref)
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
        if axis == "h":
            c = self.corner_errors(list(same))
            n_steps = 2 * (1 + 2 * len(same))
            if self.corner_match and others:
                c = c + self.hv_corner_errors(list(others))
                n_steps += 8 * len(others)
            natural = n_steps * self.natural_step  # that many steps
            ok &= c <= max(CORNER_STEPS * natural, np.quantile(c[ok], CORNER_QUANTILE))
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
            same = [s for (a, k), s in chosen.items() if a == axis and k != c]
            placed = self.role_anchors([s for key, s in chosen.items() if key != (axis, c)])
            rng = np.random.default_rng(wang_seed(base, 0, step))
            chosen[(axis, c)] = self.choose(axis, c, others, placed, rng, same)
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
        samples and from ``avoid`` (earlier tiles' windows), on the side of the median
        window detail that ``avoid`` holds fewer of (:meth:`detail_half`)."""
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
        if samples:
            self.keep_phase(allowed, (0, 0), self.tile_origin(samples[0]))
        half = self.detail_half(avoid)
        if half is not None and (allowed & half).any():
            allowed &= half
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
            out, cut = stitch_patch(
                q,
                framed,
                ring=self.ring,
                margin=self.margin,
                seam=self.interior_seam,
                weights=self.weights,
                outward=self.outward,
                depth=self.depth,
                reach=INTERIOR_REACH,
                cancel=cancel,
            )
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
            "interior_blend": self.interior_blend,
            "patch_overlap": self.ring,
            "margin": self.margin,
            "outward": self.outward,
            "min_distance": self.min_distance,
            "tolerance": self.tolerance,
            "seam": self.seam.to_dict(),
        }


def broken_period_note(scale, T: int, whole, suggested: int | None = None) -> str | None:
    """A note when the texture is periodic along an axis (``scale``: a
    :class:`engine.tiles.scale.Scale`) whose period fits at least once in T but not a whole
    number of times (``whole``: :func:`engine.reference_crops.phase_axes`), else None.

    Measured on the evaluation set's planks (boards every 48 px, 128 px tiles, 2.67 boards):
    a tile cannot continue the boards across both of its W and E edges, so every vertical tile
    line of a layout has a board of another width (31 px between gaps 15-16 px from the line
    on both sides); at 96 or 144 px the boards run straight through the layout. ``suggested``
    (:func:`engine.tiles.wang_size.whole_period_size`) is named as the size to use."""
    parts = []
    for i, axis in enumerate(("tall", "wide")):
        p = float(scale.size[i])
        if whole[i] or not scale.periodic[i] or p <= 0 or p > T:
            continue
        k = math.floor(T / p)
        parts.append(
            f"{p:.0f} px {axis} ({T / p:.2f} per tile; {round(k * p)} or "
            f"{round((k + 1) * p)} px hold whole ones)"
        )
    if not parts:
        return None
    return (
        f"the texture repeats about every {' and '.join(parts)}, measured by autocorrelation: "
        f"{T} px Wang tiles do not hold whole periods, so no tile continues the pattern across "
        "two opposite edges and every tile line breaks it (a structure of another width at "
        "each line); a tile size that holds whole periods avoids it"
        + (
            f": {suggested} px (--tile-size {suggested}, or Tile size in the editor)"
            if suggested
            else ""
        )
    )


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
