"""The main window (grows with the editor issue)."""

from __future__ import annotations

from PySide6.QtGui import QImage, QPixmap
from PySide6.QtWidgets import QLabel, QMainWindow, QScrollArea

from engine.io import load_image, to_rgb
from resources import sample_path


class MainWindow(QMainWindow):
    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Quilt Studio")
        self._label = QLabel()
        scroll = QScrollArea()
        scroll.setWidget(self._label)
        self.setCentralWidget(scroll)
        self.resize(1200, 800)
        self.image = None

    def open_initial(self, path: str | None) -> None:
        self.open_image(path or sample_path())

    def open_image(self, path) -> None:
        loaded = load_image(path)
        self.image = loaded
        rgb = (to_rgb(loaded.pixels) * 255 + 0.5).astype("uint8").copy()
        h, w, _ = rgb.shape
        qimg = QImage(rgb.data, w, h, rgb.strides[0], QImage.Format.Format_RGB888).copy()
        self._label.setPixmap(QPixmap.fromImage(qimg))
        self._label.adjustSize()
        self.setWindowTitle(f"Quilt Studio — {loaded.path}")
