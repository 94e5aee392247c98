"""The window on the screen it opens on (issue 13 item 16)."""

from __future__ import annotations

import subprocess
import sys

from PySide6.QtCore import QRect

from quilt_gui import window_geometry
from quilt_gui.main_window import MainWindow

LAPTOP = QRect(0, 0, 1366, 728)  # 1366x768 less a 40 px task bar


def test_the_window_fits_a_1366x768_screen_with_every_dock_and_remembers_its_geometry(
    qtbot, monkeypatch
):
    monkeypatch.setattr(window_geometry, "available_geometry", lambda _w: LAPTOP)
    w = MainWindow()
    qtbot.addWidget(w)
    w.files.ask_save_changes = lambda: "discard"
    frame = w.geometry().adjusted(-8, -32, 8, 8)
    assert LAPTOP.contains(frame), w.geometry()
    hint = w.minimumSizeHint()
    assert hint.width() <= w.width() and hint.height() <= w.height()  # docks reachable
    w.show()
    qtbot.waitExposed(w)
    for key, dock in w.docks.items():
        if dock.isVisible():
            assert w.rect().contains(dock.geometry()), key
            assert dock.height() >= dock.minimumSizeHint().height(), key
    w.setGeometry(QRect(40, 60, 700, 520))
    w.close()
    again = MainWindow()
    qtbot.addWidget(again)
    # remembered (the width is the window's minimum, clamped by Qt to the 800 px offscreen
    # screen: compare what that leaves alone)
    assert (again.geometry().top(), again.geometry().height()) == (60, 520)
    # a geometry saved on a big monitor is brought back onto the laptop's screen
    again.setGeometry(QRect(1900, 50, 2400, 1300))
    again.files.ask_save_changes = lambda: "discard"
    again.close()
    third = MainWindow()
    qtbot.addWidget(third)
    assert LAPTOP.contains(third.geometry())


def test_help_says_quilt_studio_file_opens_an_image_or_project():
    out = subprocess.run(
        [sys.executable, "-m", "quilt_gui", "--help"], capture_output=True, text=True, check=True
    ).stdout
    assert "quilt-studio FILE" in out and "image" in out and "project" in out
