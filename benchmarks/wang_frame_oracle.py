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
Saved to ``benchmarks/results/wang_frame_oracle.txt``.
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
from benchmarks.wang import RESULTS, _default_ring, _fit, _stamp, _textures, wang_frame  # noqa: E402
from engine.metrics import edge_distance, luminance  # noqa: E402
from engine.reference_crops import ReferenceCrops, random_origins  # noqa: E402

#: a planted frame: pixels closer than this to the tile edge come from another crop
PLANT = 3
LINE = 1.12


def _draw(L, S, T: int, limit: int, k: int, plant: bool):
    """The ratio profile of one genuine 16-crop set (draw k) and, with ``plant``, of the same
    crops with a planted frame."""
    g = np.random.default_rng(5000 + k)
    (y0, x0), *_ = random_origins(L.shape, (T, T), 1, g)
    ref = ReferenceCrops.build(L, (T, T), L[y0 : y0 + T, x0 : x0 + T])
    org = [(y0, x0), *ref.origins(15, g)]
    crops = [S[y : y + T, x : x + T] for y, x in org]
    out = [wang_frame(crops, S, limit).ratio]
    if plant:
        ring = (edge_distance((T, T)) < PLANT)[..., None]
        others = [S[y : y + T, x : x + T] for y, x in ref.origins(16, g)]
        planted = [np.where(ring, o, c) for o, c in zip(others, crops, strict=True)]
        out.append(wang_frame(planted, S, limit).ratio)
    return out


def _aggregate(profiles: np.ndarray):
    """(A, B) of consecutive triples of ratio profiles."""
    t = profiles.reshape(-1, 3, profiles.shape[-1])
    return np.median(t.max(-1), axis=1), t.mean(1).max(-1)


def oracle(which: str, triples: int, tile: int = 128) -> str:
    rows = []
    for name, S in _textures(which):
        T = _fit(S, tile)
        limit, L = 2 * _default_ring(T), luminance(S)
        gen, planted = [], []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for k in range(6 * triples):  # the first half calibrates, the second is judged
                r = _draw(L, S, T, limit, k, plant=k >= 3 * triples)
                gen.append(r[0])
                planted += r[1:]
        gen, planted = np.array(gen), np.array(planted)
        cal, test = gen[: 3 * triples], gen[3 * triples :]
        f16 = float(np.median(cal.max(-1)))
        fB = float(np.median(_aggregate(cal)[1]))
        tA, tB = _aggregate(test)
        pA, pB = _aggregate(planted)

        def spread(v):
            return f"{np.median(v):.3f} ({v.min():.3f}-{v.max():.3f}; {int((v > LINE).sum())})"

        rows.append(
            [name, T, f"{f16:.3f}", f"{fB:.3f}", spread(tA), spread(tB), spread(tA / f16)]
            + [spread(tB / fB), f"{np.median(pA):.2f}", f"{(pB / fB).min():.2f}"]
        )
        print(" | ".join(map(str, rows[-1])), file=sys.stderr, flush=True)
    heads = ["texture", "tile", "floor 1 set", "floor pooled", "genuine A", "genuine B"]
    heads += ["genuine A/f16", "genuine B/fB", "planted A", "planted B/fB min"]
    return (
        f"The Wang frame's yardstick on the {which} textures: {triples} genuine triples "
        f"(three sets of 16 source crops) and {triples} planted triples (a hard cut {PLANT} px "
        "from the tile edge) per texture. A = median of the three sets' frames (before "
        "session 7), B = max of their mean ratio profile (pooled_frame); f16 / fB = the "
        "median of A's one-set frame / of B over independent genuine draws (calibration "
        f"half). Genuine columns: median (min-max; how many of {triples} above {LINE}); "
        "the right answer for them is no frame. Planted: a frame, the right answer above "
        f"{LINE}.\n\n" + format_table(heads, rows) + "\n"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("samples", "public", "private"), default="public")
    ap.add_argument("--triples", type=int, default=8, help="genuine and planted triples")
    args = ap.parse_args(argv)
    text = f"{_stamp()}\n\n{oracle(args.set, args.triples)}"
    print(text)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / f"wang_frame_oracle_{args.set}.txt").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
