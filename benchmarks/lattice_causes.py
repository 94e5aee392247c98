"""What makes a tile set's lattice (issue 10): the candidates' figures next to three
stand-in sets built from the same run, so each cause is measured on its own.

``python -m benchmarks.lattice_causes [TEXTURE ...] [--evalset public|private|all]``
(default: the public textures whose structures are large against the tile: brick, retina,
cell, and cobblestones for comparison). Per texture, the ``tileset`` defaults (seed 0), then
frame / ring tone / lattice above floor / template share of:

* **candidates**: the set as made;
* **windows**: every candidate's source window whole (the patch as found, no cut, no blend),
  with only the template's outer margin — what the choice of patch positions alone gives;
* **ring only**: a uniformly random crop of the source pasted inside each candidate's own
  closed cut (the template outside it, hard) — what the shared ring alone gives;
* **spread 0**: the candidates re-made with the global search's band match alone
  (``spread=0``, :mod:`engine.tiles.patch_plan`);
* **hard cuts**: the candidates re-made without the gradient re-blend of showing cuts
  (``seam_shows=0``).

Each lattice figure is also split by the kind of harmonic that carries it (``--parts``,
:func:`lattice_parts`): *along y* (bins with no horizontal frequency: row structure such as a
tone step or a joint at every tile row), *along x* (column structure), *mixed* (both: structure
local in both directions, e.g. a blob at the tile's corners) — each the mean power on those
harmonics over the same between-harmonic power, minus the floor's; the ``all`` figure is the
metric's. Next to it the tiles' *tone spread*: the standard deviation of the tiles' mean
luminance over the floor crops' (below 1: tiles more alike in tone than crops of the source,
which raises the lattice ratio by itself — less power between the harmonics).

Prints a table and writes it to ``benchmarks/results/lattice_causes.txt``.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).parent / "results" / "lattice_causes.txt"
DEFAULT = ("brick", "retina", "cell", "cobblestones")


def with_margin(q: np.ndarray, T: np.ndarray, m: int) -> np.ndarray:
    """A copy of window ``q`` with its outer ``m`` px replaced by the template ``T``'s (a
    window pasted whole inside the template's margin: no cut, no blend)."""
    q = q.copy()
    q[:m], q[-m:], q[:, :m], q[:, -m:] = T[:m], T[-m:], T[:, :m], T[:, -m:]
    return q


def lattice_parts(tiles, source, *, template, margin: int, layouts=None, rng=0) -> dict:
    """:func:`engine.metrics.lattice` (same crops, same layouts, same random draws: ``all`` is
    its ``above``) split by harmonic kind, in dB above the floor: ``along y`` (bins (i, 0)),
    ``along x`` ((0, j)), ``mixed`` ((i, j), i, j > 0), ``all``; and ``tone spread`` (module
    docstring)."""
    from engine.metrics import LATTICE_LAYOUTS, edge_distance, luminance
    from engine.reference_crops import ReferenceCrops

    stack = np.stack([luminance(getattr(t, "tile", t)) for t in tiles]).astype(np.float64)
    n, h, w = stack.shape
    ring = edge_distance((h, w)) < margin
    T = luminance(getattr(template, "tile", template))
    g = np.random.default_rng(rng)
    S = luminance(source)
    where = ReferenceCrops.build(S, (h, w), T)
    R = C = 8
    ty, tx = np.arange(R)[:, None], np.arange(C)[None, :]
    r, c = np.arange(h)[:, None], np.arange(w)[None, :]
    kinds = {
        "along y": (slice(1, None), slice(0, 1)),
        "along x": (slice(0, 1), slice(1, None)),
        "mixed": (slice(1, None), slice(1, None)),
        "all": (slice(None), slice(None)),
    }

    def spectra(st, idx) -> dict:
        power = {}
        for a in (0, 1):
            for b in (0, 1):
                wts = np.zeros(st.shape[0])
                np.add.at(wts, idx.ravel(), ((-1.0) ** (ty * a + tx * b)).ravel())
                mod = np.exp(-1j * np.pi * (a * r / h + b * c / w))
                power[a, b] = np.abs(np.fft.fft2(np.tensordot(wts, st, 1) * mod)) ** 2
        harm = power[0, 0].copy()
        harm[0, 0] = np.nan  # the DC bin is no harmonic
        mid = np.concatenate([power[1, 0].ravel(), power[0, 1].ravel(), power[1, 1].ravel()])
        return {k: 10 * np.log10(np.nanmean(harm[s]) / mid.mean()) for k, s in kinds.items()}

    above = {k: [] for k in kinds}
    means = []
    for _ in range(LATTICE_LAYOUTS if layouts is None else layouts):
        org = where.origins(n, g)
        ref = np.stack([S[y : y + h, x : x + w] for y, x in org]).astype(np.float64)
        ref[:, ring] = T[ring]
        idx = g.integers(0, n, (R, C))
        v, f = spectra(stack, idx), spectra(ref, idx)
        for k in kinds:
            above[k].append(v[k] - f[k])
        means.append(ref[:, ~ring].mean(axis=1).std())
    out = {k: float(np.mean(x)) for k, x in above.items()}
    out["tone spread"] = float(stack[:, ~ring].mean(axis=1).std() / max(np.mean(means), 1e-12))
    return out


def stand_ins(res, S, seed: int = 5) -> dict:
    """The candidates and the stand-in sets of one ``tileset`` result (module docstring)."""
    from engine.tiles import candidates

    st, s = res.seamless, res.settings
    T = np.asarray(st.tile)
    h, w = T.shape[:2]
    H, W = S.shape[:2]
    m = s.margin
    rng = np.random.default_rng(seed)
    windows, ring = [], []
    for c in res.candidates:
        y, x = c.patch_origin
        windows.append(with_margin(S[y : y + h, x : x + w], T, m))
        yy, xx = int(rng.integers(0, H - h + 1)), int(rng.integers(0, W - w + 1))
        ring.append(np.where(np.asarray(c.mask)[..., None], S[yy : yy + h, xx : xx + w], T))
    opts = dict(patch_overlap=s.patch_overlap, margin=m, seam=s.seam, rng=s.seed, scale=res.scale)
    n = s.candidates
    return {
        "candidates": [c.tile for c in res.candidates],
        "windows": windows,
        "ring only": ring,
        "spread 0": [c.tile for c in candidates(S, st, n, spread=0, **opts)],
        "hard cuts": [c.tile for c in candidates(S, st, n, seam_shows=0, **opts)],
    }


def causes(name: str) -> list[list[str]]:
    from benchmarks import evalset
    from benchmarks.tileset import load_image_array
    from engine.metrics import frame, lattice, ring_tone, template_share
    from engine.settings import TilesetSettings
    from engine.tiles.pipeline import tileset, working_source

    S0 = load_image_array(evalset.load(name))
    res = tileset(S0, TilesetSettings(seed=0))
    S = working_source(S0, res.settings)
    st, wp, m = res.seamless, res.settings.patch_overlap, res.settings.margin
    rows = []
    for label, tiles in stand_ins(res, S).items():
        fr = frame(tiles, S, limit=2 * wp, template=st.tile).value
        tone = ring_tone(tiles, S, width=wp, template=st.tile)
        lat = lattice(tiles, S, template=st.tile, margin=m).above
        parts = lattice_parts(tiles, S, template=st.tile, margin=m)
        share = float(template_share(tiles, st.tile).mean())
        split = [f"{parts[k]:+.2f}" for k in ("along y", "along x", "mixed")]
        figures = [f"{fr:.2f}", f"{tone:.2f}", f"{lat:+.2f}", *split]
        figures += [f"{parts['tone spread']:.2f}", f"{share:.0%}"]
        rows.append([name, label, f"{len(tiles)}", *figures])
    return rows


def main(argv=None) -> int:
    from benchmarks import evalset
    from benchmarks._util import format_table

    ap = argparse.ArgumentParser(prog="python -m benchmarks.lattice_causes", description=__doc__)
    ap.add_argument("textures", nargs="*", help=f"evaluation-set names (default {DEFAULT})")
    ap.add_argument("--evalset", choices=("public", "private", "all"))
    args = ap.parse_args(argv)
    names = list(args.textures) or (
        evalset.texture_names(args.evalset) if args.evalset else list(DEFAULT)
    )
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in names:
            rows += causes(name)
    head = ["texture", "set", "tiles", "frame", "ring tone", "lattice dB above floor"]
    head += ["along y", "along x", "mixed", "tone spread", "share"]
    text = format_table(head, rows)
    print(text)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("python -m benchmarks.lattice_causes " + " ".join(names) + "\n\n" + text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
