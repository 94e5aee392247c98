"""``quilt-studio export PROJECT --out DIR``: write the export bundle of a project file."""

from __future__ import annotations

import argparse
import sys

from engine.cli import SUBCOMMANDS
from engine.cli._args import add_bit_depth, int_at_least


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "export",
        help=SUBCOMMANDS["export"],
        description="Write the export bundle of a .quiltproj project: per-tile PNGs per map, "
        "one atlas per map, a JSON manifest, the layout index matrix (CSV + JSON), a Tiled "
        ".tsx/.tmx, a Godot 4 .tres and the preview. The folder appears complete or not at all.",
    )
    p.add_argument(
        "project", metavar="PROJECT", help="a .quiltproj file (saved by the editor or the CLI)"
    )
    p.add_argument("--out", required=True, metavar="DIR", help="bundle folder to create")
    p.add_argument("--name", default=None, help="file-name prefix (default: the project's name)")
    p.add_argument(
        "--atlas-columns",
        type=int_at_least(1),
        default=None,
        metavar="N",
        help="tiles per atlas row (default: about square, preferring no blank cells)",
    )
    p.add_argument(
        "--spacing", type=int_at_least(0), default=0, metavar="N", help="pixels between atlas cells"
    )
    p.add_argument(
        "--margin", type=int_at_least(0), default=0, metavar="N", help="pixels around the atlas"
    )
    p.add_argument(
        "--extrude",
        type=int_at_least(0),
        default=0,
        metavar="N",
        help="pixels of edge bleed around every atlas tile",
    )
    p.add_argument(
        "--extrude-mode",
        choices=("edge", "wrap"),
        default="edge",
        help="bleed by repeating the edge pixel (default) or the opposite edge",
    )
    add_bit_depth(p, "project")
    p.add_argument(
        "--dither",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="dither when rounding (default: only when reducing a 16-bit project to 8 bits)",
    )
    p.add_argument(
        "--tile-format",
        choices=("png", "tif"),
        default="png",
        help="format of the per-tile and preview files (atlases are always PNG)",
    )
    p.add_argument(
        "--seed", type=int_at_least(0), default=0, help="seed of the dither noise (default 0)"
    )
    p.add_argument("--overwrite", action="store_true", help="replace a non-empty --out folder")
    p.add_argument(
        "--seamless",
        action="store_true",
        help="write only the seamless tile, one file per map: DIR/NAME_seamless.png "
        "(+ NAME_seamless_MAP.png), the usual 'make it tile' deliverable",
    )
    p.add_argument(
        "--wang",
        action="store_true",
        default=None,
        help="export the project's Wang set (Tiled Wang set, Godot terrain set) rather than its "
        "candidates (the default when it holds only a Wang set)",
    )
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    from engine._fs import check_folder
    from engine.export import bundle_files
    from engine.project import export_project, load_project

    if not args.seamless:  # --seamless writes files into --out, never replaces the folder
        check_folder(  # refuse an output folder before reading the project
            args.out,
            owned=bundle_files,
            inputs=[args.project],
            overwrite=args.overwrite,
            action="export to",
            overwrite_word="--overwrite",
        )
    project = load_project(args.project)
    if args.name is not None:
        project.name = args.name
    if args.seamless:
        return _export_seamless(project, args)
    print(f"quilt-studio export: writing {args.project} as a bundle to {args.out}", file=sys.stderr)
    manifest = export_project(
        project,
        args.out,
        columns=args.atlas_columns,
        spacing=args.spacing,
        margin=args.margin,
        extrude=args.extrude,
        extrude_mode=args.extrude_mode,
        bit_depth=args.bit_depth,
        dither=args.dither,
        rng=args.seed,
        tile_format=args.tile_format,
        overwrite=args.overwrite,
        wang=args.wang,
        inputs=[args.project],
    )
    print(
        f"quilt-studio export: wrote {manifest['tile_count']} tiles x {len(manifest['maps'])} maps "
        f"({manifest['tile_w']}x{manifest['tile_h']}, {manifest['bit_depth']}-bit) to {args.out}",
        file=sys.stderr,
    )
    return 0


def _export_seamless(project, args) -> int:
    """``--seamless``: the project's seamless tile per map into ``--out``."""
    from pathlib import Path

    from engine.export.seamless import export_seamless, seamless_paths

    if not project.template:
        raise ValueError(
            f"{args.project}: the project has no seamless tile (make one in the editor or with "
            "quilt-studio tileset)"
        )
    path = Path(args.out) / f"{project.name}_seamless.{args.tile_format}"
    if not args.overwrite:
        taken = [str(p) for p in seamless_paths(project.template, path).values() if p.exists()]
        if taken:
            raise ValueError(f"{taken[0]} exists (pass --overwrite to replace it)")
    written = export_seamless(
        project.template,
        path,
        bit_depth=args.bit_depth or project.bit_depth,
        dither=args.dither,
        source_bit_depth=project.bit_depth,
        rng=args.seed,
    )
    h, w = next(iter(project.template.values())).shape[:2]
    print(
        f"quilt-studio export: wrote the {w}x{h} seamless tile ({len(written)} map"
        f"{'s' if len(written) > 1 else ''}) to {path}",
        file=sys.stderr,
    )
    return 0


# ---------------------------------------------------------------- for other sub-commands


def add_project_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--project FILE`` to another sub-command (e.g. ``tileset``)."""
    parser.add_argument(
        "--project",
        metavar="FILE",
        default=None,
        help="also save everything as a .quiltproj project (opens in the editor; "
        "`quilt-studio export FILE --out DIR` exports it)",
    )


def save_project_option(args, *, into=None, **project_kwargs) -> None:
    """If ``--project`` was given, build the project with
    :func:`engine.project.project_from_tileset` (same keyword arguments) and save it there
    (or ``into`` a temporary path that becomes ``--project`` later)."""
    path = getattr(args, "project", None)
    if not path:
        return
    from engine.project import project_from_tileset, save_project

    save_project(into or path, project_from_tileset(**project_kwargs))
    print(
        f"quilt-studio {getattr(args, 'command', 'tileset')}: wrote project {path}", file=sys.stderr
    )
