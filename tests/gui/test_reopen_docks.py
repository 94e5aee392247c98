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


def test_a_dock_the_user_closed_stays_closed(qtbot):
    """Closed on the Source tab (or before going to the Wang tab), the Overlaps dock stays
    closed at the next start and after a trip to the Wang tab; the others stay open."""
    w = make_window(qtbot)
    w.docks["overlaps"].close()
    w.tabs.setCurrentWidget(w.wang_view)
    w.tabs.setCurrentIndex(0)
    assert not w.docks["overlaps"].isVisible() and w.docks["tile"].isVisible()
    w.close()
    for tab in ("source", "wang"):
        again = make_window(qtbot)
        assert again.tabs.currentIndex() == 0
        assert not again.docks["overlaps"].isVisible(), tab
        assert again.docks["tile"].isVisible() and again.docks["gallery"].isVisible(), tab
        again.tabs.setCurrentWidget(again.wang_view)  # closed on the Wang tab the second time
        again.close()
