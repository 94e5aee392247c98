"""GUI test fixtures: settings in a temporary folder, jobs shut down after every test."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QSettings

from quilt_gui import jobs, settings


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
    yield
    assert jobs.shutdown(10_000), "background jobs did not stop within 10 s"
    qapp.processEvents()
