"""The quality figures of one photo's tile set, and the warnings they raise in the index.

Joint figures (wrap border ratio and detail ratio of the seamless tile) and the interior ones
of issue 10 (frame, ring tone, duplicates, lattice above its floor, template share), with
issue 10's acceptance limits: a figure past its limit becomes a warning in words.
"""

from __future__ import annotations

import numpy as np

#: figure -> (limit, "max" or "min", what a person sees when it is past the limit)
LIMITS = {
    "wrap": (1.15, "max", "the seamless tile's joint shows (wrap border ratio {v:.2f})"),
    "detail": (0.95, "min", "the tile is blurrier than the photo (detail ratio {v:.2f})"),
    "frame": (1.15, "max", "the tiles show a frame along their edges (frame {v:.2f})"),
    "ring_tone": (1.3, "max", "the tiles' border differs in tone (ring tone {v:.2f})"),
    "duplicates": (0, "max", "{v:.0f} candidate(s) repeat the template or each other"),
    "lattice": (1.5, "max", "a layout shows a lattice ({v:+.1f} dB above its floor)"),
}


def measure(source, template, tiles, *, patch_overlap: int, margin: int) -> dict:
    """Every figure of :data:`LIMITS` plus ``share`` (mean template share) and ``tiles``."""
    from engine.metrics import (
        detail_ratio,
        duplicates,
        frame,
        lattice,
        ring_tone,
        template_share,
        wrap_border_ratio,
    )

    out = {
        "tiles": len(tiles),
        "wrap": wrap_border_ratio(template),
        "detail": detail_ratio(template, source),
    }
    if tiles:
        out["frame"] = frame(tiles, source, limit=2 * patch_overlap).value
        out["ring_tone"] = ring_tone(tiles, source, width=patch_overlap)
        out["duplicates"] = duplicates(tiles, template).count
        out["lattice"] = lattice(tiles, source, template=template, margin=margin).above
        out["share"] = float(np.mean(template_share(tiles, template)))
    return {k: (v if isinstance(v, int) else round(float(v), 4)) for k, v in out.items()}


def measure_wang(source, tiles, *, band: int, margin: int, layout) -> dict:
    """The figures of a Wang set (no template: every tile carries its own border): frame and
    ring tone within the edge band (tiles reflected, not wrapped: a Wang tile is not
    seamless with itself), duplicates among the tiles, lattice in the preview's valid
    ``layout`` against crops carrying each tile's own margin, and the median detail ratio."""
    from engine.metrics import detail_ratio, duplicates, frame, lattice, ring_tone

    out = {
        "tiles": len(tiles),
        "detail": float(np.median([detail_ratio(t, source) for t in tiles])),
        "frame": frame(tiles, source, limit=2 * band, wrap=False).value,
        "ring_tone": ring_tone(tiles, source, width=band),
        "duplicates": duplicates(tiles).count,
        "lattice": lattice(tiles, source, margin=margin, layouts=[np.asarray(layout)]).above,
    }
    return {k: (v if isinstance(v, int) else round(float(v), 4)) for k, v in out.items()}


def metric_warnings(metrics: dict) -> list[str]:
    """The figures of ``metrics`` past their :data:`LIMITS`, in words."""
    out = []
    for name, (limit, kind, text) in LIMITS.items():
        v = metrics.get(name)
        if v is None:
            continue
        if (kind == "max" and v > limit) or (kind == "min" and v < limit):
            out.append(text.format(v=v))
    return out
