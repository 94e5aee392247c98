"""The tile-set workflow's settings, in one type the command line and the editor share.

:class:`TilesetSettings` holds every option of the workflow (template search, seam, candidates,
preview layout, excluded colours) with the workflow's defaults. It is frozen, validates each
field once when it is made, and serialises itself to a plain dict (:meth:`~TilesetSettings.
to_dict` / :meth:`~TilesetSettings.from_dict`): ``quilt-studio tileset`` writes it into its
manifest and project, the editor reads and writes the same dict in its project files, so a
project moves between them with every option.

Adding an option is one line: a field with its default and its check, e.g.
``whole_structures: bool = setting(True, boolean)``. ``None`` means "chosen from the source" where a
field allows it (:func:`engine.tiles.pipeline.resolve` fills those in).

Project files keep the dict under ``parameters["tileset"]``; :func:`settings_from_parameters`
also reads the keys older versions wrote (the CLI's and the editor's own spellings).
:func:`engine.tiles.pipeline.iter_tileset` runs the whole workflow with one settings value.

This module imports no numpy (the command line builds settings before loading the engine; a
module of the ``engine.tiles`` package would load its numba kernels first).

Examples
--------
>>> s = TilesetSettings(candidates=12, seam=SeamSpec("oscillating", {"o_max": 4}))
>>> TilesetSettings.from_dict(s.to_dict()) == s
True
>>> TilesetSettings(tile_min=200, tile_max=100)
Traceback (most recent call last):
...
ValueError: tile_min (200, 200) must not exceed tile_max (100, 100) (as (h, w))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field

from engine._checks import as_size, choice, non_negative_number, positive_int
from engine.seams.spec import TILE_BLEND_MODES, SeamSpec

__all__ = [
    "DEFAULT_SEAM",
    "TilesetSettings",
    "setting",
    "settings_from_parameters",
]

#: the workflow's default cut: dp, Euclidean error, adaptive blending of the patches
DEFAULT_SEAM = SeamSpec(blend="adaptive")


# --------------------------------------------------------------------------- field checks
def setting(default, check):
    """A settings field: its default and ``check(value, name) -> value`` (raises on bad ones)."""
    return field(default=default, metadata={"check": check})


def optional(check):
    """``check`` that also lets None through ("chosen from the source")."""
    return lambda value, name: None if value is None else check(value, name)


def at_least(minimum: int):
    return lambda value, name: positive_int(value, name, minimum=minimum)


def number(value, name):
    return non_negative_number(value, name)


def boolean(value, name):
    if not isinstance(value, bool):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return value


def seam_spec(value, name) -> SeamSpec:
    if isinstance(value, Mapping):
        value = SeamSpec.from_dict(value)
    if not isinstance(value, SeamSpec) or not value.cuts:
        raise TypeError(f"{name} must be a SeamSpec of a seam method, got {value!r}")
    return value


def wang_interior(value, name):
    return choice(value, name, ("patch", "diamonds"))


def wang_interior_blend(value, name):
    return choice(value, name, ("auto", *TILE_BLEND_MODES))


def patch_search_mode(value, name):
    return choice(value, name, ("global", "local"))


def blend_mode(value, name):
    return choice(value, name, TILE_BLEND_MODES)


def colour_range(value, name):
    """(lo, hi): each a number or one number per channel, in [0, 1] (like ``--exclude-color``)."""
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a (lo, hi) pair, got {value!r}") from None

    def bound(v):
        vs = v if isinstance(v, (tuple, list)) else (v,)
        out = tuple(non_negative_number(x, name) for x in vs)
        if not out or max(out) > 1:
            raise ValueError(f"{name} bounds must be numbers in [0, 1], got {value!r}")
        return out[0] if not isinstance(v, (tuple, list)) else out

    return (bound(lo), bound(hi))


# --------------------------------------------------------------------------- the settings
@dataclass(frozen=True)
class TilesetSettings:
    """Every option of the tile-set workflow (Somol & Haindl), with its default.

    Template search: ``tile_size`` (N or (h, w): the tile's size, the search only places it;
    None: searched between ``tile_min`` and ``tile_max``), ``tile_min``/``tile_max`` (N or
    (h, w); None: a quarter / half of the source's shorter side, ``tile_max`` defaults to
    ``tile_min`` when only that is given),
    ``overlap`` w_T (None: about a tenth of the tile), ``joint_weight`` λ of the natural wrap
    joint, ``detail_weight`` κ of the detail term (:mod:`engine.tiles.detail`: keeps the tile
    out of flat or blurred regions), ``whole_structures`` (search only tiles that hold three of
    the texture's structures per side where the range allows, warn when it cannot:
    :mod:`engine.tiles.scale`). Cuts: ``seam`` (method, options, metric, blending of the
    patches) and ``template_blend`` (the template's blending; None: the same as ``seam.blend``).
    Candidates: ``candidates`` N, ``seed``, ``patch_size`` (None: the tile), ``patch_overlap``
    w_P (None: :func:`engine.tiles.default_patch_overlap`), ``margin`` (None: 1, at most
    w_P - 1), ``patch_search`` ("global": the best ring matches over the whole source, kept
    ``min_distance`` apart (None: :func:`engine.tiles.default_min_distance`); "local": the
    paper's random position refined within ``neighbourhood``). ``flatten``: Flatten lighting
    of the source (albedo only) before everything (:mod:`engine.tone`); None (default): "from
    the source" — when the stationarity check finds the lighting uneven on an otherwise
    stationary photo, flatten it and blend the cuts in the gradient domain
    (:func:`engine.tiles.pipeline.auto_tone`). Preview: ``preview`` (rows,
    cols), ``no_equal_neighbours``, ``layout_seed`` (None: ``seed``). ``exclude_color``: a
    colour range (lo, hi) no tile or patch may contain.

    Wang set instead (:mod:`engine.tiles.wang`, when ``wang`` = K colours per edge direction
    is set): square tiles of ``tile_min`` = ``tile_max`` (None: a quarter of the source's
    shorter side), ``wang_variants`` per edge signature, ``wang_interior`` ("patch" or
    "diamonds"), ``wang_interior_blend`` ("auto": gradient domain unless the seam's blend is
    "none"), ``wang_band`` (None: about a tenth of the tile), ``wang_outward``,
    ``wang_tolerance``, ``wang_min_distance`` (None: half the tile); ``seed``, ``seam``,
    ``patch_overlap``, ``margin`` (None: 1), the preview and the exclusion as above.
    """

    tile_size: tuple[int, int] | None = setting(None, optional(as_size))
    tile_min: tuple[int, int] | None = setting(None, optional(as_size))
    tile_max: tuple[int, int] | None = setting(None, optional(as_size))
    overlap: int | None = setting(None, optional(at_least(2)))
    joint_weight: float = setting(0.5, number)
    detail_weight: float = setting(1.0, number)
    whole_structures: bool = setting(True, boolean)
    seam: SeamSpec = setting(DEFAULT_SEAM, seam_spec)
    template_blend: str | None = setting("none", optional(blend_mode))
    candidates: int = setting(30, at_least(1))
    seed: int = setting(0, at_least(0))
    patch_size: tuple[int, int] | None = setting(None, optional(as_size))
    patch_overlap: int | None = setting(None, optional(at_least(2)))
    margin: int | None = setting(None, optional(at_least(0)))
    neighbourhood: int = setting(5, at_least(0))
    patch_search: str = setting("global", patch_search_mode)
    min_distance: int | None = setting(None, optional(at_least(0)))
    flatten: bool | None = setting(None, optional(boolean))
    preview: tuple[int, int] = setting((8, 8), as_size)
    no_equal_neighbours: bool = setting(True, boolean)
    layout_seed: int | None = setting(None, optional(at_least(0)))
    exclude_color: tuple | None = setting(None, optional(colour_range))
    wang: int | None = setting(None, optional(at_least(1)))
    wang_variants: int = setting(1, at_least(1))
    wang_interior: str = setting("patch", wang_interior)
    wang_interior_blend: str = setting("auto", wang_interior_blend)
    wang_band: int | None = setting(None, optional(at_least(1)))
    wang_outward: float = setting(1.0, number)
    wang_tolerance: float = setting(0.1, number)
    wang_min_distance: float | None = setting(None, optional(number))

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = f.metadata["check"](getattr(self, f.name), f.name)
            object.__setattr__(self, f.name, value)
        lo, hi = self.tile_min, self.tile_max
        if lo is not None and hi is not None and (lo[0] > hi[0] or lo[1] > hi[1]):
            raise ValueError(f"tile_min {lo} must not exceed tile_max {hi} (as (h, w))")

    # ------------------------------------------------------------------ derived values
    @property
    def template_seam(self) -> SeamSpec:
        """The template's cut: :attr:`seam` with :attr:`template_blend`."""
        if self.template_blend is None or self.template_blend == self.seam.blend:
            return self.seam
        return self.seam.replace(blend=self.template_blend)

    def replace(self, **changes) -> TilesetSettings:
        """A copy with ``changes`` (validated again)."""
        return dataclasses.replace(self, **changes)

    def tile_range(self, shape) -> tuple[tuple[int, int], tuple[int, int]]:
        """(tile_min, tile_max) as (h, w) for a source of ``shape`` (H, W): ``tile_size``
        twice when it is set, else the range (by default a quarter and half of the shorter
        side, at least 8 px)."""
        if self.tile_size is not None:
            return self.tile_size, self.tile_size
        short = min(int(shape[0]), int(shape[1]))
        lo = self.tile_min or as_size(max(8, short // 4), "tile_min")
        if self.tile_max is not None:
            hi = self.tile_max
        else:
            hi = self.tile_min or as_size(max(8, short // 2), "tile_max")
        return lo, hi

    # ------------------------------------------------------------------ plain data
    def to_dict(self) -> dict:
        """Every field as JSON values (pairs as lists, the seam as its own dict)."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, SeamSpec):
                value = value.to_dict()
            elif isinstance(value, tuple):
                value = [list(v) if isinstance(v, tuple) else v for v in value]
            out[f.name] = value
        return out

    @classmethod
    def from_dict(cls, data: Mapping, *, unknown: str = "raise") -> TilesetSettings:
        """The settings :meth:`to_dict` wrote; missing keys take their defaults. Unknown keys
        raise ValueError, or are dropped with ``unknown="ignore"`` (a file from a newer
        version)."""
        if not isinstance(data, Mapping):
            raise TypeError(f"tile-set settings must be a mapping, got {type(data).__name__}")
        names = {f.name for f in dataclasses.fields(cls)}
        extra = sorted(set(data) - names)
        if extra and unknown == "raise":
            raise ValueError(f"unknown tile-set setting(s): {', '.join(map(str, extra))}")
        values = {k: _from_json(v) for k, v in data.items() if k in names}
        return cls(**values)


def _from_json(value):
    """JSON lists back to the tuples the checks expect (sizes, pairs, colour ranges)."""
    if isinstance(value, list):
        return tuple(_from_json(v) for v in value)
    return value


# --------------------------------------------------------------------------- project files
def settings_from_parameters(parameters: Mapping, seeds: Mapping | None = None):
    """The :class:`TilesetSettings` of a project's ``parameters`` (and ``seeds``).

    Reads ``parameters["tileset"]`` (this version), or the flat keys older versions wrote:
    the ``tileset`` command's (``seam``, ``seam_options``, ``candidate_blend``...) or the
    editor's (``method``, ``n_candidates``, ``o_max``...). Values that do not pass their check
    are dropped (the default is used), so an old or hand-edited file still opens.
    """
    if isinstance(parameters.get("tileset"), Mapping):
        try:
            return TilesetSettings.from_dict(parameters["tileset"], unknown="ignore")
        except (TypeError, ValueError):
            pass  # fall back to what can be read field by field
        return _lenient(dict(parameters["tileset"]))
    from engine.settings_v1 import legacy_settings_values

    return _lenient(legacy_settings_values(parameters, seeds or {}))


def _lenient(values: dict) -> TilesetSettings:
    """Settings from ``values``, keeping each field only if it passes its check."""
    names = {f.name for f in dataclasses.fields(TilesetSettings)}
    good = {}
    for k, v in values.items():
        if k not in names:
            continue
        try:
            TilesetSettings(**{k: _from_json(v)})
        except (TypeError, ValueError):
            continue
        good[k] = _from_json(v)
    try:
        return TilesetSettings(**good)
    except ValueError:  # e.g. tile_min > tile_max: drop the range
        good.pop("tile_min", None)
        good.pop("tile_max", None)
        return TilesetSettings(**good)
