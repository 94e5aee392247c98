"""Reading the tile-set options of project files written before :class:`TilesetSettings`.

Version 1 projects kept the options as flat keys in ``parameters``, spelled one way by
``quilt-studio tileset`` (``seam``, ``seam_options``, ``template_blend``/``candidate_blend``,
``candidates``, ``preview``; seeds in the project's ``seeds``) and another by the editor
(``method``, ``blend``, ``n_candidates``, ``o_max``, ``osc_variant``..., ``preview_rows``,
``exclude_color`` as ``#rrggbb`` with ``exclude_tolerance``). This module maps either to the
field values of :class:`engine.settings.TilesetSettings`; it is only read, never written.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["legacy_settings_values"]

_SAME_NAME = (
    "tile_min",
    "tile_max",
    "overlap",
    "joint_weight",
    "patch_size",
    "patch_overlap",
    "margin",
    "neighbourhood",
    "no_equal_neighbours",
)
#: the editor's seam-option parameters -> (option, the methods that read it)
_EDITOR_OPTIONS = {
    "o_max": ("o_max", ("oscillating",)),
    "osc_variant": ("variant", ("oscillating",)),
    "osc_init": ("init", ("oscillating",)),
    "max_run": ("max_run", ("resistance",)),
    "connectivity": ("connectivity", ("dijkstra", "minimax")),
    "minimax_variant": ("variant", ("minimax",)),
    "levels": ("levels", ("minimax",)),
}


def legacy_settings_values(parameters: Mapping, seeds: Mapping) -> dict:
    """Field values of TilesetSettings from a version-1 project's ``parameters`` and
    ``seeds`` (unchecked: the caller keeps those that pass their checks)."""
    p = dict(parameters)
    out = {k: p[k] for k in _SAME_NAME if k in p}
    if "method" in p or "n_candidates" in p:  # written by the editor
        out.update(_editor_values(p))
    else:  # written by quilt-studio tileset
        out.update(_cli_values(p, seeds))
    for k in ("patch_size", "patch_overlap"):  # the editor's 0 meant "auto"
        if out.get(k) == 0:
            out[k] = None
    return out


def _cli_values(p: dict, seeds: Mapping) -> dict:
    out = {}
    blend = p.get("candidate_blend", "adaptive")
    seam = {
        "method": p.get("seam", "dp"),
        "options": p.get("seam_options") or {},
        "metric": p.get("metric", "euclid"),
        "blend": blend,
    }
    seam.update({k: p[k] for k in ("width", "rho") if k in p})
    out["seam"] = seam
    out["template_blend"] = p.get("template_blend", "none")
    if "candidates" in p:
        out["candidates"] = p["candidates"]
    if isinstance(p.get("preview"), (list, tuple)):
        out["preview"] = p["preview"]
    if "candidates" in seeds:
        out["seed"] = seeds["candidates"]
    if "layout" in seeds:
        out["layout_seed"] = seeds["layout"]
    return out


def _editor_values(p: dict) -> dict:
    method = p.get("method", "dp")
    options = {}
    for key, (option, methods) in _EDITOR_OPTIONS.items():
        if key in p and method in methods:
            value = p[key]
            options[option] = int(value) if key == "connectivity" else value
    seam = {"method": method, "options": options}
    seam.update({k: p[k] for k in ("metric", "blend", "width", "rho") if k in p})
    if isinstance(seam.get("width"), int):
        seam["width"] = float(seam["width"])
    out = {"seam": seam, "template_blend": None}
    renamed = {"n_candidates": "candidates", "seed": "seed", "layout_seed": "layout_seed"}
    out.update({new: p[old] for old, new in renamed.items() if old in p})
    if "preview_rows" in p and "preview_cols" in p:
        out["preview"] = (p["preview_rows"], p["preview_cols"])
    colour = _editor_colour_range(p.get("exclude_color"), p.get("exclude_tolerance", 0))
    if colour is not None:
        out["exclude_color"] = colour
    return out


def _editor_colour_range(text, tolerance):
    """``#rrggbb`` ± tolerance as the (lo, hi) range the editor excluded, or None."""
    from engine.exclusion import colour_range_around

    try:
        return colour_range_around(text, float(tolerance))
    except (TypeError, ValueError, IndexError):
        return None
