"""The editor's default candidate options keep the repeated template border small."""

from __future__ import annotations

import numpy as np

from engine.events import drain
from engine.io import load_image
from engine.metrics import grid_score
from engine.tiles import assemble, iter_candidates, make_seamless, random_layout
from quilt_gui import params
from resources import sample_path


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
    source = load_image(sample_path("cobblestones")).pixels
    d = params.DEFAULTS
    template = make_seamless(source, (187, 94, 102, 126), overlap=d["overlap"], blend=d["blend"])
    default = _preview_grid_score(source, template, d["patch_overlap"] or None)
    w_t = _preview_grid_score(source, template, None)  # ring = w_T, the engine's default
    assert default < 0.75 * w_t, (default, w_t)
