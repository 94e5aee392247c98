"""Does the template's own ring tone predict the tile set's? (issue 10; README "Session 13").

Every Somol-Haindl candidate keeps the template's ring, so a template whose ring alone reads
over the ring-tone line was thought to give no passing set. Per texture, at the ``tileset``
defaults (seed 0, 30 candidates): the template rectangle, w_P, the template alone scored as one
tile by :func:`engine.metrics.ring_tone` (against the metric's reference crops, in the
template's phase on periodic textures, and against random crops), where the template's ring
tone sits among the centres of every tile-sized window (the fraction darker; and the mean
|ring − window centre| over the windows' own mean |ring − centre|), the set's ring tone and
whether the set meets the line. ``--shifts dy,...`` also scores the templates of the default
rectangle moved by ``dy`` rows (the seamless tile rebuilt there) for the first texture named.

``python -m benchmarks.template_alone [--evalset public] [TEXTURE ...] [--shifts=-8,-4,0]``
"""

from __future__ import annotations

import argparse
import sys
import warnings

import numpy as np


def _alone(S, T, wp) -> tuple[float, float]:
    from engine.metrics import ring_tone

    T = np.asarray(T)
    return (
        ring_tone([T], S, width=wp, template=T),
        ring_tone([T], S, width=wp, template=T, in_phase=False),
    )


def among_centres(S, T, wp) -> tuple[float, float]:
    """Where the template's ring tone sits among the centres of every tile-sized window of
    ``S`` (the fraction darker than it) and the mean |ring − window centre| over the windows'
    own mean |ring − centre| (what a set of random centres under this ring would read)."""
    from engine.metrics import edge_distance, luminance

    L, t = luminance(S).astype(np.float64), luminance(np.asarray(T))
    h, w = t.shape
    ring = float(t[edge_distance(t.shape) < wp].mean())
    c = np.zeros((L.shape[0] + 1, L.shape[1] + 1))
    c[1:, 1:] = L.cumsum(0).cumsum(1)

    def sums(a, b):
        return c[a:, b:] - c[:-a, b:] - c[a:, :-b] + c[:-a, :-b]

    n_c = (h - 2 * wp) * (w - 2 * wp)
    whole = sums(h, w)
    centre = sums(h - 2 * wp, w - 2 * wp)[wp : wp + whole.shape[0], wp : wp + whole.shape[1]]
    own = np.abs((whole - centre) / (h * w - n_c) - centre / n_c).mean()
    centres = centre / n_c
    return float((centres < ring).mean()), float(np.abs(ring - centres).mean() / own)


def rows(names) -> list[list[str]]:
    from benchmarks import evalset
    from benchmarks.tileset import evaluate_texture, load_image_array
    from engine.metrics import QUALITY_LIMITS

    out = []
    for name in names:
        f = evaluate_texture(load_image_array(evalset.load(name)), 0)
        phase, anywhere = _alone(f["S"], f["seamless"].tile, f["w_P"])
        darker, spread = among_centres(f["S"], f["seamless"].tile, f["w_P"])
        r = f["result"].rect
        out.append(
            [
                name,
                f"{r[2]}x{r[3]} at ({r[0]}, {r[1]})",
                f"{f['w_P']}",
                f"{phase:.2f}",
                f"{anywhere:.2f}",
                f"{darker:.2f}",
                f"{spread:.2f}",
                f"{f['tone']:.2f}",
                "ok" if f["tone"] <= QUALITY_LIMITS["ring_tone"] else "fails",
            ]
        )
    return out


def shifted(name: str, shifts) -> list[list[str]]:
    """The default rectangle of ``name`` moved by each ``dy``: its template alone."""
    from benchmarks import evalset
    from benchmarks.tileset import load_image_array
    from engine.settings import TilesetSettings
    from engine.tiles.pipeline import tileset, working_source
    from engine.tiles.seamless import make_seamless

    S0 = load_image_array(evalset.load(name))
    res = tileset(S0, TilesetSettings(seed=0, candidates=2))
    S, s = working_source(S0, res.settings), res.settings
    x, y, a, b = res.rect
    out = []
    for dy in shifts:
        rect = (x, y + dy, a, b)
        st = make_seamless(S, rect, overlap=res.overlap, seam=s.template_seam)
        phase, anywhere = _alone(S, st.tile, s.patch_overlap)
        out.append([name, f"{rect}", f"{dy:+d}", f"{phase:.2f}", f"{anywhere:.2f}"])
    return out


def main(argv=None) -> int:
    from benchmarks import evalset
    from benchmarks._util import format_table, provenance

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("textures", nargs="*")
    ap.add_argument("--evalset", choices=["public", "private", "all"])
    ap.add_argument("--shifts", help="dy,... for the first texture named")
    args = ap.parse_args(argv)
    names = list(args.textures) + (evalset.texture_names(args.evalset) if args.evalset else [])
    if not names:
        ap.error("name a texture or an --evalset")
    warnings.simplefilter("ignore")
    print(provenance())
    print(f"python -m benchmarks.template_alone {' '.join(sys.argv[1:] if argv is None else argv)}")
    heads = ["texture", "template", "w_P", "alone (in phase)", "alone (random)"]
    heads += ["centres darker", "|ring − centres|", "set", "set line"]
    print(format_table(heads, rows(names)), flush=True)
    if args.shifts:
        dys = [int(v) for v in args.shifts.split(",")]
        heads = ["texture", "rect", "dy", "alone (in phase)", "alone (random)"]
        print("\n" + format_table(heads, shifted(names[0], dys)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
