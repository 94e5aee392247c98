"""Every user parameter of the editor: its type, default, range, words and place on screen.

Labels are plain words saying what changes on screen; a tooltip's first line explains it, its
second line (``paper``) gives the name the papers use (w_T, ρ, o_max ...). ``basic`` parameters
are those most photos need: the panel's Basic view shows only them, Advanced shows all.
Choices may have display ``labels`` (the stored value stays the engine's name). A special text
(``special``, e.g. "auto") is shown for the minimum, where 0 means "chosen for you".
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from engine.seams.spec import (
    BLEND_MODES,
    METHODS,
    METRICS,
    MINIMAX_VARIANTS,
    OSCILLATING_VARIANTS,
    TILE_BLEND_MODES,
)
from engine.settings import TilesetSettings

SAME = "same"  # template_blend: as the patches' blending
AUTO, ANY = "auto", "any"
TILE_SIZES = ("64", "128", "256", "512", "1024", "2048")
QUILT_SELECTIONS = ("best", "sampled", "random", "bhatia")
QUILT_SEAMS = ("straight", *METHODS)
BASIC = "Basic"
ADVANCED = "Advanced"
#: the parameter groups of each workflow (the others, exclusion and seam options, are shared)
TILESET_GROUPS = ("Tile", "Seams", "Candidates", "Preview")
QUILTING_GROUPS = ("Quilting", "Transfer")

_METHOD_LABELS = {
    "straight": "No cut (straight)",
    "dp": "Cut across, row by row",
    "dijkstra": "Winding cut",
    "minimax": "Cut avoiding the worst spot",
    "oscillating": "Refined cut (anytime)",
    "oscillating-optimal": "Refined cut, exact",
    "resistance": "Stepped cut (resistance)",
}
_METHOD_PAPERS = (
    "dp: minimum error boundary cut (Efros & Freeman) · dijkstra: shortest path (Long & "
    "Mould's baseline) · minimax: Long & Mould · oscillating: Somol & Haindl · resistance: "
    "minimum resistance cut lines (Bhatia)"
)
_BLEND_LABELS = {
    "none": "Hard cut",
    "feather": "Soft, fixed width",
    "adaptive": "Soft where needed",
    "poisson": "Gradient domain (evens out tone)",
}
_METRIC_LABELS = {"euclid": "Colour distance", "ssd": "Squared distance", "lab": "Perceptual (Lab)"}


@dataclass(frozen=True)
class Param:
    key: str
    default: Any
    label: str
    tip: str
    group: str
    minimum: float | None = None
    maximum: float | None = None
    choices: tuple = ()
    step: float = 1
    decimals: int = 2
    special: str = ""  # shown instead of the minimum (e.g. "auto" where 0 means the default)
    paper: str = ""  # the name in the papers: the tooltip's second line
    basic: bool = False  # shown in the Basic view of the panel
    labels: tuple = ()  # display texts of ``choices``

    @property
    def kind(self) -> type:
        return type(self.default)

    @property
    def tooltip(self) -> str:
        return f"{self.tip}\n{self.paper}" if self.paper else self.tip

    def choice_label(self, value) -> str:
        return self.labels[self.choices.index(value)] if self.labels else str(value)

    def coerce(self, value: Any) -> Any:
        """``value`` converted to this parameter's type and clamped; ValueError if invalid."""
        if self.choices:
            if value not in self.choices:
                raise ValueError(
                    f"{self.label} must be one of {', '.join(map(str, self.choices))}, "
                    f"got {value!r}"
                )
            return value
        if isinstance(self.default, bool):
            return bool(value)
        if isinstance(self.default, str):
            text = str(value).strip()
            if text and not re.fullmatch(r"#[0-9a-fA-F]{6}", text):
                raise ValueError(f"{self.label} must be a colour like #336699, got {value!r}")
            return text.lower()
        v = self.kind(value)
        if self.minimum is not None:
            v = max(self.kind(self.minimum), v)
        if self.maximum is not None:
            v = min(self.kind(self.maximum), v)
        return v


def _choices(values, names: dict) -> dict:
    return {"choices": tuple(values), "labels": tuple(names.get(v, v) for v in values)}


_P = Param
PARAMS: tuple[Param, ...] = (
    # -- the tile
    _P(
        "tile_size",
        AUTO,
        "Tile size",
        "Side of the square tile (px). Auto: a power of two about half the image's short "
        "side, moved to the nearest size that holds whole periods of a repeating texture "
        "(boards, bricks). Any: the search also chooses the size, between Smallest and "
        "Largest tile.",
        "Tile",
        basic=True,
        choices=(AUTO, *TILE_SIZES, ANY),
        labels=("Auto (square)", *(f"{s} × {s}" for s in TILE_SIZES), "Any (search)"),
    ),
    _P(
        "tile_min",
        0,
        "Smallest tile",
        "Tile size Any: the smallest side the search may choose (px); auto: a quarter of the "
        "image's short side.",
        "Tile",
        0,
        4096,
        special="auto",
        paper="Somol & Haindl: the template search range",
    ),
    _P(
        "tile_max",
        0,
        "Largest tile",
        "Tile size Any: the largest side the search may choose (px); auto: half the image's "
        "short side.",
        "Tile",
        0,
        4096,
        special="auto",
        paper="Somol & Haindl: the template search range",
    ),
    _P(
        "overlap",
        0,
        "Seam search width",
        "Width of the shaded strips along the tile's edges where the seams run (px): wider "
        "gives the seams more room to avoid visible edges. Auto: a tenth of the tile.",
        "Tile",
        0,
        256,
        special="auto",
        basic=True,
        paper="Somol & Haindl: w_T, the template overlap (R_L/R_R, R_T/R_B)",
    ),
    _P(
        "joint_weight",
        TilesetSettings().joint_weight,
        "Prefer calm edges",
        "How strongly the search puts the tile's edges where the texture is calm rather than "
        "on a line or an edge (0: only how well opposite edges match).",
        "Tile",
        0.0,
        4.0,
        step=0.1,
        paper="Our addition to Somol & Haindl's search: λ, the weight of the wrap joint",
    ),
    _P(
        "detail_weight",
        TilesetSettings().detail_weight,
        "Avoid blurred areas",
        "How strongly the search keeps the tile out of flat or blurred parts of the photo, "
        "where opposite edges match easily but the tile lacks detail (0: off).",
        "Tile",
        0.0,
        4.0,
        step=0.1,
        paper="Our addition to Somol & Haindl's search: κ, the weight of the detail term",
    ),
    _P(
        "flatten",
        "auto",
        "Flatten lighting",
        "Divide out the photo's uneven lighting (a smooth light field at the tile's scale) "
        "before everything; the colour map only, never normal or height maps. Auto: on, with "
        "the gradient-domain seam blending, when the lighting varies across an otherwise even "
        "photo (the banner says so). View ▸ Flattened lighting (F): before / after.",
        "Tile",
        paper="Issue 10: Flatten lighting (quilt-studio tileset --flatten / --no-flatten)",
        **_choices(("auto", "on", "off"), {"auto": "Auto", "on": "On", "off": "Off"}),
    ),
    # -- seams
    _P(
        "method",
        "dp",
        "Seam shape",
        "How each seam is found in the shaded strips (the green and cyan lines).",
        "Seams",
        paper=_METHOD_PAPERS,
        **_choices(METHODS, _METHOD_LABELS),
    ),
    _P(
        "metric",
        "euclid",
        "Difference measure",
        "How the difference between the two overlapping strips is measured (the heat map).",
        "Seams",
        paper="euclid (Somol & Haindl), ssd (Efros & Freeman), CIELAB ΔE",
        **_choices(METRICS, _METRIC_LABELS),
    ),
    _P(
        "blend",
        "adaptive",
        "Seam blending",
        "After the cut: a hard edge, a soft edge of fixed width, a soft edge only where the "
        "two sides differ, or a hard edge whose tone step is spread smoothly over both sides "
        "(gradient domain: no blur).",
        "Seams",
        basic=True,
        paper="none / feather / adaptive blending (Somol & Haindl); poisson: Pérez et al. 2003",
        **_choices(TILE_BLEND_MODES, _BLEND_LABELS),
    ),
    _P(
        "width",
        4,
        "Soft edge width",
        "Width of the soft edge across the seam (px), for Soft, fixed width.",
        "Seams",
        0,
        64,
        paper="feather width",
    ),
    _P(
        "rho",
        3,
        "Blend softness",
        "How far the soft edge spreads where the two sides differ (0: hard), for Soft where "
        "needed.",
        "Seams",
        0,
        16,
        basic=True,
        paper="Somol & Haindl: ρ, adaptive blending (default 3)",
    ),
    _P(
        "template_blend",
        SAME,
        "Tile edge blending",
        "Blending of the seamless tile's own two seams: as Seam blending, or its own.",
        "Seams",
        paper="quilt-studio tileset keeps the template's cuts hard by default",
        **_choices((SAME, *TILE_BLEND_MODES), {SAME: "As Seam blending", **_BLEND_LABELS}),
    ),
    # -- candidates
    _P(
        "n_candidates",
        30,
        "How many candidates",
        "How many candidate tiles Generate makes (they all connect to each other).",
        "Candidates",
        1,
        500,
        basic=True,
        paper="Somol & Haindl: N candidate tiles",
    ),
    _P(
        "patch_size",
        0,
        "Patch size",
        "Side of the piece of the photo sewn into each candidate (px); auto: the tile size.",
        "Candidates",
        0,
        4096,
        special="auto",
        paper="Somol & Haindl: the patch",
    ),
    _P(
        "patch_overlap",
        0,
        "Patch seam ring",
        "Width of the ring along the tile's border where each candidate's closed seam runs (px). "
        "Narrower: less of a grid in the preview, but a harder seam. Auto: half the seam "
        "search width, 8 px at least.",
        "Candidates",
        0,
        256,
        special="auto",
        paper="Somol & Haindl: w_P, the patch overlap",
    ),
    _P(
        "margin",
        1,
        "Fixed border",
        "Outer pixels of every candidate that stay the tile's, so all candidates connect (px).",
        "Candidates",
        0,
        32,
    ),
    _P(
        "neighbourhood",
        5,
        "Patch search radius",
        "Local patch search only: each random patch position is improved within this many "
        "pixels (the default global search looks over the whole source).",
        "Candidates",
        0,
        64,
    ),
    _P(
        "seed",
        1,
        "Candidate seed",
        "Another number gives other candidates; the same number, the same candidates.",
        "Candidates",
        0,
        2**31 - 1,
    ),
    # -- preview
    _P("preview_rows", 6, "Rows", "Rows of tiles in the preview.", "Preview", 1, 64),
    _P("preview_cols", 6, "Columns", "Columns of tiles in the preview.", "Preview", 1, 64),
    _P(
        "no_equal_neighbours",
        True,
        "No equal neighbours",
        "Never put the same tile next to itself in the preview.",
        "Preview",
    ),
    _P(
        "layout_seed",
        1,
        "Layout seed",
        "Another number gives another arrangement (Re-roll changes it).",
        "Preview",
        0,
        2**31 - 1,
    ),
    # -- quilting
    _P(
        "out_width",
        0,
        "Output width",
        "Width of the texture to make (px); auto: twice the source, 4096 at most.",
        "Quilting",
        0,
        8192,
        special="auto",
        basic=True,
    ),
    _P(
        "out_height",
        0,
        "Output height",
        "Height of the texture to make (px); auto: twice the source, 4096 at most.",
        "Quilting",
        0,
        8192,
        special="auto",
        basic=True,
    ),
    _P(
        "block",
        48,
        "Block size",
        "Side of the pieces copied from the source (px): large enough to hold its patterns.",
        "Quilting",
        4,
        1024,
        basic=True,
        paper="Efros & Freeman: block size B",
    ),
    _P(
        "q_overlap",
        0,
        "Block overlap",
        "How far neighbouring blocks overlap (px); auto: a sixth of the block (half for "
        "Cut avoiding the worst spot, a quarter for Random with extensions).",
        "Quilting",
        0,
        512,
        special="auto",
        paper="Efros & Freeman: overlap",
    ),
    _P(
        "select",
        "best",
        "Block choice",
        "Which source piece goes next: one of the best matches of what is already there, the "
        "best of a random sample, any, or random pieces grown by extensions.",
        "Quilting",
        paper="best (Efros & Freeman) · sampled (CS194, Core S2) · random · bhatia (Bhatia)",
        **_choices(
            QUILT_SELECTIONS,
            {
                "best": "Best match",
                "sampled": "Best of a sample",
                "random": "Random",
                "bhatia": "Random with extensions",
            },
        ),
    ),
    _P(
        "tolerance",
        0.1,
        "Match tolerance",
        "Best match: choose at random among pieces within this much of the best (0.1 = 10 %).",
        "Quilting",
        0.0,
        2.0,
        step=0.05,
        paper="Efros & Freeman: the error tolerance",
    ),
    _P(
        "q_candidates",
        0,
        "Pieces compared",
        "Best of a sample: pieces tried per block; Fast search: pieces compared exactly; "
        "auto: 200 / 32.",
        "Quilting",
        0,
        100_000,
        special="auto",
    ),
    _P(
        "q_mode",
        "auto",
        "Search",
        "Exhaustive: compare every piece of the source; Fast: find the best pieces on a reduced "
        "copy of the source, then compare them exactly (large sources in seconds); Auto: "
        "exhaustive when it takes under about 10 s. The status bar shows the estimate.",
        "Quilting",
        basic=True,
        paper="exact FFT search · coarse-to-fine search with exact re-ranking",
        **_choices(
            ("auto", "exact", "fast"), {"auto": "Auto", "exact": "Exhaustive", "fast": "Fast"}
        ),
    ),
    _P(
        "q_method",
        "dp",
        "Cut between blocks",
        "How neighbouring blocks are joined.",
        "Quilting",
        paper=_METHOD_PAPERS,
        **_choices(QUILT_SEAMS, _METHOD_LABELS),
    ),
    _P(
        "q_metric",
        "ssd",
        "Difference measure",
        "How the difference the cut follows is measured (the search always uses squares).",
        "Quilting",
        **_choices(METRICS, _METRIC_LABELS),
    ),
    _P(
        "q_blend",
        "none",
        "Seam blending",
        "Softening of the cut between blocks.",
        "Quilting",
        **_choices(BLEND_MODES, _BLEND_LABELS),
    ),
    _P("q_width", 4, "Soft edge width", "Soft edge across block seams (px).", "Quilting", 0, 64),
    _P(
        "q_rho",
        3,
        "Blend softness",
        "How far the soft edge spreads where blocks differ (0: hard).",
        "Quilting",
        0,
        16,
        paper="Somol & Haindl: ρ",
    ),
    _P(
        "adaptive_threshold",
        0.0,
        "Split blocks above",
        "Split a block in four where its best match differs by more than this (mean squared "
        "difference per pixel and channel); 0: never.",
        "Quilting",
        0.0,
        1.0,
        step=0.005,
        decimals=3,
        paper="Long & Mould: adaptive block size",
    ),
    _P(
        "min_block",
        0,
        "Smallest split block",
        "Split blocks stop at this size (px); auto: a quarter of the block.",
        "Quilting",
        0,
        1024,
        special="auto",
    ),
    _P(
        "tileable",
        False,
        "Tileable output",
        "The output's right edge continues its left edge and its bottom its top.",
        "Quilting",
        basic=True,
    ),
    _P(
        "q_seed",
        1,
        "Seed",
        "Another number gives another texture; the same, the same.",
        "Quilting",
        0,
        2**31 - 1,
    ),
    # -- source pixels never used
    _P(
        "exclude_color",
        "",
        "Excluded colour",
        "#rrggbb of a colour never to copy: no tile, patch or quilting block contains it "
        "(Ctrl+Shift+click the source to pick it; Ctrl+click in the Quilting tab).",
        "Exclusion",
    ),
    _P(
        "exclude_tolerance",
        0.0,
        "Colour tolerance",
        "Also never copy colours this close to the excluded one (per channel); 0: off.",
        "Exclusion",
        0.0,
        0.5,
        step=0.01,
    ),
    _P(
        "brush",
        8,
        "Brush radius",
        "Radius of the brushes: Shift+drag paints pixels never to use; the Heal brush paints "
        "the region to replace (right button: erase).",
        "Exclusion",
        1,
        256,
        basic=True,
    ),
    # -- options of the seam shapes (tile set and quilting)
    _P(
        "o_max",
        3,
        "Refinement reach",
        "Refined cut: how many control points move together in one try.",
        "Seam options",
        1,
        64,
        paper="Somol & Haindl: o_max",
    ),
    _P(
        "osc_variant",
        "resume",
        "Refinement order",
        "Refined cut: continue after an improvement, or restart the sweep.",
        "Seam options",
        paper="resume (ours) / faithful (Somol & Haindl)",
        **_choices(OSCILLATING_VARIANTS, {"resume": "Continue", "faithful": "Restart"}),
    ),
    _P(
        "osc_init",
        "dp",
        "Refinement start",
        "Refined cut: the path it starts from (the row-by-row cut ends within a few % of the "
        "best; each row's smallest difference, as published, 30-60 % above).",
        "Seam options",
        paper="dp (ours) / argmin (Somol & Haindl) / smoothed argmin",
        **_choices(
            ("dp", "argmin", "smoothed"),
            {"dp": "Row-by-row cut", "argmin": "Smallest per row", "smoothed": "Smoothed"},
        ),
    ),
    _P(
        "resistance_variant",
        "published",
        "Stepped cut lines",
        "Stepped cut: two lines from the overlap's corners, the second stopping where it "
        "meets the first, or one line walked from the top down.",
        "Seam options",
        paper="Bhatia: the published two minimum resistance cut lines, or one greedy walk",
        **_choices(("published", "walk"), {"published": "Two lines", "walk": "One walk"}),
    ),
    _P(
        "max_run",
        5,
        "Longest straight run",
        "Stepped cut: longest straight piece of a cut line (px).",
        "Seam options",
        1,
        256,
        paper="Bhatia: the maximum run of a minimum resistance cut line (5 in the figure)",
    ),
    _P(
        "connectivity",
        "8",
        "Diagonal steps",
        "Winding cuts: step to diagonal neighbours too (8) or not (4).",
        "Seam options",
        paper="path graph connectivity",
        **_choices(("8", "4"), {"8": "Yes (8)", "4": "No (4)"}),
    ),
    _P(
        "minimax_variant",
        "exact",
        "Worst-spot rule",
        "Cut avoiding the worst spot: exact (smallest worst difference, then the sum), the "
        "published approximation, or sorted.",
        "Seam options",
        paper="Long & Mould: minimax (exact / lm / sorted)",
        choices=MINIMAX_VARIANTS,
    ),
    _P(
        "levels",
        32,
        "Worst-spot levels",
        "Cut avoiding the worst spot: how finely differences are graded.",
        "Seam options",
        2,
        1024,
        paper="Long & Mould: quantisation levels",
    ),
    # -- texture transfer
    _P(
        "alpha_ramp",
        True,
        "Ramp the balance",
        "Each pass follows the texture more and the target less (off: the fixed balance below).",
        "Transfer",
        paper="Efros & Freeman: α from 0.1 to 0.9",
    ),
    _P(
        "alpha",
        0.5,
        "Texture vs target",
        "1: plain quilting; 0: only follow the target's light and dark.",
        "Transfer",
        0.0,
        1.0,
        step=0.05,
        paper="Efros & Freeman: α",
    ),
    _P(
        "iterations",
        3,
        "Passes",
        "Texture transfer passes, each with blocks a third smaller.",
        "Transfer",
        1,
        8,
    ),
    _P(
        "correspondence",
        "luminance",
        "Match on",
        "What is compared with the target: its brightness, or its blurred brightness.",
        "Transfer",
        **_choices(("luminance", "blurred"), {"luminance": "Brightness", "blurred": "Blurred"}),
    ),
    _P(
        "sigma",
        2.0,
        "Blur",
        "Blur of the blurred brightness (px).",
        "Transfer",
        0.5,
        16.0,
        step=0.5,
        decimals=1,
        paper="σ of the Gaussian",
    ),
)
