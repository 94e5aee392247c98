"""The project model: everything needed to reopen a tile-set session exactly, as plain data.

Conventions: rectangles are ``(x, y, w, h)`` in source pixels; points are ``(row, col)``;
``picks`` are candidate indices in export order (exported tile id ``k`` is
``candidates[picks[k]]``); ``layout`` cells are exported tile ids, -1 = empty. Images are
float32 (H, W, C) in [0, 1].
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from engine.candidate import CandidateTile

__all__ = ["PROJECT_FORMAT", "PROJECT_SUFFIX", "PROJECT_VERSION", "Project"]

PROJECT_FORMAT = "quilt-studio-project"
PROJECT_VERSION = 1
PROJECT_SUFFIX = ".quiltproj"
SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")
"""Project and map names: simple file-name parts (they name exported files)."""


@dataclass
class Project:
    """Everything needed to reopen a tile-set session exactly."""

    sources: dict[str, np.ndarray]  # map name -> float32 (H, W, C); the first is the main map
    name: str = "tileset"
    version: int = PROJECT_VERSION
    source_paths: dict[str, str] = field(
        default_factory=dict
    )  # where the maps were loaded from (info)
    map_kinds: dict[str, str] = field(default_factory=dict)
    map_weights: dict[str, float] = field(
        default_factory=dict
    )  # seam-error weights; empty = main only
    normal_convention: str = "opengl"
    bit_depth: int = 8
    parameters: dict = field(default_factory=dict)  # any JSON: every parameter of every step
    seeds: dict = field(default_factory=dict)  # any JSON: named seeds
    template_rect: tuple[int, int, int, int] | None = None  # (x, y, w, h)
    template: dict[str, np.ndarray] | None = None  # the seamless template tile per map
    # the engine's candidate type: ``tile`` is the main map's, ``maps`` the other maps'
    candidates: list[CandidateTile] = field(default_factory=list)
    picks: list[int] = field(default_factory=list)
    layout: np.ndarray | None = None  # (rows, cols) exported tile ids, -1 = empty
    waypoints: dict[str, list[tuple[int, int]]] = field(default_factory=dict)  # per seam key
    preview: dict[str, np.ndarray] | None = None
    extra: dict = field(default_factory=dict)  # any JSON the editor wants to keep
    # other images of the session, by simple name: the editor keeps its quilting or transfer
    # output ("quilt") and the transfer target ("transfer_target") here; any size
    outputs: dict[str, np.ndarray] = field(default_factory=dict)
    # a Wang set (engine.tiles.wang), beside the candidates: its record {"colours": K,
    # "tile_size": T, "variants": V, "samples": [{"axis", "colour", "origin": [row, col],
    # "error"}...], "layout": [[tile index...]...] or None, ...} and its tiles, whose params
    # hold their edge signature {"wang": {"n", "e", "s", "w"}, "variant": v, ...}
    wang: dict | None = None
    wang_tiles: list[CandidateTile] = field(default_factory=list)

    @property
    def main_map(self) -> str:
        return next(iter(self.sources))

    def exported_tiles(self) -> list[dict[str, np.ndarray]]:
        """The tiles an export writes: the picked candidates (all candidates if none picked)."""
        order = self.picks if self.picks else range(len(self.candidates))
        return [self.candidates[i].images(self.main_map) for i in order]
