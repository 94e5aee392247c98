"""One photo -> one library folder: the batch's task, a plain function of the photo and the
settings (no Qt, no scheduler state), so a local process and a Dask worker make the same bytes.

A folder ``LIB/<key>/`` holds the seamless tile (``template.png``), the tile set
(``tile_NNN.png``, ``layout.csv`` / ``layout.json``), the project ``<key>.quiltproj`` that the
editor opens, ``thumbnail.png`` (the 8x8 preview reduced) and ``manifest.json``: the tile set's
manifest plus a ``batch`` section (status, settings and their hash, the photo's digest, the
quality metrics, warnings, every file written). A photo that fails gets a folder with only
the manifest, whose ``batch.status`` is ``"failed"`` and ``batch.error`` says why.

The folder is written as a whole (:func:`engine._fs.replace_folder`: a temporary sibling
renamed into place), so a crash, a ``kill -9`` or Ctrl-C never leaves a torn folder; the
temporaries of killed runs are removed by the next run.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from engine.batch.inputs import Photo, photo_seed
from engine.batch.settings import BatchSettings

MANIFEST = "manifest.json"
THUMBNAIL = "thumbnail.png"
PROJECT_SUFFIX = ".quiltproj"
FORMAT = "quilt-studio-batch-photo"


@dataclass(frozen=True, slots=True)
class PhotoRecord:
    """What the scheduler hears of one photo (small: no pixels)."""

    key: str
    path: str
    status: str  # "done" | "failed"
    error: str = ""
    seconds: float = 0.0
    warnings: tuple[str, ...] = ()
    metrics: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()  # the tileset command's "tile size (auto): ..." line

    @property
    def failed(self) -> bool:
        return self.status != "done"


def project_name(key: str) -> str:
    return f"{key}{PROJECT_SUFFIX}"


# ---------------------------------------------------------------- the tile set
def _make_tileset(src: Path, folder: Path, photo: Photo, settings, threads: int, auto=False):
    """Run the ``tileset`` command (Somol-Haindl or Wang set, as ``settings`` say; ``auto``:
    ``--tile-size auto``, a Wang set's) on ``src`` into ``folder``, with the project; returns
    the engine's warnings. The manifest and the project name ``photo.path`` as the source even
    when ``src`` is a temporary copy."""
    from engine.cli import build_parser

    with tempfile.TemporaryDirectory(prefix="quilt-batch-") as d:
        given = Path(d) / "settings.json"
        given.write_text(json.dumps({"settings": settings.to_dict()}), encoding="utf-8")
        argv = ["tileset", str(src), "--out", str(folder), "--settings", str(given)]
        argv += ["--workers", str(threads), "--project", str(folder / project_name(photo.key))]
        argv += ["--source-name", photo.path]
        if auto:
            argv += ["--wang", str(settings.wang), "--tile-size", "auto"]
        args = build_parser(command="tileset").parse_args(argv)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            args.func(args)
    tag = "quilt-studio tileset: warning: "
    return [line[len(tag) :] for line in err.getvalue().splitlines() if line.startswith(tag)]


def _figures(folder: Path, manifest: dict, source) -> tuple[dict, list[str]]:
    """The quality figures of the set a manifest describes and the warnings they raise."""
    from engine.batch.quality import somol_figures, wang_figures

    if manifest.get("kind") != "wang":  # measured by the tileset command, warnings included
        return somol_figures(manifest), []
    from engine.io import load_image
    from engine.metrics import quality_warnings

    tiles = [load_image(folder / t["file"]).pixels for t in manifest["tiles"]]
    cells = json.loads((folder / manifest["layout"]["json"]).read_text())["cells"]
    figures = wang_figures(
        source,
        tiles,
        band=manifest["wang"]["band"],
        margin=manifest["resolved"]["margin"],
        layout=cells,
    )
    return figures, quality_warnings(figures)


# ---------------------------------------------------------------- one folder
#: A photo whose shorter side is below this is refused: its tiles would be a few pixels.
MIN_SIDE = 64


class PhotoError(ValueError):
    """A photo cannot become a tile set; the message says why (without its path)."""


@contextlib.contextmanager
def _source_file(photo: Photo, data: bytes | None):
    """The photo as a file: its own path, or a temporary file holding ``data``."""
    if data is None:
        yield Path(photo.path)
        return
    suffix = Path(photo.path).suffix
    with tempfile.TemporaryDirectory(prefix="quilt-batch-") as d:
        p = Path(d) / f"photo{suffix}"
        p.write_bytes(data)
        yield p


def _thumbnail(preview: Path, out: Path, longest: int) -> None:
    """``out``: ``preview`` reduced (box filter) so that its longer side is ``longest``."""
    from PIL import Image

    from engine.bitdepth import quantize
    from engine.io import load_image, to_rgb

    img = quantize(to_rgb(load_image(preview).pixels), 8, dither=False)
    h, w = img.shape[:2]
    scale = min(1.0, longest / max(h, w))
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    Image.fromarray(img).resize(size, Image.Resampling.BOX).save(out, optimize=False)


def fill_folder(
    folder: Path,
    photo: Photo,
    settings: BatchSettings,
    *,
    data: bytes | None = None,
    threads: int = 1,
) -> PhotoRecord:
    """Write ``photo``'s tile set, project, thumbnail and manifest into the empty ``folder``
    (read from ``data`` if given, else from ``photo.path``), the set made on ``threads``
    threads (the bytes do not depend on them). Raises on any failure."""
    from engine.batch.quality import detail_spread
    from engine.io import load_image

    t0 = time.perf_counter()
    if photo.error:
        raise PhotoError(photo.error)
    seed = photo_seed(photo.digest, settings.tileset.seed)
    with _source_file(photo, data) as src:
        try:
            source = load_image(src).pixels
        except ValueError as exc:  # ImageError names the (maybe temporary) file: drop it
            raise PhotoError(str(exc).replace(f"{src}: ", "")) from None
        h, w = source.shape[:2]
        if min(h, w) < MIN_SIDE:
            raise PhotoError(
                f"too small ({w}x{h}): a tile set needs at least {MIN_SIDE}x{MIN_SIDE} px"
            )
        engine_warnings = _make_tileset(
            src, folder, photo, settings.for_photo(seed), threads, settings.tile_size_auto
        )
    mpath = folder / MANIFEST
    manifest = json.loads(mpath.read_text(encoding="utf-8"))
    metrics, figure_warnings = _figures(folder, manifest, source)
    auto = manifest.get("tile_size_auto")  # the tileset command's stderr line, as it said it
    notes = [f"tile size (auto): {auto['why']}"] if auto else []
    metrics["spread"] = detail_spread(source)  # its warning is the template search's own
    warnings = list(
        dict.fromkeys([*manifest.get("warnings", []), *engine_warnings, *figure_warnings])
    )
    _thumbnail(folder / manifest["preview"]["file"], folder / THUMBNAIL, settings.thumbnail)
    record = PhotoRecord(
        photo.key,
        photo.path,
        "done",
        "",
        round(time.perf_counter() - t0, 3),
        tuple(warnings),
        metrics,
        tuple(notes),
    )
    project = folder / project_name(photo.key)
    manifest["batch"] = _batch_section(
        photo,
        settings,
        record,
        seed,
        {
            "tile": (manifest.get("template") or manifest["tiles"][0])["file"],
            "thumbnail": THUMBNAIL,
            "project": project.name,
            "preview": manifest["preview"]["file"],
        },
        project_sha256=_sha256(project.read_bytes()),
        size=(w, h),
    )
    manifest["batch"]["written"] = sorted([*(p.name for p in folder.iterdir()), MANIFEST])
    mpath.write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    return record


def _sha256(data: bytes) -> str:
    import hashlib

    return hashlib.sha256(data).hexdigest()


def _batch_section(photo, settings, record, seed, files, **extra) -> dict:
    return {
        "format": FORMAT,
        "status": record.status,
        "error": record.error,
        "settings": settings.to_dict(),
        "settings_hash": settings.digest(),
        "photo": {
            "path": photo.path,
            "name": photo.name,
            "sha256": photo.digest,
            "bytes": photo.size,
        },
        "seed": seed,
        "seconds": record.seconds,
        "metrics": record.metrics,
        "warnings": list(record.warnings),
        "files": files,
        **extra,
    }


def _fill_failed(folder: Path, photo: Photo, settings: BatchSettings, record) -> None:
    manifest = {"batch": _batch_section(photo, settings, record, None, {}, written=[MANIFEST])}
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")


def error_text(exc: BaseException) -> str:
    """A one-line reason for a failed photo."""
    if isinstance(exc, (PhotoError, ValueError, OSError)):
        return str(exc) or type(exc).__name__
    return f"{type(exc).__name__}: {exc}"


def make_folder(
    folder: Path,
    photo: Photo,
    settings: BatchSettings,
    *,
    data: bytes | None = None,
    threads: int = 1,
) -> PhotoRecord:
    """:func:`fill_folder`, or on failure a folder with the failed photo's manifest only;
    returns the record either way (the folder must be empty)."""
    t0 = time.perf_counter()
    try:
        return fill_folder(folder, photo, settings, data=data, threads=threads)
    except Exception as exc:  # one photo's failure never stops the batch
        for p in folder.iterdir():
            p.unlink()
        record = PhotoRecord(
            photo.key, photo.path, "failed", error_text(exc), round(time.perf_counter() - t0, 3)
        )
        _fill_failed(folder, photo, settings, record)
        return record


# ---------------------------------------------------------------- in the library
def owned_files(folder: Path) -> list[str]:
    """The files of a library folder that a batch wrote (from its manifest)."""
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        return list(doc["batch"]["written"])
    except (OSError, ValueError, KeyError, TypeError):
        return []


def store(library, key: str, fill) -> None:
    """Create or replace ``library/key`` as a whole with what ``fill(tmp)`` writes."""
    from engine._fs import replace_folder

    replace_folder(Path(library) / key, fill, owned=owned_files, action="write")


def run_photo(photo: Photo, settings: BatchSettings, library, *, threads: int = 1) -> PhotoRecord:
    """The local task: make ``photo``'s folder in ``library`` from its path."""
    out: list[PhotoRecord] = []

    def fill(tmp: Path) -> None:
        out.append(make_folder(tmp, photo, settings, threads=threads))

    try:
        store(library, photo.key, fill)
    except OSError as exc:
        return PhotoRecord(photo.key, photo.path, "failed", error_text(exc))
    return out[0]


def photo_files(photo: Photo, settings: BatchSettings, data: bytes):
    """The remote task: ``(record, {file name: bytes})`` of ``photo``'s folder made from
    ``data`` (its bytes), for :func:`store_files` on the machine that holds the library."""
    with tempfile.TemporaryDirectory(prefix="quilt-batch-") as d:
        record = make_folder(Path(d), photo, settings, data=data)
        files = {p.name: p.read_bytes() for p in sorted(Path(d).iterdir())}
    return record, files


def store_failed(library, photo: Photo, settings: BatchSettings, record: PhotoRecord) -> None:
    """Record a photo whose task could not report itself (its worker died) as failed."""
    with contextlib.suppress(OSError):
        store(library, photo.key, lambda tmp: _fill_failed(tmp, photo, settings, record))


def store_files(library, key: str, files: dict) -> None:
    """Write a folder made by :func:`photo_files` into ``library`` as a whole."""

    def fill(tmp: Path) -> None:
        for name, data in files.items():
            (tmp / name).write_bytes(data)

    store(library, key, fill)


def folder_state(folder: Path, settings_hash: str) -> str:
    """``"done"`` (made with these settings, untouched), ``"edited"`` (its project was saved
    from the editor, or files were added: kept unless forced), or ``"todo"``."""
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        batch = doc["batch"]
    except (OSError, ValueError, KeyError, TypeError):
        return "todo"
    if batch.get("status") != "done":
        return "todo"
    project = folder / batch.get("files", {}).get("project", "")
    try:
        names = {e.name for e in os.scandir(folder)}
        touched = (names - set(batch.get("written", []))) or (
            _sha256(project.read_bytes()) != batch.get("project_sha256")
        )
    except OSError:
        return "todo"
    if touched:
        return "edited"
    return "done" if batch.get("settings_hash") == settings_hash else "todo"
