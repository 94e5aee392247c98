"""Where the main window opens: its saved geometry, made to fit the screen it opens on.

A window saved on a large monitor and reopened on a 1366×768 laptop must still show every dock
and its title bar; a first start takes at most 94 % of the screen (1500×950 where there is room).
"""

from __future__ import annotations

from PySide6.QtCore import QByteArray, QRect, QSize
from PySide6.QtGui import QGuiApplication
from PySide6.QtWidgets import QWidget

DEFAULT_SIZE = QSize(1500, 950)
SCREEN_SHARE = 0.94
#: room for the window frame (title bar and borders), which Qt does not count in geometry()
FRAME = QSize(16, 40)


def available_geometry(widget: QWidget) -> QRect:
    """The usable part (no task bar) of the screen ``widget`` is on, or the primary one."""
    screen = widget.screen() or QGuiApplication.primaryScreen()
    return screen.availableGeometry()


def fitted(rect: QRect, available: QRect) -> QRect:
    """``rect`` (a window's client area) shrunk and moved so it and its frame fit
    ``available``."""
    w = min(rect.width(), available.width() - FRAME.width())
    h = min(rect.height(), available.height() - FRAME.height())
    x = min(max(rect.x(), available.left() + FRAME.width() // 2), available.right() - w)
    y = min(max(rect.y(), available.top() + FRAME.height() - 8), available.bottom() - h)
    return QRect(x, y, max(w, 1), max(h, 1))


def place(window: QWidget, saved: QByteArray) -> None:
    """Restore ``saved`` geometry (or choose a default size centred on the screen), then fit
    the window into the screen's available area."""
    available = available_geometry(window)
    if saved.isEmpty() or not window.restoreGeometry(saved):
        w = min(DEFAULT_SIZE.width(), int(available.width() * SCREEN_SHARE))
        h = min(DEFAULT_SIZE.height(), int(available.height() * SCREEN_SHARE))
        rect = QRect(0, 0, w, h)
        rect.moveCenter(available.center())
    else:
        rect = window.geometry()
    window.setGeometry(fitted(rect, available))
