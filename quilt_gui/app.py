"""QApplication set-up and the ``run`` entry used by ``quilt-studio``."""

from __future__ import annotations

import argparse
import logging
import sys

from PySide6.QtCore import QCoreApplication
from PySide6.QtGui import QColor, QIcon, QPalette
from PySide6.QtWidgets import QApplication

from quilt_gui import jobs, settings
from resources import icon_path

APP_NAME = "Quilt Studio"
ORG_NAME = "QuiltStudio"


def set_names() -> None:
    """Organisation and application names (they locate the QSettings file)."""
    QCoreApplication.setOrganizationName(ORG_NAME)
    QCoreApplication.setApplicationName(APP_NAME)


def dark_palette() -> QPalette:
    p = QPalette()
    base, window, text = QColor(30, 30, 32), QColor(45, 45, 48), QColor(225, 225, 225)
    disabled = QColor(120, 120, 120)
    for role, color in (
        (QPalette.ColorRole.Window, window),
        (QPalette.ColorRole.WindowText, text),
        (QPalette.ColorRole.Base, base),
        (QPalette.ColorRole.AlternateBase, window),
        (QPalette.ColorRole.ToolTipBase, QColor(60, 60, 64)),
        (QPalette.ColorRole.ToolTipText, text),
        (QPalette.ColorRole.PlaceholderText, disabled),
        (QPalette.ColorRole.Text, text),
        (QPalette.ColorRole.Button, window),
        (QPalette.ColorRole.ButtonText, text),
        (QPalette.ColorRole.BrightText, QColor(255, 80, 80)),
        (QPalette.ColorRole.Link, QColor(90, 160, 255)),
        (QPalette.ColorRole.Highlight, QColor(42, 130, 218)),
        (QPalette.ColorRole.HighlightedText, QColor(255, 255, 255)),
        (QPalette.ColorRole.Light, QColor(70, 70, 74)),
        (QPalette.ColorRole.Midlight, QColor(60, 60, 64)),
        (QPalette.ColorRole.Mid, QColor(40, 40, 42)),
        (QPalette.ColorRole.Dark, QColor(20, 20, 22)),
        (QPalette.ColorRole.Shadow, QColor(0, 0, 0)),
    ):
        p.setColor(role, color)
    for role in (
        QPalette.ColorRole.Text,
        QPalette.ColorRole.ButtonText,
        QPalette.ColorRole.WindowText,
    ):
        p.setColor(QPalette.ColorGroup.Disabled, role, disabled)
    return p


def apply_theme(app: QApplication, theme: str) -> None:
    """Fusion style with a dark palette ("dark") or Fusion's own light palette ("light").

    Widgets with a style sheet (superqt's slider value labels, for one) keep the palette
    they were polished with, so they are re-polished: otherwise a switch at run time leaves
    light-grey numbers on a light background.
    """
    app.setStyle("Fusion")
    if theme == "light":
        app.setPalette(app.style().standardPalette())
    else:
        app.setPalette(dark_palette())
    for widget in app.allWidgets():
        sheet = widget.styleSheet()
        if sheet:
            widget.setStyleSheet("")
            widget.setStyleSheet(sheet)


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
    from quilt_gui.main_window import MainWindow

    window = MainWindow()
    window.show()
    window.open_initial(args.image)
    return app.exec()
