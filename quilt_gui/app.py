"""QApplication set-up and the ``run`` entry used by ``quilt-studio``."""

from __future__ import annotations

import argparse
import logging
import sys

from PySide6.QtGui import QIcon
from PySide6.QtWidgets import QApplication

from quilt_gui import jobs, settings
from quilt_gui.gc_thread import GuiThreadCollector
from quilt_gui.settings import set_names
from quilt_gui.theme import apply_theme
from resources import icon_path


def make_app(argv: list[str] | None = None, *, theme: str | None = None) -> QApplication:
    app = QApplication.instance() or QApplication(argv or [sys.argv[0]])
    set_names()
    app.setWindowIcon(QIcon(str(icon_path())))
    apply_theme(app, theme or settings.get("theme"))
    app.aboutToQuit.connect(_on_about_to_quit)
    return app


def _on_about_to_quit() -> None:
    jobs.shutdown()


def run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(
        prog="quilt-studio",
        description="Quilt Studio editor. Sub-commands (tileset, synth, transfer, seam, export) "
        "run headless; see quilt-studio --help.",
    )
    parser.add_argument("image", nargs="?", help="image or .quiltproj project to open")
    theme = parser.add_mutually_exclusive_group()
    theme.add_argument("--light", action="store_true", help="use the light theme")
    theme.add_argument("--dark", action="store_true", help="use the dark theme (default)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    set_names()
    chosen = "light" if args.light else "dark" if args.dark else None
    if chosen:
        settings.set("theme", chosen)
    app = make_app(theme=chosen)
    collector = GuiThreadCollector(app)  # Qt objects are freed in the GUI thread only
    app.aboutToQuit.connect(lambda: collector.stop(restore=False))
    from quilt_gui.main_window import MainWindow

    window = MainWindow()
    window.show()
    window.open_initial(args.image)
    return app.exec()
