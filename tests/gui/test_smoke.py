from quilt_gui.main_window import MainWindow
from resources import SAMPLE_NAMES, sample_path


def test_main_window_shows_bundled_sample(qtbot):
    w = MainWindow()
    qtbot.addWidget(w)
    w.open_initial(None)
    assert w.image is not None
    assert w.image.pixels.shape[:2] == (512, 512)


def test_samples_exist():
    for name in SAMPLE_NAMES:
        assert sample_path(name).is_file()
