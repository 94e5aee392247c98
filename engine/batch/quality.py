"""The quality figures of one photo's set as the index shows them.

A Somol-Haindl set's figures are the ``tileset`` command's own (``manifest["quality"]``:
:func:`engine.metrics.tileset_quality`, with its warnings in the manifest). The ``tileset
--wang`` command measures nothing, so a Wang set's figures are taken here with the same metrics,
adapted to tiles that each carry their own border.
"""

from __future__ import annotations

import numpy as np

from engine.metrics import QUALITY_LIMITS
from engine.tiles.stationarity import DETAIL_LIMIT

#: figure -> (limit, "max" or "min"): issue 10's interior limits and issue 3's wrap and detail
#: targets; the contact sheet marks the figures past them
LIMITS = {
    **{k: (v, "max") for k, v in QUALITY_LIMITS.items()},
    "wrap": (1.15, "max"),
    "detail": (0.95, "min"),
    "spread": (DETAIL_LIMIT, "max"),
}

#: the figures an index row shows (``manifest["quality"]`` has a few more)
FIGURES = ("wrap", "detail", "frame", "ring_tone", "duplicates", "lattice", "template_share")


def past_limit(name: str, value) -> bool:
    """True when ``value`` of figure ``name`` is past its :data:`LIMITS` entry."""
    lim = LIMITS.get(name)
    if lim is None or value is None:
        return False
    return value > lim[0] if lim[1] == "max" else value < lim[0]


def somol_figures(manifest: dict) -> dict:
    """The index's figures of a Somol-Haindl set from its manifest."""
    q = manifest.get("quality") or {}
    out = {"tiles": len(manifest["tiles"])}
    out.update({k: q[k] for k in FIGURES if q.get(k) is not None})
    return _rounded(out)


def wang_figures(source, tiles, *, band: int, margin: int, layout) -> dict:
    """The figures of a Wang set (no template: every tile carries its own border): frame within
    the edge band read in the preview's valid ``layout`` (:func:`_wang_frame`), ring tone within
    it, duplicates among the tiles, lattice in that layout against crops carrying each tile's
    own margin, and the median detail ratio."""
    from engine.metrics import detail_ratio, duplicates, lattice, ring_tone

    out = {
        "tiles": len(tiles),
        "detail": float(np.median([detail_ratio(t, source) for t in tiles])),
        "frame": _wang_frame(source, tiles, 2 * band, np.asarray(layout)),
        "ring_tone": ring_tone(tiles, source, width=band),
        "duplicates": duplicates(tiles).count,
        "lattice": lattice(tiles, source, margin=margin, layouts=[np.asarray(layout)]).above,
    }
    return _rounded(out)


def _wang_frame(source, tiles, limit: int, layout: np.ndarray) -> float:
    """The frame of Wang tiles inside their ``layout``, every tile with its real neighbours
    (:func:`engine.metrics.layout_frame`; README "Session 13 (wang13)": reflected at its own
    border, a grout line cut by the tile edge read as a frame of 1.5 where the layout is a
    perfect grid), against crops in the first tile's phase on a periodic texture that the tile
    holds whole (as the Wang benchmark's; random-phase crops read the period itself as a
    frame); a layout without an interior tile line within reach (a single row or
    column, tiles under 12 px) falls back to the tiles reflected at their border."""
    from engine.metrics import frame, layout_frame
    from engine.tiles.layout import assemble

    if min(layout.shape) >= 2:
        try:
            size = np.shape(tiles[0])[:2]
            image = assemble(tiles, layout)
            return layout_frame([image], source, tile=size, limit=limit, template=tiles[0]).value
        except ValueError:
            pass
    return frame(tiles, source, limit=limit, wrap=False).value


def detail_spread(source) -> float:
    """The source's detail spread as the template search judges it
    (:func:`engine.tiles.stationarity.check_stationarity`: the busiest blocks' high-frequency
    energy over the calmest ones'; past :data:`DETAIL_LIMIT` the search warns that the
    photo is not the same texture everywhere). Capped at 1e6 (a blank region gives infinity)."""
    from engine.tiles.stationarity import check_stationarity

    return round(min(check_stationarity(source).detail, 1e6), 4)


def _rounded(d: dict) -> dict:
    return {k: (v if isinstance(v, int) else round(float(v), 4)) for k, v in d.items()}
