"""The preview's interior figures and warnings (issue 10): a planted tone ring is named."""

from __future__ import annotations

import numpy as np

from engine.settings import TilesetSettings
from quilt_gui.widgets.preview import quality_text, set_quality
from tests.engine.helpers import smooth_texture
from tests.gui.helpers import make_window


def test_a_planted_ring_is_warned_about_in_words(qtbot):
    S = smooth_texture((200, 200), 3, 1, 1.5)
    rng = np.random.default_rng(0)
    tiles = []
    for _ in range(8):
        y, x = rng.integers(0, 136, 2)
        t = S[y : y + 64, x : x + 64].copy()
        t[:6] *= 0.6  # a dark ring along every edge
        t[-6:] *= 0.6
        t[:, :6] *= 0.6
        t[:, -6:] *= 0.6
        tiles.append(t)
    s = TilesetSettings(patch_overlap=6, margin=1)
    q = set_quality(tiles, S, tiles[0], s)
    assert q["ring_tone"] > 1.3 and q["warnings"]
    w = make_window(qtbot)
    view = w.preview_view
    view._on_quality(q)
    assert quality_text(q) in view.info.text()
    assert view.warnings.isVisibleTo(view)
    assert "ring differs in tone" in view.warnings.text()
    clean = set_quality(
        [S[y : y + 64, x : x + 64] for y, x in ((10, 120), (100, 30), (130, 130))],
        S,
        S[:64, :64],
        s,
    )
    assert clean["ring_tone"] < 1.3 and clean["duplicates"] == 0
    view._on_quality(clean)
    assert view.warnings.isVisibleTo(view) == bool(clean["warnings"])
