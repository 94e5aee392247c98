"""Project files (``.quiltproj``): one zip holding ``project.json`` and PNG images.

The project is plain data (:class:`Project`, :class:`Candidate`), no Qt; the
editor maps its document to it and the CLI writes and reads the same file.
Images are stored as PNG at the project's ``bit_depth`` (8 or 16, exact: a
16-bit source stays 16-bit) and come back as float32 (H, W, C) in [0, 1].

:func:`save_project` is atomic (temporary file in the same folder, then
``os.replace``). :func:`load_project` trusts nothing: entry names escaping the
archive (``../``, absolute, drive letters, backslashes), a truncated or corrupt
zip, JSON with wrong types or missing keys, and oversized entries (declared
sizes are checked and every read is capped, so zip bombs are refused) all raise
one :class:`ProjectError` naming the file and the problem.

Conventions: rectangles are ``(x, y, w, h)`` in source pixels; points are
``(row, col)``; ``picks`` are candidate indices in export order (exported tile
id ``k`` is ``candidates[picks[k]]``); ``layout`` cells are exported tile ids,
-1 = empty.
"""

from __future__ import annotations

import json
import math
import numbers
import os
import re
import zipfile
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from engine._fs import atomic_path
from engine._validate import as_image
from engine.export import export_bundle, quantize
from engine.export._png import PNGError, decode_png, encode_png
from engine.materials import MAP_KINDS, NORMAL_CONVENTIONS, resolve_kinds

__all__ = [
    "Candidate",
    "Project",
    "ProjectError",
    "export_project",
    "load_project",
    "newer_recovery",
    "project_from_tileset",
    "recovery_path",
    "save_project",
    "PROJECT_VERSION",
    "PROJECT_SUFFIX",
]

PROJECT_FORMAT = "quilt-studio-project"
PROJECT_VERSION = 1
PROJECT_SUFFIX = ".quiltproj"
MAX_ENTRIES = 20_000
MAX_JSON_BYTES = 32 * 2**20
MAX_ENTRY_BYTES = 1 * 2**30  # one uncompressed image file
MAX_TOTAL_BYTES = 8 * 2**30  # the whole uncompressed archive
MAX_FILE_BYTES = 8 * 2**30
MAX_PIXELS = 100_000_000
_SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


class ProjectError(ValueError):
    """A project file cannot be read or written; the message names the file and the problem."""


@dataclass
class Candidate:
    """One candidate tile: its images (one per map) and how it was made."""

    maps: dict[str, np.ndarray]
    patch_origin: tuple[int, int] | None = (
        None  # (row, col) of the patch source in the source image
    )
    seed: int | None = None
    locked: bool = False
    score: float | None = None
    params: dict = field(default_factory=dict)  # any JSON (patch size, seam method, waypoints ...)


@dataclass
class Project:
    """Everything needed to reopen a tile-set session exactly."""

    sources: dict[str, np.ndarray]  # map name -> float32 (H, W, C); the first is the main map
    name: str = "tileset"
    version: int = PROJECT_VERSION
    source_paths: dict[str, str] = field(
        default_factory=dict
    )  # where the maps were loaded from (info)
    map_kinds: dict[str, str] = field(default_factory=dict)
    map_weights: dict[str, float] = field(
        default_factory=dict
    )  # seam-error weights; empty = main only
    normal_convention: str = "opengl"
    bit_depth: int = 8
    parameters: dict = field(default_factory=dict)  # any JSON: every parameter of every step
    seeds: dict = field(default_factory=dict)  # any JSON: named seeds
    template_rect: tuple[int, int, int, int] | None = None  # (x, y, w, h)
    template: dict[str, np.ndarray] | None = None  # the seamless template tile per map
    candidates: list[Candidate] = field(default_factory=list)
    picks: list[int] = field(default_factory=list)
    layout: np.ndarray | None = None  # (rows, cols) exported tile ids, -1 = empty
    waypoints: dict[str, list[tuple[int, int]]] = field(default_factory=dict)  # per seam key
    preview: dict[str, np.ndarray] | None = None
    extra: dict = field(default_factory=dict)  # any JSON the editor wants to keep

    @property
    def main_map(self) -> str:
        return next(iter(self.sources))

    def exported_tiles(self) -> list[dict[str, np.ndarray]]:
        """The tiles an export writes: the picked candidates (all candidates if none picked)."""
        order = self.picks if self.picks else range(len(self.candidates))
        return [self.candidates[i].maps for i in order]


# ---------------------------------------------------------------- building


def project_from_tileset(
    *,
    sources,
    tiles: Sequence,
    name: str = "tileset",
    template=None,
    template_rect=None,
    patch_origins=None,
    seeds=None,
    scores=None,
    locked=None,
    picks=None,
    layout=None,
    parameters=None,
    project_seeds=None,
    bit_depth: int = 8,
    source_paths=None,
    map_kinds=None,
    map_weights=None,
    normal_convention: str = "opengl",
    waypoints=None,
    preview=None,
    extra=None,
) -> Project:
    """Build a validated :class:`Project` from plain arrays (for the ``tileset`` CLI and tests).

    ``sources`` is an image or {map: image}; ``tiles`` a list of images or of
    {map: image} (same maps as ``sources``); ``template`` likewise.
    ``patch_origins``, ``seeds``, ``scores``, ``locked`` are per-tile lists (or None).
    """

    def as_maps(v, what):
        if isinstance(v, Mapping):
            return {str(k): _as_float(a, f"{what}[{k!r}]") for k, a in v.items()}
        return {"albedo": _as_float(v, what)}

    srcs = as_maps(sources, "sources")
    tiles = list(tiles)
    n = len(tiles)

    def per_tile(v, what):
        if v is None:
            return [None] * n
        v = list(v)
        if len(v) != n:
            raise ValueError(f"{what} must have one entry per tile ({n}), got {len(v)}")
        return v

    po, sd, sc, lk = (
        per_tile(patch_origins, "patch_origins"),
        per_tile(seeds, "seeds"),
        per_tile(scores, "scores"),
        per_tile(locked, "locked"),
    )
    cands = []
    for i, t in enumerate(tiles):
        maps = as_maps(t, f"tiles[{i}]")
        if not isinstance(t, Mapping) and len(srcs) == 1:
            maps = {next(iter(srcs)): maps["albedo"]}
        cands.append(
            Candidate(
                maps=maps,
                patch_origin=None if po[i] is None else (int(po[i][0]), int(po[i][1])),
                seed=None if sd[i] is None else int(sd[i]),
                locked=bool(lk[i]) if lk[i] is not None else False,
                score=None if sc[i] is None else float(sc[i]),
            )
        )
    tmpl = None
    if template is not None:
        tmpl = as_maps(template, "template")
        if not isinstance(template, Mapping) and len(srcs) == 1:
            tmpl = {next(iter(srcs)): tmpl["albedo"]}
    prev = None
    if preview is not None:
        prev = as_maps(preview, "preview")
        if not isinstance(preview, Mapping) and len(srcs) == 1:
            prev = {next(iter(srcs)): prev["albedo"]}
    p = Project(
        sources=srcs,
        name=name,
        source_paths=dict(source_paths or {}),
        map_kinds=resolve_kinds(srcs, map_kinds),
        map_weights=dict(map_weights or {}),
        normal_convention=normal_convention,
        bit_depth=bit_depth,
        parameters=dict(parameters or {}),
        seeds=dict(project_seeds or {}),
        template_rect=None if template_rect is None else tuple(int(v) for v in template_rect),
        template=tmpl,
        candidates=cands,
        picks=[int(i) for i in (picks or [])],
        layout=None if layout is None else np.asarray(layout, dtype=np.int64),
        waypoints={
            str(k): [(int(r), int(c)) for r, c in v] for k, v in dict(waypoints or {}).items()
        },
        preview=prev,
        extra=dict(extra or {}),
    )
    _check_project(p, "project")
    return p


def export_project(project: Project, out_dir, **options) -> dict:
    """Export the picked tiles with :func:`engine.export.export_bundle`; returns the manifest.

    ``options`` are passed on (columns, spacing, margin, extrude, bit_depth,
    dither, overwrite ...); bit depth defaults to the project's.
    """
    _check_project(project, "project")
    order = list(project.picks) if project.picks else list(range(len(project.candidates)))
    if not order:
        raise ValueError("the project has no candidate tiles to export")
    cands = [project.candidates[i] for i in order]
    origins = [None if c.patch_origin is None else list(c.patch_origin) for c in cands]
    extra = {
        "parameters": project.parameters,
        "seeds": {"project": project.seeds, "tiles": [c.seed for c in cands]},
        "scores": [c.score for c in cands],
        "source_rects": [
            {
                "template": list(project.template_rect) if project.template_rect else None,
                "patch_origin": o,
                "candidate": i,
            }
            for o, i in zip(origins, order, strict=True)
        ],
        "map_kinds": project.map_kinds,
        "map_weights": project.map_weights,
        "source_paths": project.source_paths,
    }
    options.setdefault("source_bit_depth", project.bit_depth)
    if options.get("bit_depth") is None:
        options["bit_depth"] = project.bit_depth
    if options.get("normal_convention") is None:
        options["normal_convention"] = project.normal_convention
    wts = [c.params.get("weight") for c in cands]
    if "weights" not in options and all(isinstance(w, (int, float)) for w in wts):
        options["weights"] = wts  # candidate params {"weight": w} -> Tiled tile probability
    return export_bundle(
        out_dir,
        name=project.name,
        tiles=[c.maps for c in cands],
        index_matrix=project.layout,
        preview=project.preview,
        manifest_extra=extra,
        **options,
    )


def _as_float(a, what: str) -> np.ndarray:
    """Like ``as_image`` but uint8/uint16 are divided exactly as ``engine.io.load_image`` does,
    so a project built from integer arrays holds the same floats as one built from loaded files."""
    arr = np.asarray(a)
    if arr.dtype in (np.uint8, np.uint16):
        arr = arr[:, :, None] if arr.ndim == 2 else arr
        if arr.ndim != 3:
            raise ValueError(f"{what} must be shaped (H, W) or (H, W, C), got {np.shape(a)}")
        return arr.astype(np.float32) / (255.0 if arr.dtype == np.uint8 else 65535.0)
    return as_image(a, what)


# ---------------------------------------------------------------- consistency


def _finite_number(v) -> bool:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return False
    try:
        return math.isfinite(v)
    except OverflowError:  # an int beyond the float range
        return False


def _check_project(p: Project, where: str) -> None:
    """Cross-field checks shared by building, saving and loading; raises ValueError."""
    if not isinstance(p, Project):
        raise TypeError(f"{where} must be a Project, got {type(p).__name__}")
    if not isinstance(p.name, str) or not _SAFE_NAME.match(p.name) or len(p.name) > 100:
        raise ValueError(
            f"{where}: name must be a simple file-name part (letters, digits, . _ -), got "
            f"{p.name!r}"
        )
    if p.version != PROJECT_VERSION:
        raise ValueError(
            f"{where}: version {p.version!r} is not supported (this build reads version "
            f"{PROJECT_VERSION})"
        )
    if not isinstance(p.sources, dict) or not p.sources:
        raise ValueError(f"{where}: sources must be a non-empty dict of map name -> image")
    for m in p.sources:
        if not isinstance(m, str) or not _SAFE_NAME.match(m) or len(m) > 64:
            raise ValueError(f"{where}: bad map name {m!r} (letters, digits, . _ - only)")
    shapes = {m: np.shape(a) for m, a in p.sources.items()}
    hw = shapes[p.main_map][:2]
    for m, s in shapes.items():
        if len(s) != 3 or s[:2] != hw:
            raise ValueError(
                f"{where}: source map {m!r} is shaped {s}; all maps must be (H, W, C) of the main "
                f"map's size {hw}"
            )
    if p.normal_convention not in NORMAL_CONVENTIONS:
        raise ValueError(
            f"{where}: normal_convention must be one of {NORMAL_CONVENTIONS}, got "
            f"{p.normal_convention!r}"
        )
    if p.bit_depth not in (8, 16) or isinstance(p.bit_depth, bool):
        raise ValueError(f"{where}: bit_depth must be 8 or 16, got {p.bit_depth!r}")
    for m, k in p.map_kinds.items():
        if m not in p.sources or k not in MAP_KINDS:
            raise ValueError(f"{where}: map_kinds has a bad entry {m!r}: {k!r}")
    for m, w in p.map_weights.items():
        if m not in p.sources or not _finite_number(w) or w < 0:
            raise ValueError(f"{where}: map_weights has a bad entry {m!r}: {w!r:.40}")
    if p.template_rect is not None:
        r = p.template_rect
        if (
            len(r) != 4
            or any(isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in r)
            or r[2] < 1
            or r[3] < 1
            or r[0] < 0
            or r[1] < 0
        ):
            raise ValueError(
                f"{where}: template_rect must be 4 integers (x, y, w, h) with w, h >= 1, got {r!r}"
            )
    tile_shape = None

    def check_tile(maps, what):
        nonlocal tile_shape
        if not isinstance(maps, dict) or list(maps) != list(p.sources):
            raise ValueError(
                f"{where}: {what} must have the maps {list(p.sources)}, got "
                f"{list(maps) if isinstance(maps, dict) else type(maps).__name__}"
            )
        for m, a in maps.items():
            s = np.shape(a)
            if len(s) != 3 or s[2] != shapes[m][2]:
                raise ValueError(
                    f"{where}: {what}[{m!r}] is shaped {s}, expected (h, w, {shapes[m][2]})"
                )
            if tile_shape is None:
                tile_shape = s[:2]
            if s[:2] != tile_shape:
                raise ValueError(
                    f"{where}: {what}[{m!r}] is {s[1]}x{s[0]}, other tiles are "
                    f"{tile_shape[1]}x{tile_shape[0]}"
                )

    if p.template is not None:
        check_tile(p.template, "template")
    for i, c in enumerate(p.candidates):
        if not isinstance(c, Candidate):
            raise TypeError(f"{where}: candidates[{i}] must be a Candidate")
        check_tile(c.maps, f"candidates[{i}]")
        if c.patch_origin is not None and (
            len(c.patch_origin) != 2
            or any(
                isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in c.patch_origin
            )
        ):
            raise ValueError(
                f"{where}: candidates[{i}].patch_origin must be (row, col) integers or None"
            )
        if c.seed is not None and (
            isinstance(c.seed, bool)
            or not isinstance(c.seed, numbers.Integral)
            or not 0 <= c.seed < 2**64
        ):
            raise ValueError(
                f"{where}: candidates[{i}].seed must be an integer in [0, 2**64) or None"
            )
        if c.score is not None and not _finite_number(c.score):
            raise ValueError(f"{where}: candidates[{i}].score must be a finite number or None")
        if not isinstance(c.locked, bool) or not isinstance(c.params, dict):
            raise ValueError(f"{where}: candidates[{i}].locked must be a bool and params a dict")
    n = len(p.candidates)
    for k in p.picks:
        if isinstance(k, bool) or not isinstance(k, numbers.Integral) or not 0 <= k < n:
            raise ValueError(f"{where}: picks must be candidate indices in [0, {n - 1}], got {k!r}")
    if len(set(p.picks)) != len(p.picks):
        raise ValueError(f"{where}: picks must not repeat a candidate")
    if p.layout is not None:
        lay = np.asarray(p.layout)
        count = len(p.picks) if p.picks else n
        if lay.ndim != 2 or lay.size == 0 or not np.issubdtype(lay.dtype, np.integer):
            raise ValueError(
                f"{where}: layout must be a non-empty 2-D integer matrix, got shape {lay.shape} "
                f"{lay.dtype}"
            )
        if lay.min() < -1 or lay.max() >= count:
            raise ValueError(
                f"{where}: layout cells must be exported tile ids in [0, {count - 1}] or -1"
            )
    if not isinstance(p.waypoints, dict):
        raise ValueError(f"{where}: waypoints must be a dict of seam key -> [(row, col), ...]")
    for key, pts in p.waypoints.items():
        for pt in pts:
            if len(pt) != 2 or any(
                isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in pt
            ):
                raise ValueError(
                    f"{where}: waypoints[{key!r}] must be (row, col) integer pairs, got {pt!r}"
                )
    if p.preview is not None:
        if not isinstance(p.preview, dict) or set(p.preview) - set(p.sources):
            raise ValueError(f"{where}: preview keys must be map names")
        for m, a in p.preview.items():
            if len(np.shape(a)) != 3 or np.shape(a)[2] != shapes[m][2]:
                raise ValueError(f"{where}: preview[{m!r}] is shaped {np.shape(a)}")
    for key in ("parameters", "seeds", "extra"):
        if not isinstance(getattr(p, key), dict):
            raise ValueError(f"{where}: {key} must be a dict")


# ---------------------------------------------------------------- saving


def _to_json(o):
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.floating):
        return float(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (tuple, set, frozenset)):
        return list(o)
    raise TypeError(f"{type(o).__name__} is not JSON-serialisable")


def save_project(path, project: Project) -> Path:
    """Write ``project`` to ``path`` (a ``.quiltproj`` zip) atomically; returns the path."""
    p = Path(os.fspath(path))
    try:
        _check_project(project, f"{p}")
    except (TypeError, ValueError) as exc:
        raise ProjectError(f"{exc}") from None
    images: dict[str, bytes] = {}

    def put(arr, entry: str) -> str:
        q = quantize(arr, project.bit_depth, dither=False)
        images[entry] = encode_png(q)
        return entry

    doc = {
        "format": PROJECT_FORMAT,
        "version": PROJECT_VERSION,
        "name": project.name,
        "bit_depth": project.bit_depth,
        "normal_convention": project.normal_convention,
        "maps": list(project.sources),
        "sources": {m: put(a, f"images/source_{m}.png") for m, a in project.sources.items()},
        "source_paths": {str(k): str(v) for k, v in project.source_paths.items()},
        "map_kinds": dict(project.map_kinds),
        "map_weights": {k: float(v) for k, v in project.map_weights.items()},
        "parameters": project.parameters,
        "seeds": project.seeds,
        "template_rect": None
        if project.template_rect is None
        else [int(v) for v in project.template_rect],
        "template": None
        if project.template is None
        else {m: put(a, f"images/template_{m}.png") for m, a in project.template.items()},
        "candidates": [
            {
                "images": {
                    m: put(a, f"images/candidate_{i:04}_{m}.png") for m, a in c.maps.items()
                },
                "patch_origin": None
                if c.patch_origin is None
                else [int(v) for v in c.patch_origin],
                "seed": None if c.seed is None else int(c.seed),
                "locked": bool(c.locked),
                "score": None if c.score is None else float(c.score),
                "params": c.params,
            }
            for i, c in enumerate(project.candidates)
        ],
        "picks": [int(k) for k in project.picks],
        "layout": None
        if project.layout is None
        else np.asarray(project.layout).astype(int).tolist(),
        "waypoints": {
            str(k): [[int(r), int(c)] for r, c in v] for k, v in project.waypoints.items()
        },
        "preview": None
        if project.preview is None
        else {m: put(a, f"images/preview_{m}.png") for m, a in project.preview.items()},
        "extra": project.extra,
    }
    try:
        text = json.dumps(doc, indent=1, allow_nan=False, default=_to_json)
    except (TypeError, ValueError) as exc:
        raise ProjectError(
            f"{p}: parameters, seeds, params or extra are not JSON-serialisable ({exc})"
        ) from None
    try:
        with atomic_path(p) as tmp, open(tmp, "wb") as f:
            with zipfile.ZipFile(f, "w", compression=zipfile.ZIP_DEFLATED) as zf:
                zf.writestr(_zinfo("project.json"), text.encode("utf-8"))
                for entry, data in images.items():
                    zf.writestr(_zinfo(entry, stored=True), data)  # PNG is already compressed
            f.flush()
            os.fsync(f.fileno())
    except OSError as exc:
        raise ProjectError(
            f"{p}: cannot save the project ({exc.strerror or exc}); the previous file, "
            "if any, is unchanged"
        ) from exc
    return p


def _zinfo(name: str, *, stored: bool = False) -> zipfile.ZipInfo:
    zi = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))  # fixed: same project -> same bytes
    zi.compress_type = zipfile.ZIP_STORED if stored else zipfile.ZIP_DEFLATED
    zi.external_attr = 0o644 << 16
    return zi


def recovery_path(path) -> Path:
    """Where the editor autosaves a project saved at ``path`` (a hidden sibling file)."""
    p = Path(os.fspath(path))
    return p.with_name(f".{p.stem}.recovery{PROJECT_SUFFIX}")


def newer_recovery(path) -> Path | None:
    """The recovery file of ``path`` if it exists and is newer than ``path`` (offer it after a "
    "crash)."""
    p = Path(os.fspath(path))
    r = recovery_path(p)
    if not r.is_file():
        return None
    if p.is_file() and p.stat().st_mtime_ns >= r.stat().st_mtime_ns:
        return None
    return r


# ---------------------------------------------------------------- loading


def _safe_entry(name: str) -> bool:
    if (
        not name
        or "\\" in name
        or "\x00" in name
        or name.startswith("/")
        or re.match(r"^[A-Za-z]:", name)
    ):
        return False
    return all(part not in ("..", ".", "") for part in name.split("/"))


def load_project(
    path,
    *,
    max_pixels: int = MAX_PIXELS,
    max_entry_bytes: int = MAX_ENTRY_BYTES,
    max_total_bytes: int = MAX_TOTAL_BYTES,
) -> Project:
    """Read and strictly validate a ``.quiltproj`` file; any problem raises "
    ":class:`ProjectError`."""
    p = Path(os.fspath(path))

    def fail(msg: str):
        raise ProjectError(f"{p}: {msg}")

    if not p.exists():
        fail("no such file")
    if p.is_dir():
        fail("is a folder, not a project file")
    size = p.stat().st_size
    if size == 0:
        fail("the file is empty")
    if size > MAX_FILE_BYTES:
        fail(f"the file is {size:,} bytes, over the limit of {MAX_FILE_BYTES:,}")
    try:
        zf = zipfile.ZipFile(p)
    except zipfile.BadZipFile:
        fail("not a Quilt Studio project (not a zip archive, or the zip is truncated or corrupt)")
    except OSError as exc:
        fail(f"cannot be read ({exc.strerror or exc})")
    with zf:
        infos = zf.infolist()
        if len(infos) > MAX_ENTRIES:
            fail(f"the archive has {len(infos):,} entries, over the limit of {MAX_ENTRIES:,}")
        seen = set()
        total = 0
        for info in infos:
            if not _safe_entry(info.filename[:-1] if info.is_dir() else info.filename):
                fail(
                    f"entry {info.filename!r} has an unsafe path (absolute, '..' or backslash); "
                    "refused"
                )
            if info.filename in seen:
                fail(f"entry {info.filename!r} appears twice")
            seen.add(info.filename)
            if info.flag_bits & 0x1:
                fail(f"entry {info.filename!r} is encrypted")
            if info.file_size > max_entry_bytes:
                fail(
                    f"entry {info.filename!r} declares {info.file_size:,} bytes, over the limit "
                    f"of {max_entry_bytes:,}"
                )
            total += info.file_size
        if total > max_total_bytes:
            fail(
                f"the archive declares {total:,} uncompressed bytes, over the limit of "
                f"{max_total_bytes:,}"
            )

        def read(entry: str, cap: int) -> bytes:
            if entry not in seen:
                fail(f"entry {entry!r} is referenced by project.json but missing from the archive")
            info = zf.getinfo(entry)
            try:
                with zf.open(info) as f:
                    data = f.read(min(cap, info.file_size) + 1)
            except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError) as exc:
                fail(f"entry {entry!r} is truncated or corrupt ({exc})")
            if len(data) > min(cap, info.file_size):
                fail(
                    f"entry {entry!r} inflates beyond its declared size (possible zip bomb); "
                    "refused"
                )
            return data

        if "project.json" not in seen:
            fail("missing project.json (not a Quilt Studio project)")
        raw = read("project.json", MAX_JSON_BYTES)
        try:
            doc = json.loads(raw.decode("utf-8"), parse_constant=_no_constant)
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            fail(f"project.json is not valid JSON ({exc})")
        except _NotJSON as exc:
            fail(f"project.json is not valid JSON ({exc} is not a JSON number)")
        except RecursionError:
            fail("project.json is nested too deeply; refused")
        project = _from_doc(
            doc, fail, lambda entry: _read_image(entry, read, fail, max_pixels, max_entry_bytes)
        )
    try:
        _check_project(project, "project.json")
    except (TypeError, ValueError) as exc:
        fail(str(exc))
    return project


class _NotJSON(ValueError):
    pass


def _no_constant(name: str):
    """NaN / Infinity / -Infinity: Python's extension, not JSON (and nothing we write)."""
    raise _NotJSON(name)


def _read_image(entry, read, fail, max_pixels, cap) -> np.ndarray:
    if not isinstance(entry, str) or not _safe_entry(entry):
        fail(f"project.json: image reference {entry!r} is not a safe archive path; refused")
    data = read(entry, cap)
    try:
        q = decode_png(data, max_pixels=max_pixels)
    except PNGError as exc:
        fail(f"entry {entry!r}: {exc}")
    return _as_float(q, entry)


class _Spec:
    """Tiny typed accessor over the parsed JSON that reports the key path on errors."""

    def __init__(self, fail):
        self.fail = fail

    def get(self, d, key, types, where, *, optional=False, default=None):
        if not isinstance(d, dict):
            self.fail(f"project.json: {where} must be an object")
        if key not in d:
            if optional:
                return default
            self.fail(
                f"project.json: missing key {where}.{key}"
                if where
                else f"project.json: missing key {key!r}"
            )
        v = d[key]
        if v is None and optional:
            return default
        if isinstance(v, bool) and bool not in (types if isinstance(types, tuple) else (types,)):
            self.fail(
                f"project.json: {where + '.' if where else ''}{key} has the wrong type (bool)"
            )
        if not isinstance(v, types):
            names = "/".join(t.__name__ for t in (types if isinstance(types, tuple) else (types,)))
            self.fail(
                f"project.json: {where + '.' if where else ''}{key} must be {names}, got "
                f"{type(v).__name__}"
            )
        return v


def _int_list(s: _Spec, v, n, what):
    if (
        not isinstance(v, list)
        or (n is not None and len(v) != n)
        or any(isinstance(x, bool) or not isinstance(x, int) for x in v)
    ):
        s.fail(
            f"project.json: {what} must be a list of {n if n else ''} integers".replace("  ", " ")
        )
    return v


def _from_doc(doc, fail, image) -> Project:
    s = _Spec(fail)
    if not isinstance(doc, dict):
        fail("project.json: the document must be a JSON object")
    fmt = s.get(doc, "format", str, "")
    if fmt != PROJECT_FORMAT:
        fail(f"project.json: format is {fmt!r}, expected {PROJECT_FORMAT!r}")
    version = s.get(doc, "version", int, "")
    if version > PROJECT_VERSION:
        fail(
            f"project.json: version {version} was written by a newer Quilt Studio (this one reads "
            f"{PROJECT_VERSION})"
        )
    if version < 1:
        fail(f"project.json: bad version {version}")
    maps = s.get(doc, "maps", list, "")
    if (
        not maps
        or not all(isinstance(m, str) and _SAFE_NAME.match(m) for m in maps)
        or len(set(maps)) != len(maps)
    ):
        fail("project.json: maps must be a non-empty list of distinct simple names")

    def map_images(d, where):
        if not isinstance(d, dict) or list(d) != maps:
            fail(f"project.json: {where} must map exactly the maps {maps} to image entries")
        return {m: image(d[m]) for m in maps}

    sources = map_images(s.get(doc, "sources", dict, ""), "sources")
    tmpl_d = s.get(doc, "template", dict, "", optional=True)
    prev_d = s.get(doc, "preview", dict, "", optional=True)
    preview = None
    if prev_d is not None:
        if set(prev_d) - set(maps):
            fail("project.json: preview keys must be map names")
        preview = {m: image(v) for m, v in prev_d.items()}
    cands = []
    for i, c in enumerate(s.get(doc, "candidates", list, "")):
        where = f"candidates[{i}]"
        imgs = map_images(s.get(c, "images", dict, where), f"{where}.images")
        po = s.get(c, "patch_origin", list, where, optional=True)
        cands.append(
            Candidate(
                maps=imgs,
                patch_origin=None
                if po is None
                else tuple(_int_list(s, po, 2, f"{where}.patch_origin")),
                seed=s.get(c, "seed", int, where, optional=True),
                locked=s.get(c, "locked", bool, where),
                score=s.get(c, "score", (int, float), where, optional=True),
                params=s.get(c, "params", dict, where, optional=True, default={}),
            )
        )
    rect = s.get(doc, "template_rect", list, "", optional=True)
    layout = s.get(doc, "layout", list, "", optional=True)
    if layout is not None:
        if not layout or not all(isinstance(r, list) and len(r) == len(layout[0]) for r in layout):
            fail("project.json: layout must be a non-empty rectangular list of lists")
        for r in layout:
            _int_list(s, r, None, "layout rows")
        layout = np.asarray(layout, dtype=np.int64)
    wps = s.get(doc, "waypoints", dict, "", optional=True, default={})
    waypoints = {}
    for k, v in wps.items():
        if not isinstance(v, list):
            fail(f"project.json: waypoints[{k!r}] must be a list of [row, col]")
        waypoints[k] = [tuple(_int_list(s, pt, 2, f"waypoints[{k!r}] entries")) for pt in v]
    kinds = s.get(doc, "map_kinds", dict, "", optional=True, default={})
    weights = s.get(doc, "map_weights", dict, "", optional=True, default={})
    paths = s.get(doc, "source_paths", dict, "", optional=True, default={})
    if not all(isinstance(v, str) for v in paths.values()):
        fail("project.json: source_paths values must be strings")
    return Project(
        sources=sources,
        name=s.get(doc, "name", str, ""),
        version=PROJECT_VERSION,
        source_paths=paths,
        map_kinds=kinds,
        map_weights=weights,
        normal_convention=s.get(doc, "normal_convention", str, ""),
        bit_depth=s.get(doc, "bit_depth", int, ""),
        parameters=s.get(doc, "parameters", dict, ""),
        seeds=s.get(doc, "seeds", dict, ""),
        template_rect=None if rect is None else tuple(_int_list(s, rect, 4, "template_rect")),
        template=None if tmpl_d is None else map_images(tmpl_d, "template"),
        candidates=cands,
        picks=_int_list(s, s.get(doc, "picks", list, ""), None, "picks"),
        layout=layout,
        waypoints=waypoints,
        preview=preview,
        extra=s.get(doc, "extra", dict, "", optional=True, default={}),
    )
