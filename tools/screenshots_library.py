"""Screenshot of the editor's Library dock on a library made by ``quilt-studio batch``:

    python -m benchmarks.batch --acceptance /tmp/acc      # or any quilt-studio batch --out DIR
    xvfb-run -s "-screen 0 1600x1000x24" python tools/screenshots_library.py /tmp/acc/lib

Opens the library (File ▸ Open library…: the dock takes the lower half of the centre), opens
the first photo that was made (its project: tile, candidates) and writes docs/library.png.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main(library: str) -> int:
    from PySide6.QtCore import QSettings

    from quilt_gui.app import make_app

    app = make_app(theme="dark")
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    tmp = Path(tempfile.mkdtemp(prefix="quilt_shots_"))
    QSettings.setPath(QSettings.Format.IniFormat, QSettings.Scope.UserScope, str(tmp))
    from quilt_gui.main_window import MainWindow
    from quilt_gui.responsiveness import wait_until
    from tools.screenshots import save_png

    w = MainWindow()
    w.files.ask_save_changes = lambda: "discard"
    w.show()
    idle = lambda: not w.pipeline.busy() and not w.jobs.busy()  # noqa: E731
    w.open_library(library)
    wait_until(lambda: idle() and w.library_view.model.rowCount() > 0)
    view = w.library_view
    first_done = next(r for r in range(view.model.rowCount()) if view.entry_at(r).status == "done")
    view.open_row(first_done)
    wait_until(lambda: idle() and w.doc.has_source)
    w.message_bar.dismiss()
    for _ in range(10):
        app.processEvents()
    path = ROOT / "docs" / "library.png"
    save_png(w.grab(), path)
    print("wrote", path)
    w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
