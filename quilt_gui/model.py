"""Plain data of the document (no Qt): the opened source (a candidate tile is the engine's own
:class:`engine.candidate.CandidateTile`). The document modules (:mod:`quilt_gui.document`,
:mod:`quilt_gui.tileset_doc`, :mod:`quilt_gui.quilting_doc`) and the views share these types."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

WAYPOINT_KEYS = ("horizontal", "vertical")


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
