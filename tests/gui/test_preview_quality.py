"""The preview's interior figures and warnings (issue 10): a planted tone ring is named."""

from __future__ import annotations

import numpy as np

from engine.settings import TilesetSettings
from quilt_gui.widgets.preview import quality_text, set_quality
from tests.engine.helpers import smooth_texture
from tests.gui.helpers import make_window, open_sample, template, wait_idle


def planted_ring_tiles():
    """A texture and 8 crops of it with a dark ring along every edge."""
    S = smooth_texture((200, 200), 3, 1, 1.5)
    rng = np.random.default_rng(0)
    tiles = []
    for _ in range(8):
        y, x = rng.integers(0, 136, 2)
        t = S[y : y + 64, x : x + 64].copy()
        t[:6] *= 0.6
        t[-6:] *= 0.6
        t[:, :6] *= 0.6
        t[:, -6:] *= 0.6
        tiles.append(t)
    return S, tiles


def test_a_planted_ring_is_warned_about_in_words(qtbot):
    S, tiles = planted_ring_tiles()
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


def test_the_warnings_suggest_flatten_lighting_only_while_it_is_off(qtbot):
    S, tiles = planted_ring_tiles()
    view = make_window(qtbot).preview_view
    for flatten in (False, True):
        s = TilesetSettings(patch_overlap=6, margin=1, flatten=flatten)
        q = set_quality(tiles, S, tiles[0], s)
        assert q["ring_tone"] > 1.3
        view._on_quality(q)
        text = view.warnings.text()
        assert "ring differs in tone" in text
        if flatten:  # already on (as Auto tone turns it on): not suggested again
            assert "although Flatten lighting is on" in text and "“Flatten lighting”" not in text
        else:
            assert "“Flatten lighting”: On (Parameters ▸ Advanced ▸ Tile)" in text


def test_the_warnings_name_only_controls_the_editor_has(qtbot):
    S, tiles = planted_ring_tiles()
    q = set_quality(tiles, S, tiles[0], TilesetSettings(patch_overlap=6, margin=1))
    view = make_window(qtbot).preview_view
    view._on_quality({**q, "frame": 2.0, "duplicates": 1, "lattice": 3.0})  # every warning
    text = view.warnings.text()
    assert len(text.splitlines()) == 4
    for engine_only in ("patch search", "minimum distance", "patch ring", "patch rings"):
        assert engine_only not in text
    assert "“Patch seam ring” (Parameters ▸ Advanced ▸ Candidates)" in text
    assert "“Tile size”" in text and "“How many candidates”" in text


def test_fewer_candidates_than_asked_says_what_to_do_in_the_editor(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_param("n_candidates", 400)  # this source has far fewer patch positions
    generate_all(qtbot, w)
    text = w.message_bar.text
    assert text.startswith("Made ") and "of 400 candidates" in text
    assert "minimum distance" not in text
    assert "a larger source or a smaller “Tile size” gives more" in text


def generate_all(qtbot, w):
    template(qtbot, w)
    w.act_generate.trigger()
    wait_idle(qtbot, w)
