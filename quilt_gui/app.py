"""QApplication set-up and the ``run`` entry used by ``quilt-studio``."""

from __future__ import annotations

import argparse
import sys

from PySide6.QtWidgets import QApplication

APP_NAME = "Quilt Studio"
ORG_NAME = "QuiltStudio"


def make_app(argv: list[str] | None = None) -> QApplication:
    app = QApplication.instance() or QApplication(argv or [sys.argv[0]])
    app.setApplicationName(APP_NAME)
    app.setOrganizationName(ORG_NAME)
    app.setStyle("Fusion")
    return app


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="quilt-studio", add_help=False)
    parser.add_argument("image", nargs="?", help="image or project to open")
    args, _ = parser.parse_known_args(argv)
    app = make_app()
    from quilt_gui.main_window import MainWindow

    window = MainWindow()
    window.open_initial(args.image)
    window.show()
    return app.exec()
