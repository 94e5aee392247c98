"""GUI test fixtures: the numba kernels compiled once per test process, settings in a temporary
folder, jobs shut down after every test."""

from __future__ import annotations

import warnings

import pytest
from PySide6.QtCore import QSettings

from quilt_gui import jobs, settings
from quilt_gui.gc_thread import GuiThreadCollector
from tests.gui.helpers import WAIT_MS


@pytest.fixture(scope="session", autouse=True)
def _kernels_compiled():
    """Compile (a fresh clone: about 30 s of CPU, 2 minutes at load 7) or load from numba's
    cache every kernel the editor's jobs use, once per test process before its first GUI test:
    else the first test's waits and its teardown's shutdown hold the compile (the editor's
    warm-up job and the first template search, neither can be cancelled) and time out on a
    loaded machine. Bounded by pytest-timeout only, like any test."""
    import numpy as np

    import engine.quilting.synthesis
    import engine.seams
    from engine.io import load_image
    from engine.settings import TilesetSettings
    from engine.tiles import tileset
    from resources import sample_path

    engine.seams.warmup()  # loads numba: the small runs below take the kernels, not numpy
    engine.quilting.synthesis.warmup()
    crop = np.ascontiguousarray(load_image(sample_path("cobblestones")).pixels[:192, :192, :3])
    with warnings.catch_warnings():  # the crop's notes (e.g. uneven sharpness) say nothing here
        warnings.simplefilter("ignore")
        tileset(crop, TilesetSettings(tile_min=64, tile_max=64, candidates=3))


@pytest.fixture(autouse=True)
def _isolated_settings(tmp_path, qapp):
    settings.set_names()
    QSettings.setDefaultFormat(QSettings.Format.IniFormat)
    QSettings.setPath(QSettings.Format.IniFormat, QSettings.Scope.UserScope, str(tmp_path / "cfg"))
    QSettings().clear()
    yield
    QSettings().clear()


@pytest.fixture(autouse=True)
def _stop_jobs(qapp):
    # as in the editor, the garbage collector runs in this (the GUI) thread only: a collection
    # in a job's thread freed a test's whole window there (quilt_gui.gc_thread); the test's
    # garbage is collected here after its jobs have stopped
    collector = GuiThreadCollector()
    try:
        yield
        # a margin: an aborted job that cannot be cancelled (a preview, the set's figures) runs
        # to its end, about 1 s of CPU, 5 s at load 10
        assert jobs.shutdown(WAIT_MS), f"background jobs did not stop within {WAIT_MS // 1000} s"
        qapp.processEvents()
    finally:
        collector.stop()
