"""How a cut is made: seam method and its options, error metric and blending, in one value.

:class:`SeamSpec` is frozen and validates once, when it is made; every engine entry point that
cuts (:func:`engine.stitch.stitch`, :func:`engine.stitch.patch_cut`, the tile workflow,
quilting), the command line and the editor pass it down unchanged, so an option has one name
and one check on every floor. It serialises itself to a plain dict (:meth:`SeamSpec.to_dict`,
:meth:`SeamSpec.from_dict`) for project files, manifests and settings. It is a value only:
``find_seam(error, seam=spec)`` searches with it, ``blend_weights(seam, error, spec=spec)``
blends with it (this module imports neither, so every arrow points here).

This module imports no numpy: the command line's parsers read its tables (:data:`METHODS`,
:data:`OPTIONS`, :data:`METRICS`, :data:`BLEND_MODES`) without loading the engine.

Examples
--------
>>> spec = SeamSpec("oscillating", {"o_max": 5}, blend="adaptive")
>>> spec.options["o_max"], spec.options["init"]
(5, 'dp')
>>> SeamSpec.from_dict(spec.to_dict()) == spec
True
>>> SeamSpec("dp", {"o_max": 5})
Traceback (most recent call last):
...
TypeError: unexpected option(s) for method 'dp': o_max (allowed: none)
"""

from __future__ import annotations

import dataclasses
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from engine._checks import choice, non_negative_number, positive_int

#: seam search methods (:func:`engine.seams.find_seam`)
METHODS = ("dp", "dijkstra", "minimax", "oscillating", "oscillating-optimal", "resistance")
#: methods with a cyclic mode (rows 0 and h - 1 neighbours)
CYCLIC_METHODS = ("dp", "oscillating", "oscillating-optimal")
#: no search: the new region covers the whole overlap (quilting only)
STRAIGHT = "straight"
#: error metrics (:func:`engine.errormap.error_map`)
METRICS = ("euclid", "ssd", "lab")
#: blending after the cut (:func:`engine.blend.blend_weights`)
BLEND_MODES = ("none", "feather", "adaptive")
#: gradient-domain blending along a hard cut (:mod:`engine.poisson`): tile sets only
POISSON = "poisson"
#: the blends a tile set's cuts take (:class:`SeamSpec` accepts them all)
TILE_BLEND_MODES = (*BLEND_MODES, POISSON)
#: variants of the minimax method: which path metric the graph search minimises
MINIMAX_VARIANTS = ("exact", "lm", "sorted")
#: variants of the oscillating search (restart after an improvement, or continue)
OSCILLATING_VARIANTS = ("resume", "faithful")
#: variants of Bhatia's minimum resistance cut line: the paper's two lines, or one walk
RESISTANCE_VARIANTS = ("published", "walk")
#: starting paths of the oscillating search (:func:`engine.seams.oscillating.initial_controls`)
INITS = ("argmin", "dp", "smoothed")

#: keyword options of every method with their defaults (``resistance`` also takes a per-call
#: step-cost ``image``, which is an input like the error map, not a setting)
OPTIONS: dict[str, dict[str, object]] = {
    "dp": {},
    "dijkstra": {"connectivity": 8},
    "minimax": {"variant": "exact", "levels": 32, "connectivity": 8},
    "oscillating": {"o_max": 3, "variant": "resume", "init": "dp"},
    "oscillating-optimal": {},
    "resistance": {"variant": "published", "max_run": 5},
}

__all__ = [
    "BLEND_MODES",
    "POISSON",
    "TILE_BLEND_MODES",
    "CYCLIC_METHODS",
    "INITS",
    "METHODS",
    "METRICS",
    "MINIMAX_VARIANTS",
    "OPTIONS",
    "OSCILLATING_VARIANTS",
    "RESISTANCE_VARIANTS",
    "STRAIGHT",
    "SeamSpec",
    "as_seam_spec",
    "check_blend",
    "check_option_names",
]


def check_connectivity(value) -> int:
    """4 or 8 (pixel neighbours of the graph methods); ValueError otherwise."""
    if isinstance(value, bool) or value not in (4, 8):
        raise ValueError(f"connectivity must be 4 or 8, got {value!r}")
    return int(value)


def check_option_names(method: str, options, name: str = "method") -> None:
    """TypeError naming ``options`` that ``method`` (a parameter called ``name``) does not take."""
    allowed = OPTIONS.get(method, {})
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise TypeError(
            f"unexpected option(s) for {name} {method!r}: {', '.join(unknown)}"
            f" (allowed: {', '.join(allowed) or 'none'})"
        )


_VARIANTS = {
    "minimax": MINIMAX_VARIANTS,
    "oscillating": OSCILLATING_VARIANTS,
    "resistance": RESISTANCE_VARIANTS,
}


def _check_option(method: str, key: str, value):
    if key == "connectivity":
        return check_connectivity(value)
    if key in ("levels", "o_max", "max_run"):
        return positive_int(value, key)
    if key == "variant":
        return choice(value, key, _VARIANTS[method])
    return choice(value, key, INITS)  # "init", the only other option


def check_options(method: str, options) -> dict:
    """Every option of ``method``: the defaults updated with ``options``, each checked."""
    check_option_names(method, options)
    merged = {**OPTIONS.get(method, {}), **options}
    return {k: _check_option(method, k, v) for k, v in merged.items()}


@dataclass(frozen=True)
class SeamSpec:
    """A seam method with its options, the error metric its map uses and the blend after it.

    Parameters
    ----------
    method : str
        One of :data:`METHODS`, or :data:`STRAIGHT` (no cut; quilting only).
    options : mapping
        Options of ``method`` (:data:`OPTIONS`); missing ones take their defaults, so
        ``spec.options`` always holds all of them and equal specs compare equal.
    metric : {"euclid", "ssd", "lab"}
        Error metric of the map the seam runs through.
    blend : {"none", "feather", "adaptive", "poisson"}
        Blending after the cut: hard, a ramp of ``width`` pixels, ρ-adaptive (``rho``), or
        in the gradient domain along a hard cut (``"poisson"``, :mod:`engine.poisson`; tile
        sets only: quilting, heal and the seam command refuse it, :func:`check_blend`).
    width : float
        Feather width in pixels (>= 0).
    rho : int
        ρ of adaptive blending (>= 0; 0 = hard).

    Bad values raise TypeError / ValueError naming the field, at construction.
    """

    method: str = "dp"
    options: Mapping[str, object] = field(default_factory=dict)
    metric: str = "euclid"
    blend: str = "none"
    width: float = 4.0
    rho: int = 3

    def __post_init__(self) -> None:
        choice(self.method, "method", (STRAIGHT, *METHODS))
        if not isinstance(self.options, Mapping):
            raise TypeError(f"options must be a mapping, got {type(self.options).__name__}")
        opts = check_options(self.method, dict(self.options))
        choice(self.metric, "metric", METRICS)
        choice(self.blend, "blend", TILE_BLEND_MODES)
        set_ = object.__setattr__
        set_(self, "options", MappingProxyType(opts))
        set_(self, "width", non_negative_number(self.width, "width"))
        set_(self, "rho", positive_int(self.rho, "rho", minimum=0))

    def __hash__(self) -> int:
        items = tuple(sorted(self.options.items()))
        return hash((self.method, items, self.metric, self.blend, self.width, self.rho))

    def __repr__(self) -> str:
        return (
            f"SeamSpec(method={self.method!r}, options={dict(self.options)!r}, "
            f"metric={self.metric!r}, blend={self.blend!r}, width={self.width:g}, rho={self.rho})"
        )

    # ------------------------------------------------------------------ variants
    @property
    def cuts(self) -> bool:
        """False for :data:`STRAIGHT` (no seam search)."""
        return self.method != STRAIGHT

    def replace(self, **changes) -> SeamSpec:
        """A copy with ``changes`` (validated again). A new ``method`` without ``options``
        keeps only the options that method takes."""
        if "method" in changes and "options" not in changes:
            keep = OPTIONS.get(changes["method"], {})
            changes["options"] = {k: v for k, v in self.options.items() if k in keep}
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ plain data
    def to_dict(self) -> dict:
        """``{"method", "options", "metric", "blend", "width", "rho"}`` of JSON values."""
        return {
            "method": self.method,
            "options": dict(self.options),
            "metric": self.metric,
            "blend": self.blend,
            "width": self.width,
            "rho": self.rho,
        }

    @classmethod
    def from_dict(cls, data: Mapping) -> SeamSpec:
        """The spec :meth:`to_dict` wrote; missing keys take their defaults, unknown ones raise
        ValueError."""
        if not isinstance(data, Mapping):
            raise TypeError(f"a seam spec must be a mapping, got {type(data).__name__}")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown seam spec key(s): {', '.join(map(str, unknown))}")
        values = dict(data)
        if "options" in values and values["options"] is None:
            values["options"] = {}
        if isinstance(values.get("width"), numbers.Integral):
            values["width"] = float(values["width"])
        return cls(**values)


def check_blend(spec: SeamSpec, what: str) -> SeamSpec:
    """``spec`` if its blend is one of :data:`BLEND_MODES`; ValueError naming ``what`` (e.g.
    "quilting") for the tile sets' gradient-domain blend."""
    if spec.blend not in BLEND_MODES:
        raise ValueError(
            f"blend {spec.blend!r} (gradient domain) is for tile sets; {what} takes "
            f"{', '.join(BLEND_MODES)}"
        )
    return spec


def as_seam_spec(value, name: str = "seam", *, default: SeamSpec | None = None) -> SeamSpec:
    """``value`` if it is a :class:`SeamSpec` that cuts, ``default`` (or ``SeamSpec()``) for
    None; TypeError for anything else, ValueError for ``straight``."""
    if value is None:
        return default if default is not None else SeamSpec()
    if not isinstance(value, SeamSpec):
        raise TypeError(
            f"{name} must be an engine.seams.SeamSpec (e.g. SeamSpec(method='dp', "
            f"blend='adaptive')), got {type(value).__name__}"
        )
    if not value.cuts:
        raise ValueError(f"{name} method 'straight' makes no cut; choose one of {METHODS}")
    return value
