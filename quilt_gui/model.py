"""Plain data of the document (no Qt): the opened source and one candidate tile as the editor
shows it. The document modules (:mod:`quilt_gui.document`, :mod:`quilt_gui.tileset_doc`,
:mod:`quilt_gui.quilting_doc`) and the views share these types."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

WAYPOINT_KEYS = ("horizontal", "vertical")


@dataclass(frozen=True)
class CandidateEntry:
    """One candidate tile as the editor shows it.

    ``maps`` holds the tile per material map (main map first); ``patch_rect`` is the
    patch source in source pixels (x, y, w, h) and ``patch_origin`` its (row, col);
    ``target_rect`` where that window lies in the tile (x, y, w, h); ``loop`` the closed
    seam pixels (row, col) in tile coordinates.
    """

    maps: dict[str, np.ndarray]
    patch_origin: tuple[int, int] | None = None
    patch_rect: tuple[int, int, int, int] | None = None
    seed: int | None = None
    score: float | None = None
    scores: dict = field(default_factory=dict)
    locked: bool = False
    weight: float = 1.0
    loop: np.ndarray | None = None
    target_rect: tuple[int, int, int, int] | None = None

    @property
    def tile(self) -> np.ndarray:
        return next(iter(self.maps.values()))


@dataclass(frozen=True)
class Source:
    """The opened source: material maps (main first), where they came from, bit depth."""

    maps: dict[str, np.ndarray]
    paths: dict[str, str]
    bit_depth: int = 8
    kinds: dict[str, str] = field(default_factory=dict)

    @property
    def main(self) -> np.ndarray:
        return next(iter(self.maps.values()))

    @property
    def main_name(self) -> str:
        return next(iter(self.maps))

    @property
    def extra_maps(self) -> dict[str, np.ndarray]:
        """The material maps other than the main one."""
        return {k: v for k, v in self.maps.items() if k != self.main_name}

    @property
    def path(self) -> str:
        return next(iter(self.paths.values()), "")

    @property
    def shape(self) -> tuple[int, int]:
        return self.main.shape[:2]


def safe_name(text: str) -> str:
    """A project / file-name part made of letters, digits, ``. _ -`` (export names)."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._-")
    return (s or "tileset")[:100]
