"""Image quilting: Efros & Freeman 2001 and the variants of Long & Mould, Bhatia, CS194, Core S2.

ALGORITHMS.md §0, §2, §3, §4, §5. ``iter_quilt`` synthesizes an output of any size from a
sample, streaming a :class:`BlockPlaced` item per block and :class:`~engine.events.Progress`;
``quilt`` drains it and returns the :class:`QuiltResult`.

Modules: :mod:`~engine.quilting.synthesis` (the entry points), :mod:`~engine.quilting.options`
(checked once), :mod:`~engine.quilting.layout` (the block grid), :mod:`~engine.quilting.core`
(the block loop: search, choose, cut, paste), :mod:`~engine.quilting.cut` (cut and blend of an
overlap), :mod:`~engine.quilting.scheduler` (levels, dependencies, threads),
:mod:`~engine.quilting.bhatia` (Bhatia's random blocks with extensions),
:mod:`~engine.quilting.records` (what is streamed and returned). The grid metric is
:func:`engine.metrics.block_grid_border_ratio`.

Layout and order
    Blocks of ``block`` pixels lie on a grid with a step of ``block - overlap``; per axis
    ``ceil((N - overlap) / step)`` blocks, the last ones cropped (only their valid part is
    compared). ``tileable=True`` places ``ceil(N / step)`` evenly spaced blocks on a torus, so the
    last column and row overlap the first ones (wrap-around overlaps) and the output tiles.
    ``adaptive_threshold`` splits a block whose best overlap error is too high into four smaller
    overlapping blocks (recursively, down to ``min_block``), as in the hybrid framework Long &
    Mould built on.

Selection (``select``)
    ``"best"``: every sample position is scored by the masked SSD over the overlap (the *union* of
    the left and top strips, no double-counted corner; §2.2 FIX), computed for all positions at
    once by FFT (:mod:`engine.matching`); the block is drawn uniformly among the positions within
    ``1 + tolerance`` of the best. ``mode="fast"`` ranks positions by a principal-component
    estimate and re-ranks the ``candidates`` best exactly. ``"sampled"``: the best of
    ``candidates`` uniformly random positions (CS194: several hundred; Core S2: a dozen).
    ``"random"``: any position (CS194's naive baseline). ``"bhatia"``: Bhatia's random blocks on a
    non-overlapping grid whose neighbours' source *extensions* fill territories cut by minimum
    resistance lines (§4).

Boundary (``seam``)
    ``"straight"``: the new block covers the whole overlap (``blend="feather"`` cross-fades it);
    otherwise a cut by any :mod:`engine.seams` method through the overlap error map: the L-shaped
    overlap is cut as one path joined in the corner (:func:`engine.stitch.l_cut`), wrap-around
    arms get a cut each. ``blend`` softens the cut (``"feather"``: ``blend_width`` pixels;
    ``"adaptive"``: ρ-adaptive half-widths, §1.3).

Determinism and threads
    Every block draws from its own generator seeded by (seed, block index), and each block is
    searched on exactly the canvas its predecessors left: the output is identical for any number
    of threads (:mod:`~engine.quilting.scheduler`).
"""

from engine._lazy import lazy_exports

# Names are loaded on first use (PEP 562): the command line's parsers read the tables of
# engine.quilting.names without loading numpy, and a module imports what it uses once.
_EXPORTS = {
    "MODES": "engine.quilting.names",
    "SEAMS": "engine.quilting.names",
    "SELECTIONS": "engine.quilting.names",
    "BlockPlaced": "engine.quilting.records",
    "BlockRecord": "engine.quilting.records",
    "Estimated": "engine.quilting.estimate",
    "Plan": "engine.quilting.estimate",
    "QuiltResult": "engine.quilting.records",
    "iter_quilt": "engine.quilting.synthesis",
    "quilt": "engine.quilting.synthesis",
}

__all__ = sorted(_EXPORTS)


__getattr__, __dir__ = lazy_exports(globals(), _EXPORTS)
