"""Tile sets after Somol & Haindl (ALGORITHMS.md §1.5–§1.8).

1. :func:`iter_find_template` — where and how big the tile is (opposite borders that match);
2. :func:`iter_make_seamless` — stitch R_R over R_L and R_B over R_T (cyclic second seam);
3. :func:`iter_candidates` — variants of the template with one patch each along a closed,
   pinned cut, all keeping the template's border so every tile connects to every other;
4. :func:`random_layout` / :func:`assemble` — index matrices and tiled synthesis.

:func:`iter_tileset` runs them all with one :class:`TilesetSettings` (:mod:`engine.settings`).

Each ``iter_x`` validates eagerly and returns a generator of events whose value is the
result; ``x`` drains it.
"""

from engine.tiles.candidates import (
    CandidateTile,
    candidate_seed,
    candidates,
    default_patch_overlap,
    iter_candidates,
    make_candidate,
)
from engine.tiles.layout import assemble, random_layout
from engine.tiles.pipeline import TilesetResult, TilesetSettings, iter_tileset, tileset
from engine.tiles.seamless import (
    MAIN,
    SeamlessTile,
    SeamlessUpdate,
    iter_make_seamless,
    make_seamless,
)
from engine.tiles.template import (
    Template,
    TemplateSweep,
    TemplateUpdate,
    default_overlap,
    find_template,
    iter_find_template,
    template_cost,
)

__all__ = [
    "MAIN",
    "CandidateTile",
    "SeamlessTile",
    "SeamlessUpdate",
    "Template",
    "TilesetResult",
    "TilesetSettings",
    "TemplateSweep",
    "TemplateUpdate",
    "assemble",
    "candidate_seed",
    "candidates",
    "default_overlap",
    "default_patch_overlap",
    "find_template",
    "iter_candidates",
    "iter_find_template",
    "iter_make_seamless",
    "iter_tileset",
    "make_candidate",
    "make_seamless",
    "random_layout",
    "template_cost",
    "tileset",
]
