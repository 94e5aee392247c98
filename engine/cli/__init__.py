"""Headless command line: ``quilt-studio SUBCOMMAND ...`` over the same engine.

Each sub-command lives in its own module of this package exposing
``add_parser(subparsers)`` (which registers it and sets ``func``) so that
commands can be added without touching each other.
"""

from __future__ import annotations

import argparse
import importlib

SUBCOMMANDS = ("seam", "tileset", "synth", "transfer", "export", "heal")


def build_parser(prog: str = "quilt-studio") -> argparse.ArgumentParser:
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
    for name in SUBCOMMANDS:
        try:
            module = importlib.import_module(f"engine.cli.{name}")
        except ModuleNotFoundError as exc:  # a command still being written
            if exc.name != f"engine.cli.{name}":
                raise
            continue
        module.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run a headless sub-command; returns the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    from engine.cli.outcome import run_command

    return run_command(args)
