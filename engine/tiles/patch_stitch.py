"""One patch stitched into a tile along a closed cut in its ring (candidates, Wang interiors).

:func:`stitch_patch` searches the closed minimum-error cut (:func:`engine.stitch.patch_cut`)
on the maps' weighted error, drawn toward the fixed outer margin, and applies it (hard or
adaptive alpha, or blended in the gradient domain: :func:`gradient_blend`).

**The cut beside the margin** (``continue_margin``, the candidates' default) [REC]: the outer
``margin`` pixels always keep the template, so a cut through the first free pixels (distance
``margin`` from the edge) joins the patch to the template's margin pixel — that joint is good
when the patch *continues* the margin (its own pixel there matches the template's), whatever
the template holds just inside. The pixel error alone (patch against template at the cut
pixel) made such cuts expensive exactly where the template has a structure 1-3 px in from its
edge — a plank's butt joint, a stroke of text crossing the edge — so the cut went round it
and every candidate kept it: the same mark at every tile of a layout (planks: 86 % of the
candidates kept the template's joint). There the error is the smaller of the pixel's own and
its outer neighbour's (the margin pixel's).
"""

from __future__ import annotations

import numpy as np

from engine._validate import positive_int
from engine.cancel import check
from engine.materials import apply_cut
from engine.poisson import solve_maps
from engine.seams.spec import POISSON
from engine.stitch import patch_cut
from engine.tiles.seamless import MAIN, seam_error

__all__ = ["POISSON_REACH", "check_ring", "continuing_margin", "gradient_blend", "stitch_patch"]

#: blend "poisson": the correction fades over about this many rings' widths from the cut (a
#: screened solve), so a patch keeps its own tone inside instead of taking the shared ring's
POISSON_REACH = 2.0


def check_ring(patch_overlap, margin, *, min_margin: int = 0) -> tuple[int, int]:
    """(w_P, margin) validated: the ring a closed patch cut runs in (>= 2 px) and the outer
    pixels it never touches (``min_margin`` .. w_P - 1)."""
    ring = positive_int(patch_overlap, "patch_overlap", minimum=2)
    m = positive_int(margin, "margin", minimum=min_margin)
    if m >= ring:
        raise ValueError(
            f"margin must be smaller than patch_overlap, got margin={m}, patch_overlap={ring}"
        )
    return ring, m


def continuing_margin(error: np.ndarray, margin: int, *, copy: bool = True) -> np.ndarray:
    """``error`` (h, w) with the pixels at distance ``margin`` from the window's edge (the
    first a cut may use) costing the smaller of their own error and their outer neighbour's
    (module docstring); unchanged for ``margin`` 0. ``copy=False`` changes ``error`` itself
    (the outer neighbours it reads are never written)."""
    m = int(margin)
    h, w = error.shape
    if m < 1 or min(h, w) < 2 * m + 2:
        return error
    e = np.array(error, copy=True) if copy else error
    for a, b in ((m, m - 1), (h - 1 - m, h - m)):  # top and bottom rows
        e[a, m : w - m] = np.minimum(error[a, m : w - m], error[b, m : w - m])
    for a, b in ((m, m - 1), (w - 1 - m, w - m)):  # left and right columns
        e[m : h - m, a] = np.minimum(e[m : h - m, a], error[m : h - m, b])
    return e


def stitch_patch(
    q,
    u,
    *,
    ring,
    margin,
    seam,
    weights,
    outward,
    depth,
    continue_margin=False,
    reach=POISSON_REACH,
    cancel=None,
):
    """Window ``q`` ({map: image}) stitched into ``u`` along a closed cut in the ring (its
    error the maps' weighted error, drawn toward the outer margin by ``outward`` x the mean
    error x ``depth``; ``continue_margin``: beside the margin as :func:`continuing_margin`):
    ``({map: result}, PatchCut)``. Candidates and Wang interiors.

    ``seam.blend == "poisson"``: the hard cut blended in the gradient domain
    (:func:`gradient_blend`, screened at ``reach`` x ``ring``)."""
    err = seam_error(q, u, weights, seam.metric)
    if continue_margin:
        err = continuing_margin(err, margin, copy=False)  # err is this call's own
    bias = (outward * float(err.mean())) * depth if outward else None
    cut = patch_cut(
        q[MAIN], u[MAIN], ring=ring, margin=margin, seam=seam, error=err, bias=bias, cancel=cancel
    )
    check(cancel)
    if seam.blend == POISSON:
        return gradient_blend(q, u, cut, ring=ring, margin=margin, reach=reach), cut
    return apply_cut(q, u, cut.alpha), cut


def gradient_blend(q, u, cut, *, ring, margin, reach=POISSON_REACH):
    """Window ``q`` stitched into ``u`` along ``cut``'s hard cut, blended in the gradient domain
    (:func:`engine.poisson.solve_maps`, screened at ``reach`` x ``ring``, by default
    :data:`POISSON_REACH`), the outer ``margin`` pixels (at least 1) kept bit for bit."""
    return solve_maps(q, u, cut.mask, fixed=max(1, margin), reach=reach * ring)
