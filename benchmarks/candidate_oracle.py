"""What an *ideal* candidate set scores: an oracle for issue 10's interior metrics.

Run ``python -m benchmarks.candidate_oracle`` (``--help`` for options). On a stationary
Gaussian random field (:class:`benchmarks.wang_oracle.Field`: white noise filtered by a
Gaussian of ``ell`` px on a 512 px torus) the ideal Somol–Haindl candidate set can be made
exactly, so its figures are the right answer the metrics must give a set without any flaw:

* the **template** is a draw of the same field on a T x T torus (a seamless tile: its top row
  continues its bottom row, as the engine's wrap does);
* every **candidate** is an exact draw of the field given the template's outer 1 px ring
  (kriging of a fresh unconditional crop, ``x = u + C_ib C_bb^-1 (t_b - u_b)``: Gaussian, so
  exact) — every candidate keeps the template's margin, as the engine's do, and is otherwise
  distributed exactly as the texture given it: no cut, no blend, no selection bias;
* a **planted ring** set: the same tiles with the template pasted over their outer
  ``PLANTED`` px (a shared ring every tile repeats: what the lattice must still catch).

Per correlation length, medians over the fields: :func:`engine.metrics.lattice` above its
floor (random crops with the template's 1 px margin pasted), the same tiles above the
continued floor (:mod:`benchmarks.continued_floor`: the crops continued from the margin by
kriging), :func:`engine.metrics.frame` (limit 2 w_P) and :func:`engine.metrics.ring_tone`
(w_P = max(8, T // 20)). Saved to ``benchmarks/results/candidate_oracle.txt``.

``--textures NAME,...`` (evaluation-set names, :mod:`benchmarks.evalset`) or ``--evalset
public``: the same oracle for each texture's **Gaussian surrogate** — a field with exactly the
source's luminance power spectrum (periodogram, random phases: :class:`Surrogate`), the
template a draw of it on the tile's torus, at the tile size and w_P the ``tileset`` defaults
choose for that texture — next to the engine's own set (defaults, seed 0). A flawless set of
a texture with that spectrum scores the surrogate's figures: what is left of the engine's
figures above them is the set's own. Saved to ``benchmarks/results/candidate_oracle_*.txt``.
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

from benchmarks._util import format_table  # noqa: E402
from benchmarks.continued_floor import continued_floor_lattice  # noqa: E402
from benchmarks.wang_oracle import Field  # noqa: E402
from engine.metrics import edge_distance, frame, lattice, ring_tone  # noqa: E402

RESULTS = Path(__file__).parent / "results" / "candidate_oracle.txt"
PLANTED = 6  # px of the planted shared ring
CANDIDATES = 30


class Surrogate:
    """A stationary Gaussian field on the torus of ``L``'s shape with exactly ``L``'s power
    spectrum (the periodogram of the luminance minus its mean; random phases), grey at
    ``L``'s mean: what a texture "like" ``L`` is to second order, where the ideal set can be
    made exactly."""

    def __init__(self, L: np.ndarray, rng: np.random.Generator):
        L = np.asarray(L, np.float64)
        self.rng = rng
        self.shape = L.shape
        self.mean = float(L.mean())
        self.power = np.abs(np.fft.fft2(L - self.mean)) ** 2 / L.size
        self.cov = np.real(np.fft.ifft2(self.power))  # circular autocovariance by offset

    def draw(self) -> np.ndarray:
        w = np.fft.fft2(self.rng.standard_normal(self.shape))
        return self.mean + np.real(np.fft.ifft2(np.sqrt(self.power) * w))

    def torus(self, h: int, w: int) -> np.ndarray:
        """A draw on an h x w torus (a seamless tile): the spectrum at the torus's
        frequencies (nearest bins)."""
        H, W = self.shape
        iy = np.rint(np.fft.fftfreq(h) * H).astype(int) % H
        ix = np.rint(np.fft.fftfreq(w) * W).astype(int) % W
        p = self.power[iy][:, ix]
        noise = np.fft.fft2(self.rng.standard_normal((h, w)))
        return self.mean + np.real(np.fft.ifft2(np.sqrt(p) * noise))

    def c(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Covariance between the pixel sets a (n, 2) and b (m, 2) (row, col)."""
        d = (a[:, None, :] - b[None, :, :]) % np.asarray(self.shape)
        return self.cov[d[..., 0], d[..., 1]]


def _template(field, size) -> np.ndarray:
    h, w = size
    if isinstance(field, Surrogate):
        return field.torus(h, w)
    noise = field.rng.standard_normal((h, w))
    return 0.5 + field.gain * ndimage.gaussian_filter(noise, field.ell, mode="wrap")


def ideal_candidates(field, size, n: int = CANDIDATES):
    """(template (h, w, 1), ideal candidates, planted-ring candidates) of ``field`` (a
    :class:`benchmarks.wang_oracle.Field` or a :class:`Surrogate`) for tiles of ``size``
    (h, w) (an int: square)."""
    h, w = (size, size) if np.isscalar(size) else (int(size[0]), int(size[1]))
    rng = field.rng
    tpl = _template(field, (h, w))
    on = edge_distance((h, w)) == 0
    bnd = np.argwhere(on)
    every = np.argwhere(np.ones((h, w), bool))
    Cbb = field.c(bnd, bnd)
    Cbb = 0.5 * (Cbb + Cbb.T) + 1e-6 * float(Cbb.diagonal().mean()) * np.eye(len(bnd))
    inv = np.linalg.inv(Cbb)
    gain = np.empty((h * w, len(bnd)))  # C_ib C_bb^-1, in blocks of pixels (memory)
    for s in range(0, h * w, 4096):
        gain[s : s + 4096] = field.c(every[s : s + 4096], bnd) @ inv
    planted = edge_distance((h, w)) < PLANTED
    H, W = field.draw().shape
    tiles, rings = [], []
    for _ in range(n):
        y, x = rng.integers(0, H - h + 1), rng.integers(0, W - w + 1)
        u = field.draw()[y : y + h, x : x + w]
        t = u + (gain @ (tpl[on] - u[on])).reshape(h, w)
        t[on] = tpl[on]
        tiles.append(t[..., None].astype(np.float32))
        p = t.copy()
        p[planted] = tpl[planted]
        rings.append(p[..., None].astype(np.float32))
    return tpl[..., None].astype(np.float32), tiles, rings


def figures(tiles, S, tpl, T: int, wp: int | None = None) -> list[float]:
    """Lattice above the pasted floor, above the continued floor, frame, ring tone."""
    wp = max(8, T // 20) if wp is None else wp
    return [
        lattice(tiles, S, template=tpl, margin=1).above,
        continued_floor_lattice(tiles, S, template=tpl, margin=1)[2],
        frame(tiles, S, limit=2 * wp, template=tpl).value,
        ring_tone(tiles, S, width=wp, template=tpl),
    ]


def run(ells, T: int, seeds: int) -> str:
    rows = []
    for ell in ells:
        per = {"ideal": [], "planted ring": []}
        for seed in range(seeds):
            field = Field(ell, np.random.default_rng(500 + seed))
            S = field.draw()[..., None].astype(np.float32)
            tpl, tiles, rings = ideal_candidates(field, T)
            per["ideal"].append(figures(tiles, S, tpl, T))
            per["planted ring"].append(figures(rings, S, tpl, T))
        for name, figs in per.items():
            a = np.array(figs)
            m = np.median(a, axis=0)
            rows.append(
                [f"{ell:g}", name, f"{m[0]:+.2f} ({a[:, 0].min():+.1f} … {a[:, 0].max():+.1f})",
                 f"{m[1]:+.2f} ({a[:, 1].min():+.1f} … {a[:, 1].max():+.1f})",
                 f"{m[2]:.2f} ({a[:, 2].min():.2f} … {a[:, 2].max():.2f})",
                 f"{m[3]:.2f} ({a[:, 3].min():.2f} … {a[:, 3].max():.2f})"]
            )  # fmt: skip
            print(" | ".join(rows[-1]), file=sys.stderr, flush=True)
    heads = ["ell px", "set", "lattice dB above pasted floor", "above continued floor"]
    heads += ["frame", "ring tone"]
    return (
        f"Ideal candidate sets of Gaussian fields ({CANDIDATES} candidates of {T} px tiles, "
        f"median (range) over {seeds} fields): every candidate an exact draw of the field "
        "given the template's 1 px ring; planted ring: the same tiles with the template's "
        f"outer {PLANTED} px pasted. Issue 10's lines: lattice <= +1.5 dB, frame <= 1.15, "
        "ring tone <= 1.3.\n\n" + format_table(heads, rows) + "\n"
    )


def texture_rows(names, seeds: int) -> str:
    """The surrogate oracle beside the engine's own set, per evaluation-set texture (module
    docstring)."""
    import warnings

    from benchmarks import evalset
    from benchmarks.tileset import evaluate_texture, load_image_array
    from engine.metrics import luminance

    rows = []
    for name in names:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = evaluate_texture(load_image_array(evalset.load(name)), 0)
        L = luminance(f["S"])
        figs = []
        for seed in range(seeds):
            sur = Surrogate(L, np.random.default_rng(700 + seed))
            S = sur.draw()[..., None].astype(np.float32)
            tpl, tiles, rings = ideal_candidates(sur, f["tile"])
            wp = f["w_P"]
            figs.append(
                [
                    frame(tiles, S, limit=2 * wp, template=tpl).value,
                    ring_tone(tiles, S, width=wp, template=tpl),
                    lattice(tiles, S, template=tpl, margin=1).above,
                    lattice(rings, S, template=tpl, margin=1).above,
                ]
            )
        a = np.array(figs)
        m = np.median(a, axis=0)
        h, w = f["tile"]
        rows.append(
            [name, f"{w}x{h}", f"{f['w_P']}",
             f"{f['frame']:.2f} · {f['tone']:.2f} · {f['lattice']:+.2f}",
             f"{m[0]:.2f} · {m[1]:.2f} · {m[2]:+.2f} ({a[:, 2].min():+.1f} … {a[:, 2].max():+.1f})",
             f"{m[3]:+.2f}"]
        )  # fmt: skip
        print(" | ".join(rows[-1]), file=sys.stderr, flush=True)
    heads = ["texture", "tile", "w_P", "engine set: frame · ring tone · lattice dB"]
    heads += ["ideal set of the surrogate: frame · ring tone · lattice dB (range)"]
    heads += [f"planted {PLANTED} px ring: lattice dB"]
    return (
        "Ideal candidate sets of each texture's Gaussian surrogate (the source's luminance "
        f"power spectrum, random phases; {CANDIDATES} exact draws given a seamless template's "
        f"1 px ring, the tileset defaults' tile size and w_P; median over {seeds} fields) "
        "beside the engine's own set (defaults, seed 0). Lattice: dB above the pasted floor of "
        "engine.metrics.lattice. Lines: frame <= 1.15, ring tone <= 1.3, lattice <= +1.5 dB.\n\n"
        + format_table(heads, rows)
        + "\n"
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ell", default="1,2,4,8,16", help="correlation lengths (px)")
    ap.add_argument("--tile", type=int, default=64, help="tile size (px)")
    ap.add_argument("--seeds", type=int, default=3, help="fields per length")
    ap.add_argument("--textures", help="evaluation-set textures (comma-separated): surrogates")
    ap.add_argument("--evalset", choices=("public", "private", "all"), help="... or a whole set")
    args = ap.parse_args(argv)
    stamp = time.strftime("%Y-%m-%d %H:%M")
    out = RESULTS
    if args.textures or args.evalset:
        from benchmarks import evalset

        names = args.textures.split(",") if args.textures else evalset.texture_names(args.evalset)
        text = f"{stamp}\n\n{texture_rows(names, args.seeds)}"
        out = RESULTS.with_name(f"candidate_oracle_{args.evalset or 'textures'}.txt")
    else:
        ells = [float(v) for v in args.ell.split(",")]
        text = f"{stamp}\n\n{run(ells, args.tile, args.seeds)}"
    print(text)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
