"""Headless command line: ``quilt-studio SUBCOMMAND ...`` over the same engine.

Each sub-command lives in its own module of this package exposing
``add_parser(subparsers)`` (which registers it and sets ``func``) so that
commands can be added without touching each other; :data:`SUBCOMMANDS` lists them with
their one-line help. Only the module of the sub-command that runs is imported (``--help``
imports none, so it needs no numpy): a command's start-up costs what that command uses.
"""

from __future__ import annotations

import argparse
import importlib
import sys

#: every sub-command (module engine.cli.<name>) and its line in ``quilt-studio --help``
SUBCOMMANDS = {
    "seam": "find a minimum-error seam between two equally sized overlap images",
    "tileset": "make a seamless template tile and N mutually connectable candidate tiles",
    "synth": "synthesize a larger texture from a sample by image quilting",
    "transfer": "texture transfer: render TARGET with the texture of SAMPLE",
    "export": "export a project's picked tiles as a bundle (PNGs, atlases, manifest, Tiled, Godot)",
    "heal": "fill a masked region of an image from the rest of it (remove a leaf, a logo...)",
    "batch": "make a tile set for every photo of a folder: a browsable, resumable library",
}


def build_parser(prog: str = "quilt-studio", command: str | None = None):
    """The parser of ``quilt-studio``: every sub-command's help line, and the whole parser of
    ``command`` (its module imported) when one is given."""
    parser = argparse.ArgumentParser(
        prog=prog,
        usage=f"{prog} [FILE] | {prog} SUBCOMMAND [options] | {prog} -h",
        description="Quilt Studio: seamless tiles, connectable tile sets, image quilting and "
        "texture transfer.\n\n"
        f"  {prog}              open the editor on a bundled sample\n"
        f"  {prog} FILE         open FILE in the editor: an image (PNG, JPEG, TIFF, BMP,\n"
        "                            WebP) or a .quiltproj project\n"
        f"  {prog} SUBCOMMAND   run headless (listed below; SUBCOMMAND -h for its options)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", metavar="SUBCOMMAND")
    for name, line in SUBCOMMANDS.items():
        if name == command:
            importlib.import_module(f"engine.cli.{name}").add_parser(sub)
        else:
            sub.add_parser(name, help=line, add_help=False)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run a headless sub-command; returns the process exit code."""
    from engine.cli.outcome import run_command, stopped_early

    argv = sys.argv[1:] if argv is None else list(argv)
    with stopped_early() as code:  # Ctrl+C / SIGTERM while the command is being set up
        parser = build_parser(command=argv[0] if argv and argv[0] in SUBCOMMANDS else None)
        args = parser.parse_args(argv)
        if args.command is None:
            parser.print_help()
            return 2
    if code:
        return code[0]
    return run_command(args)
