"""Seam search benchmark: median time and criterion of every method on four map sizes.

Run ``python -m benchmarks.seams`` (or ``python benchmarks/seams.py``); ``--help`` for options.
Maps: smoothed random noise, and real overlaps (RGB Euclidean error between two strips of a
bundled sample). Numba kernels are compiled (``engine.seams.warmup``) before timing. Each row
shows the method's median time, its ratio to a straightforward row-by-row numpy DP, the criterion
(sum of E on the path) relative to ``dp``'s (the optimal one-pixel-per-row cut) and, for the
oscillating search, the time to its first path.

After the timing table, a Bhatia table compares the two ``resistance`` variants (the paper's
two lines from the corners, and the single walk, both cut corner to corner as quilting cuts its
bands) on real overlaps: time, criterion against the DP cut with the same pinned corners, how
far the cut reaches into the overlap and how often it touches the far column.

``--quality`` instead measures how far the oscillating search ends above ``oscillating-optimal``
(the exact optimum of its path model) on the bundled samples' overlaps: random strip pairs and
the overlaps the product really cuts (seamless template, candidate patch rings, best-match
quilting), for the paper's setting and the other options. ``--diagnose`` adds why.
"""

from __future__ import annotations

import argparse
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import engine.seams.search as seam_search  # noqa: E402
import resources  # noqa: E402
from benchmarks._util import format_table, median_time  # noqa: E402
from engine.events import drain  # noqa: E402
from engine.seams import SeamSpec, find_seam, iter_find_seam, warmup  # noqa: E402

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
    ("oscillating argmin start o_max=3", "oscillating", {"o_max": 3, "init": "argmin"}),
    (
        "oscillating paper (faithful, argmin) o_max=3",
        "oscillating",
        {"o_max": 3, "variant": "faithful", "init": "argmin"},
    ),
    ("oscillating-optimal", "oscillating-optimal", {}),
    ("resistance published (Bhatia)", "resistance", {}),
    ("resistance walk", "resistance", {"variant": "walk"}),
    ("dp cyclic", "dp", {"cyclic": True}),
    ("oscillating o_max=3 cyclic", "oscillating", {"cyclic": True}),
]

#: targets at 512x64 (ms)
TARGETS = {
    "dp": 1.0,
    "resistance published (Bhatia)": 1.0,
    "resistance walk": 1.0,
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


def _sample(name: str) -> np.ndarray:
    """A bundled sample as float32 RGB in [0, 1]."""
    from engine.io import load_image, to_rgb

    return to_rgb(load_image(resources.sample_path(name)).pixels)


def sample_map(h: int, w: int, name: str, seed: int = 0) -> np.ndarray:
    """Error between two h x w strips at random positions of a sample (mirror-extended)."""
    img = _sample(name).astype(np.float64)
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


# ----------------------------------------------------------------------------- Bhatia
#: overlap shapes of the Bhatia table: quilting bands (block 48, overlap 12 = block / 4, the
#: default band; block 96, overlap 24) and a wide overlap
BHATIA_SHAPES = ((48, 12), (96, 24), (512, 64))


def bhatia_table(sample: str, n_maps: int = 12, min_time: float = 0.05) -> str:
    """The ``resistance`` variants corner to corner (start = end = 0) on ``n_maps`` real
    overlaps per shape: median time, criterion / the pinned DP cut's, mean reach (R1's share of
    the overlap) and the share of cuts that touch the overlap's far column."""
    rows = []
    for h, w in BHATIA_SHAPES:
        maps = [sample_map(h, w, sample, seed=s) for s in range(n_maps)]
        dp = [find_seam(e, method="dp", start=0, end=0).criterion for e in maps]
        for variant in ("published", "walk"):
            times, ratio, reach, touch = [], [], [], 0
            for e, d in zip(maps, dp, strict=True):
                opts = dict(method="resistance", variant=variant, start=0, end=0)
                t, seam = median_time(lambda e=e, o=opts: find_seam(e, **o), min_time=min_time)
                times.append(t)
                ratio.append(seam.criterion / d)
                reach.append(seam.mask.mean())
                touch += int(seam.path[:, 1].max() == w - 1)
            rows.append(
                (
                    f"{h}x{w}",
                    variant,
                    f"{1e3 * np.median(times):.3f}",
                    f"{np.median(ratio):.2f}",
                    f"{np.mean(reach):.2f}",
                    f"{touch}/{n_maps}",
                )
            )
    headers = ("overlap", "variant", "median ms", "criterion / dp", "R1 share", "far column")
    return format_table(headers, rows)


# ----------------------------------------------------------------------------- quality
@dataclass(frozen=True)
class Overlap:
    """An error map as one seam search saw it: pinned column per row (-1: free), cyclic."""

    error: np.ndarray
    pins: np.ndarray
    cyclic: bool = False

    @property
    def constraints(self) -> dict:
        """The same constraints as :func:`engine.seams.find_seam` keywords."""
        h = self.error.shape[0]
        pinned = {int(r): int(self.pins[r]) for r in np.flatnonzero(self.pins >= 0)}
        cons = {"cyclic": True} if self.cyclic else {}
        if 0 in pinned:
            cons["start"] = pinned.pop(0)
        if h - 1 in pinned:
            cons["end"] = pinned.pop(h - 1)
        if pinned:
            cons["waypoints"] = tuple(pinned.items())
        return cons


def random_overlaps(n_per_sample=8, h=64, w=16, seed=0) -> list[Overlap]:
    """Error maps (RGB Euclidean) between two random h x w strips of each bundled sample."""
    rng = np.random.default_rng(seed)
    out = []
    for name in resources.SAMPLE_NAMES:
        img = _sample(name).astype(np.float64)
        H, W = img.shape[:2]
        for _ in range(n_per_sample):
            y1, y2 = rng.integers(0, H - h, 2)
            x1, x2 = rng.integers(0, W - w, 2)
            a, b = img[y1 : y1 + h, x1 : x1 + w], img[y2 : y2 + h, x2 : x2 + w]
            out.append(Overlap(np.sqrt(((a - b) ** 2).sum(axis=2)), np.full(h, -1)))
    return out


@contextmanager
def recording_oscillating(store: list):
    """Record (as :class:`Overlap`) every map the oscillating search is run on meanwhile."""
    original = seam_search.iter_oscillating

    def record(error, pins, **kw):
        store.append(Overlap(error.copy(), pins.copy(), kw["cyclic"]))
        return original(error, pins, **kw)

    seam_search.iter_oscillating = record
    try:
        yield store
    finally:
        seam_search.iter_oscillating = original


def product_overlaps(names=None, *, quilting=True) -> dict[str, list[Overlap]]:
    """The overlaps the product cuts on each sample with the oscillating search (default
    options): the template's two (``find_template`` with the CLI's default sizes, then
    ``make_seamless``; the second is cyclic), four candidates' patch rings (four sides each,
    corner points pinned) and a 192 x 192 best-match quilt of 48 px blocks (L-shaped and
    single-arm overlaps)."""
    from engine.quilting import quilt
    from engine.tiles import candidates, find_template, make_seamless

    sets = {"template": [], "patch ring": [], "quilting": []}
    for name in names or resources.SAMPLE_NAMES:
        S = _sample(name)
        short = min(S.shape[:2])
        template = find_template(S, tile_min=short // 4, tile_max=short // 2)
        with recording_oscillating(sets["template"]):
            tile = make_seamless(S, template, seam=SeamSpec("oscillating"))
        with recording_oscillating(sets["patch ring"]):
            # the rings' own error maps: without the candidates' outward bias (a ramp that
            # makes every row's argmin the outer column, i.e. the paper's start near-optimal)
            seam = SeamSpec("oscillating", blend="adaptive")
            candidates(S, tile, 4, seam=seam, rng=0, workers=1, outward=0)
        if quilting:
            with recording_oscillating(sets["quilting"]):
                quilt(
                    S,
                    (192, 192),
                    block=48,
                    seam=SeamSpec("oscillating", metric="ssd"),
                    rng=0,
                    threads=1,
                )
    return {k: v for k, v in sets.items() if v}


def optima(overlaps) -> np.ndarray:
    """Criterion of ``oscillating-optimal`` on every overlap."""
    return np.array(
        [
            find_seam(ov.error, method="oscillating-optimal", **ov.constraints).criterion
            for ov in overlaps
        ]
    )


def gaps(overlaps, optimum=None, *, start_only=False, **options) -> tuple[np.ndarray, float]:
    """Relative excess criterion / optimum - 1 of the oscillating search with ``options`` on
    every overlap whose optimum is not 0 (exact copies in quilting), and the mean time per
    overlap. ``optimum``: :func:`optima` of the overlaps (computed when None); ``start_only``:
    of the first streamed path instead of the final one."""
    optimum = optima(overlaps) if optimum is None else optimum
    crit = np.empty(len(overlaps))
    t0 = time.perf_counter()
    for k, ov in enumerate(overlaps):
        gen = iter_find_seam(ov.error, method="oscillating", **ov.constraints, **options)
        crit[k] = (next(gen).seam if start_only else drain(gen)).criterion
        gen.close()
    spent = (time.perf_counter() - t0) / max(1, len(overlaps))
    tiny = 1e-12 * np.array([max(1.0, float(ov.error.max())) for ov in overlaps])
    nonzero = optimum > tiny
    return crit[nonzero] / optimum[nonzero] - 1.0, spent


#: (label, oscillating options); the paper's algorithm is variant="faithful", init="argmin"
QUALITY_SETTINGS = [
    ("argmin start alone (first path)", {"init": "argmin", "start_only": True}),
    ("dp start alone (first path)", {"init": "dp", "start_only": True}),
    ("paper: faithful, argmin, o_max=1", {"variant": "faithful", "init": "argmin", "o_max": 1}),
    ("paper: faithful, argmin, o_max=3", {"variant": "faithful", "init": "argmin", "o_max": 3}),
    ("paper: faithful, argmin, o_max=8", {"variant": "faithful", "init": "argmin", "o_max": 8}),
    ("resume, argmin, o_max=3", {"init": "argmin", "o_max": 3}),
    ("resume, argmin, o_max=8", {"init": "argmin", "o_max": 8}),
    ("resume, argmin, o_max=16", {"init": "argmin", "o_max": 16}),
    ("resume, smoothed, o_max=3", {"init": "smoothed", "o_max": 3}),
    ("resume, dp, o_max=1", {"init": "dp", "o_max": 1}),
    ("faithful, dp, o_max=3", {"variant": "faithful", "init": "dp", "o_max": 3}),
    ("resume, dp, o_max=3 (default)", {}),
]


def quality(sets: dict[str, list[Overlap]]) -> str:
    """Table: setting x overlap set -> mean / median excess over the optimum, and time."""
    headers = ["setting"]
    for k, v in sets.items():
        headers.append(f"{k} ({len(v)}) mean / median")
    headers.append("ms / overlap")
    rows = []
    best = {k: optima(v) for k, v in sets.items()}
    for label, opts in QUALITY_SETTINGS:
        cells, spent = [label], []
        for k, v in sets.items():
            g, t = gaps(v, best[k], **opts)
            cells.append(f"{100 * g.mean():+.1f} % / {100 * np.median(g):+.1f} %")
            spent.append(t)
        cells.append(f"{1e3 * np.mean(spent):.2f}")
        rows.append(cells)
    return format_table(headers, rows)


def _criteria(error: np.ndarray, C: np.ndarray, cyclic: bool) -> np.ndarray:
    """Criterion of every row of control points C (n, h), vectorised (diagnosis only)."""
    h, w = error.shape
    P = np.zeros((h, w + 1))
    np.cumsum(error, axis=1, out=P[:, 1:])
    none = np.full((len(C), 1), w + 2)
    prev = np.roll(C, 1, axis=1) + 1 if cyclic else np.hstack([none, C[:, :-1] + 1])
    nxt = np.roll(C, -1, axis=1) + 1 if cyclic else np.hstack([C[:, 1:] + 1, none])
    mu = np.minimum(np.minimum(C, prev), nxt)
    rows = np.arange(h)[None, :]
    return (P[rows, C + 1] - P[rows, mu]).sum(axis=1)


def _neighbours(c, pins, o_max, cyclic, w) -> np.ndarray:
    """Every block move of size <= o_max from c (frozen rows skipped), one per row."""
    h = len(c)
    out = []
    for o in range(1, min(o_max, h) + 1):
        for j in range(h if cyclic and o < h else 1) if cyclic else range(h - o + 1):
            rows = (j + np.arange(o)) % h
            if (pins[rows] >= 0).any():
                continue
            block = np.repeat(c[None], w, axis=0)
            block[:, rows] = np.arange(w)[:, None]
            out.append(block)
    return np.concatenate(out) if out else c[None].copy()


def diagnose(sets: dict[str, list[Overlap]], *, o_max=3, limit=10) -> str:
    """Why the paper's start ends far above the optimum: per set, the argmin start's excess,
    its share of rows jumping more than one column and its path pixels per row (start / final /
    optimum); the gain a move could still make at tau = 0 from the final path (first
    improvement, resume); and best improvement (steepest descent, slow: ``limit`` maps spread
    over the set, beside first improvement on the same maps)."""
    from engine.seams.oscillating import controls_seam, criterion, initial_controls

    rows = []
    for name, overlaps in sets.items():
        start, jumps, px, left, first, best = [], [], [], [], [], []
        step = max(1, len(overlaps) // limit)
        for k, ov in enumerate(overlaps):
            e, cons, pins, cyc = ov.error, ov.constraints, ov.pins, ov.cyclic
            h, w = e.shape
            opt = find_seam(e, method="oscillating-optimal", **cons)
            if opt.criterion <= 1e-12 * max(1.0, float(e.max())):
                continue
            c0 = initial_controls(e, pins, "argmin", cyclic=cyc)
            fin = find_seam(e, method="oscillating", init="argmin", o_max=o_max, **cons)
            cf = np.full(h, -1)
            np.maximum.at(cf, fin.path[:, 0], fin.path[:, 1])
            start.append(criterion(e, c0, cyclic=cyc) / opt.criterion - 1)
            jumps.append(np.mean(np.abs(np.diff(c0)) > 1))
            n0 = len(controls_seam(e, c0, cyc, "oscillating").path)  # the start's path pixels
            px.append((n0 / h, len(fin.path) / h, len(opt.path) / h))
            nb = _criteria(e, _neighbours(cf, pins, o_max, cyc, w), cyc).min()
            left.append(max(0.0, (fin.criterion - nb) / fin.criterion))
            first.append(fin.criterion / opt.criterion - 1)
            if k % step == 0 and len(best) < limit:
                c, eps = c0, criterion(e, c0, cyclic=cyc)
                while True:  # steepest descent over the same moves
                    cand = _neighbours(c, pins, o_max, cyc, w)
                    v = _criteria(e, cand, cyc)
                    i = int(np.argmin(v))
                    if not v[i] < eps - 1e-9 * eps:
                        break
                    c, eps = cand[i], v[i]
                best.append((eps / opt.criterion - 1, first[-1]))
        bi = np.array(best)
        rows.append(
            (
                name,
                f"{100 * np.mean(start):+.0f} %",
                f"{100 * np.mean(jumps):.0f} %",
                " / ".join(f"{v:.2f}" for v in np.mean(px, axis=0)),
                f"{max(left):.1e}",
                f"{100 * np.mean(first):+.1f} %",
                f"{100 * bi[:, 0].mean():+.1f} % ({100 * bi[:, 1].mean():+.1f} %)",
            )
        )
    headers = (
        "overlaps",
        "argmin start",
        "start rows jumping > 1",
        "path px/row start / final / opt",
        "max gain left at tau=0",
        f"first impr. o_max={o_max}",
        f"best impr. ({limit} maps; first impr. there)",
    )
    return format_table(headers, rows)


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
    ap.add_argument(
        "--quality",
        action="store_true",
        help="oscillating search vs its exact optimum on the samples' overlaps (no timing table)",
    )
    ap.add_argument("--diagnose", action="store_true", help="with --quality: why (slow)")
    args = ap.parse_args(argv)
    if args.quality:
        warmup()
        t0 = time.perf_counter()
        sets = {"random strips": random_overlaps(), **product_overlaps()}
        print(f"overlaps collected in {time.perf_counter() - t0:.1f} s")
        print("Oscillating search: criterion above oscillating-optimal (overlaps with a zero")
        print("optimum, exact copies in quilting, are left out of the averages)")
        print(quality(sets))
        if args.diagnose:
            print("\nDiagnosis (paper's argmin start, resume variant):")
            print(diagnose(sets))
        return 0
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
    print(f"\nBhatia's minimum resistance cut line, corner to corner on {args.sample} overlaps")
    print("(criterion / the DP cut between the same corners, medians over 12 maps):")
    print(bhatia_table(args.sample))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
