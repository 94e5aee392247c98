"""The Wang frame's yardstick against genuine crops and planted frames (issue 11, session 7).

Run ``python -m benchmarks.wang_frame_oracle`` (``--help`` for options). Per texture of an
evaluation set, with the benchmark's yardstick (:func:`benchmarks.wang.wang_frame`, 2 w_P,
tiles reflected, crops in the set's phase on periodic textures):

* **genuine** triples: three sets of 16 genuine source crops (what three seeds of a Wang set
  without any construction flaw are), drawn as :func:`benchmarks.wang.crop_frame` draws them;
* **planted** triples: the same kind of crops with every pixel closer than 3 px to the tile
  edge taken from another random crop at the same place: a hard cut 3 px from the edge, the
  kind of frame a Wang set's interior cut makes (the right answer: a frame);

and four aggregations of a triple: **A** the median of the three sets' own frames (the
benchmark's figure before session 7), **B** the frame of the mean ratio profile
(:func:`benchmarks.wang.pooled_frame`), each also over its floor: the median of the same
statistic over as many independent genuine triples (**A/f16** is A over the one-set floor,
**B/fB** is B over the pooled floor; the benchmark's frame is now B/fB). The floors are
calibrated on the first half of the draws and the figures are taken on the second half.

The **layout frame** (session 13; :func:`benchmarks.wang.context_frame`, the yardstick of
:func:`benchmarks.wang.layout_wang_frame`) reads the same crops with their real neighbours
instead of reflected: genuine crops inside their source windows, planted ones with the 3 px
band either side of every crop edge taken from the other crop's place (continuous across the
edge, as a Wang tile's edge sample is; the crop itself is the planted crop above), B/fB over
its own pooled floor. **Grid**: the whole source cut into a grid of the tile's period at the
first crop's offset (:func:`engine.metrics.layout_frame`, the genuine layout itself; B of
three offsets, no floor). Saved to ``benchmarks/results/wang_frame_oracle_SET.txt``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._util import format_table  # noqa: E402
from benchmarks.wang import (  # noqa: E402
    RESULTS,
    context_frame,
    context_windows,
    default_ring,
    fit_tile,
    stamp,
    textures,
    wang_frame,
)
from engine.metrics import edge_distance, layout_frame, luminance, tile_line_distance  # noqa: E402
from engine.reference_crops import ReferenceCrops, random_origins  # noqa: E402

#: a planted frame: pixels closer than this to the tile edge come from another crop
PLANT = 3
LINE = 1.12


def _draw(L, S, T: int, limit: int, k: int, plant: bool):
    """Ratio profiles of one genuine 16-crop set (draw k): reflected (``old``), inside its
    windows (``layout``), the whole source under the first crop's grid (``grid``); with
    ``plant``, the planted crops reflected (``old planted``) and inside windows whose band
    either side of the crop edge is planted (``layout planted``)."""
    g = np.random.default_rng(5000 + k)
    (y0, x0), *_ = random_origins(L.shape, (T, T), 1, g)
    ref = ReferenceCrops.build(L, (T, T), L[y0 : y0 + T, x0 : x0 + T])
    org = [(y0, x0), *ref.origins(15, g)]
    crops = [S[y : y + T, x : x + T] for y, x in org]
    first = crops[0]
    wins = context_windows(S, T, org)
    out = {
        "old": wang_frame(crops, S, limit).ratio,
        "layout": context_frame(wins, S, T, limit, first).ratio,
        "grid": layout_frame([S], S, tile=T, limit=limit, offset=(y0, x0), template=first).ratio,
    }
    if plant:
        ring = (edge_distance((T, T)) < PLANT)[..., None]
        oth = ref.origins(16, g)
        others = [S[y : y + T, x : x + T] for y, x in oth]
        planted = [np.where(ring, o, c) for o, c in zip(others, crops, strict=True)]
        out["old planted"] = wang_frame(planted, S, limit).ratio
        pad = (wins[0].shape[0] - T) // 2
        band = (tile_line_distance(wins[0].shape[:2], T, (pad, pad)) < PLANT)[..., None]
        pw = [np.where(band, o, w) for o, w in zip(context_windows(S, T, oth), wins, strict=True)]
        out["layout planted"] = context_frame(pw, S, T, limit, first).ratio
    return out


def _aggregate(profiles: np.ndarray):
    """(A, B) of consecutive triples of ratio profiles."""
    t = profiles.reshape(-1, 3, profiles.shape[-1])
    return np.median(t.max(-1), axis=1), t.mean(1).max(-1)


def _spread(v) -> str:
    return f"{np.median(v):.3f} ({v.min():.3f}-{v.max():.3f}; {int((v > LINE).sum())})"


def oracle(which: str, triples: int, tile: int = 128, names=None) -> str:
    rows = []
    for name, S in textures(which):
        if names and name not in names:
            continue
        T = fit_tile(S, tile)
        limit, L = 2 * default_ring(T), luminance(S)
        draws = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for k in range(6 * triples):  # the first half calibrates, the second is judged
                draws.append(_draw(L, S, T, limit, k, plant=k >= 3 * triples))
        half = 3 * triples

        def col(key, part, draws=draws, half=half):
            return np.array([d[key] for d in (draws[:half] if part == 0 else draws[half:])])

        cal, test, planted = col("old", 0), col("old", 1), col("old planted", 1)
        f16 = float(np.median(cal.max(-1)))
        fB = float(np.median(_aggregate(cal)[1]))
        tA, tB = _aggregate(test)
        pA, pB = _aggregate(planted)
        lB = float(np.median(_aggregate(col("layout", 0))[1]))
        ltB = _aggregate(col("layout", 1))[1]
        lpB = _aggregate(col("layout planted", 1))[1]
        gB = _aggregate(np.array([d["grid"] for d in draws]))[1]
        rows.append(
            [name, T, f"{f16:.3f}", f"{fB:.3f}", _spread(tA), _spread(tB), _spread(tA / f16)]
            + [_spread(tB / fB), f"{np.median(pA):.2f}", f"{(pB / fB).min():.2f}"]
            + [f"{lB:.3f}", _spread(ltB / lB), f"{(lpB / lB).min():.2f}", _spread(gB)]
        )
        print(" | ".join(map(str, rows[-1])), file=sys.stderr, flush=True)
    heads = ["texture", "tile", "floor 1 set", "floor pooled", "genuine A", "genuine B"]
    heads += ["genuine A/f16", "genuine B/fB", "planted A", "planted B/fB min"]
    heads += ["layout floor", "layout genuine B/fB", "layout planted B/fB min", "grid B"]
    return (
        f"The Wang frame's yardstick on the {which} textures: {triples} genuine triples "
        f"(three sets of 16 source crops) and {triples} planted triples (a hard cut {PLANT} px "
        "from the tile edge) per texture. A = median of the three sets' frames (before "
        "session 7), B = max of their mean ratio profile (pooled_frame); f16 / fB = the "
        "median of A's one-set frame / of B over independent genuine draws (calibration "
        f"half). Genuine columns: median (min-max; how many of {triples} above {LINE}); "
        "the right answer for them is no frame. Planted: a frame, the right answer above "
        f"{LINE}. Layout columns (session 13): the same crops read with their real neighbours "
        "(context_frame), the planted ones with the band either side of their edge from the "
        f"other crop's place; floor and B/fB as above. Grid B: the whole source cut into a "
        f"grid at each draw's first crop (layout_frame), B of {2 * triples} triples, no floor."
        "\n\n" + format_table(heads, rows) + "\n"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("samples", "public", "private"), default="public")
    ap.add_argument("--triples", type=int, default=8, help="genuine and planted triples")
    ap.add_argument("--only", nargs="*", default=None, help="these textures only (not saved)")
    args = ap.parse_args(argv)
    text = f"{stamp()}\n\n{oracle(args.set, args.triples, names=args.only)}"
    print(text)
    if not args.only:
        RESULTS.mkdir(exist_ok=True)
        (RESULTS / f"wang_frame_oracle_{args.set}.txt").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
