"""The engine must stay pure: importing every engine module pulls in no Qt."""

import pkgutil
import subprocess
import sys

import engine


def test_engine_imports_no_qt():
    modules = [m.name for m in pkgutil.walk_packages(engine.__path__, "engine.")]
    code = (
        "import importlib, sys\n"
        f"for m in {modules!r}: importlib.import_module(m)\n"
        "bad = [m for m in sys.modules if m.split('.')[0] in "
        "('PySide6', 'PyQt5', 'PyQt6', 'qtpy', 'superqt', 'quilt_gui', 'shiboken6')]\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"engine imported Qt/GUI modules: {out.stdout}"
    assert len(modules) > 3
