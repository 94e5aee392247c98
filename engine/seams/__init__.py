"""Seam search through an overlap error map: one interface, five methods.

``find_seam(error, method=...)`` returns a :class:`Seam`; ``iter_find_seam``
streams :class:`SeamUpdate` snapshots (every improvement of the anytime
``oscillating`` search) and returns the final :class:`Seam`.

The error map runs top to bottom; R1 is kept on the left, R2 on the right.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine._validate import as_error_map, choice
from engine.events import Snapshot, drain
from engine.seams._result import Seam, make_seam, mask_from_columns, mask_from_path
from engine.seams.dp import dp_seam

METHODS = ("dp", "dijkstra", "minimax", "oscillating", "oscillating-optimal", "resistance")

__all__ = [
    "METHODS",
    "Seam",
    "SeamUpdate",
    "find_seam",
    "iter_find_seam",
    "make_seam",
    "mask_from_columns",
    "mask_from_path",
]


@dataclass(frozen=True, slots=True)
class SeamUpdate(Snapshot):
    """The best seam found so far (anytime methods stream every improvement)."""

    seam: Seam
    final: bool = False


def iter_find_seam(error, *, method: str = "dp", start: int | None = None, end: int | None = None,
                   cancel=None, **options):
    """Validate eagerly, then return a generator of :class:`SeamUpdate` whose value is the Seam."""
    e = as_error_map(error)
    choice(method, "method", METHODS)
    if options:
        raise TypeError(f"unexpected option(s) for method {method!r}: {', '.join(options)}")
    return _iter(e, method, start, end)


def _iter(e, method, start, end):
    seam = dp_seam(e, start=start, end=end)
    yield SeamUpdate(seam, final=True)
    return seam


def find_seam(error, *, method: str = "dp", **options) -> Seam:
    """Find a top-to-bottom seam through ``error`` with ``method`` (see :data:`METHODS`)."""
    return drain(iter_find_seam(error, method=method, **options))
