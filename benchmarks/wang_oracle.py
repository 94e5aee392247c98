"""What an *ideal* Wang set scores: an oracle for the lattice and frame bounds of issue 11.

Run ``python -m benchmarks.wang_oracle`` (``--help`` for options). On a stationary Gaussian
random field the ideal Wang set can be made exactly, so its figures are the right answer the
metrics must give a set without any construction flaw:

* the **source** is a 512 x 512 field on a torus: white noise filtered by a Gaussian of
  ``ell`` px (correlation length), grey around 0.5;
* every **edge colour** is a pair of adjacent rows (h) or columns (v) of a fresh
  realisation: the row a tile shows as its north edge and the row the tile above shows as its
  south edge, as :mod:`engine.tiles.wang` takes them from one edge sample (rows 0 and T-1 in
  full from the N / S colours, columns 0 and T-1 between them from the W / E colours);
* every **tile** is an exact draw of the field conditioned on its four edges (kriging of a
  fresh unconditional draw: ``x = f + C_ib C_bb^-1 (b - f_b)``, Gaussian, so exact), except
  within 2 ``ell`` px of its corners, which are left free (the corner problem: no draw of a
  smooth field joins the ends of two unrelated rows).

Such a set joins perfectly (each pair of rows across a tile line is a genuine pair) and each
tile is distributed exactly as the texture given its border: no cut, no blend, no selection
bias. The table gives its figures with the benchmark's yardstick (:mod:`benchmarks.wang`:
16 valid 8x8 layouts without equal neighbours, crops carrying each tile's outer pixel;
frame over 2 w_P with the tiles reflected), beside the engine's own Wang set of the same
field (:func:`engine.tiles.wang.wang_set`, default options) and a *floor* set: random crops
with their four edges replaced by the colours' rows (what the lattice's floor measures: the
shared pixels without any continuation).

The result is saved to ``benchmarks/results/wang_oracle.txt``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np
from scipy import ndimage

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._util import format_table  # noqa: E402
from benchmarks.wang import RESULTS, crop_detail, default_ring, stamp  # noqa: E402
from benchmarks.wang_lattice import continued_lattice  # noqa: E402
from engine.metrics import LATTICE_LAYOUTS, border_ratio, detail_ratio, frame, lattice  # noqa: E402
from engine.tiles.wang import canonical_signatures  # noqa: E402
from engine.tiles.wang_layout import wang_layout  # noqa: E402

N = 512
STD = 0.15


class Field:
    """A stationary Gaussian field on a ``size`` x ``size`` torus, correlation length ``ell``
    px."""

    def __init__(self, ell: float, rng: np.random.Generator, size: int = N):
        self.ell = float(ell)
        self.rng = rng
        self.n = n = int(size)
        delta = np.zeros((n, n))
        delta[0, 0] = 1.0
        h = ndimage.gaussian_filter(delta, ell, mode="wrap")
        self.gain = STD / np.sqrt((h * h).sum())
        #: covariance by offset (dy, dx) mod N: the autocorrelation of the filter, scaled
        self.cov = np.real(np.fft.ifft2(np.abs(np.fft.fft2(h)) ** 2)) * self.gain**2

    def draw(self) -> np.ndarray:
        w = self.rng.standard_normal((self.n, self.n))
        return 0.5 + self.gain * ndimage.gaussian_filter(w, self.ell, mode="wrap")

    def c(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Covariance between the pixel sets a (n, 2) and b (m, 2) (row, col)."""
        d = (a[:, None, :] - b[None, :, :]) % self.n
        return self.cov[d[..., 0], d[..., 1]]


def _boundary(T: int, free: int) -> np.ndarray:
    """Tile pixels on the border, but ``free`` px from each corner along the edges."""
    r, c = np.mgrid[0:T, 0:T]
    on = (r == 0) | (r == T - 1) | (c == 0) | (c == T - 1)
    corner = (np.minimum(r, T - 1 - r) < free) & (np.minimum(c, T - 1 - c) < free)
    keep = on & ~corner
    return np.stack([r[keep], c[keep]], axis=1)


def ideal_set(field: Field, T: int, K: int = 2):
    """(tiles, signatures, floor tiles) of the ideal K-colour set of ``field`` (see the module
    docstring); the floor tiles are unconditional crops with the same edges pasted in."""
    rows = []  # h colour: (row shown as a south edge, the row below it shown as a north edge)
    cols = []
    for _ in range(K):
        f = field.draw()
        y, x = field.rng.integers(0, field.n - T, 2)
        rows.append((f[y, x : x + T].copy(), f[y + 1, x : x + T].copy()))
        f = field.draw()
        y, x = field.rng.integers(0, field.n - T, 2)
        cols.append((f[y : y + T, x].copy(), f[y : y + T, x + 1].copy()))
    # the corners are left free: where four tiles meet, the ends of two unrelated rows and
    # columns meet (the corner problem) and no field draw can join them; conditioning on
    # them would make the draw ring around an impossible step
    bnd = _boundary(T, max(2, round(2 * field.ell)))
    r, c = np.mgrid[0:T, 0:T]
    every = np.stack([r.ravel(), c.ravel()], axis=1)
    Cbb = field.c(bnd, bnd) + 1e-6 * STD**2 * np.eye(len(bnd))
    gain = np.linalg.solve(Cbb, field.c(bnd, every)).T  # (T², nb): C_ib C_bb^-1
    is_b = np.zeros((T, T), bool)
    is_b[bnd[:, 0], bnd[:, 1]] = True
    tiles, floors, sigs = [], [], canonical_signatures(K)
    for n, e, s, w in sigs:
        edge = np.zeros((T, T))
        edge[:, 0] = cols[w][1]
        edge[:, T - 1] = cols[e][0]
        edge[0] = rows[n][1]
        edge[T - 1] = rows[s][0]
        f = field.draw()
        y, x = field.rng.integers(0, field.n - T, 2)
        u = f[y : y + T, x : x + T]
        b = edge[bnd[:, 0], bnd[:, 1]] - u[bnd[:, 0], bnd[:, 1]]
        t = u + (gain @ b).reshape(T, T)
        t[is_b] = edge[is_b]  # exact on the border (the solve is, up to round-off)
        tiles.append(t[..., None].astype(np.float32))
        fl = field.draw()[y : y + T, x : x + T].copy()
        fl[is_b] = edge[is_b]
        floors.append(fl[..., None].astype(np.float32))
    return tiles, sigs, floors


def figures(tiles, sigs, S, T: int, seed: int) -> list[float]:
    """Joints med / max, lattice dB above floor, frame, detail (over crops'), as
    :func:`benchmarks.wang.wang_figures`."""
    pairs = []
    for a, sa in zip(tiles, sigs, strict=True):
        for b, sb in zip(tiles, sigs, strict=True):
            if sa[1] == sb[3]:
                pairs.append(border_ratio(a, b, direction="horizontal"))
            if sa[2] == sb[0]:
                pairs.append(border_ratio(a, b, direction="vertical"))
    layouts = [
        wang_layout(sigs, 8, 8, rng=100 * seed + k, no_equal_neighbours=True)
        for k in range(LATTICE_LAYOUTS)
    ]
    lat = lattice(tiles, S, margin=1, layouts=layouts)
    cont = continued_lattice(tiles, S, layouts=layouts)[2]
    fr = frame(tiles, S, limit=2 * default_ring(T), wrap=False)
    det = float(np.median([detail_ratio(t, S) for t in tiles])) / crop_detail(S, T)
    return [float(np.median(pairs)), max(pairs), lat.above, fr.value, det, cont]


def run(ells, T: int, seeds: int, engine: bool) -> str:
    from engine.tiles.wang import wang_set

    rows = []
    for ell in ells:
        per = {"ideal": [], "floor": [], "engine": []}
        for seed in range(seeds):
            field = Field(ell, np.random.default_rng(1000 + seed))
            S = field.draw()[..., None].astype(np.float32)
            tiles, sigs, floors = ideal_set(field, T)
            per["ideal"].append(figures(tiles, sigs, S, T, seed))
            per["floor"].append(figures(floors, sigs, S, T, seed))
            if engine:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    ws = wang_set(S, tile_size=T, rng=seed)
                per["engine"].append(figures([t.tile for t in ws.tiles], ws.signatures, S, T, seed))
        for name, figs in per.items():
            if not figs:
                continue
            m = np.median(np.array(figs), axis=0)
            mx = max(f[1] for f in figs)
            rows.append(
                [f"{ell:g}", name, f"{m[0]:.2f} / {mx:.2f}", f"{m[2]:+.2f}", f"{m[5]:+.2f}",
                 f"{m[3]:.2f}", f"{m[4]:.2f}"]
            )  # fmt: skip
            print(" | ".join(rows[-1]), file=sys.stderr, flush=True)
    heads = ["ell px", "set", "joints med / max", "lattice dB", "continued lattice dB", "frame"]
    heads += ["detail"]
    return (
        f"Ideal Wang sets of Gaussian fields (K = 2, {T} px tiles, medians over {seeds} fields; "
        "the benchmark's yardstick: lattice over 16 valid 8x8 layouts above crops carrying each "
        "tile's outer pixel, frame over 2 w_P, tiles reflected; targets lattice <= +1 dB, frame "
        "<= 1.12). ideal: exact conditional draws given the edges; floor: unconditional crops "
        "with the edges pasted; engine: engine.tiles.wang.wang_set, default options.\n\n"
        + format_table(heads, rows)
        + "\n"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ell", default="1,2,4,8,16", help="correlation lengths (px), comma-separated")
    ap.add_argument("--tile", type=int, default=64, help="tile size (px)")
    ap.add_argument("--seeds", type=int, default=3, help="fields per length")
    ap.add_argument("--no-engine", action="store_true", help="skip the engine's own sets")
    args = ap.parse_args(argv)
    ells = [float(v) for v in args.ell.split(",")]
    text = f"{stamp()}\n\n{run(ells, args.tile, args.seeds, not args.no_engine)}"
    print(text)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "wang_oracle.txt").write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
