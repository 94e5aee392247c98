"""The editor's default candidate options: the engine's scale-aware patch ring ("auto")."""

from __future__ import annotations

import numpy as np

from engine.events import drain
from engine.io import load_image
from engine.metrics import grid_score
from engine.seams import SeamSpec
from engine.tiles import (
    assemble,
    default_patch_overlap,
    iter_candidates,
    make_seamless,
    random_layout,
)
from quilt_gui import params
from resources import sample_path
from tests.gui.helpers import generate, make_window, open_sample


def _preview_grid_score(source, template, patch_overlap) -> float:
    cands = drain(iter_candidates(source, template, 30, patch_overlap=patch_overlap, rng=1))
    tiles = [c.tile for c in sorted(cands, key=lambda c: c.index)]
    period = tiles[0].shape[:2]
    return float(
        np.mean(
            [
                grid_score(assemble(tiles, random_layout(30, 8, 8, rng=s)), period, source=source)
                for s in range(3)
            ]
        )
    )


def test_default_patch_ring_shows_less_grid_than_the_template_overlap():
    """The editor's "auto" ring (the engine default: w_T 16 -> 8 px) shows less grid. (It
    used to halve it; since the candidates' cuts are drawn toward the outer margin (issue 10)
    a wide ring shows little more grid than the narrow one.)"""
    source = load_image(sample_path("cobblestones")).pixels
    d = params.DEFAULTS
    seam = SeamSpec(blend=d["blend"])
    template = make_seamless(source, (187, 94, 102, 126), overlap=16, seam=seam)  # w_T 16
    default = _preview_grid_score(source, template, d["patch_overlap"] or None)
    w_t = _preview_grid_score(source, template, template.overlap)
    assert default < w_t, (default, w_t)


def test_editor_patch_ring_defaults_to_auto_which_is_the_engine_default(qtbot):
    """0 = auto: the candidates the editor makes use the ring the engine and CLI choose."""
    assert params.DEFAULTS["patch_overlap"] == 0
    assert params.BY_KEY["patch_overlap"].special == "auto"
    w = make_window(qtbot)
    open_sample(qtbot, w)
    w.doc.set_param("overlap", 24)  # default ring 12, not 24 nor 8
    assert w.pipeline._tile_options()["patch_overlap"] is None
    generate(qtbot, w, n=2)
    st, entry = w.doc.tileset.seamless, w.doc.tileset.candidates[0]
    assert default_patch_overlap(st.overlap) == 12
    h, wd = entry.tile.shape[:2]
    r, c = entry.loop[:, 0], entry.loop[:, 1]
    depth = np.minimum.reduce([r, c, h - 1 - r, wd - 1 - c])
    assert depth.max() <= 11, depth.max()
