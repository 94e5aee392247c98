"""The window reopened after closing on a tab that hides the tile set's docks (ux12)."""

from __future__ import annotations

from tests.gui.helpers import make_window


def test_closed_on_the_wang_tab_the_source_tab_reopens_with_its_docks(qtbot):
    w = make_window(qtbot)
    w.tabs.setCurrentWidget(w.wang_view)
    assert not w.docks["gallery"].isVisible()  # the Wang tab hides them
    w.close()
    again = make_window(qtbot)
    assert again.tabs.currentIndex() == 0
    for key in ("overlaps", "tile", "gallery"):
        assert again.docks[key].isVisible(), key
