"""Quilt Studio editor (PySide6). The engine package never imports this."""

import os

os.environ.setdefault("QT_API", "pyside6")

from quilt_gui._compat import top_up  # noqa: E402

top_up()  # PySide6 6.12.0 + Python 3.11 reference-count bug (see quilt_gui/_compat.py)
