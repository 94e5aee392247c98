"""Quilt Studio editor (PySide6). The engine package never imports this."""

import os

os.environ.setdefault("QT_API", "pyside6")
