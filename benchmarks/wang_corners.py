"""Where four Wang tiles meet: the step energy around the crossings (issue 11, session 8).

Run ``python -m benchmarks.wang_corners`` (``--help`` for options). Per texture of an
evaluation set, K = 2 Wang sets of the benchmark's tile size (:func:`benchmarks.wang.fit_tile`),
seeds 0 .. ``--seeds`` − 1, each in the benchmark's 16 random valid 8x8 layouts without equal
neighbours; :func:`engine.metrics.corner_energy` of every layout (the mean step — across, along
and off the tile lines — within r px of the 49 crossings, over the layout's own mean step),
averaged over the layouts, median over the seeds:

* **corners r4 / r8**: within 4 and 8 px; **lines r4**: the same around the midpoints of the
  tile edges (the joints away from any crossing);
* **profile**: the r8 window by ring (floor of the Chebyshev distance to the crossing, 0..7);
* **floor**: what genuine pixels read: 200 draws of as many r4 windows (49 x 16) at random
  points of the *source*, each over the source's mean step; the 5 % and 95 % quantiles;
* **vs source**: the corners' mean step over the source's (not the layout's) mean step;
* **planted**: the oracle of a defect: the source itself cut by a grid of the tile size, a
  6x6 patch from elsewhere pasted on every crossing, read as the tiles' corners are.

Saved to ``benchmarks/results/wang_corners_SET.txt``.
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
from benchmarks.wang import RESULTS, fit_tile, layouts_of, stamp, textures  # noqa: E402
from engine.metrics import LATTICE_LAYOUTS, corner_energy, mean_step, step_windows  # noqa: E402
from engine.tiles.layout import assemble  # noqa: E402
from engine.tiles.wang import wang_set  # noqa: E402

#: draws of random source windows behind the floor
FLOOR_DRAWS = 200
#: side of the patch pasted on every crossing by the planted oracle
PLANT = 6


def set_corners(S, T: int, seed: int, options: dict, docs_file: Path | None = None):
    """(corners r4, lines r4, corners r8, profile r8, corners r4 over the source's level) of
    one set, means over its layouts."""
    ws = wang_set(S, tile_size=T, rng=seed, **options)
    level = mean_step(S)
    out = []
    for k, lay in enumerate(layouts_of(ws, seed)):
        img = assemble(ws.tiles, lay)
        if docs_file is not None and k == 0:
            from engine.io import save_image

            save_image(docs_file, img)
        e4, e8 = corner_energy(img, T, radius=4), corner_energy(img, T, radius=8)
        out.append((e4.value, e4.lines, e8.value, *e8.profile, e4.value * e4.level / level))
    m = np.mean(np.array(out), axis=0)
    return m[0], m[1], m[2], m[3:11], m[11]


def floor(S, count: int, radius: int = 4) -> tuple[float, float]:
    """5 % and 95 % quantiles over :data:`FLOOR_DRAWS` of ``count`` windows at random points
    of ``S`` (each draw's mean step over the source's)."""
    H, W = S.shape[:2]
    g = np.random.default_rng(0)
    level = mean_step(S)
    vals = []
    for _ in range(FLOOR_DRAWS):
        p = np.stack(
            [g.integers(radius, H - radius + 1, count), g.integers(radius, W - radius + 1, count)],
            1,
        )
        vals.append(step_windows(S, p, radius)[0].mean() / level)
    lo, hi = np.quantile(vals, [0.05, 0.95])
    return float(lo), float(hi)


def planted(S, T: int) -> float:
    """:func:`corner_energy` (r4) of the source cut by a grid of T px at a random offset with
    a :data:`PLANT`-px patch of elsewhere pasted on every crossing (median of 8 offsets)."""
    H, W = S.shape[:2]
    g = np.random.default_rng(1)
    h = PLANT // 2
    vals = []
    if min(H, W) < T + 2 * PLANT:
        return float("nan")
    for _ in range(8):
        oy, ox = g.integers(0, min(T, H - T - PLANT)), g.integers(0, min(T, W - T - PLANT))
        img = S[oy:, ox:].copy()
        for y in range(T, img.shape[0] - 4, T):
            for x in range(T, img.shape[1] - 4, T):
                sy, sx = g.integers(0, H - PLANT, 1)[0], g.integers(0, W - PLANT, 1)[0]
                img[y - h : y + h, x - h : x + h] = S[sy : sy + PLANT, sx : sx + PLANT]
        vals.append(corner_energy(img, T, radius=4).value)
    return float(np.median(vals))


def corners(which: str, tile: int, seeds: int, options: dict, docs: Path | None) -> str:
    rows = []
    for name, S in textures(which):
        T = fit_tile(S, tile)
        figs = []
        for seed in range(seeds):
            out = None if docs is None or seed else docs / f"{name}_wang_8x8.png"
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                figs.append(set_corners(S, T, seed, options, out))
        c4, l4, c8, prof, vs = (np.median(np.array([f[i] for f in figs]), axis=0) for i in range(5))
        lo, hi = floor(S, 49 * LATTICE_LAYOUTS)
        rows.append(
            [
                name,
                T,
                f"{c4:.2f}",
                f"{l4:.2f}",
                f"{c8:.2f}",
                " ".join(f"{v:.2f}" for v in prof),
                f"{lo:.2f}-{hi:.2f}",
                f"{vs:.2f}",
                f"{planted(S, T):.2f}",
            ]
        )
        print(" | ".join(str(c) for c in rows[-1]), file=sys.stderr, flush=True)
    heads = ["texture", "tile", "corners r4", "lines r4", "corners r8", "profile r8 (rings 0-7)"]
    heads += ["floor 5-95 %", "r4 vs source", "planted r4"]
    opts = ", ".join(f"{k}={v!r}" for k, v in options.items()) or "default settings"
    return (
        f"Corner step energy on the {which} textures: K = 2 Wang sets ({opts}), medians over "
        f"seeds 0..{seeds - 1} of the mean over {LATTICE_LAYOUTS} valid 8x8 layouts of "
        "engine.metrics.corner_energy (1.0: the crossings as smooth as the layout anywhere); "
        "floor: random source windows; planted: the source with a 6x6 patch of elsewhere on "
        "every crossing of a tile grid\n\n" + format_table(heads, rows) + "\n"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("samples", "public", "private"), default="public")
    ap.add_argument("--tile", type=int, default=128)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--docs", type=Path, default=None, help="save seed 0's first layout here")
    ap.add_argument(
        "--no-corner-match",
        action="store_true",
        help="Wang sets with corner_match=False, the default before session 10 (results file "
        "wang_corners_SET_no_corner_match.txt)",
    )
    args = ap.parse_args(argv)
    if args.docs is not None:
        args.docs.mkdir(parents=True, exist_ok=True)
    options = {"corner_match": False} if args.no_corner_match else {}
    text = f"{stamp()}\n\n{corners(args.set, args.tile, args.seeds, options, args.docs)}"
    print(text)
    suffix = "_no_corner_match" if args.no_corner_match else ""
    (RESULTS / f"wang_corners_{args.set}{suffix}.txt").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
