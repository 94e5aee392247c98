"""Seam search through an overlap error map: one interface, six methods.

``find_seam(error, method=...)`` returns a :class:`Seam`; ``iter_find_seam`` streams
:class:`SeamUpdate` snapshots (every improvement of the anytime ``oscillating`` search, a single
final one for the others) and returns the final :class:`Seam`. A :class:`SeamSpec` (method,
options, metric, blend) is what the workflows pass around: ``find_seam(error, seam=spec)``
and ``iter_find_seam(error, seam=spec)`` search with it.

The error map runs top to bottom; a path starts anywhere in the top row and ends anywhere in the
bottom row; R1 is kept on the left, R2 on the right.

=======================  ===================================================  ==============
method                   what                                                 options
=======================  ===================================================  ==============
``dp``                   minimum error boundary cut, one pixel per row        —
``dijkstra``             cumulative node cost on the pixel graph (may wind)   connectivity
``minimax``              Long & Mould (peak, sum): exact / lm / sorted        variant, levels,
                                                                              connectivity
``oscillating``          Somol & Haindl's anytime control-point search        o_max, variant,
                                                                              init
``oscillating-optimal``  exact optimum of the same control-point model        —
``resistance``           Bhatia's minimum resistance cut line                 variant,
                                                                              max_run
                                                                              (+ ``image``)
=======================  ===================================================  ==============

Constraints: ``start`` / ``end`` pin the column of the first / last row; ``waypoints`` are
(row, col) pixels the path passes through (distinct rows). One-point-per-row models (dp and the
control-point models) pin those rows; the graph methods and the walk solve one segment between
consecutive anchors, each inside its band of rows and off the pixels of earlier segments.
``cyclic`` makes rows 0 and h-1 neighbours (toroidal template): supported by ``dp``,
``oscillating`` and ``oscillating-optimal``; the other methods raise ValueError.

``oscillating`` options: ``o_max`` (largest block of control points moved at once), ``variant``
(``"faithful"``: restart at o = 1, j = 0 after every improvement, as published; ``"resume"``:
continue at the current row) and ``init``, the starting path (``"argmin"``: per-row argmin, as
published; ``"dp"``: the exact one-pixel-per-row cut; ``"smoothed"``: per-row argmin of the map
smoothed along the rows). The paper's algorithm is ``variant="faithful", init="argmin"``; the
default ``variant="resume", init="dp"`` keeps its moves but starts from the DP cut: from the
argmin start the search ends 31-65 % above the model's optimum on real overlaps at o_max = 3,
from the DP cut 0.7-2.3 % (see :mod:`engine.seams.oscillating`).

``resistance`` options: ``variant`` (``"published"``: Bhatia's two lines from the corners that
meet, the cut running from (0, start or 0) to (h - 1, end or 0); ``"walk"``: one greedy walk from
the top row down) and ``max_run`` (longest straight run, 5 as in the paper's figure); the new
block's colours as ``image`` give the paper's step cost. See :mod:`engine.seams.resistance`.
"""

from __future__ import annotations

from engine._lazy import lazy_exports

# Names are loaded on first use (PEP 562), so that importing the light tables of
# :mod:`engine.seams.spec` (the command line's parsers do) does not load the numba solvers.
_EXPORTS = {
    "BLEND_MODES": "engine.seams.spec",
    "CYCLIC_METHODS": "engine.seams.spec",
    "METHODS": "engine.seams.spec",
    "METRICS": "engine.seams.spec",
    "OPTIONS": "engine.seams.spec",
    "SeamSpec": "engine.seams.spec",
    "check_option_names": "engine.seams.spec",
    "Seam": "engine.seams._result",
    "make_seam": "engine.seams._result",
    "mask_from_columns": "engine.seams._result",
    "mask_from_path": "engine.seams._result",
    "graph_path": "engine.seams.graph",
    "SeamUpdate": "engine.seams.search",
    "find_seam": "engine.seams.search",
    "iter_find_seam": "engine.seams.search",
    "warmup": "engine.seams.search",
}

__all__ = sorted(_EXPORTS)


__getattr__, __dir__ = lazy_exports(globals(), _EXPORTS)
