"""Every user parameter of the editor in one table: type, default, range, label, tooltip.

The parameters panel is built from :data:`PARAMS`; the document stores a flat dict
``{key: value}``; :func:`engine_options` turns it into the keyword arguments of the
engine calls. Keeping the table here means a new option is one line, not three widgets.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
from dataclasses import dataclass
from typing import Any

from engine.exclusion import colour_range_around
from engine.seams.spec import (
    BLEND_MODES,
    METHODS,
    METRICS,
    MINIMAX_VARIANTS,
    OPTIONS,
    OSCILLATING_VARIANTS,
    SeamSpec,
)
from engine.settings import TilesetSettings, settings_from_parameters

SEAM_METHODS = METHODS
BLENDS = BLEND_MODES
SAME = "same"  # template_blend: as the patches' blending
QUILT_SELECTIONS = ("best", "sampled", "random", "bhatia")
QUILT_SEAMS = ("straight", *SEAM_METHODS)


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

    @property
    def kind(self) -> type:
        return type(self.default)

    def coerce(self, value: Any) -> Any:
        """``value`` converted to this parameter's type and clamped; ValueError if invalid."""
        if self.choices:
            if value not in self.choices:
                raise ValueError(
                    f"{self.key} must be one of {', '.join(map(str, self.choices))}, got {value!r}"
                )
            return value
        if isinstance(self.default, bool):
            return bool(value)
        if isinstance(self.default, str):
            text = str(value).strip()
            if text and not re.fullmatch(r"#[0-9a-fA-F]{6}", text):
                raise ValueError(f"{self.key} must be a colour like #336699, got {value!r}")
            return text.lower()
        v = self.kind(value)
        if self.minimum is not None:
            v = max(self.kind(self.minimum), v)
        if self.maximum is not None:
            v = min(self.kind(self.maximum), v)
        return v


_P = Param
PARAMS: tuple[Param, ...] = (
    # -- template search
    _P(
        "tile_min",
        64,
        "Tile min",
        "Smallest tile side the template search may choose (px).",
        "Template",
        8,
        4096,
    ),
    _P(
        "tile_max",
        192,
        "Tile max",
        "Largest tile side the template search may choose (px).",
        "Template",
        8,
        4096,
    ),
    _P(
        "overlap",
        16,
        "Overlap w_T",
        "Width of the border regions R_L/R_R and R_T/R_B that are "
        "matched and stitched (px). About 1/10 of the tile.",
        "Template",
        2,
        256,
    ),
    _P(
        "joint_weight",
        TilesetSettings().joint_weight,
        "Joint weight",
        "Weight of the tile's natural wrap joint in the template search: the tile edge falls "
        "where the texture is calm (0 = strip mismatch only, as in the paper).",
        "Template",
        0.0,
        4.0,
        step=0.1,
    ),
    # -- seam
    _P(
        "method",
        "dp",
        "Seam method",
        "How the minimum-error seam through each overlap is found:\n"
        "dp: dynamic programming, one pixel per row (Efros & Freeman)\n"
        "dijkstra: shortest path, may wind\n"
        "minimax: smallest worst error, then sum (Long & Mould)\n"
        "oscillating: anytime control-point search (Somol & Haindl)\n"
        "resistance: minimum resistance cut line (Bhatia)",
        "Seam",
        choices=SEAM_METHODS,
    ),
    _P(
        "metric",
        "euclid",
        "Error metric",
        "Per-pixel error between the overlapping regions.",
        "Seam",
        choices=METRICS,
    ),
    _P(
        "blend",
        "adaptive",
        "Blending",
        "After the cut: none (hard cut), feather (fixed width) or "
        "adaptive (width follows the error along the seam, parameter rho).",
        "Seam",
        choices=BLENDS,
    ),
    _P(
        "width",
        4,
        "Feather width",
        "Width of the feather ramp across the seam (px).",
        "Seam",
        0,
        64,
    ),
    _P("rho", 3, "rho", "Adaptive blending strength (Somol & Haindl, default 3).", "Seam", 0, 16),
    _P(
        "template_blend",
        SAME,
        "Template blending",
        "Blending of the seamless tile's two cuts: the same as the patches' (Blending above), "
        "or its own (quilt-studio tileset leaves the template's cuts hard by default).",
        "Seam",
        choices=(SAME, *BLEND_MODES),
    ),
    # -- candidates
    _P(
        "n_candidates",
        30,
        "Candidates",
        "How many variant tiles 'Generate' makes.",
        "Candidates",
        1,
        500,
    ),
    _P(
        "patch_size",
        0,
        "Patch size",
        "Side of the patch stitched into each candidate (px); 0 = the tile size.",
        "Candidates",
        0,
        4096,
        special="auto",
    ),
    _P(
        "patch_overlap",
        0,
        "Patch ring w_P",
        "Width of the ring along the tile border in which the closed patch seam runs (px).\n"
        "auto (0): half the template overlap w_T, at least 8 px and at most w_T, as the "
        "tileset command does (w_T 16 -> 8 px, w_T 26 -> 13 px).\nEverything outside the "
        "seam is the template, the same in every tile: a narrower ring shows less of a grid "
        "in the preview but leaves the seam less room (higher seam error).",
        "Candidates",
        0,
        256,
        special="auto",
    ),
    _P(
        "margin",
        2,
        "Margin",
        "Outer pixels of every tile that always stay the template's, so all tiles connect (px).",
        "Candidates",
        0,
        32,
    ),
    _P(
        "neighbourhood",
        5,
        "Neighbourhood",
        "Random patch positions are refined within this many pixels.",
        "Candidates",
        0,
        64,
    ),
    _P(
        "seed",
        1,
        "Seed",
        "Random seed of the candidates (same seed, same tiles).",
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
        "Never put the same tile next to itself in the preview layout.",
        "Preview",
    ),
    _P(
        "layout_seed",
        1,
        "Layout seed",
        "Random seed of the preview layout (Re-roll changes it).",
        "Preview",
        0,
        2**31 - 1,
    ),
    # -- quilting / transfer
    # fmt: off
    _P(
        "out_width",
        384,
        "Output width",
        "Width of the synthesized texture (px).",
        "Quilting",
        16,
        8192,
    ),
    _P(
        "out_height",
        384,
        "Output height",
        "Height of the synthesized texture (px).",
        "Quilting",
        16,
        8192,
    ),
    _P(
        "block",
        48,
        "Block",
        "Block size B (px): must capture the texture's structures.",
        "Quilting",
        4,
        1024,
    ),
    _P(
        "q_overlap",
        0,
        "Overlap",
        "Overlap between blocks (px); 0 = the method's default "
        "(block / 6; block / 2 for minimax; block / 4 as Bhatia's cut band).",
        "Quilting",
        0,
        512,
        special="auto",
    ),
    _P(
        "select",
        "best",
        "Selection",
        "best: among the blocks within the tolerance of the best "
        "overlap match (Efros & Freeman, exhaustive FFT search)\nsampled: best of N random "
        "blocks (CS194, Core S2)\nrandom: any block\nbhatia: random blocks with extensions cut "
        "by minimum resistance lines (Bhatia)",
        "Quilting",
        choices=QUILT_SELECTIONS,
    ),
    _P(
        "tolerance",
        0.1,
        "Tolerance",
        "best: draw among blocks whose overlap error is within (1 + tolerance) of the best.",
        "Quilting",
        0.0,
        2.0,
        step=0.05,
    ),
    _P(
        "q_candidates",
        0,
        "Candidates",
        "sampled: random blocks tried per position; fast mode: "
        "blocks re-ranked exactly (0 = default: 200 / 32).",
        "Quilting",
        0,
        100_000,
        special="auto",
    ),
    _P(
        "q_mode",
        "exact",
        "Search",
        "exact: exhaustive FFT search; fast: principal-component "
        "ranking, exact re-ranking of the best candidates.",
        "Quilting",
        choices=("exact", "fast"),
    ),
    _P(
        "q_method",
        "dp",
        "Seam method",
        "The cut between blocks: straight (no cut) or a seam method.",
        "Quilting",
        choices=QUILT_SEAMS,
    ),
    _P(
        "q_metric",
        "ssd",
        "Error metric",
        "Error map the cut runs on (the block search always uses the SSD).",
        "Quilting",
        choices=METRICS,
    ),
    _P(
        "q_blend",
        "none",
        "Blending",
        "Softening of the cut: none, feather (fixed width) or adaptive (rho).",
        "Quilting",
        choices=BLENDS,
    ),
    _P("q_width", 4, "Feather width", "Feather width across block seams (px).", "Quilting", 0, 64),
    _P("q_rho", 3, "rho", "Adaptive blending strength across block seams.", "Quilting", 0, 16),
    _P(
        "adaptive_threshold",
        0.0,
        "Split above",
        "Split a block in four when its best overlap "
        "error (mean squared difference per pixel and channel) exceeds this; 0 = never.",
        "Quilting",
        0.0,
        1.0,
        step=0.005,
        decimals=3,
    ),
    _P(
        "min_block",
        0,
        "Min block",
        "Smallest block when splitting (0 = default).",
        "Quilting",
        0,
        1024,
        special="auto",
    ),
    _P(
        "tileable",
        False,
        "Tileable output",
        "Wrap-around overlaps on the last column and row: the output tiles seamlessly.",
        "Quilting",
    ),
    _P("q_seed", 1, "Seed", "Random seed of the synthesis.", "Quilting", 0, 2**31 - 1),
    # -- excluded source pixels: template search, candidates and quilting
    _P(
        "exclude_color",
        "",
        "Excluded colour",
        "#rrggbb of a source colour never to use: no tile rectangle, patch or quilting block "
        "contains it (Ctrl+Shift+click the source to pick it; Ctrl+click in the Quilting "
        "tab); empty = none.",
        "Exclusion",
    ),
    _P(
        "exclude_tolerance",
        0.0,
        "Exclude colour ±",
        "Never use source pixels within this distance of the picked colour (per channel); 0 = off.",
        "Exclusion",
        0.0,
        0.5,
        step=0.01,
    ),
    _P(
        "brush",
        8,
        "Brush radius",
        "Radius of the exclusion brush: Shift+drag on the source (or the Quilting tab's "
        "sample) paints pixels never to use, Shift+right-drag erases.",
        "Exclusion",
        1,
        256,
    ),
    # -- options of the seam methods (shared by the tile set and quilting)
    _P(
        "o_max",
        3,
        "o_max",
        "oscillating: largest block of control points moved at once.",
        "Seam options",
        1,
        64,
    ),
    _P(
        "osc_variant",
        "resume",
        "Oscillating variant",
        "oscillating: resume (continue from the "
        "last improvement) or faithful (restart the sweep, as in the paper).",
        "Seam options",
        choices=OSCILLATING_VARIANTS,
    ),
    _P(
        "osc_init",
        "dp",
        "Oscillating start",
        "oscillating: the path the search starts from. dp: the exact one-pixel-per-row cut "
        "(default; ends within a few % of the optimum); argmin: each row's smallest error, as "
        "in the paper (Somol & Haindl; with 'faithful' this is the published algorithm, which "
        "ends 30-60 % above the optimum on real overlaps); smoothed: argmin of a blurred map.",
        "Seam options",
        choices=("dp", "argmin", "smoothed"),
    ),
    _P(
        "resistance_variant",
        "published",
        "Resistance variant",
        "resistance: published (Bhatia's two lines from the overlap's corners, the second "
        "stopping where it meets the first, as in the paper) or walk (one greedy walk from the "
        "top row down).",
        "Seam options",
        choices=("published", "walk"),
    ),
    _P(
        "max_run",
        5,
        "Max run",
        "resistance: longest straight run of a cut line (px; 5 in Bhatia's figure).",
        "Seam options",
        1,
        256,
    ),
    _P(
        "connectivity",
        "8",
        "Connectivity",
        "dijkstra, minimax: pixel neighbours of the path graph.",
        "Seam options",
        choices=("8", "4"),
    ),
    _P(
        "minimax_variant",
        "exact",
        "Minimax variant",
        "minimax: exact (smallest peak, then sum), lm (Long & Mould) or sorted.",
        "Seam options",
        choices=MINIMAX_VARIANTS,
    ),
    _P(
        "levels",
        32,
        "Minimax levels",
        "minimax: error quantisation levels.",
        "Seam options",
        2,
        1024,
    ),
    _P(
        "alpha_ramp",
        True,
        "Ramp alpha",
        "Texture transfer: alpha rises from 0.1 to 0.9 over the iterations (Efros & Freeman); "
        "off: the fixed alpha below in every iteration.",
        "Transfer",
    ),
    _P(
        "alpha",
        0.5,
        "Alpha",
        "Texture transfer: weight of the texture match (overlap and previous iteration) against "
        "the target correspondence (1 = plain quilting, 0 = only follow the target).",
        "Transfer",
        0.0,
        1.0,
        step=0.05,
    ),
    _P(
        "iterations",
        3,
        "Iterations",
        "Texture transfer passes, each with a block 2/3 the size.",
        "Transfer",
        1,
        8,
    ),
    _P(
        "correspondence",
        "luminance",
        "Correspondence",
        "What is matched against the target: its luminance, or its luminance blurred by sigma.",
        "Transfer",
        choices=("luminance", "blurred"),
    ),
    _P(
        "sigma",
        2.0,
        "Blur sigma",
        "Gaussian blur of the blurred correspondence map (px).",
        "Transfer",
        0.5,
        16.0,
        step=0.5,
        decimals=1,
    ),
    # fmt: on
)

BY_KEY: dict[str, Param] = {p.key: p for p in PARAMS}
GROUPS: tuple[str, ...] = tuple(dict.fromkeys(p.group for p in PARAMS))
DEFAULTS: dict[str, Any] = {p.key: p.default for p in PARAMS}

#: The options of the seam methods (which ones a method uses: :func:`seam_option_keys`).
SEAM_OPTION_KEYS = frozenset(p.key for p in PARAMS if p.group == "Seam options")
#: Parameters whose change invalidates the seamless tile (and everything after it).
SEAMLESS_KEYS = (
    frozenset({"overlap", "method", "metric", "blend", "width", "rho", "template_blend"})
    | SEAM_OPTION_KEYS
)
PREVIEW_KEYS = frozenset({"preview_rows", "preview_cols", "no_equal_neighbours", "layout_seed"})
#: Parameters whose change re-runs a shown quilting / transfer result (the brush only paints).
QUILT_KEYS = frozenset(
    p.key for p in PARAMS if p.group in ("Quilting", "Transfer", "Seam options", "Exclusion")
) - {"brush"}


def coerce_all(values: dict) -> dict:
    """Defaults updated with every known, valid entry of ``values`` (others are ignored)."""
    out = dict(DEFAULTS)
    for k, v in (values or {}).items():
        if k in BY_KEY:
            with contextlib.suppress(TypeError, ValueError):
                out[k] = BY_KEY[k].coerce(v)
    return out


#: the parameter holding each method's ``variant`` option
_VARIANT_KEYS = {
    "minimax": "minimax_variant",
    "oscillating": "osc_variant",
    "resistance": "resistance_variant",
}


def seam_option_keys(method: str) -> frozenset[str]:
    """The "Seam options" parameters that seam ``method`` uses (the others do nothing)."""
    allowed = OPTIONS.get(method, {})
    return frozenset(_option_key(k, method) for k in allowed if _option_key(k, method) in BY_KEY)


def seam_spec(p: dict) -> SeamSpec:
    """The :class:`engine.seams.SeamSpec` of the tile set (seamless tile and candidates)."""
    method = p["method"]
    return SeamSpec(
        method,
        seam_options(p, method),
        metric=p["metric"],
        blend=p["blend"],
        width=p["width"],
        rho=p["rho"],
    )


def seam_options(p: dict, method: str) -> dict:
    """The options seam ``method`` takes (engine.seams.OPTIONS), from the parameters."""
    opts = {k: p[_option_key(k, method)] for k in OPTIONS.get(method, {})}
    if "connectivity" in opts:
        opts["connectivity"] = int(opts["connectivity"])  # a choice of "8" / "4" on screen
    return opts


# ------------------------------------------------------------------ the tile set's settings
#: editor parameters that are a TilesetSettings field of another name
_RENAMED = {"n_candidates": "candidates"}
#: editor parameters that make up one settings field (or its seam)
_COMPOSED = frozenset(
    {"method", "metric", "blend", "width", "rho", "template_blend"}
    | {"preview_rows", "preview_cols", "exclude_color", "exclude_tolerance"}
)
_FIELDS = {f.name for f in dataclasses.fields(TilesetSettings)}
#: the parameters :func:`tileset_settings` reads (the other parameters are the editor's own)
TILESET_KEYS = frozenset(k for k in BY_KEY if k in _FIELDS or k in _RENAMED or k in _COMPOSED) - {
    "exclude_color",
    "exclude_tolerance",
}


def tileset_settings(p: dict) -> TilesetSettings:
    """The :class:`engine.tiles.TilesetSettings` of the editor's parameters ``p``."""
    values = {_RENAMED.get(k, k): p[k] for k in BY_KEY if _RENAMED.get(k, k) in _FIELDS}
    values.update(
        tile_max=max(p["tile_min"], p["tile_max"]),
        seam=seam_spec(p),
        template_blend=None if p["template_blend"] == SAME else p["template_blend"],
        patch_size=p["patch_size"] or None,
        patch_overlap=p["patch_overlap"] if p["patch_overlap"] >= 2 else None,  # 0: auto
        preview=(p["preview_rows"], p["preview_cols"]),
        exclude_color=colour_range_around(p["exclude_color"], p["exclude_tolerance"]),
    )
    return TilesetSettings(**values)


def settings_params(s: TilesetSettings) -> dict:
    """The editor's parameters for settings ``s`` (values it cannot show are left out: an
    (h, w) tile range becomes its smallest and largest side; the excluded colour range of
    the command line arrives as excluded pixels, see :mod:`quilt_gui.project_io`)."""
    out = {}
    for k in BY_KEY:
        name = _RENAMED.get(k, k)
        if name in _FIELDS and k not in _COMPOSED:
            value = getattr(s, name)
            if isinstance(value, tuple):  # a size (h, w)
                value = max(value) if k == "tile_max" else min(value)
            if value is not None:
                out[k] = value
    seam = s.seam
    out.update(
        method=seam.method,
        metric=seam.metric,
        blend=seam.blend,
        width=round(seam.width),
        rho=seam.rho,
        template_blend=SAME if s.template_blend is None else s.template_blend,
        preview_rows=s.preview[0],
        preview_cols=s.preview[1],
        patch_overlap=s.patch_overlap or 0,
        patch_size=min(s.patch_size) if s.patch_size else 0,
        layout_seed=s.seed if s.layout_seed is None else s.layout_seed,
    )
    for option, value in seam.options.items():
        key = _option_key(option, seam.method)
        out[key] = str(value) if key == "connectivity" else value
    return out


def project_parameters(p: dict) -> dict:
    """A project's ``parameters``: the tile set's settings and the editor's own parameters."""
    return {
        "tileset": tileset_settings(p).to_dict(),
        "editor": {k: v for k, v in p.items() if k not in TILESET_KEYS},
    }


def from_project_parameters(parameters: dict, seeds: dict | None = None) -> dict:
    """The editor's parameters of a project: its own (``parameters["editor"]``, or the flat
    keys of older files), then the tile set's settings (any version, the command line's too)."""
    own = parameters.get("editor")
    out = coerce_all(own if isinstance(own, dict) else parameters)
    settings = settings_from_parameters(parameters, seeds or {})
    for k, v in settings_params(settings).items():
        with contextlib.suppress(TypeError, ValueError):
            out[k] = BY_KEY[k].coerce(v)
    return out


def _option_key(option: str, method: str) -> str:
    """The parameter of seam ``option`` of ``method`` (each method's variant has its own)."""
    if option == "variant":
        return _VARIANT_KEYS[method]
    return "osc_init" if option == "init" else option
