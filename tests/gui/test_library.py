"""File ▸ Open library…: a batch library as a list, warnings first, projects opened one by one."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt

from engine.batch import find_photos
from engine.batch.library import read_library
from engine.batch.task import run_photo
from quilt_gui.widgets.library import HEADERS
from tests.engine.batch_helpers import SMALL, write_bad_photos, write_photos
from tests.gui.helpers import WAIT_MS, make_window, wait_idle


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    root = tmp_path_factory.mktemp("library")
    write_photos(root / "in", names=("brick", "gravel"))
    write_bad_photos(root / "in")[1].unlink()  # the corrupt photo stays
    lib = root / "lib"
    lib.mkdir()
    for ph in find_photos([str(root / "in")])[0]:
        run_photo(ph, SMALL, lib)
    return lib


def open_library(qtbot, window, lib):
    window.files.ask_library_path = lambda: str(lib)
    with qtbot.waitSignal(window.library_view.model.modelReset, timeout=WAIT_MS):
        window.act_open_library.trigger()
    return window.library_view


def test_library_lists_every_photo_failed_first_with_the_index_columns(qtbot, library):
    window = make_window(qtbot)
    view = open_library(qtbot, window, library)
    assert window.docks["library"].isVisible()
    qtbot.waitUntil(  # browsable
        lambda: window.docks["library"].height() >= 0.4 * window.height(), timeout=WAIT_MS
    )
    table = view.table
    names = [table.model().index(r, 0).data() for r in range(table.model().rowCount())]
    assert names == [e.name for e in read_library(library)]
    assert names[0] == "corrupt.png"
    headers = [table.model().headerData(c, Qt.Orientation.Horizontal) for c in range(len(HEADERS))]
    assert headers[:2] == ["Photo", "Warnings / error"] and "Frame" in headers
    notes = table.model().index(0, 1).data()
    assert "truncated or corrupt" in notes
    assert table.model().index(1, 0).data(Qt.ItemDataRole.DecorationRole) is not None  # thumb
    assert "3 photos, 1 failed" in view.summary.text()
    from engine.batch.quality import past_limit

    fg = Qt.ItemDataRole.ForegroundRole
    for r, e in enumerate(read_library(library)[1:], start=1):  # figures past limit marked
        for c, (key, _) in enumerate(HEADERS[2:], start=2):
            marked = table.model().index(r, c).data(fg) is not None
            assert marked == past_limit(key, e.values.get(key)), (e.name, key)


def test_double_click_opens_the_project_and_next_the_following(qtbot, library):
    window = make_window(qtbot)
    view = open_library(qtbot, window, library)
    opened = []
    window.files.open_path = lambda path, **kw: opened.append(path)
    table = view.table
    rect = table.visualRect(table.model().index(1, 0))
    qtbot.mouseClick(table.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    qtbot.mouseDClick(table.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    first = read_library(library)[1]
    assert opened == [str(first.file("project"))]
    assert table.model().index(1, 0).data(Qt.ItemDataRole.FontRole).italic()
    assert view.open_next()
    assert opened[-1] == str(read_library(library)[2].file("project"))
    assert not view.open_next()  # the last one
    view.open_row(0)  # the failed photo has nothing to open
    assert len(opened) == 2
    assert "no tile set to open" in window.last_message()


def test_a_library_project_opens_in_the_editor(qtbot, library):
    window = make_window(qtbot)
    view = open_library(qtbot, window, library)
    with qtbot.waitSignal(window.doc.source_changed, timeout=WAIT_MS):
        view.open_row(1)
    wait_idle(qtbot, window)
    assert len(window.doc.tileset.candidates) == 3
    assert window.doc.project_path == str(read_library(library)[1].file("project"))
