"""Entry point ``quilt-studio``: the editor without a sub-command, else the headless CLI."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    from engine.cli import SUBCOMMANDS, build_parser
    from engine.cli import main as cli_main

    if argv and (argv[0] in SUBCOMMANDS or argv[0] in ("-h", "--help")):
        if argv[0] in ("-h", "--help"):
            build_parser().print_help()
            return 0
        return cli_main(argv)
    from quilt_gui.app import run

    return run(argv)


if __name__ == "__main__":
    sys.exit(main())
