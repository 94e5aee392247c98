"""The editor's parameters as data: the table's indexes, and the settings the engine takes.

The table itself (labels, tooltips, ranges) is :mod:`quilt_gui.param_table`; the document stores
a flat dict ``{key: value}``. :func:`tileset_settings` turns it into the tile set's
:class:`engine.settings.TilesetSettings` (what the command line reads and writes too),
:func:`seam_spec` and :func:`seam_options` into seam arguments, :func:`ui_words` puts the
labels into the engine's messages.
"""

from __future__ import annotations

import contextlib
import dataclasses
import re
from typing import Any

from engine.exclusion import colour_range_around
from engine.seams.spec import BLEND_MODES, METHODS, OPTIONS, SeamSpec
from engine.settings import TilesetSettings, settings_from_parameters
from quilt_gui.param_table import (
    ANY,
    AUTO,
    PARAMS,
    QUILT_SEAMS,
    QUILT_SELECTIONS,
    SAME,
    TILE_SIZES,
    Param,
)

__all__ = [
    "ANY",
    "AUTO",
    "BY_KEY",
    "DEFAULTS",
    "GROUPS",
    "PARAMS",
    "QUILT_SEAMS",
    "QUILT_SELECTIONS",
    "Param",
    "auto_tile_size",
    "coerce_all",
    "fit_to_source",
    "output_shape",
    "seam_option_keys",
    "seam_options",
    "seam_spec",
    "tileset_settings",
    "ui_words",
]

SEAM_METHODS = METHODS
BLENDS = BLEND_MODES

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
#: Parameters whose change means a new tile size: the template search runs again.
TILE_SIZE_KEYS = frozenset({"tile_size", "tile_min", "tile_max"})
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
    {"tile_size", "method", "metric", "blend", "width", "rho", "template_blend"}
    | {"preview_rows", "preview_cols", "exclude_color", "exclude_tolerance", "flatten"}
)
#: the Flatten lighting parameter's values and the settings' (None: "from the source")
_FLATTEN = {"auto": None, "on": True, "off": False}
_FIELDS = {f.name for f in dataclasses.fields(TilesetSettings)}
#: the parameters :func:`tileset_settings` reads (the other parameters are the editor's own)
TILESET_KEYS = frozenset(k for k in BY_KEY if k in _FIELDS or k in _RENAMED or k in _COMPOSED) - {
    "exclude_color",
    "exclude_tolerance",
    "tile_size",  # kept as the editor's own too: "auto" is resolved for the source at hand
}


#: the smallest square tile Auto gives a source under 128 px (the searched range's minimum)
MIN_AUTO_TILE = 8


def auto_tile_size(shape, scale=None) -> int | None:
    """The "Auto" tile size for a source of ``shape`` (H, W): the largest power of two of
    64 … 2048 px that is at most half the shorter side; for a source under 128 px, the largest
    square the searched range holds (half the shorter side, at least :data:`MIN_AUTO_TILE` px)
    whose side plus overlap fits the shorter side (15 px on a 40×30 photo, where the range
    found 15×8); None when not even that fits. With the source's structure ``scale``
    (:class:`engine.tiles.scale.Scale`), that side moved to the nearest one within a quarter of
    it that holds whole periods of a periodic texture and still fits the source (the Wang
    sets' rule, :func:`engine.tiles.wang_size.whole_period_size`): 256 px cuts 48 px planks at
    every tile line, 240 px holds five (README, issue 10 Session 11)."""
    from engine.tiles.template import default_overlap

    short = min(int(shape[0]), int(shape[1]))
    fits = [int(s) for s in TILE_SIZES if int(s) <= short // 2]
    if not fits:  # under 128 px: no power of two; the largest square that fits
        top = max(MIN_AUTO_TILE, short // 2)  # the searched range's largest side
        sides = [n for n in range(MIN_AUTO_TILE, top + 1) if n + default_overlap(n) <= short]
        return sides[-1] if sides else None
    if scale is None:
        return fits[-1]
    from engine.tiles.wang_size import whole_period_size

    side = whole_period_size(scale, fits[-1], lambda n: n + default_overlap(n) <= short)
    return side or fits[-1]


def auto_size_note(shape, scale, size) -> str | None:
    """What the Auto tile size did, in words, when it moved the power of two of a source of
    ``shape`` to ``size`` to hold whole periods of its structure ``scale`` ("Auto tile size
    240 px, not 256: it holds whole periods of the texture (5 × 48 px wide, measured) ...", the
    facts first: the status bar cuts a long line); None when Auto kept the power of two."""
    pow2 = auto_tile_size(shape)
    if scale is None or size is None or pow2 is None or size == pow2:
        return None
    from engine.tiles.wang_size import periods_held

    held = periods_held(scale, size, pow2)
    if not held:
        return None
    what = ", ".join(f"{k} × {p:.0f} px {axis}" for k, p, axis in held)
    if len(held) == 2 and len({(k, f"{p:.0f}") for k, p, _ in held}) == 1:  # the weave, tiles
        what = f"{held[0][0]} × {held[0][1]:.0f} px each way"
    return (
        f"Auto tile size {size} px, not {pow2}: it holds whole periods of the texture ({what}, "
        "measured), so the pattern continues across the tile lines"
    )


def tile_size(p: dict, shape=None, scale=None) -> int | None:
    """The square tile side the parameters ask for (None: the search chooses the size;
    ``scale``: the source's structure scale, which the Auto size keeps whole periods of)."""
    if p["tile_size"] == ANY:
        return None
    if p["tile_size"] == AUTO:
        return None if shape is None else auto_tile_size(shape, scale)
    return int(p["tile_size"])


def fit_to_source(p: dict, shape) -> dict:
    """The sizes in ``p`` that cannot work on a source of ``shape`` (H, W), set back to their
    automatic value (a new image smaller than the last one's tile must not fail)."""
    short = min(int(shape[0]), int(shape[1]))
    changes = {}
    if p["tile_size"] not in (AUTO, ANY) and int(p["tile_size"]) > short - 2:
        changes["tile_size"] = AUTO
    for key, limit in (
        ("tile_min", short - 2),
        ("tile_max", short - 2),
        ("overlap", short // 4),
        ("patch_size", short - 2),
    ):
        if p[key] > max(limit, 0):
            changes[key] = 0
    if p["block"] > short:
        changes["block"] = max(BY_KEY["block"].minimum, short // 2)
    return changes


#: the largest side of an Auto quilting output
MAX_AUTO_OUTPUT = 2048


def output_shape(p: dict, source_shape) -> tuple[int, int]:
    """(height, width) of the quilting output: the parameters, or (auto) twice the source,
    at most :data:`MAX_AUTO_OUTPUT` a side."""
    H, W = int(source_shape[0]), int(source_shape[1])
    return (
        int(p["out_height"]) or min(2 * H, MAX_AUTO_OUTPUT),
        int(p["out_width"]) or min(2 * W, MAX_AUTO_OUTPUT),
    )


#: the settings fields :func:`tileset_settings` makes from parameters of other names
_SET_HERE = {"tile_size", "tile_min", "tile_max", "overlap", "seam", "template_blend"}
_SET_HERE |= {"patch_size", "patch_overlap", "preview", "exclude_color", "flatten"}
#: the settings fields no editor parameter shows: a project's values of them are kept under
#: this key of the parameters and used as they are (an option added to TilesetSettings before
#: the editor has a control for it still travels from the command line to the editor and back)
KEPT = "tileset_kept"
KEPT_FIELDS = _FIELDS - _SET_HERE - {_RENAMED.get(k, k) for k in BY_KEY}


def tileset_settings(p: dict, shape=None, scale=None) -> TilesetSettings:
    """The :class:`engine.tiles.TilesetSettings` of the editor's parameters ``p`` (``shape``
    (H, W) of the source settles the Auto tile size; without it Auto searches a range;
    ``scale``, the source's structure scale, moves it to whole periods unless the settings
    turn ``whole_structures`` off)."""
    base = settings_from_parameters({"tileset": p.get(KEPT) or {}})
    if not base.whole_structures:
        scale = None
    values = {_RENAMED.get(k, k): p[k] for k in BY_KEY if _RENAMED.get(k, k) in _FIELDS}
    lo, hi = p["tile_min"] or None, p["tile_max"] or None
    if lo is not None and hi is not None:
        hi = max(lo, hi)
    values.update(
        tile_size=tile_size(p, shape, scale),
        tile_min=lo,
        tile_max=hi,
        overlap=p["overlap"] or None,
        seam=seam_spec(p),
        template_blend=None if p["template_blend"] == SAME else p["template_blend"],
        patch_size=p["patch_size"] or None,
        patch_overlap=p["patch_overlap"] if p["patch_overlap"] >= 2 else None,  # 0: auto
        preview=(p["preview_rows"], p["preview_cols"]),
        exclude_color=colour_range_around(p["exclude_color"], p["exclude_tolerance"]),
        flatten=_FLATTEN[p["flatten"]],
    )
    return base.replace(**values)


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
    size = s.tile_size or (
        s.tile_min if s.tile_min is not None and s.tile_min == s.tile_max else None
    )
    square = size is not None and size[0] == size[1] and str(size[0]) in TILE_SIZES
    out.update(
        tile_size=str(size[0]) if square else ANY,
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
        flatten={v: k for k, v in _FLATTEN.items()}[s.flatten],
    )
    for option, value in seam.options.items():
        key = _option_key(option, seam.method)
        out[key] = str(value) if key == "connectivity" else value
    return out


def project_parameters(p: dict, shape=None, scale=None) -> dict:
    """A project's ``parameters``: the tile set's settings (for a source of ``shape`` and
    structure ``scale``) and the editor's own parameters."""
    return {
        "tileset": tileset_settings(p, shape, scale).to_dict(),
        "editor": {k: v for k, v in p.items() if k not in TILESET_KEYS and k != KEPT},
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
    values = settings.to_dict()
    out[KEPT] = {f: values[f] for f in sorted(KEPT_FIELDS)}
    if isinstance(own, dict) and own.get("tile_size") == AUTO:
        out["tile_size"] = AUTO  # the settings hold the size Auto chose for that source
    return out


#: names in the engine's messages -> the words on screen: the identifiers only (a plain word
#: such as "overlap" or "width" is left alone, it may mean something else in the sentence)
_UI_NAMES = {
    p.key: p.label for p in PARAMS if "_" in p.key and not p.key.startswith(("q_", "osc_"))
} | {"rho": BY_KEY["rho"].label, "blend_width": BY_KEY["q_width"].label}


def ui_words(text: str) -> str:
    """``text`` (an engine message) with parameter names replaced by the labels on screen:
    "tile_min must be ..." reads "Smallest tile must be ..."."""
    names = sorted(_UI_NAMES, key=len, reverse=True)
    pattern = r"(?<![\w./])(" + "|".join(map(re.escape, names)) + r")(?![\w/])"
    return re.sub(pattern, lambda m: f"“{_UI_NAMES[m.group(1)]}”", text)


#: the command line's hints in the engine's notes -> the editor's words (the notes name both)
_CLI_HINTS = (
    # "(a larger tile size: --tile-max, or Tile size in the editor)" -> "(Tile size)", also
    # "(--tile-size 144, or ...)"
    (re.compile(r"\([^()]*?--[\w-]+(?: N| \d+)?, or ([^()]+?) in the editor\)"), r"(\1)"),
    # "--no-flatten, or Flatten lighting: Off in the editor, keeps" -> "Flatten lighting: Off keeps"
    (re.compile(r"--[\w-]+, or ([^()]+?) in the editor,?"), r"\1"),
    # "try Flatten lighting (tileset --flatten)" -> "... (Parameters ▸ Advanced ▸ Tile)"
    (re.compile(r"\(tileset --flatten\)"), "(Parameters ▸ Advanced ▸ Tile)"),
)


#: the engine's advice naming options the editor has no control for (the command line's
#: --min-distance) -> what to do in the editor
_ENGINE_ONLY = (
    (
        re.compile(r"a larger source, smaller tiles or a smaller minimum distance give more"),
        f"a larger source or a smaller “{BY_KEY['tile_size'].label}” gives more",
    ),
    (  # a Wang set's samples kept apart by min_distance (half a tile; no control for it)
        re.compile(r"at min_distance ([\d.]+): samples are ([\d.]+) px apart"),
        r"with their edge samples \1 px (half a tile) apart: they are \2 px apart (fewer "
        r"Colours, a smaller Tile size or a larger source give them room)",
    ),
)


def sentence(note: str) -> str:
    """An engine note (lower case: it also ends up inside other sentences) as a sentence."""
    return note[:1].upper() + note[1:]


def editor_words(text: str) -> str:
    """``text`` (an engine note) without the command line's flags where the note also names
    the editor's control, and without advice the editor has no control for, so the banner
    speaks of what is on screen."""
    for pattern, repl in (*_CLI_HINTS, *_ENGINE_ONLY):
        text = pattern.sub(repl, text)
    return text


def _choice_label(key: str, value: str) -> str:
    par = BY_KEY[key]
    return par.labels[par.choices.index(value)]


#: the quilting engine's option names in its messages -> the labels on the Quilting panel
_QUILT_WORDS = (
    (
        re.compile(r"select='bhatia' needs a cut: choose a seam method, e\.g\. 'resistance'"),
        f"“{BY_KEY['select'].label}: {_choice_label('select', 'bhatia')}” needs a cut: choose "
        f"a “{BY_KEY['q_method'].label}” other than “{_choice_label('q_method', 'straight')}”",
    ),
    (re.compile(r"with select='bhatia'"), f"with “{_choice_label('select', 'bhatia')}”"),
    # texture transfer's passes: "iterations=1 shrinks block 16 to 16 px and overlap 16 to ..."
    (  # its first pass (nothing shrunk): the overlap is as wide as the block
        re.compile(
            r"iterations=\d+ shrinks block (\d+) to \1 px and overlap (\d+) to \2 px at "
            r"iteration 1: .*"
        ),
        f"a “{BY_KEY['q_overlap'].label}” of \\2 px does not fit a “{BY_KEY['block'].label}” "
        f"of \\1 px: choose a smaller “{BY_KEY['q_overlap'].label}” or a larger "
        f"“{BY_KEY['block'].label}”",
    ),
    (re.compile(r"iterations=(\d+)"), f"“{BY_KEY['iterations'].label}” \\1"),
    (re.compile(r"shrinks block\b"), f"shrinks the “{BY_KEY['block'].label}”"),
    (re.compile(r"at iteration (\d+)"), r"in pass \1"),
    (re.compile(r"fewer iterations"), f"fewer “{BY_KEY['iterations'].label}”"),
    (re.compile(r"a larger block\b"), f"a larger “{BY_KEY['block'].label}”"),
    (re.compile(r"a smaller overlap\b"), f"a smaller “{BY_KEY['q_overlap'].label}”"),
    (re.compile(r"\bmin_block\b"), f"“{BY_KEY['min_block'].label}”"),
    (re.compile(r"\ban overlap\b"), f"a “{BY_KEY['q_overlap'].label}”"),
    (re.compile(r"^overlap\b|\boverlap(?= \d)"), f"“{BY_KEY['q_overlap'].label}”"),
)


def quilt_words(text: str) -> str:
    """``text`` (a message of the quilting engine's option check) in the Quilting panel's
    words: "select='bhatia' needs a cut ..." reads "“Block choice: Random with extensions”
    needs a cut ..."."""
    for pattern, repl in _QUILT_WORDS:
        text = pattern.sub(repl, text)
    return text


def _option_key(option: str, method: str) -> str:
    """The parameter of seam ``option`` of ``method`` (each method's variant has its own)."""
    if option == "variant":
        return _VARIANT_KEYS[method]
    return "osc_init" if option == "init" else option
