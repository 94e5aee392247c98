"""An independent implementation of issue 10's tile-set metrics, and a check of engine.metrics.

Written from the issue's text and the README's definitions alone (it neither imports nor copies
:mod:`engine.metrics`), so that the evaluation on the held-out set does not trust one
implementation: frame, ring tone, duplicates, lattice and template share are computed here by
the plainest means (whole-image FFTs, explicit loops over tiles), with their own random crops.

``python -m benchmarks.metrics_check [--evalset public|private|all]`` runs every texture through
the ``tileset`` defaults (:func:`benchmarks.tileset.evaluate_texture`, which also measures with
:mod:`engine.metrics`), prints both implementations' figures side by side and which acceptance
lines each says the texture misses, and saves the table to
``benchmarks/results/metrics_check.txt``.

Definitions (the issue, item 1; the README's "Interior metrics"):

* luminance ``0.2125 R + 0.7154 G + 0.0721 B`` (one channel: itself);
* **frame**: Gaussian blur (σ = 1 px) of the luminance, gradient magnitude by central
  differences; each tile wrapped (as it repeats in a layout), random crops of the tile's size
  taken from the blurred gradient of the whole source (reflected at its border); mean over all
  tiles at each distance d = min(r, c, h-1-r, w-1-c) from the tile edge, divided by the same for
  the crops; the maximum (and minimum) over d < 2·w_P;
* **ring tone**: mean over tiles of |mean luminance of the ring (d < w_P) − of the centre|, over
  the same for crops;
* **duplicates**: candidates whose mean absolute luminance difference to the template (or to
  another candidate) is below 1/255;
* **lattice**: an 8×8 layout of uniformly drawn tiles, DFT power of its luminance; harmonics of
  the tile period are the bins (8i, 8j) ≠ (0, 0), half-way the bins offset by (4, 0), (0, 4),
  (4, 4); dB = 10·log10(mean harmonic power / mean half-way power); the floor the same for a
  layout (same indices) of random crops whose outer ``margin`` pixels are the template's; the
  figure is tiles − floor, a mean over several layouts;
* **template share**: per candidate, the fraction of pixels whose every channel is within
  0.5/255 of the template's (the mean over candidates is reported);
* **the crops** (frame, ring tone and the lattice floor): random positions of the source; along
  every axis where the texture has a period (its autocorrelation, lighting removed and each
  row/column centred, has a first clear peak) and the tile holds a whole number of periods,
  each drawn position is moved to the best match of the template's structure within one
  period around it (the template's phase: an aligned set of a periodic texture *is* the
  texture, and random phases read its period as a frame and a lattice) — unless the texture
  repeats exactly (the in-phase crops are copies of the template), where they stay random.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

RESULTS = Path(__file__).resolve().parent / "results" / "metrics_check.txt"
LUMA = (0.2125, 0.7154, 0.0721)
CROPS = 256  # random crops for the frame and ring-tone references
LAYOUTS = 8  # random layouts the lattice figure is averaged over


# ----------------------------------------------------------------------------- the metrics
def luma(img) -> np.ndarray:
    a = np.asarray(img, dtype=np.float64)
    if a.ndim == 2:
        return a
    if a.shape[2] >= 3:
        return LUMA[0] * a[..., 0] + LUMA[1] * a[..., 1] + LUMA[2] * a[..., 2]
    return a[..., 0]


def tile_pixels(t) -> np.ndarray:
    """A candidate object (with ``.tile``) or an array -> (h, w, C) float array."""
    a = np.asarray(getattr(t, "tile", t), dtype=np.float64)
    return a[..., None] if a.ndim == 2 else a


def distance_map(h: int, w: int) -> np.ndarray:
    r = np.arange(h)[:, None]
    c = np.arange(w)[None, :]
    return np.minimum(np.minimum(r, h - 1 - r), np.minimum(c, w - 1 - c))


def gradient_magnitude(y: np.ndarray, mode: str) -> np.ndarray:
    """|∇ blur(y)| with central differences; ``mode`` 'wrap' (a tile) or 'reflect' (a source)."""
    b = ndimage.gaussian_filter(y, 1.0, mode=mode)
    if mode == "wrap":
        gy = (np.roll(b, -1, 0) - np.roll(b, 1, 0)) / 2
        gx = (np.roll(b, -1, 1) - np.roll(b, 1, 1)) / 2
    else:
        p = np.pad(b, 1, mode="symmetric")
        gy = (p[2:, 1:-1] - p[:-2, 1:-1]) / 2
        gx = (p[1:-1, 2:] - p[1:-1, :-2]) / 2
    return np.hypot(gy, gx)


def crop_corners(shape, size, n, rng) -> list[tuple[int, int]]:
    H, W = shape
    h, w = size
    ys = rng.integers(0, H - h + 1, n)
    xs = rng.integers(0, W - w + 1, n)
    return list(zip(ys.tolist(), xs.tolist(), strict=True))


# ----------------------------------------------------------- the crops: in the template's phase
def autocorrelation_period(Y: np.ndarray) -> float:
    """The period along axis 1 of ``Y`` (lighting already removed): the lag of the first
    autocorrelation peak >= 0.25 that rises >= 0.1 above the lowest value before it (rows
    centred, summed over the rows, each lag over its number of pairs); 0 without one."""
    Z = Y - Y.mean(axis=1, keepdims=True)
    n = Z.shape[1]
    acf = np.zeros(n // 2 + 1)
    for lag in range(n // 2 + 1):
        acf[lag] = (Z[:, : n - lag] * Z[:, lag:]).sum() / (n - lag)
    if acf[0] <= 0:
        return 0.0
    acf /= acf[0]
    low = acf[1]
    for k in range(2, len(acf) - 1):
        low = min(low, acf[k])
        if acf[k] >= max(acf[k - 1], 0.25) and acf[k] > acf[k + 1] and acf[k] - low >= 0.1:
            a, b, c = acf[k - 1], acf[k], acf[k + 1]
            return float(k + (0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0))
    return 0.0


def reference_corners(Y: np.ndarray, size, template=None):
    """A function (n, rng) -> n crop corners: random, moved into the template's phase along
    the axes where the texture is periodic and the tile holds whole periods."""
    h, w = size
    plain = lambda n, rng: crop_corners(Y.shape, size, n, rng)  # noqa: E731
    if template is None:
        return plain
    flat = Y - ndimage.gaussian_filter(Y, max(Y.shape) / 8)
    periods = (autocorrelation_period(flat.T), autocorrelation_period(flat))
    snap = []
    for p, n in zip(periods, size, strict=True):
        k = round(n / p) if p > 0 else 0
        snap.append(k >= 1 and abs(n - k * p) <= max(1.0, 0.02 * n))
    if not any(snap):
        return plain
    from scipy import signal

    hs = Y - ndimage.gaussian_filter(Y, max(h, w) / 4)
    ht = template - ndimage.gaussian_filter(template, max(h, w) / 4, mode="wrap")
    ht = ht - ht.mean()
    box = np.ones((h, w))
    local = signal.correlate(hs, box, mode="valid", method="fft")
    energy = signal.correlate(hs * hs, box, mode="valid", method="fft") - local**2 / (h * w)
    ncc = signal.correlate(hs, ht, mode="valid", method="fft")
    ncc /= np.sqrt(np.maximum(energy, 1e-12) * (ht * ht).sum())

    def moved(n, rng):
        out = []
        for y, x in crop_corners(Y.shape, size, n, rng):
            lo, hi = [y, x], [y + 1, x + 1]
            for i, c in enumerate((y, x)):
                if snap[i]:
                    span = min(ncc.shape[i], int(np.ceil(periods[i])))
                    lo[i] = min(max(0, c - span // 2), ncc.shape[i] - span)
                    hi[i] = lo[i] + span
            win = ncc[lo[0] : hi[0], lo[1] : hi[1]]
            dy, dx = np.unravel_index(int(np.argmax(win)), win.shape)
            out.append((lo[0] + int(dy), lo[1] + int(dx)))
        return out

    probe = moved(32, np.random.default_rng(0))
    if np.median([ncc[y, x] for y, x in probe]) >= 0.97:
        return plain  # an exact repeat: every in-phase crop is a copy of the template
    return moved


def profile(images, dist, dmax) -> np.ndarray:
    """Mean of ``images`` (each (h, w)) at each distance 0..dmax-1."""
    total = np.zeros(dmax)
    count = np.zeros(dmax)
    for im in images:
        for d in range(dmax):
            sel = dist == d
            total[d] += im[sel].sum()
            count[d] += sel.sum()
    return total / np.maximum(count, 1)


def frame_check(tiles, source, limit: int, seed: int = 1, template=None) -> tuple[float, float]:
    """(max, min) over d < ``limit`` of the tiles' edge-distance gradient profile over the
    crops'."""
    T = [luma(tile_pixels(t)) for t in tiles]
    h, w = T[0].shape
    dist = distance_map(h, w)
    dmax = min(limit, int(dist.max()) + 1)
    tiles_p = profile([gradient_magnitude(t, "wrap") for t in T], dist, dmax)
    Y = luma(tile_pixels(source))
    G = gradient_magnitude(Y, "reflect")
    tm = None if template is None else luma(tile_pixels(template))
    corners = reference_corners(Y, (h, w), tm)(CROPS, np.random.default_rng(seed))
    crops_p = profile([G[y : y + h, x : x + w] for y, x in corners], dist, dmax)
    ratio = tiles_p / np.maximum(crops_p, 1e-12)
    return float(ratio.max()), float(ratio.min())


def ring_tone_check(tiles, source, width: int, seed: int = 2, template=None) -> float:
    T = [luma(tile_pixels(t)) for t in tiles]
    h, w = T[0].shape
    ring = distance_map(h, w) < width

    def step(y):
        return abs(y[ring].mean() - y[~ring].mean())

    Y = luma(tile_pixels(source))
    tm = None if template is None else luma(tile_pixels(template))
    corners = reference_corners(Y, (h, w), tm)(CROPS, np.random.default_rng(seed))
    ref = np.mean([step(Y[y : y + h, x : x + w]) for y, x in corners])
    return float(np.mean([step(t) for t in T]) / max(ref, 1e-12))


def duplicates_check(tiles, template) -> tuple[int, int]:
    """(candidates equal to the template, pairs of equal candidates)."""
    T = [luma(tile_pixels(t)) for t in tiles]
    tm = luma(tile_pixels(template))
    of_template = sum(np.abs(t - tm).mean() < 1 / 255 for t in T)
    pairs = 0
    for i in range(len(T)):
        for j in range(i + 1, len(T)):
            pairs += np.abs(T[i] - T[j]).mean() < 1 / 255
    return int(of_template), int(pairs)


def lattice_db_image(y: np.ndarray, rows: int = 8, cols: int = 8) -> float:
    """10·log10(mean power on the tile harmonics / mean power half-way) of a layout image."""
    P = np.abs(np.fft.fft2(y)) ** 2
    H, W = y.shape
    # a tile period of H / rows pixels has its harmonics on every rows-th bin
    u = np.arange(H)[:, None] % rows  # the bins' offsets from a harmonic...
    v = np.arange(W)[None, :] % cols
    hu, hv = rows // 2, cols // 2  # ...and half-way
    harm = (u == 0) & (v == 0)
    harm[0, 0] = False
    half = ((u == hu) & (v == 0)) | ((u == 0) & (v == hv)) | ((u == hu) & (v == hv))
    return float(10 * np.log10(P[harm].mean() / P[half].mean()))


def lattice_check(tiles, source, template, margin: int, layouts: int = LAYOUTS, seed: int = 3):
    """(tiles dB − floor dB, floor dB), means over ``layouts`` random 8x8 layouts."""
    T = [luma(tile_pixels(t)) for t in tiles]
    h, w = T[0].shape
    Y = luma(tile_pixels(source))
    tm = luma(tile_pixels(template))
    rng = np.random.default_rng(seed)
    inner = np.zeros((h, w), bool)
    inner[margin : h - margin, margin : w - margin] = True
    where = reference_corners(Y, (h, w), tm)
    above, floors = [], []
    for _ in range(layouts):
        idx = rng.integers(0, len(T), (8, 8))
        crops = []
        for y, x in where(len(T), rng):
            c = tm.copy()
            c[inner] = Y[y : y + h, x : x + w][inner]
            crops.append(c)
        lay = np.block([[T[k] for k in row] for row in idx])
        ref = np.block([[crops[k] for k in row] for row in idx])
        f = lattice_db_image(ref)
        above.append(lattice_db_image(lay) - f)
        floors.append(f)
    return float(np.mean(above)), float(np.mean(floors))


def share_check(tiles, template) -> float:
    tm = tile_pixels(template)
    return float(
        np.mean([(np.abs(tile_pixels(t) - tm) <= 0.5 / 255).all(axis=2).mean() for t in tiles])
    )


def measure(tiles, source, template, *, ring: int, margin: int) -> dict:
    """Every figure of this implementation for one set."""
    fr, low = frame_check(tiles, source, 2 * ring, template=template)
    dup_t, dup_p = duplicates_check(tiles, template)
    lat, floor = lattice_check(tiles, source, template, margin)
    return {
        "frame": fr,
        "frame_low": low,
        "tone": ring_tone_check(tiles, source, ring, template=template),
        "dups": dup_t + dup_p,
        "dups_template": dup_t,
        "dups_pairs": dup_p,
        "lattice": lat,
        "lattice_floor": floor,
        "share": share_check(tiles, template),
    }


# ----------------------------------------------------------------------------- the check
LIMITS = {"frame": 1.15, "tone": 1.3, "dups": 0, "lattice": 1.5}


def misses(f: dict) -> list[str]:
    return [k for k, lim in LIMITS.items() if f[k] > lim]


def compare(which: str, seed: int = 0) -> str:
    from benchmarks import evalset
    from benchmarks.tileset import evaluate_texture, failures, format_table, load_image_array

    rows = []
    for name in evalset.texture_names(which):
        S = load_image_array(evalset.load(name))
        e = evaluate_texture(S, seed)
        s = e["result"].settings
        t0 = time.perf_counter()
        S = e["S"]  # the source the tiles were taken from (flattened with Flatten lighting)
        m = measure(e["cands"], S, e["seamless"].tile, ring=s.patch_overlap, margin=s.margin)
        took = time.perf_counter() - t0
        pairs = {k: e[k] for k in ("pairs med", "pairs max", "wrap", "detail")}
        engine_miss = failures(e)
        own_miss = misses(m) + [k for k in failures({**e, **m}) if k in pairs]
        rows.append(
            [
                name,
                f"{e['n']}",
                f"{e['frame']:.2f} / {m['frame']:.2f}",
                f"{e['frame_low']:.2f} / {m['frame_low']:.2f}",
                f"{e['tone']:.2f} / {m['tone']:.2f}",
                f"{e['dups']} / {m['dups']}",
                f"{e['lattice']:+.2f} / {m['lattice']:+.2f}",
                f"{e['lattice_floor']:.1f} / {m['lattice_floor']:.1f}",
                f"{e['share']:.1%} / {m['share']:.1%}",
                ", ".join(engine_miss) or "ok",
                ", ".join(sorted(set(own_miss), key=own_miss.index)) or "ok",
                f"{took:.1f}",
            ]
        )
    return format_table(
        [
            "texture",
            "cands",
            "frame eng / ind",
            "frame low",
            "ring tone",
            "dups",
            "lattice dB above floor",
            "floor dB",
            "template share",
            "fails (engine)",
            "fails (independent)",
            "ind. s",
        ],
        rows,
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.metrics_check", description=__doc__)
    ap.add_argument("--evalset", choices=("public", "private", "all"), default="all")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    import os

    head = (
        f"python -m benchmarks.metrics_check --evalset {args.evalset} (tileset defaults; each "
        f"cell: engine.metrics / this independent implementation; load average at start "
        f"{os.getloadavg()[0]:.1f}; {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())})"
    )
    print(head, flush=True)
    table = compare(args.evalset, args.seed)
    print(table)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(head + "\n" + table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
