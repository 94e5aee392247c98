"""Project files (``.quiltproj``) on disk: one zip holding ``project.json`` and PNG images.

Images are stored as PNG at the project's ``bit_depth`` (8 or 16, exact: a 16-bit source stays
16-bit). :func:`save_project` is atomic (temporary file in the same folder, then ``os.replace``).

:func:`load_project` trusts nothing and every failure is one :class:`ProjectError` naming the
file and the problem. In order, before anything is decoded:

1. the file itself: a regular file (not a FIFO, device, folder or link loop) of bounded size;
2. the zip's directory: entry count, safe names (no ``../``, absolute paths, drive letters,
   backslashes, empty names), no duplicates, no encryption, declared sizes;
3. ``project.json``: read with a cap, its number of values and nesting bounded before Python
   builds them (:func:`engine.jsondata.loads_bounded`), every key typed;
4. the images: each referenced entry's PNG signature and header are read from its first bytes,
   so the *total* decoded size of every reference is known and bounded (and checked against
   the memory available) before one pixel is inflated; then each entry is inflated once, with
   a cap of what its header declares, and decoded.

Damage the zip module reports in its own ways (``NotImplementedError`` for an unknown
compression or version, ``IndexError``, ``EOFError``, zlib errors, a ``MemoryError``) ends the
same way.
"""

from __future__ import annotations

import os
import re
import zipfile
from pathlib import Path

import numpy as np

from engine._fs import InputError, atomic_path, open_input
from engine.bitdepth import quantize, to_float
from engine.budget import MemoryBudgetError, check_memory, format_bytes
from engine.jsondata import JSONDataError, json_default, loads_bounded
from engine.png import HEADER_BYTES, PNGError, PNGHeader, check_header, decode_png, encode_png
from engine.png import read_header as read_png_header
from engine.project.checks import check_project
from engine.project.document import from_doc, to_doc
from engine.project.model import PROJECT_SUFFIX, Project

__all__ = [
    "MAX_DECODED_BYTES",
    "ProjectError",
    "load_project",
    "newer_recovery",
    "recovery_path",
    "save_project",
]

MAX_ENTRIES = 20_000
MAX_JSON_BYTES = 32 * 2**20
MAX_ENTRY_BYTES = 1 * 2**30  # one uncompressed image file
MAX_TOTAL_BYTES = 8 * 2**30  # the whole uncompressed archive, as its directory declares
MAX_FILE_BYTES = 8 * 2**30
MAX_PIXELS = 100_000_000
MAX_DECODED_BYTES = 16 * 2**30
"""Most memory every image reference of a project may take decoded (float32); the memory
available here may lower it (:mod:`engine.budget`)."""


class ProjectError(ValueError):
    """A project file cannot be read or written; the message names the file and the problem."""


# ---------------------------------------------------------------- saving


def save_project(path, project: Project) -> Path:
    """Write ``project`` to ``path`` (a ``.quiltproj`` zip) atomically; returns the path."""
    import json

    p = Path(os.fspath(path))
    try:
        check_project(project, f"{p}")
    except (TypeError, ValueError) as exc:
        raise ProjectError(f"{exc}") from None
    images: dict[str, bytes] = {}

    def put(arr, entry: str) -> str:
        images[entry] = encode_png(quantize(arr, project.bit_depth, dither=False))
        return entry

    doc = to_doc(project, put)
    try:
        text = json.dumps(doc, indent=1, allow_nan=False, default=json_default)
    except (TypeError, ValueError, OverflowError) as exc:
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
    """The recovery file of ``path`` if it exists and is newer than ``path`` (offer it after a
    crash)."""
    p = Path(os.fspath(path))
    r = recovery_path(p)
    if not r.is_file():
        return None
    if p.is_file() and p.stat().st_mtime_ns >= r.stat().st_mtime_ns:
        return None
    return r


# ---------------------------------------------------------------- loading


def load_project(
    path,
    *,
    max_pixels: int = MAX_PIXELS,
    max_entry_bytes: int = MAX_ENTRY_BYTES,
    max_total_bytes: int = MAX_TOTAL_BYTES,
    max_decoded_bytes: int = MAX_DECODED_BYTES,
) -> Project:
    """Read and strictly validate a ``.quiltproj`` file (see the module docstring); any problem
    raises :class:`ProjectError`."""
    p = Path(os.fspath(path))

    def fail(msg: str):
        raise ProjectError(f"{p}: {msg}")

    try:
        f = open_input(p, max_bytes=MAX_FILE_BYTES, what="a project file")
    except InputError as exc:
        fail(str(exc))
    try:
        with f, _open_zip(f, fail) as zf:
            reader = _Reader(zf, fail, max_entry_bytes=max_entry_bytes)
            reader.check_directory(max_total_bytes)
            if "project.json" not in reader.names:
                fail("missing project.json (not a Quilt Studio project)")
            try:
                doc = loads_bounded(reader.read("project.json", MAX_JSON_BYTES))
            except JSONDataError as exc:
                fail(f"project.json: {exc}")
            project = from_doc(doc, fail, lambda ref: _entry_name(ref, fail))
            _load_images(project, reader, fail, max_pixels, max_decoded_bytes, p.name)
    except ProjectError:
        raise
    except MemoryError:
        fail("there is not enough memory to read it")
    except RecursionError:
        fail("project.json is nested too deeply; refused")
    except Exception as exc:  # noqa: BLE001 - the zip module fails in many ways on damage
        fail(f"the archive is damaged or uses an unsupported zip feature ({_describe(exc)})")
    try:
        check_project(project, "project.json")
    except (TypeError, ValueError, OverflowError) as exc:
        fail(str(exc))
    return project


def _describe(exc: BaseException) -> str:
    text = str(exc)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _open_zip(f, fail) -> zipfile.ZipFile:
    try:
        return zipfile.ZipFile(f)
    except zipfile.BadZipFile:
        fail("not a Quilt Studio project (not a zip archive, or the zip is truncated or corrupt)")
    except OSError as exc:
        fail(f"cannot be read ({exc.strerror or exc})")


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


def _entry_name(ref, fail) -> str:
    """An image reference of project.json, checked to be a safe archive path."""
    if not isinstance(ref, str) or not _safe_entry(ref):
        fail(f"project.json: image reference {ref!r:.80} is not a safe archive path; refused")
    return ref


class _Reader:
    """Capped reads of a zip's entries, every failure reported through ``fail``."""

    def __init__(self, zf: zipfile.ZipFile, fail, *, max_entry_bytes: int):
        self.zf = zf
        self.fail = fail
        self.max_entry_bytes = max_entry_bytes
        self.names: set[str] = set()

    def check_directory(self, max_total_bytes: int) -> None:
        infos = self.zf.infolist()
        fail = self.fail
        if len(infos) > MAX_ENTRIES:
            fail(f"the archive has {len(infos):,} entries, over the limit of {MAX_ENTRIES:,}")
        total = 0
        for info in infos:
            name = info.filename
            if not name:
                fail("the archive has an entry with an empty name; refused")
            if not _safe_entry(name.rstrip("/") if name.endswith("/") else name):
                fail(f"entry {name!r} has an unsafe path (absolute, '..' or backslash); refused")
            if name in self.names:
                fail(f"entry {name!r} appears twice")
            self.names.add(name)
            if info.flag_bits & 0x1:
                fail(f"entry {name!r} is encrypted")
            if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                fail(
                    f"entry {name!r} uses zip compression method {info.compress_type}; projects "
                    "use only stored or deflated entries"
                )
            if info.file_size > self.max_entry_bytes:
                fail(
                    f"entry {name!r} declares {info.file_size:,} bytes, over the limit "
                    f"of {self.max_entry_bytes:,}"
                )
            total += info.file_size
        if total > max_total_bytes:
            fail(
                f"the archive declares {total:,} uncompressed bytes, over the limit of "
                f"{max_total_bytes:,}"
            )

    def _info(self, entry: str) -> zipfile.ZipInfo:
        if entry not in self.names:
            self.fail(f"entry {entry!r} is referenced by project.json but missing from the archive")
        return self.zf.getinfo(entry)

    def read(self, entry: str, cap: int) -> bytes:
        """The entry's bytes, inflating at most ``cap`` (+1 to notice more)."""
        info = self._info(entry)
        limit = min(cap, info.file_size, self.max_entry_bytes)
        try:
            with self.zf.open(info) as f:
                data = f.read(limit + 1)
        except (zipfile.BadZipFile, EOFError, OSError) as exc:
            self.fail(f"entry {entry!r} is truncated or corrupt ({_describe(exc)})")
        if len(data) > limit:
            self.fail(
                f"entry {entry!r} inflates beyond its declared size (possible zip bomb); refused"
            )
        return data

    def png_header(self, entry: str, max_pixels: int) -> PNGHeader:
        """The PNG header of an entry, from its first bytes only."""
        info = self._info(entry)
        try:
            with self.zf.open(info) as f:
                head = f.read(HEADER_BYTES)
        except (zipfile.BadZipFile, EOFError, OSError) as exc:
            self.fail(f"entry {entry!r} is truncated or corrupt ({_describe(exc)})")
        try:
            h = check_header(read_png_header(head), max_pixels=max_pixels)
        except PNGError as exc:
            self.fail(f"entry {entry!r}: {exc}")
        if info.file_size > h.max_file_bytes:
            self.fail(
                f"entry {entry!r} declares {info.file_size:,} bytes, more than a "
                f"{h.width}x{h.height} PNG can hold (possible zip bomb); refused"
            )
        return h

    def png(self, entry: str, head: PNGHeader, max_pixels: int) -> np.ndarray:
        """Inflate the entry (capped by what its header declares) and decode it."""
        data = self.read(entry, head.max_file_bytes)
        try:
            return decode_png(data, max_pixels=max_pixels)
        except PNGError as exc:
            self.fail(f"entry {entry!r}: {exc}")


def _load_images(project, reader: _Reader, fail, max_pixels, max_decoded_bytes, name) -> None:
    """Replace every entry name in ``project`` by its decoded image: headers and the total
    decoded size of every reference first, then each entry inflated and decoded once."""
    main = project.main_map
    tiles = [c.images(main) for c in project.candidates]  # the candidates' images, by map
    wang = [c.images(main) for c in project.wang_tiles]
    groups = [project.sources, project.template, project.preview, project.outputs, *tiles, *wang]
    slots = [(g, key) for g in groups if g is not None for key in g]
    heads: dict[str, PNGHeader] = {}
    total = 0
    for group, key in slots:
        entry = group[key]
        if entry not in heads:
            heads[entry] = reader.png_header(entry, max_pixels)
        total += heads[entry].pixels * heads[entry].channels * 4  # float32
    what = (
        f"its {len(slots)} image references ({len(heads)} distinct images) would take "
        f"{format_bytes(total)} decoded"
    )
    if total > max_decoded_bytes:
        fail(f"{what}, over the limit of {format_bytes(max_decoded_bytes)}; refused")
    try:
        check_memory(
            total + sum(h.decoded_bytes for h in heads.values()),
            what=f"opening {name}",
            way_out="close other programs or open it on a machine with more memory",
        )
    except MemoryBudgetError as exc:
        fail(str(exc))
    decoded: dict[str, np.ndarray] = {}
    for group, key in slots:
        entry = group[key]
        if entry in decoded:
            group[key] = decoded[entry].copy()  # each reference its own array, decoded once
            continue
        decoded[entry] = to_float(reader.png(entry, heads[entry], max_pixels))
        group[key] = decoded[entry]
    project.candidates = [
        c.replace(tile=t[main], maps={m: a for m, a in t.items() if m != main})
        for c, t in zip(project.candidates, tiles, strict=True)
    ]
    project.wang_tiles = [
        c.replace(tile=t[main], maps={m: a for m, a in t.items() if m != main})
        for c, t in zip(project.wang_tiles, wang, strict=True)
    ]
