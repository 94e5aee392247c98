"""The options of image quilting, checked once: names, defaults and the messages for bad input."""

from __future__ import annotations

import math
import numbers
import os

import numpy as np

from engine._validate import as_image, choice, non_negative_number, positive_int
from engine.exclusion import valid_anchors
from engine.matching import check_block
from engine.quilting.bhatia import bhatia_anchors
from engine.quilting.layout import check_torus_axis, torus_overlap
from engine.quilting.names import MODES, SEAMS, SELECTIONS
from engine.seams import SeamSpec
from engine.seams.spec import check_blend

QUILT_SEAM = SeamSpec("dp", metric="ssd")
"""Quilting's default cut: Efros & Freeman's minimum error boundary cut on the squared error,
no blending."""
BHATIA_SEAM = SeamSpec("resistance", metric="ssd", blend="feather")
"""The default cut of ``select="bhatia"``: Bhatia's minimum resistance cut line as published,
the pixels around it blended ("the pixels around the cut line are blended", Bhatia §3)."""
DEFAULT_SAMPLED = 200
DEFAULT_RERANK = 32

__all__ = [
    "DEFAULT_RERANK",
    "DEFAULT_SAMPLED",
    "BHATIA_SEAM",
    "QUILT_SEAM",
    "MODES",
    "SEAMS",
    "SELECTIONS",
    "check_options",
    "check_out_shape",
    "sample_array",
    "resolve_threads",
]


def resolve_threads(threads) -> int:
    """``threads`` as a positive int (None: every core)."""
    if threads is None:
        return max(1, os.cpu_count() or 1)
    return positive_int(threads, "threads")


def check_out_shape(out_shape) -> tuple[int, int]:
    """``out_shape`` as (height, width), two positive ints."""
    try:
        h, w = out_shape
    except (TypeError, ValueError):
        raise TypeError(f"out_shape must be (height, width), got {out_shape!r}") from None
    for v in (h, w):
        if isinstance(v, bool) or not isinstance(v, numbers.Integral):
            raise TypeError(f"out_shape must hold two integers, got {out_shape!r}")
    if h < 1 or w < 1:
        raise ValueError(f"out_shape must be at least 1x1, got {w}x{h} (width x height)")
    return int(h), int(w)


def sample_array(sample, name: str = "sample") -> np.ndarray:
    """``sample`` as float32 (H, W, C) in [0, 1]: a read-only view when it already is float32
    (a large photo is not copied; the caller must not change it while a run reads it), else
    :func:`engine._validate.as_image`'s converted copy."""
    a = sample if isinstance(sample, np.ndarray) else None
    if a is None or a.dtype != np.float32 or a.ndim not in (2, 3) or 0 in a.shape:
        return as_image(sample, name)
    for i in range(0, a.shape[0], 256):  # finite, checked in strips (no full-size temporary)
        if not np.isfinite(a[i : i + 256]).all():
            raise ValueError(f"{name} contains NaN or infinite values")
    v = a[:, :, None] if a.ndim == 2 else a.view()
    v.setflags(write=False)
    return v


def check_options(
    sample,
    out_shape,
    *,
    block,
    overlap,
    select,
    tolerance,
    candidates,
    seam,
    excluded,
    tileable,
    adaptive_threshold,
    min_block,
    mode,
) -> dict:
    """The keywords of :func:`engine.quilting.iter_quilt` validated, defaults filled in: a dict
    with the same names (``sample`` as float32 (H, W, C), ``seam`` a :class:`SeamSpec`,
    ``excluded`` as bool or None)."""
    s = sample_array(sample)
    H, W = s.shape[:2]
    Ho, Wo = check_out_shape(out_shape)
    bh, bw = check_block(block)
    choice(select, "select", SELECTIONS)
    if seam is None:
        seam = BHATIA_SEAM if select == "bhatia" else QUILT_SEAM
    if not isinstance(seam, SeamSpec):
        raise TypeError(
            "seam must be an engine.seams.SeamSpec (e.g. SeamSpec('dp', metric='ssd')), "
            f"got {type(seam).__name__}"
        )
    check_blend(seam, "quilting")
    choice(mode, "mode", MODES)
    if overlap is None:
        overlap = max(1, min(bh, bw) // (2 if seam.method == "minimax" else 6))
        if select == "bhatia":
            overlap = max(1, min(bh, bw) // 4)
        elif tileable:  # the torus spaces blocks evenly: keep them more than half a block apart
            overlap = min(torus_overlap(Ho, bh, overlap), torus_overlap(Wo, bw, overlap))
    overlap = positive_int(overlap, "overlap", minimum=0)
    if overlap >= min(bh, bw):
        raise ValueError(f"overlap must be smaller than the block ({min(bh, bw)}), got {overlap}")
    if select == "bhatia" and overlap < 1:
        raise ValueError("overlap (the cut band) must be >= 1 with select='bhatia'")
    if select == "bhatia" and not seam.cuts:
        raise ValueError("select='bhatia' needs a cut: choose a seam method, e.g. 'resistance'")
    if bh > H or bw > W:
        raise ValueError(
            f"the sample ({W}x{H}) is smaller than the block ({bw}x{bh}); use a smaller block"
        )
    if bh > Ho or bw > Wo:
        raise ValueError(
            f"the block ({bw}x{bh}) is larger than the output ({Wo}x{Ho}); use a smaller block"
        )
    if tileable and select != "bhatia":
        check_torus_axis(Ho, bh, overlap, "height")
        check_torus_axis(Wo, bw, overlap, "width")
    tolerance = non_negative_number(tolerance, "tolerance")
    if candidates is None:
        candidates = DEFAULT_SAMPLED if select == "sampled" else DEFAULT_RERANK
    candidates = positive_int(candidates, "candidates")
    ex = None
    if excluded is not None:
        ex = np.asarray(excluded)
        if ex.shape != (H, W):
            raise ValueError(f"excluded must be shaped {(H, W)} like the sample, got {ex.shape}")
        ex = ex.astype(bool)
        if select == "bhatia":
            if not bhatia_anchors(ex, (bh, bw), overlap).any():
                raise ValueError(
                    "every block position (with its extension) in the sample contains an "
                    "excluded pixel"
                )
        elif not valid_anchors(ex, (bh, bw)).any():
            raise ValueError("every block position in the sample contains an excluded pixel")
    if adaptive_threshold is not None:
        if isinstance(adaptive_threshold, bool) or not isinstance(adaptive_threshold, numbers.Real):
            raise TypeError(f"adaptive_threshold must be a number, got {adaptive_threshold!r}")
        if not (math.isfinite(adaptive_threshold) and adaptive_threshold > 0):
            raise ValueError(f"adaptive_threshold must be > 0, got {adaptive_threshold}")
    if min_block is None:
        min_block = max(2 * overlap + 1, min(bh, bw) // 4)
    else:
        min_block = positive_int(min_block, "min_block")
        if min_block > min(bh, bw):
            raise ValueError(
                f"min_block ({min_block}) is larger than the block ({bw}x{bh}); adaptive "
                "splitting only makes blocks smaller"
            )
    min_block = positive_int(min_block, "min_block")
    if min_block <= overlap:
        raise ValueError(f"min_block must be larger than the overlap ({overlap}), got {min_block}")
    return dict(
        sample=s,
        out_shape=(Ho, Wo),
        block=(bh, bw),
        overlap=overlap,
        select=select,
        tolerance=tolerance,
        candidates=candidates,
        seam=seam,
        excluded=ex,
        tileable=tileable,
        adaptive_threshold=adaptive_threshold,
        min_block=min_block,
        mode=mode,
    )
