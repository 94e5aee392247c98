import subprocess
import sys

from resources import SAMPLE_NAMES, sample_path
from tests.gui.helpers import WAIT_MS, make_window, open_sample


def test_main_window_shows_bundled_sample(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    assert w.doc.source.shape == (512, 512)
    assert w.windowTitle().startswith("cobblestones")


def test_samples_exist():
    for name in SAMPLE_NAMES:
        assert sample_path(name).is_file()


def test_entry_point_sends_subcommands_to_the_cli():
    out = subprocess.run(
        [sys.executable, "-m", "quilt_gui", "--help"],
        capture_output=True,
        text=True,
        timeout=WAIT_MS / 1000,
    )
    assert out.returncode == 0 and "SUBCOMMAND" in out.stdout


def test_application_has_its_icon(qtbot):
    from PySide6.QtWidgets import QApplication

    from quilt_gui.app import make_app

    make_app()
    assert not QApplication.windowIcon().isNull()
