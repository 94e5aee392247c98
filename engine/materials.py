"""Materials: a main map plus co-registered extra maps that follow every cut.

A *material* is a stack of images of the same height and width: the main map
(albedo / colour, the one shown and cut) and any number of named extra maps
(normal, roughness, height, ao, metallic ...). Seams are searched on a weighted
combination of per-map error maps (default: the main map only) and the same
alpha (weight of R1) is then applied to every map by :func:`apply_cut`.

Normal maps are never averaged as plain colours: where alpha is exactly 0 or 1
the pixel is copied bit for bit; elsewhere the encoded colours are decoded to
vectors (``2 c - 1``), mixed, renormalised to unit length and re-encoded. The
OpenGL / DirectX convention (sign of green) is recorded on the material; the
blend itself is the same in both (flipping y commutes with normalisation).
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from engine._validate import as_image, choice
from engine.errormap import error_map

NORMAL_CONVENTIONS = ("opengl", "directx")
MAP_KINDS = ("color", "normal", "height", "roughness", "ao", "metallic", "mask", "other")

_KIND_BY_NAME = {
    "albedo": "color",
    "basecolor": "color",
    "base_color": "color",
    "diffuse": "color",
    "color": "color",
    "colour": "color",
    "main": "color",
    "normal": "normal",
    "normals": "normal",
    "nrm": "normal",
    "norm": "normal",
    "height": "height",
    "displacement": "height",
    "disp": "height",
    "bump": "height",
    "roughness": "roughness",
    "rough": "roughness",
    "gloss": "roughness",
    "glossiness": "roughness",
    "ao": "ao",
    "occlusion": "ao",
    "ambientocclusion": "ao",
    "ambient_occlusion": "ao",
    "metallic": "metallic",
    "metalness": "metallic",
    "metal": "metallic",
    "mask": "mask",
    "opacity": "mask",
    "alpha": "mask",
}


def infer_kind(name: str) -> str:
    """Guess a map kind from its name (``"normal"``, ``"rock_Normal"`` -> ``"normal"``)."""
    if not isinstance(name, str):
        raise TypeError(f"name must be a string, got {type(name).__name__}")
    key = name.lower().replace("-", "_").rsplit("_", 1)[-1] if name else ""
    full = name.lower().replace("-", "_")
    return _KIND_BY_NAME.get(full, _KIND_BY_NAME.get(key, "other"))


@dataclass(frozen=True)
class Material:
    """Main map + named co-registered maps (all float32 (H, W, C) in [0, 1]).

    ``maps`` is ordered, the main map first; ``kinds`` maps every name to one of
    :data:`MAP_KINDS`; ``normal_convention`` is ``"opengl"`` (green up) or
    ``"directx"`` (green down). Build one with :func:`make_material`.
    """

    maps: dict[str, np.ndarray]
    main: str
    kinds: dict[str, str] = field(default_factory=dict)
    normal_convention: str = "opengl"

    @property
    def shape(self) -> tuple[int, int]:
        return self.maps[self.main].shape[:2]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.maps)

    def crop(self, top: int, left: int, height: int, width: int) -> dict[str, np.ndarray]:
        """The same rectangle of every map (views, not copies)."""
        return {k: v[top : top + height, left : left + width] for k, v in self.maps.items()}


def make_material(
    main,
    *,
    extra: Mapping | None = None,
    main_name: str = "albedo",
    kinds: Mapping | None = None,
    normal_convention: str = "opengl",
) -> Material:
    """Validate and bundle a main map with extra maps of the same size."""
    choice(normal_convention, "normal_convention", NORMAL_CONVENTIONS)
    if not isinstance(main_name, str) or not main_name:
        raise ValueError("main_name must be a non-empty string")
    maps = {main_name: as_image(main, "main")}
    h, w = maps[main_name].shape[:2]
    for name, img in dict(extra or {}).items():
        if not isinstance(name, str) or not name or name in maps:
            raise ValueError(f"extra: bad or duplicate map name {name!r}")
        a = as_image(img, f"extra[{name!r}]")
        if a.shape[:2] != (h, w):
            raise ValueError(
                f"extra[{name!r}] is {a.shape[1]}x{a.shape[0]}, the main map is {w}x{h}; "
                "maps of a material must be co-registered (same size)"
            )
        maps[name] = a
    resolved = resolve_kinds(maps, kinds)
    for name, kind in resolved.items():
        if kind == "normal" and maps[name].shape[2] < 3:
            raise ValueError(f"normal map {name!r} needs 3 channels, got {maps[name].shape[2]}")
    return Material(maps=maps, main=main_name, kinds=resolved, normal_convention=normal_convention)


def resolve_kinds(names, kinds: Mapping | None = None) -> dict[str, str]:
    """Kinds for every map name: given ones (validated) else :func:`infer_kind`."""
    kinds = dict(kinds or {})
    out = {}
    names = list(names)
    for k in kinds:
        if k not in names:
            raise ValueError(f"kinds names an unknown map {k!r}")
    for n in names:
        out[n] = choice(kinds[n], f"kinds[{n!r}]", MAP_KINDS) if n in kinds else infer_kind(n)
    return out


def material_error(
    maps_r1: Mapping,
    maps_r2: Mapping,
    *,
    weights: Mapping | None = None,
    main: str | None = None,
    metric: str = "euclid",
) -> np.ndarray:
    """Weighted sum of per-map error maps (each scaled to mean 1 so weights are comparable).

    ``weights`` maps map names to non-negative floats; default: the main map (or
    the first map) only, unscaled, which is exactly ``error_map(r1[main], r2[main])``.
    """
    if not maps_r1 or set(maps_r1) != set(maps_r2):
        raise ValueError("maps_r1 and maps_r2 must name the same, non-empty set of maps")
    if weights is None:
        key = main if main is not None else next(iter(maps_r1))
        if key not in maps_r1:
            raise ValueError(f"main map {key!r} is not in the maps")
        return _error(maps_r1[key], maps_r2[key], metric)
    total = None
    for name, wgt in dict(weights).items():
        if name not in maps_r1:
            raise ValueError(f"weights names an unknown map {name!r}")
        if (
            isinstance(wgt, bool)
            or not isinstance(wgt, numbers.Real)
            or not np.isfinite(wgt)
            or wgt < 0
        ):
            raise ValueError(f"weights[{name!r}] must be a finite number >= 0, got {wgt!r}")
        if wgt == 0:
            continue
        e = _error(maps_r1[name], maps_r2[name], metric)
        m = float(e.mean())
        e = e / m if m > 0 else e
        total = wgt * e if total is None else total + wgt * e
    if total is None:
        raise ValueError("weights must give at least one map a positive weight")
    return total


def _error(a, b, metric: str) -> np.ndarray:
    a = as_image(a, "r1")
    b = as_image(b, "r2")
    if a.shape != b.shape:
        raise ValueError(f"r1 and r2 must have the same shape, got {a.shape} and {b.shape}")
    return error_map(a, b, metric=metric)


def decode_normals(rgb: np.ndarray) -> np.ndarray:
    """Encoded normal colours in [0, 1] (H, W, >=3) -> float64 vectors (H, W, 3) in [-1, 1]."""
    return np.asarray(rgb, dtype=np.float64)[..., :3] * 2.0 - 1.0


def encode_normals(vectors: np.ndarray) -> np.ndarray:
    """Unit vectors (H, W, 3) -> float32 colours in [0, 1]."""
    return np.clip((np.asarray(vectors) + 1.0) * 0.5, 0.0, 1.0).astype(np.float32)


def convert_normal_convention(normals, *, source: str, target: str) -> np.ndarray:
    """Flip the green channel between OpenGL (Y+) and DirectX (Y-) normal maps."""
    choice(source, "source", NORMAL_CONVENTIONS)
    choice(target, "target", NORMAL_CONVENTIONS)
    n = as_image(normals, "normals")
    if n.shape[2] < 3:
        raise ValueError(f"normals must have 3 channels, got {n.shape[2]}")
    if source != target:
        n[..., 1] = 1.0 - n[..., 1]
    return n


def blend_normals(n1, n2, alpha) -> np.ndarray:
    """Mix two encoded normal maps with weight ``alpha`` of ``n1``; exact copies at 0 and 1.

    Blended pixels are decoded, mixed as vectors, renormalised and re-encoded;
    where the mix cancels out (opposite vectors) the heavier side's vector is kept.
    Extra channels beyond the first three (alpha) are mixed linearly.
    """
    a1 = as_image(n1, "n1")
    a2 = as_image(n2, "n2")
    if a1.shape != a2.shape or a1.shape[2] < 3:
        raise ValueError(
            f"n1 and n2 must be equal-shaped normal maps with >= 3 channels, got {a1.shape}, "
            f"{a2.shape}"
        )
    al = _as_alpha(alpha, a1.shape[:2])
    out = np.where(al[..., None] >= 1.0, a1, a2).astype(np.float32)
    mixed = (al > 0) & (al < 1)
    if mixed.any():
        w = al[mixed].astype(np.float64)[:, None]
        v1 = decode_normals(a1[mixed])
        v2 = decode_normals(a2[mixed])
        v = w * v1 + (1 - w) * v2
        length = np.linalg.norm(v, axis=1, keepdims=True)
        fallback = np.where(w >= 0.5, v1, v2)
        fallback = fallback / np.maximum(np.linalg.norm(fallback, axis=1, keepdims=True), 1e-12)
        v = np.where(length > 1e-6, v / np.maximum(length, 1e-12), fallback)
        block = out[mixed]
        block[:, :3] = encode_normals(v)
        if a1.shape[2] > 3:
            block[:, 3:] = (w * a1[mixed][:, 3:] + (1 - w) * a2[mixed][:, 3:]).astype(np.float32)
        out[mixed] = block
    return out


def _as_alpha(alpha, shape) -> np.ndarray:
    al = np.asarray(alpha, dtype=np.float32)
    if al.ndim == 3 and al.shape[2] == 1:
        al = al[:, :, 0]
    if al.shape != tuple(shape):
        raise ValueError(f"alpha must be shaped {tuple(shape)}, got {al.shape}")
    if not np.all(np.isfinite(al)) or al.min(initial=0) < 0 or al.max(initial=0) > 1:
        raise ValueError("alpha must be finite and in [0, 1]")
    return al


def apply_cut(
    maps_r1: Mapping, maps_r2: Mapping, alpha, *, kinds: Mapping | None = None
) -> dict[str, np.ndarray]:
    """Composite every map of R1 over R2 with the same ``alpha`` (weight of R1, (h, w)).

    ``kinds`` gives each map's kind (default inferred from the names); maps of
    kind ``"normal"`` go through :func:`blend_normals`, every other map is mixed
    linearly. Wherever alpha is exactly 1 (resp. 0) every output map holds the
    R1 (resp. R2) pixel unchanged, so a cut lands on the same pixels in all maps.
    Returns float32 (h, w, C) arrays in the order of ``maps_r1``.
    """
    if not isinstance(maps_r1, Mapping) or not isinstance(maps_r2, Mapping):
        raise TypeError("maps_r1 and maps_r2 must be mappings of map name -> image")
    if not maps_r1 or set(maps_r1) != set(maps_r2):
        raise ValueError(
            f"maps_r1 and maps_r2 must name the same maps, got {sorted(maps_r1)} and "
            f"{sorted(maps_r2)}"
        )
    resolved = resolve_kinds(maps_r1, kinds)
    first = as_image(next(iter(maps_r1.values())), "maps_r1")
    al = _as_alpha(alpha, first.shape[:2])
    out = {}
    for name in maps_r1:
        a = as_image(maps_r1[name], f"maps_r1[{name!r}]")
        b = as_image(maps_r2[name], f"maps_r2[{name!r}]")
        if a.shape != b.shape or a.shape[:2] != al.shape:
            raise ValueError(
                f"map {name!r}: r1 {a.shape}, r2 {b.shape} and alpha {al.shape} must agree"
            )
        if resolved[name] == "normal":
            if a.shape[2] < 3:
                raise ValueError(f"normal map {name!r} needs 3 channels, got {a.shape[2]}")
            out[name] = blend_normals(a, b, al)
        else:
            # hard pixels copied, the soft ones (a patch cut's ring) mixed: the same values
            res = np.where(al[..., None] >= 1, a, b)
            soft = (al > 0) & (al < 1)
            if soft.any():
                s = al[soft][:, None]
                res[soft] = (s * a[soft] + (1 - s) * b[soft]).astype(np.float32)
            out[name] = res
    return out
