"""``quilt-studio tileset SOURCE --out DIR``: template, seamless tile, candidates, preview.

Writes into DIR (created if needed):

- ``template.png``: the seamless template tile;
- ``tile_000.png`` ...: every candidate (``tile_000_<map>.png`` for material maps);
- ``manifest.json``: parameters, seed, template rectangle and costs, per-tile source
  rectangle, seed and scores, picks, layout, warnings;
- ``layout.csv`` / ``layout.json``: the preview's index matrix (cells are tile indices,
  i.e. the NNN of ``tile_NNN.png``);
- ``preview.png``: the picked tiles assembled by that matrix.

Images keep the source's bit depth (16-bit in, 16-bit out) and channels. Progress goes to
stderr, one line per step.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import re
import sys
import time
from pathlib import Path

import numpy as np

from engine._fs import write_bytes_atomically
from engine.cli._args import (
    add_exclusion,
    add_seam_options,
    excluded_pixels,
    int_at_least,
    non_negative_float,
)
from engine.cli.export import add_project_option, save_project_option

FORMAT = "quilt-studio-tileset"
VERSION = 1
MAIN_MAP = "albedo"  # the source's map name in a project file


# ---------------------------------------------------------------- argument types
def _size(text: str):
    """``N`` or ``HxW`` -> int or (h, w)."""
    m = re.fullmatch(r"\s*(\d+)\s*(?:[xX]\s*(\d+)\s*)?", text)
    if not m:
        raise argparse.ArgumentTypeError(f"expected N or HxW (e.g. 256 or 200x300), got {text!r}")
    h = int(m.group(1))
    w = int(m.group(2)) if m.group(2) else None
    if h < 1 or (w is not None and w < 1):
        raise argparse.ArgumentTypeError(f"sizes must be >= 1, got {text!r}")
    return h if w is None else (h, w)


def _picks(text: str) -> list[int]:
    try:
        out = [int(t) for t in text.replace(" ", "").split(",") if t != ""]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated tile indices like 0,3,7, got {text!r}"
        ) from None
    if not out or min(out) < 0 or len(set(out)) != len(out):
        raise argparse.ArgumentTypeError(f"picks must be distinct indices >= 0, got {text!r}")
    return out


def _grid(text: str) -> tuple[int, int]:
    v = _size(text)
    return (v, v) if isinstance(v, int) else v


def _named(kind: str):
    def parse(text: str):
        name, sep, value = text.partition("=")
        if not sep or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", name):
            raise argparse.ArgumentTypeError(f"expected NAME={kind.upper()}, got {text!r}")
        if kind == "weight":
            try:
                return name, float(value)
            except ValueError:
                raise argparse.ArgumentTypeError(f"expected NAME=NUMBER, got {text!r}") from None
        return name, value

    return parse


def add_parser(subparsers) -> argparse.ArgumentParser:
    from engine.blend import BLEND_MODES
    from engine.errormap import METRICS
    from engine.seams import METHODS

    p = subparsers.add_parser(
        "tileset",
        help="make a seamless template tile and N mutually connectable candidate tiles",
        description="Search the template tile in SOURCE, make it seamless, derive N candidate "
        "tiles that all connect to each other (Somol & Haindl), and write them with a "
        "manifest, an index matrix and a synthesized preview into DIR.",
    )
    p.add_argument("source", metavar="SOURCE", help="source texture (PNG, JPEG, TIFF, BMP, WebP)")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created)")
    p.add_argument(
        "--candidates",
        type=int_at_least(1),
        default=30,
        metavar="N",
        help="number of candidate tiles (default 30)",
    )
    p.add_argument(
        "--tile-min",
        type=_size,
        default=None,
        metavar="N|HxW",
        help="smallest tile (default: a quarter of the source's shorter side)",
    )
    p.add_argument(
        "--tile-max",
        type=_size,
        default=None,
        metavar="N|HxW",
        help="largest tile (default: --tile-min if given, else half the source's shorter side)",
    )
    p.add_argument(
        "--rect",
        default=None,
        metavar="X,Y,W,H",
        help="use this tile rectangle instead of searching one",
    )
    p.add_argument(
        "--joint-weight",
        type=non_negative_float,
        default=None,
        metavar="L",
        help="weight of the tile's natural wrap joint in the template search, so the tile edge "
        "falls where the texture is calm (default 0.5; 0 = strip mismatch only, as in the paper)",
    )
    p.add_argument(
        "--overlap",
        type=int_at_least(2),
        default=None,
        metavar="N",
        help="w_T, width of the template's border regions (default: tile/10)",
    )
    p.add_argument(
        "--patch-overlap",
        type=int_at_least(2),
        default=None,
        metavar="N",
        help="w_P, the ring the patch cut runs in (default: min(w_T, max(8, w_T // 2)) of the "
        "template overlap w_T, see engine.tiles.default_patch_overlap)",
    )
    p.add_argument(
        "--patch-size",
        type=_size,
        default=None,
        metavar="N|HxW",
        help="patch window (default: the tile size)",
    )
    p.add_argument(
        "--margin",
        type=int_at_least(0),
        default=None,
        metavar="N",
        help="outer pixels every candidate keeps from the template (default 2, at most w_P - 1)",
    )
    p.add_argument(
        "--neighbourhood",
        type=int_at_least(0),
        default=5,
        metavar="N",
        help="refine each random patch position within +-N px (default 5)",
    )
    p.add_argument("--seam", choices=METHODS, default="dp", help="seam method (default dp)")
    add_seam_options(p)
    p.add_argument("--metric", choices=METRICS, default="euclid", help="error metric")
    p.add_argument(
        "--blend",
        choices=BLEND_MODES,
        default=None,
        help="blending of every cut (default: none for the template, adaptive for the patches)",
    )
    p.add_argument("--rho", type=int_at_least(0), default=3, help="adaptive blending ρ")
    p.add_argument("--width", type=int_at_least(0), default=4, help="feather width in px")
    p.add_argument("--seed", type=int_at_least(0), default=0, help="random seed (default 0)")
    p.add_argument(
        "--pick",
        type=_picks,
        default=None,
        metavar="I,J,...",
        help="tile indices for the preview and the project (default: all)",
    )
    p.add_argument(
        "--preview",
        type=_grid,
        default=(8, 8),
        metavar="RxC",
        help="preview grid in tiles (default 8x8)",
    )
    p.add_argument(
        "--equal-neighbours",
        action="store_true",
        help="allow equal neighbouring tiles in the preview's index matrix",
    )
    p.add_argument("--workers", type=int_at_least(1), default=2, help="threads (default 2)")
    p.add_argument(
        "--map",
        type=_named("file"),
        action="append",
        default=[],
        metavar="NAME=FILE",
        help="a co-registered material map (repeatable)",
    )
    p.add_argument(
        "--weight",
        type=_named("weight"),
        action="append",
        default=[],
        metavar="NAME=W",
        help="seam error weight of a map ('main' = SOURCE)",
    )
    add_exclusion(p, "source")
    add_project_option(p)
    p.set_defaults(func=run)
    return p


# ---------------------------------------------------------------- running
class _Reporter:
    """Progress lines on stderr."""

    def __init__(self):
        self.t0 = time.perf_counter()

    def __call__(self, text: str) -> None:
        print(f"[{time.perf_counter() - self.t0:7.2f}s] {text}", file=sys.stderr, flush=True)


def _parse_rect(text: str):
    try:
        v = [int(t) for t in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 4:
        raise ValueError(f"--rect must be X,Y,W,H integers, got {text!r}")
    return tuple(v)


def run(args) -> int:
    """Run the command; engine warnings become ``warning:`` lines on stderr (and the manifest)."""
    import warnings

    if args.pick is not None and max(args.pick) >= args.candidates:
        bad = [k for k in args.pick if k >= args.candidates]
        raise ValueError(f"--pick {bad} out of range: --candidates is {args.candidates}")
    out = Path(args.out)
    created = not out.exists()
    _check_out(out)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = _run(args)
        except TypeError as exc:  # a bad --seam-option, named by the engine
            raise ValueError(str(exc)) from None
        finally:
            if created and out.is_dir() and not any(out.iterdir()):
                out.rmdir()  # nothing written: leave no empty folder behind
    for text in dict.fromkeys(str(w.message) for w in caught):  # each once, in order
        print(f"quilt-studio tileset: warning: {text}", file=sys.stderr)
    return code


def _check_out(out: Path) -> None:
    """Create the --out folder and make sure files can be written there, before any work."""
    import tempfile

    from engine._fs import write_problem

    try:
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out):
            pass
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot write there ({write_problem(out, exc)})") from None


def _run(args) -> int:
    from engine.bitdepth import quantize
    from engine.events import Progress, drain
    from engine.io import load_image
    from engine.png import encode_png
    from engine.seams import SeamSpec
    from engine.tiles import (
        CandidateTile,
        TemplateUpdate,
        default_patch_overlap,
        iter_candidates,
        iter_find_template,
        iter_make_seamless,
        random_layout,
        template_cost,
    )
    from engine.tiles.template import JOINT_WEIGHT

    say = _Reporter()
    loaded = load_image(args.source)
    S, depth = loaded.pixels, loaded.bit_depth
    H, W = S.shape[:2]
    say(f"source {args.source}: {W}x{H}, {S.shape[2]} channel(s), {depth}-bit")
    maps = {}
    for name, path in args.map:
        if name in maps or name == "main":
            raise ValueError(f"--map {name}: duplicate or reserved map name")
        maps[name] = load_image(path).pixels
    weights = dict(args.weight) or None
    excluded = excluded_pixels(args, S, "source")
    if excluded is not None:
        say(f"excluded: {int(excluded.sum())} of {H * W} source pixels")
        if excluded.all():
            raise ValueError(
                f"--exclude-color / --exclude-mask exclude every pixel of {args.source}: "
                "no tile can be taken from it"
            )

    tmpl_blend = args.blend or "none"
    cand_blend = args.blend or "adaptive"
    seam = SeamSpec(
        args.seam, dict(args.seam_option), metric=args.metric, width=args.width, rho=args.rho
    )
    short = min(H, W)
    tile_min = args.tile_min if args.tile_min is not None else max(8, short // 4)
    tile_max = args.tile_max if args.tile_max is not None else max(8, short // 2)
    if args.tile_min is not None and args.tile_max is None:
        tile_max = tile_min
    warn_list: list[str] = []

    # 1. template rectangle
    joint = JOINT_WEIGHT if args.joint_weight is None else args.joint_weight
    if args.rect:
        rect = _parse_rect(args.rect)
        from engine.tiles import default_overlap

        overlap = args.overlap or default_overlap((rect[3], rect[2]))
        cost = template_cost(S, rect, overlap=overlap, excluded=excluded, joint_weight=joint)[0]
        say(f"template: fixed rectangle {rect}, overlap {overlap}")
    else:

        def on_template(ev):
            if isinstance(ev, TemplateUpdate):
                say(f"template: {ev.phase} rect {ev.rect} cost {ev.cost:.4f}")

        tmpl = drain(
            iter_find_template(
                S,
                tile_min=tile_min,
                tile_max=tile_max,
                overlap=args.overlap,
                excluded=excluded,
                joint_weight=joint,
            ),
            on_template,
        )
        rect, overlap, cost = tmpl.rect, tmpl.overlap, tmpl.cost
        warn_list += list(tmpl.warnings)

    # 2. seamless tile
    st = drain(
        iter_make_seamless(
            S,
            rect,
            overlap=overlap,
            seam=seam.replace(blend=tmpl_blend),
            maps=maps or None,
            weights=weights,
        )
    )
    warn_list += [w for w in st.warnings if w not in warn_list]
    say(
        f"seamless tile {rect[2]}x{rect[3]}: seam criterion h {st.criterion['horizontal']:.2f}"
        f" v {st.criterion['vertical']:.2f}"
    )

    # 3. candidates
    n = args.candidates
    ring = args.patch_overlap or default_patch_overlap(overlap)
    margin = args.margin if args.margin is not None else min(2, ring - 1)

    def on_candidate(ev):
        if isinstance(ev, CandidateTile):
            say(
                f"candidate {ev.index:3d} ({done[0] + 1}/{n}): patch {ev.patch_rect}, criterion "
                f"{ev.scores['criterion']:.2f}, changed {ev.scores['changed']:.0%}"
            )
            done[0] += 1
        elif isinstance(ev, Progress) and ev.message.endswith("cancelled"):
            say(ev.message)

    done = [0]
    cands = drain(
        iter_candidates(
            S,
            st,
            n,
            patch_size=args.patch_size,
            patch_overlap=ring,
            margin=margin,
            neighbourhood=args.neighbourhood,
            seam=seam.replace(blend=cand_blend),
            excluded=excluded,
            maps=maps or None,
            weights=weights,
            rng=args.seed,
            workers=args.workers,
        ),
        on_candidate,
    )

    # 4. picks and preview layout
    picks = args.pick if args.pick is not None else list(range(len(cands)))
    bad = [k for k in picks if k >= len(cands)]
    if bad:
        raise ValueError(f"--pick {bad} out of range: there are {len(cands)} candidates")
    rows, cols = args.preview
    ids = random_layout(
        len(picks),
        rows,
        cols,
        rng=args.seed,
        no_equal_neighbours=not args.equal_neighbours and len(picks) > 1,
    )
    cells = np.asarray(picks, dtype=np.int64)[ids]  # candidate indices
    from engine.tiles import assemble

    preview = {
        m: assemble([cands[k] for k in picks], ids, map_name=None if m == "main" else m)
        for m in ["main", *maps]
    }

    # 5. files (the folder was checked before the work)
    out = Path(args.out)

    def write(stem: str, images: dict) -> dict:
        files = {}
        for m, img in images.items():
            fname = f"{stem}.png" if m == "main" else f"{stem}_{m}.png"
            write_bytes_atomically(out / fname, encode_png(quantize(img, depth, dither=False)))
            files[m] = fname
        return files

    template_files = write("template", {"main": st.tile, **st.maps})
    tile_entries = []
    for c in cands:
        files = write(f"tile_{c.index:03d}", {"main": c.tile, **c.maps})
        x, y, w, h = c.patch_rect
        tile_entries.append(
            {
                "index": c.index,
                "file": files["main"],
                "maps": files,
                "seed": c.seed,
                "source_rect": [x, y, w, h],
                "patch_origin": list(c.patch_origin),
                "target_rect": list(c.target_rect),
                "scores": {k: float(v) for k, v in c.scores.items()},
            }
        )
    preview_files = write("preview", preview)
    _write_text(out / "layout.csv", _csv(cells))
    layout_doc = {
        "tile_w": int(rect[2]),
        "tile_h": int(rect[3]),
        "rows": rows,
        "cols": cols,
        "cells": cells.tolist(),
        "cells_are": "tile indices (tile_NNN.png)",
    }
    _write_text(out / "layout.json", json.dumps(layout_doc, indent=1) + "\n")
    parameters = {
        "tile_min": tile_min,
        "tile_max": tile_max,
        "joint_weight": joint,
        "overlap": overlap,
        "patch_overlap": ring,
        "patch_size": args.patch_size or [int(rect[3]), int(rect[2])],
        "margin": margin,
        "neighbourhood": args.neighbourhood,
        "seam": args.seam,
        "seam_options": dict(args.seam_option),
        "metric": args.metric,
        "template_blend": tmpl_blend,
        "candidate_blend": cand_blend,
        "rho": args.rho,
        "width": args.width,
        "candidates": n,
        "workers": args.workers,
        "weights": weights,
        "preview": [rows, cols],
        "no_equal_neighbours": not args.equal_neighbours,
    }
    manifest = {
        "format": FORMAT,
        "version": VERSION,
        "source": {
            "path": str(args.source),
            "width": W,
            "height": H,
            "channels": int(S.shape[2]),
            "bit_depth": depth,
            "maps": {k: p for k, p in args.map},
        },
        "seed": args.seed,
        "parameters": parameters,
        "template": {
            "file": template_files["main"],
            "maps": template_files,
            "rect": list(rect),
            "overlap": overlap,
            "footprint": [rect[0], rect[1], rect[2] + overlap, rect[3] + overlap],
            "cost": cost,
            "seam_criterion": st.criterion,
            "seam_peak": st.peak,
        },
        "tiles": tile_entries,
        "picks": picks,
        "layout": {"csv": "layout.csv", "json": "layout.json"},
        "preview": {"file": preview_files["main"], "maps": preview_files},
        "warnings": warn_list,
    }
    _write_text(out / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    say(f"wrote template, {len(cands)} tiles, manifest, layout and preview to {out}")

    # 6. project
    src_maps = {MAIN_MAP: S, **maps}

    def as_project_maps(main, extra):
        return {MAIN_MAP: np.asarray(main), **{k: np.asarray(v) for k, v in extra.items()}}

    save_project_option(
        args,
        sources=src_maps,
        tiles=[as_project_maps(c.tile, c.maps) for c in cands],
        name="tileset",
        template=as_project_maps(st.tile, st.maps),
        template_rect=rect,
        patch_origins=[c.patch_origin for c in cands],
        seeds=[c.seed for c in cands],
        scores=[c.scores["criterion"] for c in cands],
        picks=picks,
        layout=ids,
        parameters=parameters,
        project_seeds={"candidates": args.seed, "layout": args.seed},
        bit_depth=depth,
        source_paths={MAIN_MAP: str(args.source), **{k: p for k, p in args.map}},
        map_weights={(MAIN_MAP if k == "main" else k): v for k, v in (weights or {}).items()},
        preview=as_project_maps(preview["main"], {m: preview[m] for m in maps}),
    )
    return 0


def _csv(cells: np.ndarray) -> str:
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerows(cells.tolist())
    return buf.getvalue()


def _write_text(path: Path, text: str) -> None:
    write_bytes_atomically(path, text.encode("utf-8"))
