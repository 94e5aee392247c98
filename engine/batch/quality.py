"""The quality figures of one photo's set as the index shows them.

A Somol-Haindl set's figures are the ``tileset`` command's own (``manifest["quality"]``:
:func:`engine.metrics.tileset_quality`, with its warnings in the manifest). The ``tileset
--wang`` command measures nothing, so a Wang set's figures are taken here with the same metrics,
adapted to tiles that each carry their own border.
"""

from __future__ import annotations

import numpy as np

from engine.metrics import QUALITY_LIMITS

#: a photo whose detail varies more than this between its regions is not stationary
#: (:func:`detail_spread`; bundled samples and the public evaluation set: 1.1-2.3 for the
#: textures, 3.2 for the unevenly lit retina, 5-24 for the cell, the moon, the page, the text)
SPREAD_LIMIT = 4.0

#: figure -> (limit, "max" or "min"): issue 10's interior limits and issue 3's wrap and detail
#: targets; the contact sheet marks the figures past them
LIMITS = {
    **{k: (v, "max") for k, v in QUALITY_LIMITS.items()},
    "wrap": (1.15, "max"),
    "detail": (0.95, "min"),
    "spread": (SPREAD_LIMIT, "max"),
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
    """The figures of a Wang set (no template: every tile carries its own border): frame and
    ring tone within the edge band (tiles reflected, not wrapped: a Wang tile is not seamless
    with itself), duplicates among the tiles, lattice in the preview's valid ``layout``
    against crops carrying each tile's own margin, and the median detail ratio."""
    from engine.metrics import detail_ratio, duplicates, frame, lattice, ring_tone

    out = {
        "tiles": len(tiles),
        "detail": float(np.median([detail_ratio(t, source) for t in tiles])),
        "frame": frame(tiles, source, limit=2 * band, wrap=False).value,
        "ring_tone": ring_tone(tiles, source, width=band),
        "duplicates": duplicates(tiles).count,
        "lattice": lattice(tiles, source, margin=margin, layouts=[np.asarray(layout)]).above,
    }
    return _rounded(out)


def detail_spread(source, *, cells: int = 4) -> float:
    """How unevenly the detail is spread over a photo: the largest over the smallest standard
    deviation of the luminance in a ``cells`` x ``cells`` grid. A stationary texture keeps it
    near 1-2; a photo whose content changes across it (one object, text on a page, a region
    of another material) goes far higher, and a tile set can then only repeat one region's
    look. A lighting gradient alone barely changes it (the ring-tone figure and ``--flatten``
    deal with those)."""
    from engine.metrics import luminance

    y = luminance(source)
    rows = np.array_split(np.arange(y.shape[0]), cells)
    cols = np.array_split(np.arange(y.shape[1]), cells)
    sd = np.array([y[r[0] : r[-1] + 1, c[0] : c[-1] + 1].std() for r in rows for c in cols])
    floor = 1e-3  # a flat cell (a scan's border, a blank area) counts as barely textured
    return round(float(np.maximum(sd, floor).max() / np.maximum(sd, floor).min()), 4)


def spread_warning(spread: float) -> list[str]:
    """The warning a non-stationary photo gets (none below :data:`SPREAD_LIMIT`)."""
    if spread <= SPREAD_LIMIT:
        return []
    return [
        f"the photo is not stationary: its detail varies {spread:.1f}x between regions "
        f"(> {SPREAD_LIMIT:g}): the tiles repeat one region's look; crop the photo to a "
        "uniform region of the texture"
    ]


def _rounded(d: dict) -> dict:
    return {k: (v if isinstance(v, int) else round(float(v), 4)) for k, v in d.items()}
