"""The tile set's output folder: the files both kinds of set write (the Somol-Haindl set of
:mod:`engine.cli.tileset`, the Wang set of :mod:`engine.cli.tileset_wang`), the folder written
as a whole, the inputs the flags name, and progress lines.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import os
import re
import sys
import time
from pathlib import Path

from engine._fs import replace_folder, write_bytes_atomically
from engine.cli._args import excluded_pixels
from engine.cli.export import save_project_option
from engine.settings import TilesetSettings

FORMAT = "quilt-studio-tileset"
VERSION = 2  # 2: "settings" (TilesetSettings.to_dict()) replaces "parameters"
MAIN_MAP = "albedo"  # the source's map name in a project file
WRITE_ACTION = "write the tile set to"


class Reporter:
    """Progress lines on stderr."""

    def __init__(self):
        self.t0 = time.perf_counter()

    def __call__(self, text: str) -> None:
        print(f"[{time.perf_counter() - self.t0:7.2f}s] {text}", file=sys.stderr, flush=True)


def source_name(args) -> str:
    """The source's path as the manifest and the project record it: SOURCE, or the hidden
    ``--source-name`` when SOURCE is a temporary copy (``quilt-studio batch`` on a cluster)."""
    return getattr(args, "source_name", None) or str(args.source)


def inputs(args) -> list:
    return [args.source, *(p for _, p in args.map), args.exclude_mask]


def project_inside(args) -> str | None:
    """The file name of ``--project`` if it goes into the ``--out`` folder, else None."""
    project = getattr(args, "project", None)
    if not project:
        return None
    out = Path(os.path.abspath(args.out))
    p = Path(os.path.abspath(project))
    if p.parent == out:
        return p.name
    if out in p.parents:
        raise ValueError(
            f"--project {project}: a project inside --out goes directly in that folder, not in "
            "a subfolder of it"
        )
    return None


def check_out(args) -> None:
    """Refuse, before any work, an --out folder the set cannot replace as a whole (holding
    other files or an input, the current folder) or cannot be written next to."""
    from engine._fs import OutputError, check_folder, check_writable

    out = Path(args.out)
    project_inside(args)
    try:
        check_folder(out, owned=tileset_files, inputs=inputs(args), action=WRITE_ACTION)
        check_writable(Path(os.path.abspath(out)).parent, name=f"--out {out}")
    except OutputError as exc:
        raise ValueError(str(exc)) from None


def tileset_files(folder: Path) -> set[str]:
    """The files the tile-set manifest in ``folder`` says an earlier run wrote there."""
    path = Path(folder) / "manifest.json"
    try:
        if path.stat().st_size > 64 * 2**20:
            return set()
        doc = json.loads(path.read_text("utf-8"))
    except (OSError, ValueError, RecursionError):
        return set()
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        return set()
    names = ["manifest.json", *_names(doc.get("files"))]
    names += _names(doc.get("layout"))
    for key in ("template", "preview"):
        names += _names(
            (doc.get(key) or {}).get("maps") if isinstance(doc.get(key), dict) else None
        )
    for tile in doc.get("tiles") or []:
        names += _names(tile.get("maps") if isinstance(tile, dict) else None)
    return {n for n in names if re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", n)}


def _names(v) -> list[str]:
    if isinstance(v, dict):
        v = list(v.values())
    return [n for n in v if isinstance(n, str)] if isinstance(v, list) else []


def load_inputs(args, settings: TilesetSettings, say):
    """The source, its bit depth, the material maps, the seam weights and the excluded
    pixels the flags name: ``(S, depth, maps, weights, excluded)``."""
    from engine.io import load_image

    loaded = load_image(args.source)
    S, depth = loaded.pixels, loaded.bit_depth
    H, W = S.shape[:2]
    say(f"source {args.source}: {W}x{H}, {S.shape[2]} channel(s), {depth}-bit")
    maps = {}
    for name, path in args.map:
        if name in maps or name == "main":
            raise ValueError(f"--map {name}: duplicate or reserved map name")
        maps[name] = load_image(path).pixels
    weights = dict(args.weight) or None
    given = argparse.Namespace(exclude_color=settings.exclude_color, exclude_mask=args.exclude_mask)
    excluded = excluded_pixels(given, S, "source")
    if excluded is not None:
        say(f"excluded: {int(excluded.sum())} of {H * W} source pixels")
        if excluded.all():
            raise ValueError(
                f"--exclude-color / --exclude-mask exclude every pixel of {args.source}: "
                "no tile can be taken from it"
            )
    return S, depth, maps, weights, excluded


def write_set(args, write, project: dict) -> None:
    """Write the --out folder as a whole: ``write(tmp)`` writes the images and layout into an
    empty temporary folder and returns the manifest, which gets the list of every file and is
    written last, with the project if ``--project`` goes into that folder (``project``: the
    keyword arguments of :func:`engine.project.project_from_tileset`). The folder is then
    swapped in (:func:`engine._fs.replace_folder`); a project elsewhere is saved after it."""
    inside = project_inside(args)

    def fill(tmp: Path) -> None:
        manifest = write(tmp)
        extra = ["manifest.json"] + ([inside] if inside else [])
        manifest["files"] = sorted([*os.listdir(tmp), *extra])
        write_text(tmp / "manifest.json", json.dumps(manifest, indent=1) + "\n")
        if inside:
            save_project_option(args, into=tmp / inside, **project)

    replace_folder(args.out, fill, owned=tileset_files, inputs=inputs(args), action=WRITE_ACTION)
    if project and not inside:
        save_project_option(args, **project)


def write_images(out: Path, stem: str, images: dict, depth: int) -> dict:
    """``stem.png`` (map ``main``) and ``stem_<map>.png`` at ``depth`` bits; {map: file name}."""
    from engine.bitdepth import quantize
    from engine.png import encode_png

    files = {}
    for m, img in images.items():
        fname = f"{stem}.png" if m == "main" else f"{stem}_{m}.png"
        write_bytes_atomically(out / fname, encode_png(quantize(img, depth, dither=False)))
        files[m] = fname
    return files


def map_weights(weights) -> dict:
    """The project's seam-error weights per map name: given weights leave out a map's weight
    as 0, the source's too (``engine.materials.material_error``), so it is written out."""
    if not weights:
        return {}
    return {MAIN_MAP: weights.get("main", 0.0), **{k: v for k, v in weights.items() if k != "main"}}


def csv_text(cells) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(cells.tolist())
    return buf.getvalue()


def write_text(path: Path, text: str) -> None:
    write_bytes_atomically(path, text.encode("utf-8"))


def check_sizes(
    args, settings: TilesetSettings, S, tile_hw, maps, *, tiles: int
) -> TilesetSettings:
    """The preview of tiles up to ``tile_hw`` within :data:`engine.export.MAX_PREVIEW_PIXELS`
    (a default grid shrinks with a warning, a given ``--preview`` is refused) and the whole run
    of ``tiles`` tiles within the memory available, before any work; the settings to run with.
    Shared by the template and the Wang workflows."""
    import warnings

    from engine.budget import check_memory, tileset_bytes
    from engine.export import MAX_PREVIEW_PIXELS

    H, W = S.shape[:2]
    th, tw = tile_hw
    rows, cols = settings.preview
    if rows * th * cols * tw > MAX_PREVIEW_PIXELS:
        size = f"{cols * tw}x{rows * th} px, over the limit of {MAX_PREVIEW_PIXELS:,} pixels"
        if args.preview is not None:
            raise ValueError(
                f"--preview {rows}x{cols}: a preview of tiles up to {tw}x{th} would be {size}; "
                "choose a smaller grid"
            )
        r, c = rows, cols
        while r * th * c * tw > MAX_PREVIEW_PIXELS and (r > 1 or c > 1):
            r, c = max(1, r - 1), max(1, c - 1)
        warnings.warn(
            f"the {rows}x{cols} preview of tiles up to {tw}x{th} would be {size}; "
            f"using {r}x{c} (--preview sets it)",
            stacklevel=2,
        )
        settings = settings.replace(preview=(r, c))
    check_memory(
        tileset_bytes(
            S.shape,
            (th, tw),
            candidates=tiles,
            preview=settings.preview,
            map_channels=[m.shape[2] for m in maps.values()],
        ),
        what=f"a tile set from this {W}x{H} source",
        way_out="use a smaller source, a smaller tile size, fewer tiles or a smaller --preview",
    )
    return settings
