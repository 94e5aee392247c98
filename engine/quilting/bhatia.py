"""Bhatia 2004 (ALGORITHMS §4): random-block quilting with minimum resistance cut lines.

Blocks are chosen uniformly at random (no error matching) and placed on a non-overlapping grid;
each block's left and top bands are cut corner to corner, and the territories on the far side of
the cuts are filled with the neighbours' source *extensions* (the sample pixels just right of /
below the neighbour's window), the sample reflected where an extension runs out.
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from engine.cancel import check
from engine.errormap import error_map
from engine.events import Progress
from engine.exclusion import valid_anchors
from engine.quilting.core import Quilter
from engine.quilting.records import BlockPlaced, BlockRecord, read_only
from engine.seams import find_seam, make_seam

__all__ = ["bhatia_anchors", "iter_bhatia"]


def iter_bhatia(q: Quilter, band: int):
    """Bhatia 2004 (ALGORITHMS §4): random blocks on a non-overlapping grid, territories of the
    neighbours' source extensions cut by minimum resistance lines."""
    S = q.sample
    H, W = S.shape[:2]
    bh, bw = q.block
    Ho, Wo = q.out_shape
    # reflection padding where an extension runs out of the sample
    Sp = np.pad(S, ((0, band), (0, band), (0, 0)), mode="reflect")
    flat = None if q.excluded is None else np.flatnonzero(bhatia_anchors(q.excluded, q.block, band))
    nx = W - bw + 1
    ys = list(range(0, Ho, bh))
    xs = list(range(0, Wo, bw))
    ny_, nx_ = len(ys), len(xs)
    anchors = {}
    sizes = {}
    for i, y in enumerate(ys):
        for j, x in enumerate(xs):
            rng = np.random.default_rng([q.seed, i * nx_ + j])
            n = (H - bh + 1) * nx if flat is None else flat.size
            k = int(rng.integers(n))
            anchors[i, j] = divmod(k if flat is None else int(flat[k]), nx)
            sizes[i, j] = (min(bh, Ho - y), min(bw, Wo - x))

    def neighbour(i, j, di, dj):
        a, b = i + di, j + dj
        if q.tileable:
            return a % ny_, b % nx_
        return (a, b) if a >= 0 and b >= 0 else None

    def do_block(ij):
        check(q.cancel)
        i, j = ij
        h, w = sizes[ij]
        ay, ax = anchors[ij]
        own = Sp[ay : ay + h, ax : ax + w]
        srcs = [own]
        terr = np.zeros((h, w), np.int8)
        err = np.zeros((h, w), np.float32)
        paths, crit, peak = [], 0.0, 0.0
        arms = [0, 0, 0, 0]
        exts = [None, None, None]
        L, U = neighbour(i, j, 0, -1), neighbour(i, j, -1, 0)
        kb = min(band, w)
        if L is not None and w > 1:
            (ly, lx), (_, lw) = anchors[L], sizes[L]
            ext = own.copy()
            ext[:, :kb] = Sp[ly : ly + h, lx + lw : lx + lw + kb]
            e = error_map(ext[:, :kb], own[:, :kb], metric=q.seam.metric)
            seam = _bhatia_seam(q, e, own[:, :kb])
            terr[:, :kb][seam.mask] |= 1
            err[:, :kb] = e
            paths.append(np.asarray(seam.path))
            crit, peak = crit + seam.criterion, max(peak, seam.peak)
            exts[0] = ext
            arms[1] = kb
        kt = min(band, h)
        if U is not None and h > 1:
            (uy, ux), (uh, _) = anchors[U], sizes[U]
            ext = own.copy()
            ext[:kt] = Sp[uy + uh : uy + uh + kt, ux : ux + w]
            e = error_map(ext[:kt], own[:kt], metric=q.seam.metric)
            seam = _bhatia_seam(
                q, np.ascontiguousarray(e.T), np.ascontiguousarray(own[:kt].transpose(1, 0, 2))
            )
            terr[:kt][seam.mask.T] |= 2
            err[:kt] = np.maximum(err[:kt], e)
            paths.append(np.asarray(seam.path)[:, ::-1])
            crit, peak = crit + seam.criterion, max(peak, seam.peak)
            exts[1] = ext
            arms[0] = kt
        if (terr == 3).any():
            D = neighbour(i, j, -1, -1)
            (dy, dx), (dh, dw) = anchors[D], sizes[D]
            ext = own.copy()
            ext[:kt, :kb] = Sp[dy + dh : dy + dh + kt, dx + dw : dx + dw + kb]
            exts[2] = ext
        srcs += exts
        pixels = _territory_composite(terr, srcs, q.seam.blend, q.seam.width)
        path = np.concatenate(paths).astype(np.intp) if paths else np.zeros((0, 2), np.intp)
        keep = terr != 0
        rec = BlockRecord(
            index=-1,
            position=(ys[i], xs[j]),
            size=(h, w),
            source=(ax, ay, w, h),
            arms=tuple(arms),
            error=read_only(err) if paths else None,
            keep_old=read_only(keep) if paths else None,
            path=read_only(path),
            criterion=crit if paths else math.nan,
            peak=peak if paths else math.nan,
            match_error=math.nan,
            best_error=math.nan,
            candidates=1,
            territory=read_only(terr),
        )
        return rec, pixels

    cells = [(i, j) for i in range(ny_) for j in range(nx_)]
    pool = ThreadPoolExecutor(q.threads) if q.threads > 1 else None
    records = []
    try:
        chunk = max(1, nx_)
        for s in range(0, len(cells), chunk):
            check(q.cancel)
            batch = cells[s : s + chunk]
            results = list(pool.map(do_block, batch)) if pool else [do_block(c) for c in batch]
            for (i, j), (rec, pixels) in zip(batch, results, strict=True):
                h, w = sizes[i, j]
                q.canvas[ys[i] : ys[i] + h, xs[j] : xs[j] + w] = pixels
                rec = replace(rec, index=len(records))
                records.append(rec)
                if q.stream:
                    yield BlockPlaced(rec, read_only(pixels))
            if q.stream:
                yield Progress(len(records), len(cells), "blocks")
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
    return records


def bhatia_anchors(excluded: np.ndarray, block, band: int) -> np.ndarray:
    """Valid anchors of Bhatia's blocks: block plus its right/bottom extension clean, in the
    sample reflected where the extension runs out (the padding the synthesis reads)."""
    (H, W), (bh, bw) = excluded.shape, block
    padded = np.pad(excluded, ((0, band), (0, band)), mode="reflect")
    return valid_anchors(padded, block, extension=(band, band))[: H - bh + 1, : W - bw + 1]


def _bhatia_seam(q: Quilter, e: np.ndarray, own_band: np.ndarray):
    """Corner-to-corner cut of one band (canonical: extension = R1 on the left; row 0 is the
    corner the block shares with the blocks placed before it).

    The paper's blocks grow from the bottom-left corner and its line 1 starts at that corner;
    ours grow from the top-left, so the published resistance cut runs on the band turned upside
    down (its line 1 then starts at the shared corner) and is turned back."""
    spec = q.seam
    if spec.method != "resistance":
        return find_seam(e, seam=spec, start=0, end=0, cancel=q.cancel)
    # Bhatia's step: the colour difference inside the new block
    if spec.options["variant"] != "published":
        return find_seam(e, seam=spec, start=0, end=0, image=own_band, cancel=q.cancel)
    up = find_seam(
        e[::-1].copy(), seam=spec, start=0, end=0, image=own_band[::-1].copy(), cancel=q.cancel
    )
    path = np.asarray(up.path)[::-1] * (-1, 1) + (e.shape[0] - 1, 0)
    return make_seam(e, path, up.method, mask=up.mask[::-1])


def _territory_composite(terr, srcs, blend: str, width: float) -> np.ndarray:
    """Composite the territories' sources: hard, or blurred one-hot weights renormalised."""
    from scipy import ndimage

    h, w = terr.shape
    if blend == "none":
        out = srcs[0].copy()
        for t in (1, 2, 3):
            if srcs[t] is not None:
                m = terr == t
                out[m] = srcs[t][m]
        return out
    sigma = max(width / 2.0, 0.5)
    acc = np.zeros(srcs[0].shape, np.float32)
    tot = np.zeros((h, w), np.float32)
    for t in range(4):
        if t and srcs[t] is None:
            continue
        wt = ndimage.gaussian_filter((terr == t).astype(np.float32), sigma, mode="nearest")
        acc += wt[:, :, None] * srcs[t]
        tot += wt
    return acc / np.maximum(tot, 1e-12)[:, :, None]
