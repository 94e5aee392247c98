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

Prints a table and writes it to ``benchmarks/results/lattice_causes.txt``.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).parent / "results" / "lattice_causes.txt"
DEFAULT = ("brick", "retina", "cell", "cobblestones")


def _with_margin(q: np.ndarray, T: np.ndarray, m: int) -> np.ndarray:
    q = q.copy()
    q[:m], q[-m:], q[:, :m], q[:, -m:] = T[:m], T[-m:], T[:, :m], T[:, -m:]
    return q


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
        windows.append(_with_margin(S[y : y + h, x : x + w], T, m))
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
        share = float(template_share(tiles, st.tile).mean())
        figures = [f"{fr:.2f}", f"{tone:.2f}", f"{lat:+.2f}", f"{share:.0%}"]
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
    head = ["texture", "set", "tiles", "frame", "ring tone", "lattice dB above floor", "share"]
    text = format_table(head, rows)
    print(text)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("python -m benchmarks.lattice_causes " + " ".join(names) + "\n\n" + text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
