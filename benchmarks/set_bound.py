"""Where a Somol-Haindl set's frame comes from, and how far the choice of patches alone can go
(issue 10; README "Session 12").

``python -m benchmarks.set_bound [TEXTURE ...] [--stride S] [--ks 5,10,15,20,30]`` (default:
coins, stride 2). Per texture, the ``tileset`` defaults (seed 0), then:

1. **Where the frame comes from**: the frame ratio (:func:`engine.metrics.frame`, the
   metric's own reference crops) by distance d from the tile edge of the *candidates*, of
   their *windows* pasted whole inside the template's outer margin (no cut, no blend), of the
   same candidates with *hard cuts* (``seam_shows=0``: no gradient re-blend) and of the
   *template* alone (one tile: its row is noisy; a single seamless tile has no wrap step,
   but a single crop of coins or retina already reads 0.9-1.4 at d >= 3).
2. **Every position as a candidate**: each patch position of the source on a regular grid of
   ``stride`` px (the template's own position and its minimum distance left out, as the
   engine does) made into a candidate exactly there by the engine's cut and re-blend; per
   candidate its gradient profile by distance over the crops' (the frame's ``ratio``) and its
   |mean ring − mean centre| over the crops' mean (the ring tone's term). A set's frame is the
   maximum over d of the mean of its candidates' ratios and its ring tone the mean of their
   terms, so the best set of k candidates at least the engine's minimum distance apart
   (Chebyshev, as ``engine.tiles.candidates``) is an integer program: minimise z with frame
   <= 1.15 z and ring tone <= 1.3 z (z <= 1: both lines met), solved by HiGHS
   (:func:`scipy.optimize.milp`): ``LP bound`` is the relaxed program's optimum, a lower bound
   of z for every set of k grid candidates; ``z`` the integer optimum (``*``: the best found
   within the time limit, not proven); each line alone for the largest k. The set found for both
   lines is rebuilt and measured by the metrics themselves (``measured``), lattice and pairs
   included.

Prints the tables and writes them to ``benchmarks/results/set_bound.txt``.
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from engine.tileset_metrics import QUALITY_LIMITS

RESULTS = Path(__file__).parent / "results" / "set_bound.txt"
#: the tile-set warnings' lines
FRAME_LINE, TONE_LINE = QUALITY_LIMITS["frame"], QUALITY_LIMITS["ring_tone"]
SHOWN = 8  # distances shown in the first table


def _run(name: str):
    from benchmarks import evalset
    from benchmarks.tileset import load_image_array
    from engine.settings import TilesetSettings
    from engine.tiles.pipeline import tileset, working_source

    S0 = load_image_array(evalset.load(name))
    res = tileset(S0, TilesetSettings(seed=0))
    return res, working_source(S0, res.settings)


def where_frame(res, S) -> list[list[str]]:
    """Table 1: frame ratio by distance of the candidates and their stand-ins."""
    from benchmarks.lattice_causes import with_margin
    from engine.metrics import frame
    from engine.tiles import candidates

    st, s = res.seamless, res.settings
    T = np.asarray(st.tile)
    h, w = T.shape[:2]
    m, wp = s.margin, s.patch_overlap
    windows = []
    for c in res.candidates:
        y, x = c.patch_origin
        windows.append(with_margin(S[y : y + h, x : x + w], T, m))
    opts = dict(patch_overlap=wp, margin=m, seam=s.seam, rng=s.seed, scale=res.scale)
    sets = {
        "candidates": [c.tile for c in res.candidates],
        "windows": windows,
        "hard cuts": [c.tile for c in candidates(S, st, s.candidates, seam_shows=0, **opts)],
        "template": [T],
    }
    rows = []
    for label, tiles in sets.items():
        f = frame(tiles, S, limit=2 * wp, template=st.tile)
        ratios = [f"{r:.2f}" for r in f.ratio[:SHOWN]]
        rows.append([label, f"{len(tiles)}", f"{f.value:.2f} @ {f.distance}", *ratios])
    return rows


def position_figures(res, S, stride: int) -> dict:
    """Every grid position made into a candidate: origins, frame ratio profiles, ring terms."""
    from engine.tiles.candidates import CandidateSetup
    from engine.tileset_metrics import frame, frame_profiles, ring_reference, ring_steps

    st, s = res.seamless, res.settings
    wp, m = s.patch_overlap, s.margin
    setup = CandidateSetup(
        S,
        st,
        patch_size=None,
        patch_overlap=wp,
        margin=m,
        neighbourhood=0,
        seam=s.seam,
        excluded=None,
        maps=None,
        weights=None,
        scale=res.scale,
    )
    lim = 2 * wp
    h, w = setup.ph, setup.pw
    ref = frame([st.tile], S, limit=lim, template=st.tile).reference  # the metric's crops
    ref_tone = ring_reference(S, (h, w), width=wp, template=st.tile)  # ring_tone's crops
    H, W = S.shape[:2]
    ty, tx = setup.template_origin
    d = setup.min_distance
    origins, ratios, terms = [], [], []
    t0 = time.perf_counter()
    for y in range(0, H - h + 1, stride):
        for x in range(0, W - w + 1, stride):
            if max(abs(y - ty), abs(x - tx)) < d:
                continue
            tile = setup.make(0, None, (y, x), 0, None).tile
            ratios.append(frame_profiles([tile], limit=lim)[0] / ref)
            terms.append(ring_steps([tile], width=wp)[0] / ref_tone)
            origins.append((y, x))
    return {
        "origins": np.array(origins),
        "ratios": np.array(ratios),
        "terms": np.array(terms),
        "min_distance": d,
        "seconds": time.perf_counter() - t0,
    }


def best_set(fig: dict, k: int, lines=("frame", "tone"), time_limit: float = 120.0) -> dict:
    """The k grid candidates at least the minimum distance apart that minimise z, frame <=
    1.15 z and / or ring tone <= 1.3 z (module docstring)."""
    from scipy import sparse
    from scipy.optimize import Bounds, LinearConstraint, milp

    org, R, Tm, md = fig["origins"], fig["ratios"], fig["terms"], fig["min_distance"]
    n = len(org)
    col = sparse.csr_matrix
    cons = [LinearConstraint(col(np.r_[np.ones(n), 0][None]), k, k)]
    if "frame" in lines:
        A = sparse.hstack([col(R.T), col(np.full((R.shape[1], 1), -FRAME_LINE * k))])
        cons.append(LinearConstraint(A, -np.inf, 0))
    if "tone" in lines:
        cons.append(LinearConstraint(col(np.r_[Tm, -TONE_LINE * k][None]), -np.inf, 0))
    # the minimum distance: at most one origin in every md x md box anchored at an origin
    # (exact on a regular grid: two origins closer than md lie in the box at their minima)
    rows, cols = [], []
    for r, (y, x) in enumerate(org):
        q = np.nonzero(
            (org[:, 0] >= y) & (org[:, 0] < y + md) & (org[:, 1] >= x) & (org[:, 1] < x + md)
        )
        rows.append(np.full(len(q[0]), r))
        cols.append(q[0])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    box = col((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    cons.append(LinearConstraint(sparse.hstack([box, col((n, 1))]), -np.inf, 1))
    c = np.r_[np.zeros(n), 1.0]
    bounds = Bounds(np.zeros(n + 1), np.r_[np.ones(n), np.inf])
    relaxed = milp(c, constraints=cons, bounds=bounds)  # the LP: a lower bound of any set
    out = milp(
        c,
        constraints=cons,
        integrality=np.r_[np.ones(n), 0],
        bounds=bounds,
        options={"time_limit": time_limit},
    )
    got = {"k": k, "lp": float(relaxed.fun), "z": float("nan"), "chosen": np.zeros(0, int)}
    if out.x is not None:
        chosen = np.nonzero(np.round(out.x[:n]))[0]
        got.update(
            z=float(out.fun),
            optimal=out.status == 0,
            chosen=chosen,
            frame=float(R[chosen].mean(axis=0).max()),
            tone=float(Tm[chosen].mean()),
        )
    return got


def measure(res, S, origins) -> dict:
    """The candidates made exactly at ``origins``, measured by the metrics themselves."""
    from benchmarks.tileset import pair_ratios
    from engine.metrics import duplicates, frame, lattice, ring_tone
    from engine.tiles import make_candidate

    st, s = res.seamless, res.settings
    wp, m = s.patch_overlap, s.margin
    opts = dict(patch_overlap=wp, margin=m, seam=s.seam, scale=res.scale)
    cands = [
        make_candidate(S, st, patch_origin=(int(y), int(x)), index=i, **opts)
        for i, (y, x) in enumerate(origins)
    ]
    r = pair_ratios([c.tile for c in cands])
    return {
        "cands": cands,
        "frame": frame(cands, S, limit=2 * wp, template=st.tile).value,
        "tone": ring_tone(cands, S, width=wp, template=st.tile),
        "lattice": lattice(cands, S, template=st.tile, margin=m).above,
        "dups": duplicates(cands, st.tile).count,
        "pairs": (float(np.median(r)), float(r.max())),
    }


def _pair(got: dict) -> str:
    return f"{got['frame']:.2f} · {got['tone']:.2f}" if "frame" in got else "-"


def bounds_table(
    name: str, res, S, fig: dict, ks, layouts: Path | None, time_limit: float
) -> list[list[str]]:
    """Table 2 rows: per k, the best set for both lines (and measured); each line alone for
    the largest k."""
    from benchmarks.tileset import save_layout

    rows = []
    for k in ks:
        both = best_set(fig, k, time_limit=time_limit)
        alone = {line: {} for line in ("frame", "tone")}
        if k == max(ks):
            alone = {line: best_set(fig, k, (line,), time_limit) for line in alone}
        row = [
            name,
            f"{k}",
            f"{both['lp']:.3f}",
            f"{both['z']:.3f}" + ("" if both.get("optimal") else "*"),
        ]
        row.append(_pair(both))
        if len(both["chosen"]) == k:
            got = measure(res, S, fig["origins"][both["chosen"]])
            row.append(
                f"{got['frame']:.2f} · {got['tone']:.2f} · {got['lattice']:+.2f} dB, "
                f"dups {got['dups']}, pairs {got['pairs'][0]:.2f} / {got['pairs'][1]:.2f}"
            )
            if layouts is not None and both["z"] <= 1:
                save_layout({"cands": got["cands"]}, layouts / f"{name}_best{k}.png")
        else:
            row.append("-")
        row += [_pair(alone["frame"]), _pair(alone["tone"])]
        rows.append(row)
    return rows


def main(argv=None) -> int:
    from benchmarks._util import format_table, provenance

    ap = argparse.ArgumentParser(prog="python -m benchmarks.set_bound", description=__doc__)
    ap.add_argument(
        "textures", nargs="*", default=["coins"], help="evaluation-set names, NAME[:STRIDE]"
    )
    ap.add_argument("--stride", type=int, default=2, help="grid of patch positions (px)")
    ap.add_argument("--ks", default="5,10,15,20,30", help="set sizes")
    ap.add_argument("--time-limit", type=float, default=30, help="per integer program (s)")
    ap.add_argument("--layouts", type=Path, help="write the best sets meeting both lines here")
    args = ap.parse_args(argv)
    ks = [int(k) for k in args.ks.split(",")]
    warnings.simplefilter("ignore")
    out = [
        provenance(),
        f"python -m benchmarks.set_bound {' '.join(args.textures)} "
        f"--stride {args.stride} --ks {args.ks} --time-limit {args.time_limit:g} (seed 0)",
        "",
    ]
    head1 = ["texture", "set", "n", "frame @ d", *[f"d={d}" for d in range(SHOWN)]]
    head2 = [
        "texture",
        "k",
        "LP bound",
        "z both",
        "frame · tone",
        "measured (rebuilt)",
        "frame alone: frame · tone",
        "tone alone: frame · tone",
    ]
    t1, t2 = [], []
    for spec in args.textures:
        name, _, step = spec.partition(":")
        stride = int(step) if step else args.stride
        res, S = _run(name)
        t1 += [[name, *r] for r in where_frame(res, S)]
        fig = position_figures(res, S, stride)
        out.append(
            f"{name}: {len(fig['origins'])} grid positions (stride {stride}, minimum "
            f"distance {fig['min_distance']} px, {fig['seconds']:.0f} s); engine set "
            f"{len(res.candidates)} candidates"
        )
        t2 += bounds_table(name, res, S, fig, ks, args.layouts, args.time_limit)
    out += ["", format_table(head1, t1), "", format_table(head2, t2)]
    text = "\n".join(out)
    print(text)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
