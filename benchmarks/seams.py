"""Seam search benchmark: median time and criterion of every method on four map sizes.

Run ``python -m benchmarks.seams`` (or ``python benchmarks/seams.py``); ``--help`` for options.
Maps: smoothed random noise, and real overlaps (RGB Euclidean error between two strips of a
bundled sample). Numba kernels are compiled (``engine.seams.warmup``) before timing. Each row
shows the method's median time, its ratio to a straightforward row-by-row numpy DP, the criterion
(sum of E on the path) relative to ``dp``'s (the optimal one-pixel-per-row cut) and, for the
oscillating search, the time to its first (per-row argmin) path.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._util import format_table, median_time  # noqa: E402
from engine.seams import find_seam, iter_find_seam, warmup  # noqa: E402

SIZES = ((32, 6), (256, 16), (512, 64), (2048, 128))

#: (label, method, options)
VARIANTS = [
    ("dp", "dp", {}),
    ("dijkstra", "dijkstra", {}),
    ("dijkstra 4-conn", "dijkstra", {"connectivity": 4}),
    ("minimax exact", "minimax", {}),
    ("minimax lm", "minimax", {"variant": "lm"}),
    ("minimax sorted", "minimax", {"variant": "sorted"}),
    ("oscillating o_max=1", "oscillating", {"o_max": 1}),
    ("oscillating o_max=3", "oscillating", {"o_max": 3}),
    ("oscillating o_max=10", "oscillating", {"o_max": 10}),
    ("oscillating faithful o_max=3", "oscillating", {"o_max": 3, "variant": "faithful"}),
    ("oscillating-optimal", "oscillating-optimal", {}),
    ("resistance", "resistance", {}),
    ("dp cyclic", "dp", {"cyclic": True}),
    ("oscillating o_max=3 cyclic", "oscillating", {"cyclic": True}),
]

#: targets at 512x64 (ms)
TARGETS = {
    "dp": 1.0,
    "resistance": 1.0,
    "dijkstra": 15.0,
    "minimax exact": 30.0,
    "oscillating o_max=3": 40.0,
    "first path": 1.0,
}


def numpy_dp(error: np.ndarray) -> np.ndarray:
    """The straightforward baseline: row-by-row numpy DP with stored argmin pointers."""
    h, w = error.shape
    cost = error[0].copy()
    back = np.zeros((h, w), dtype=np.int8)
    for j in range(1, h):
        left = np.concatenate(([np.inf], cost[:-1]))
        right = np.concatenate((cost[1:], [np.inf]))
        stack = np.stack([left, cost, right])
        k = np.argmin(stack, axis=0)
        back[j] = k - 1
        cost = stack[k, np.arange(w)] + error[j]
    cols = np.empty(h, dtype=np.intp)
    cols[-1] = int(np.argmin(cost))
    for j in range(h - 1, 0, -1):
        cols[j - 1] = cols[j] + back[j, cols[j]]
    return cols


def smooth_map(h: int, w: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return ndimage.gaussian_filter(rng.random((h, w)), 2.0)


def sample_map(h: int, w: int, name: str, seed: int = 0) -> np.ndarray:
    """Error between two h x w strips at random positions of a sample (mirror-extended)."""
    from PIL import Image

    import resources

    img = np.asarray(Image.open(resources.sample_path(name)).convert("RGB"), np.float64) / 255
    ph, pw = max(0, h + 1 - img.shape[0]), max(0, w + 1 - img.shape[1])
    img = np.pad(img, ((0, ph), (0, pw), (0, 0)), mode="symmetric")
    rng = np.random.default_rng(seed)
    (y1, y2), (x1, x2) = rng.integers(0, img.shape[0] - h, 2), rng.integers(0, img.shape[1] - w, 2)
    a, b = img[y1 : y1 + h, x1 : x1 + w], img[y2 : y2 + h, x2 : x2 + w]
    return np.sqrt(((a - b) ** 2).sum(axis=2))


def first_path_time(error: np.ndarray, **options) -> float:
    def first():
        seam = next(iter_find_seam(error, method="oscillating", **options)).seam
        return seam.path, seam.mask  # built, as a viewer would draw it

    return median_time(first, min_time=0.05, min_repeats=5)[0]


def run(sizes, sample: str, min_time: float, max_seconds: float) -> tuple[list, dict]:
    rows = []
    at_512 = {}
    skip = set()  # (label, map) too slow at a smaller size: skip the larger ones
    for h, w in sizes:
        for kind, error in (("smooth", smooth_map(h, w)), (sample, sample_map(h, w, sample))):
            base_t, _ = median_time(lambda e=error: numpy_dp(e), min_time=min_time)
            dp_crit = find_seam(error, method="dp").criterion
            for label, method, opts in VARIANTS:
                if (label, kind) in skip:
                    rows.append((f"{h}x{w}", kind, label, "skipped", "", "", ""))
                    continue
                t, seam = median_time(
                    lambda e=error, m=method, o=opts: find_seam(e, method=m, **o),
                    min_time=min_time,
                    max_repeats=50 if h * w <= 40_000 else 9,
                )
                first = ""
                if method == "oscillating":
                    ft = first_path_time(error, **opts)
                    first = f"{1e3 * ft:.3f}"
                    if (h, w) == (512, 64) and label == "oscillating o_max=3":
                        at_512.setdefault("first path", []).append(1e3 * ft)
                if (h, w) == (512, 64) and label in TARGETS:
                    at_512.setdefault(label, []).append(1e3 * t)
                if t > max_seconds:
                    skip.add((label, kind))
                rows.append(
                    (
                        f"{h}x{w}",
                        kind,
                        label,
                        f"{1e3 * t:.3f}",
                        f"{t / base_t:.3f}",
                        f"{seam.criterion / dp_crit:.3f}",
                        first,
                    )
                )
            rows.append(
                (
                    f"{h}x{w}",
                    kind,
                    "numpy row DP (baseline)",
                    f"{1e3 * base_t:.3f}",
                    "1.000",
                    "1.000",
                    "",
                )
            )
    return rows, at_512


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--sizes",
        default="all",
        help="comma-separated HxW list, e.g. 32x6,512x64 (default: all four)",
    )
    ap.add_argument("--sample", default="cobblestones", help="bundled sample for real overlaps")
    ap.add_argument(
        "--min-time",
        type=float,
        default=0.2,
        help="seconds of repeats per measurement (at least 3 runs)",
    )
    ap.add_argument(
        "--max-seconds",
        type=float,
        default=5.0,
        help="a variant slower than this (one run) is skipped at larger sizes",
    )
    args = ap.parse_args(argv)
    sizes = (
        SIZES
        if args.sizes == "all"
        else [tuple(int(v) for v in s.lower().split("x")) for s in args.sizes.split(",")]
    )
    t0 = time.perf_counter()
    warmup()
    print(f"numba warm-up (compile or cache load): {time.perf_counter() - t0:.2f} s")
    rows, at_512 = run(sizes, args.sample, args.min_time, args.max_seconds)
    print(
        format_table(
            ("size", "map", "method", "median ms", "x numpy DP", "criterion / dp", "first path ms"),
            rows,
        )
    )
    if at_512:
        print("\nTargets at 512x64 (worst of the two maps):")
        for label, limit in TARGETS.items():
            if label in at_512:
                worst = max(at_512[label])
                print(
                    f"  {label:<22} {worst:8.3f} ms  (target <= {limit:g} ms: "
                    f"{'ok' if worst <= limit else 'MISSED'})"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
