"""One candidate tile, the same value from the engine to the project file to the editor.

:class:`CandidateTile` is what :func:`engine.tiles.iter_candidates` streams, what a
:class:`engine.project.Project` holds in ``candidates`` and saves, and what the editor's
gallery shows; the user's choices about it (``locked``, ``weight``) are fields of it too. A
layer that needs less reads less: the command line's manifest entry is :meth:`manifest_entry`,
a project's images per map name are :meth:`images`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from engine.events import Item

__all__ = ["CandidateTile"]


@dataclass(frozen=True, slots=True)
class CandidateTile(Item):
    """One candidate tile.

    Attributes
    ----------
    index : int
        Its slot (0 .. n-1) in the run that made it (its position in a project).
    tile : (h, w, C) float32
        The template with the patch stitched in (the source's map).
    maps : dict
        The same candidate for every other material map, by map name.
    patch_rect : (x, y, w, h) or None
        Where the patch comes from in the source.
    patch_origin : (row, col) or None
        Its top-left corner (what :func:`engine.tiles.make_candidate` takes back).
    target_rect : (x, y, w, h) or None
        Where the patch window lies in the tile.
    loop : (N, 2) int or None
        The closed cut path (row, col) in tile coordinates.
    mask, alpha : (h, w) or None
        True / weight where the tile shows the patch (not kept in project files).
    scores : dict
        ``criterion`` and ``peak`` (sum and max of the error on the loop), ``band_error``
        (mean ring error of the chosen position), ``changed`` (share of tile pixels that
        differ from the template), ``coverage`` (share inside the loop).
    seed : int or None
        The candidate's own seed (``None`` for a user-placed patch).
    locked : bool
        Kept when the candidates are generated again.
    weight : float
        How often a random layout uses it, relative to the others.
    params : dict
        Any other JSON a project keeps with it (a Wang tile's edge colours ``"wang"``...).
    """

    index: int
    tile: np.ndarray
    maps: dict = field(default_factory=dict)
    patch_rect: tuple[int, int, int, int] | None = None
    patch_origin: tuple[int, int] | None = None
    target_rect: tuple[int, int, int, int] | None = None
    loop: np.ndarray | None = None
    mask: np.ndarray | None = None
    alpha: np.ndarray | None = None
    scores: dict = field(default_factory=dict)
    seed: int | None = None
    locked: bool = False
    weight: float = 1.0
    params: dict = field(default_factory=dict)

    @property
    def score(self) -> float | None:
        """The mean error per pixel of the closed cut (``criterion`` over the loop's length),
        the gallery's score; a project that kept only a score has it in ``scores["score"]``."""
        crit = self.scores.get("criterion")
        if crit is not None and self.loop is not None and len(self.loop):
            return float(crit) / len(self.loop)
        value = self.scores.get("score")
        return None if value is None else float(value)

    def images(self, main: str = "main") -> dict[str, np.ndarray]:
        """The tile of every map by name, the source's (named ``main``) first."""
        return {main: self.tile, **self.maps}

    def replace(self, **changes) -> CandidateTile:
        """A copy with ``changes`` (e.g. ``locked=True``, ``weight=2.0``)."""
        return dataclasses.replace(self, **changes)

    def manifest_entry(self, files: dict[str, str]) -> dict:
        """The JSON entry of this tile in an output manifest whose image ``files`` are given
        per map (``"main"`` for the source's)."""
        return {
            "index": self.index,
            "file": files["main"],
            "maps": files,
            "seed": self.seed,
            "source_rect": None if self.patch_rect is None else list(self.patch_rect),
            "patch_origin": None if self.patch_origin is None else list(self.patch_origin),
            "target_rect": None if self.target_rect is None else list(self.target_rect),
            "scores": {k: float(v) for k, v in self.scores.items()},
        }
