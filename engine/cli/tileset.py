"""``quilt-studio tileset SOURCE --out DIR``: template, seamless tile, candidates, preview.

Writes the folder DIR as a whole (built as a hidden sibling, then swapped in: a failure or a
kill leaves the previous set or none, never a mix; a re-run replaces only a folder holding
nothing but an earlier set's files, as its manifest lists them):

- ``template.png``: the seamless template tile;
- ``tile_000.png`` ...: every candidate (``tile_000_<map>.png`` for material maps);
- ``manifest.json``: the settings as given (:class:`engine.tiles.TilesetSettings`;
  ``--settings manifest.json`` runs them again) and as used (``resolved``: every value chosen
  from the source filled in), seed,
  template rectangle and costs, per-tile source rectangle, seed and scores, picks, layout,
  warnings;
- ``layout.csv`` / ``layout.json``: the preview's index matrix (cells are tile indices,
  i.e. the NNN of ``tile_NNN.png``);
- ``preview.png``: the picked tiles assembled by that matrix.

Images keep the source's bit depth (16-bit in, 16-bit out) and channels. Progress goes to
stderr, one line per step.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from engine.cli import SUBCOMMANDS
from engine.cli._args import (
    add_exclusion,
    add_seam_options,
    int_at_least,
    non_negative_float,
    thread_count,
)
from engine.cli.export import add_project_option
from engine.cli.tileset_output import (
    FORMAT,
    MAIN_MAP,
    VERSION,
    Reporter,
    check_out,
    check_sizes,
    csv_text,
    load_inputs,
    map_weights,
    source_name,
    write_images,
    write_set,
    write_text,
)
from engine.seams.spec import METHODS, METRICS, TILE_BLEND_MODES
from engine.settings import TilesetSettings


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
    d = TilesetSettings()
    p = subparsers.add_parser(
        "tileset",
        help=SUBCOMMANDS["tileset"],
        description="Search the template tile in SOURCE, make it seamless, derive N candidate "
        "tiles that all connect to each other (Somol & Haindl), and write them with a "
        "manifest, an index matrix and a synthesized preview into DIR. Options not given "
        "come from --settings (if given), else the workflow's defaults.",
    )
    p.add_argument("source", metavar="SOURCE", help="source texture (PNG, JPEG, TIFF, BMP, WebP)")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created)")
    p.add_argument(
        "--settings",
        metavar="FILE",
        default=None,
        help="start from the settings of an earlier run: its manifest.json or a .quiltproj "
        "project (the editor's too)",
    )
    p.add_argument(
        "--candidates",
        type=int_at_least(1),
        metavar="N",
        help=f"number of candidate tiles (default {d.candidates})",
    )
    p.add_argument(
        "--tile-min",
        type=_size,
        metavar="N|HxW",
        help="smallest tile (default: a quarter of the source's shorter side)",
    )
    p.add_argument(
        "--tile-max",
        type=_size,
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
        metavar="L",
        help="weight of the tile's natural wrap joint in the template search, so the tile edge "
        f"falls where the texture is calm (default {d.joint_weight}; 0 = strip mismatch only, "
        "as in the paper)",
    )
    p.add_argument(
        "--detail-weight",
        type=non_negative_float,
        metavar="K",
        help="how strongly the template search avoids flat or blurred regions, where opposite "
        f"edges match easily (default {d.detail_weight}; 0 = off, as in the paper)",
    )
    p.add_argument(
        "--overlap",
        type=int_at_least(2),
        metavar="N",
        help="w_T, width of the template's border regions (default: tile/10)",
    )
    p.add_argument(
        "--patch-overlap",
        type=int_at_least(2),
        metavar="N",
        help="w_P, the ring the patch cut runs in (default: min(w_T, max(8, w_T // 2)) of the "
        "template overlap w_T, see engine.tiles.default_patch_overlap)",
    )
    p.add_argument(
        "--patch-size", type=_size, metavar="N|HxW", help="patch window (default: the tile size)"
    )
    p.add_argument(
        "--margin",
        type=int_at_least(0),
        metavar="N",
        help="outer pixels every candidate keeps from the template (default 1, at most w_P - 1)",
    )
    p.add_argument(
        "--patch-search",
        choices=("global", "local"),
        help="where patches come from: 'global' (default) draws each among the best matches "
        "of the template's ring over the whole source, away from the template's position and "
        "from each other; 'local' is the paper's random position refined within "
        "--neighbourhood",
    )
    p.add_argument(
        "--neighbourhood",
        type=int_at_least(0),
        metavar="N",
        help="--patch-search local: refine each random patch position within +-N px "
        f"(default {d.neighbourhood})",
    )
    p.add_argument(
        "--min-distance",
        type=int_at_least(0),
        metavar="PX",
        help="--patch-search global: keep the candidates' patch sources at least PX apart and "
        "away from the template's position (default: a quarter tile, less on small sources)",
    )
    p.add_argument(
        "--cut-structures",
        dest="whole_structures",
        action="store_false",
        default=None,
        help="search the whole tile range as given; by default the template search measures "
        "the texture's structure scale (autocorrelation) and prefers tiles that hold three "
        "structures per side, and warns when the range cannot",
    )
    p.add_argument(
        "--flatten",
        action="store_true",
        default=None,
        help="Flatten lighting: divide out the source's low-frequency illumination (a smooth "
        "field at the scale of the largest tile, mean colour kept) before the search; the "
        "albedo only, never the --map material maps. Default: automatic — on, with the "
        "gradient-domain blend of the cuts, when the lighting varies across an otherwise "
        "even photo (said on stderr and in the manifest's warnings)",
    )
    p.add_argument(
        "--no-flatten",
        dest="flatten",
        action="store_false",
        help="never flatten the lighting (and keep the default blending)",
    )
    p.add_argument("--seam", choices=METHODS, help=f"seam method (default {d.seam.method})")
    add_seam_options(p)
    p.add_argument("--metric", choices=METRICS, help=f"error metric (default {d.seam.metric})")
    p.add_argument(
        "--blend",
        choices=TILE_BLEND_MODES,
        help=f"blending of every cut (default: {d.template_blend} for the template, "
        f"{d.seam.blend} for the patches)",
    )
    p.add_argument(
        "--rho", type=int_at_least(0), help=f"adaptive blending ρ (default {d.seam.rho})"
    )
    p.add_argument(
        "--width",
        type=non_negative_float,
        help=f"feather width in px (default {d.seam.width:g})",
    )
    p.add_argument("--seed", type=int_at_least(0), help=f"random seed (default {d.seed})")
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
        metavar="RxC",
        help="preview grid in tiles (default {}x{})".format(*d.preview),
    )
    p.add_argument(
        "--equal-neighbours",
        action="store_true",
        default=None,
        help="allow equal neighbouring tiles in the preview's index matrix",
    )
    p.add_argument("--workers", type=thread_count, default=2, help="threads (default 2)")
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
    p.add_argument("--source-name", default=None, help=argparse.SUPPRESS)  # see source_name()
    from engine.cli.tileset_wang import add_wang_options

    add_wang_options(p, _size)
    p.set_defaults(func=run)
    return p


# ---------------------------------------------------------------- settings from the flags
#: flag -> settings field, for the flags that are one field each
_FIELDS = {
    "tile_min": "tile_min",
    "tile_max": "tile_max",
    "overlap": "overlap",
    "joint_weight": "joint_weight",
    "detail_weight": "detail_weight",
    "whole_structures": "whole_structures",
    "candidates": "candidates",
    "seed": "seed",
    "patch_size": "patch_size",
    "patch_overlap": "patch_overlap",
    "margin": "margin",
    "neighbourhood": "neighbourhood",
    "patch_search": "patch_search",
    "min_distance": "min_distance",
    "flatten": "flatten",
    "preview": "preview",
    "exclude_color": "exclude_color",
}


def settings_from_args(args) -> TilesetSettings:
    """The run's settings: ``--settings FILE`` (or the defaults) with every given flag on top.
    A flag's bad value raises ValueError naming the flag."""
    base = read_settings(args.settings) if args.settings else TilesetSettings()
    changes = {f: getattr(args, a) for a, f in _FIELDS.items() if getattr(args, a) is not None}
    if args.tile_min is not None and args.tile_max is None:
        changes["tile_max"] = args.tile_min  # a fixed size unless a range is asked for
    from engine.cli.tileset_wang import check_tile_size_auto, wang_changes

    changes.update(wang_changes(args))
    if args.equal_neighbours:
        changes["no_equal_neighbours"] = False
    seam = {"method": args.seam, "metric": args.metric, "width": args.width, "rho": args.rho}
    seam = {k: v for k, v in seam.items() if v is not None}
    if args.blend is not None:
        seam["blend"] = args.blend
        changes["template_blend"] = None  # --blend sets every cut
    if args.seam_option:
        seam["options"] = {
            **(base.seam.options if "method" not in seam else {}),
            **dict(args.seam_option),
        }
    try:
        if seam:
            changes["seam"] = base.seam.replace(**seam)
        settings = base.replace(**changes)
    except TypeError as exc:  # a bad --seam-option, named by the settings
        raise ValueError(str(exc)) from None
    check_tile_size_auto(args, settings)  # --wang or a Wang manifest's settings
    return settings


def read_settings(path) -> TilesetSettings:
    """The settings of a manifest.json (``settings``), a .quiltproj project or a JSON file of
    settings."""
    from engine.settings import settings_from_parameters

    p = Path(path)
    if p.suffix.lower() == ".quiltproj":
        from engine.project import load_project

        project = load_project(p)
        return settings_from_parameters(project.parameters, project.seeds)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"--settings {p}: cannot be read ({exc})") from None
    if isinstance(data, dict) and isinstance(data.get("settings"), dict):
        data = data["settings"]
    try:
        return TilesetSettings.from_dict(data)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"--settings {p}: {exc}") from None


# ---------------------------------------------------------------- running


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

    settings = settings_from_args(args)
    if settings.wang is not None:
        from engine.cli.tileset_wang import check_wang_args, run_wang

        check_wang_args(args)
        work = run_wang
    else:
        work = _run
    if args.pick is not None and max(args.pick) >= settings.candidates:
        bad = [k for k in args.pick if k >= settings.candidates]
        raise ValueError(f"--pick {bad} out of range: --candidates is {settings.candidates}")
    rect = _parse_rect(args.rect) if args.rect else None
    check_out(args)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = work(args, settings, rect)
        except ValueError as exc:  # the engine's names of the sizes -> the flags given (ux13)
            raise ValueError(flag_words(str(exc), args)) from None
    for text in dict.fromkeys(str(w.message) for w in caught):  # each once, in order
        print(f"quilt-studio tileset: warning: {flag_words(text, args)}", file=sys.stderr)
    return code


def flag_words(text: str, args) -> str:
    """An engine message with the settings' names of the tile sizes as the flags that set them:
    "choose a smaller tile_min" reads "choose a smaller --tile-size" after ``--tile-size 600``;
    a size written after one (the engine's WxH) as the flag takes it: "tile_max 400x400" reads
    "--tile-max 400", "using tile_max 140x130" reads "using --tile-max 130x140 (HxW)"."""
    given = getattr(args, "tile_size", None) is not None
    flags = {"tile_min": "--tile-size" if given else "--tile-min", "tile_max": "--tile-max"}
    if given:
        flags["tile_max"] = "--tile-size"

    def flag(m) -> str:
        w, h = m[2], m[3]
        size = "" if w is None else f" {h}" if w == h else f" {h}x{w} (HxW)"
        return flags[m[1]] + size

    return re.sub(r"(?<![\w./-])(tile_min|tile_max)(?![\w/])(?: (\d+)x(\d+)\b)?", flag, text)


def _events(say, n: int):
    """The progress line of each event worth one."""
    from engine.events import Progress
    from engine.tiles import CandidateTile, TemplateUpdate

    done = [0]

    def on_event(ev):
        if isinstance(ev, TemplateUpdate):
            say(f"template: {ev.phase} rect {ev.rect} cost {ev.cost:.4f}")
        elif isinstance(ev, CandidateTile):
            done[0] += 1
            say(
                f"candidate {ev.index:3d} ({done[0]}/{n}): patch {ev.patch_rect}, criterion "
                f"{ev.scores['criterion']:.2f}, changed {ev.scores['changed']:.0%}"
            )
        elif isinstance(ev, Progress) and ev.message.endswith("cancelled"):
            say(ev.message)

    return on_event


def _run(args, settings: TilesetSettings, rect) -> int:
    from engine.events import drain
    from engine.tiles.pipeline import iter_tileset

    say = Reporter()
    S, depth, maps, weights, excluded = load_inputs(args, settings, say)
    H, W = S.shape[:2]
    tile_hw = (rect[3], rect[2]) if rect else settings.tile_range((H, W))[1]
    settings = check_sizes(args, settings, S, tile_hw, maps, tiles=settings.candidates)
    if rect is not None:
        say(f"template: fixed rectangle {rect}")
    result = drain(
        iter_tileset(
            S,
            settings,
            rect=rect,
            maps=maps or None,
            weights=weights,
            excluded=excluded,
            picks=args.pick,
            workers=args.workers,
        ),
        _events(say, settings.candidates),
    )
    out = args.out
    st = result.seamless
    say(
        f"seamless tile {result.rect[2]}x{result.rect[3]} (overlap {result.overlap}): seam "
        f"criterion h {st.criterion['horizontal']:.2f} v {st.criterion['vertical']:.2f}"
    )
    if result.scale is not None:
        sc = result.scale
        kind = ["period" if p else "size" for p in sc.periodic]
        say(
            f"structure scale: {sc.height:.0f} px tall ({kind[0]}), {sc.width:.0f} px wide "
            f"({kind[1]}); tile {result.rect[2]}x{result.rect[3]} holds "
            f"{result.rect[3] / max(sc.height, 1):.1f} x {result.rect[2] / max(sc.width, 1):.1f}"
        )
    quality = _quality_summary(S, result, say)

    def write(tmp: Path) -> dict:
        manifest = write_files(tmp, result, depth)
        manifest["quality"] = quality
        manifest["scale"] = None if result.scale is None else result.scale.to_dict()
        manifest["warnings"] = manifest["warnings"] + quality["warnings"]
        manifest.update(
            settings=settings.to_dict(),
            source={
                "path": source_name(args),
                "width": W,
                "height": H,
                "channels": int(S.shape[2]),
                "bit_depth": depth,
                "maps": {k: p for k, p in args.map},
                "exclude_mask": args.exclude_mask or None,
            },
            workers=args.workers,
            weights=weights,
        )
        return manifest

    project = (
        project_arguments(result, S, maps, depth, args, weights, excluded)
        if getattr(args, "project", None)
        else {}
    )
    write_set(args, write, project)
    say(f"wrote template, {len(result.candidates)} tiles, manifest, layout and preview to {out}")
    return 0


def _quality_summary(S, result, say) -> dict:
    """The set's figures (issue 10: interior metrics beside the joint ones) on stderr, with
    warnings in words; returned for the manifest."""
    import warnings

    from engine.metrics import (
        detail_ratio,
        quality_warnings,
        tileset_quality,
        wrap_border_ratio,
    )

    st, s = result.seamless, result.settings
    if s.flatten:  # the tiles come from the flattened source: compare with it
        from engine.tone import flatten_lighting, flatten_scale

        S = flatten_lighting(S, scale=flatten_scale(s.tile_max))
    q = {"wrap": wrap_border_ratio(st.tile), "detail": None}
    try:
        q["detail"] = detail_ratio(st.tile, S)
    except ValueError:  # a flat source (already warned about): no figures to give
        q["warnings"] = []
        return q
    if result.candidates:
        q.update(
            tileset_quality(
                result.candidates, S, template=st.tile, ring=s.patch_overlap, margin=s.margin
            )
        )
        say(
            f"quality: {len(result.candidates)} candidates, frame {q['frame']:.2f} "
            f"(1 = none), ring tone {q['ring_tone']:.2f}, duplicates {q['duplicates']}, "
            f"lattice {q['lattice']:+.1f} dB above its floor, template share "
            f"{q['template_share']:.0%}; template wrap {q['wrap']:.2f}, detail {q['detail']:.2f}"
        )
    q["warnings"] = quality_warnings(q, flattened=s.flatten) if result.candidates else []
    for text in q["warnings"]:
        warnings.warn(text, stacklevel=2)
    return q


def write_files(out: Path, result, depth: int) -> dict:
    """Write the images, layout.csv and layout.json of ``result``; the manifest's content."""

    def write(stem: str, images: dict) -> dict:
        return write_images(out, stem, images, depth)

    st, rect, overlap = result.seamless, result.rect, result.overlap
    template_files = write("template", {"main": st.tile, **st.maps})
    tile_entries = [
        c.manifest_entry(write(f"tile_{c.index:03d}", c.images())) for c in result.candidates
    ]
    preview_files = write("preview", result.preview)
    cells = result.cells
    rows, cols = result.settings.preview
    write_text(out / "layout.csv", csv_text(cells))
    layout_doc = {
        "tile_w": int(rect[2]),
        "tile_h": int(rect[3]),
        "rows": rows,
        "cols": cols,
        "cells": cells.tolist(),
        "cells_are": "tile indices (tile_NNN.png)",
    }
    write_text(out / "layout.json", json.dumps(layout_doc, indent=1) + "\n")
    return {
        "format": FORMAT,
        "version": VERSION,
        "seed": result.settings.seed,
        "resolved": result.settings.to_dict(),
        "template": {
            "file": template_files["main"],
            "maps": template_files,
            "rect": list(rect),
            "overlap": overlap,
            "footprint": [rect[0], rect[1], rect[2] + overlap, rect[3] + overlap],
            "cost": result.cost,
            "seam_criterion": st.criterion,
            "seam_peak": st.peak,
        },
        "tiles": tile_entries,
        "picks": result.picks,
        "layout": {"csv": "layout.csv", "json": "layout.json"},
        "preview": {"file": preview_files["main"], "maps": preview_files},
        "warnings": list(result.warnings),
    }


def project_arguments(result, S, maps, depth, args, weights, excluded) -> dict:
    """The keyword arguments of :func:`engine.project.project_from_tileset` for ``result``."""
    import numpy as np

    from engine.exclusion import mask_to_json

    def as_project_maps(main, extra):
        return {MAIN_MAP: np.asarray(main), **{k: np.asarray(v) for k, v in extra.items()}}

    s = result.settings
    cands = result.candidates
    extra_maps = {m: result.preview[m] for m in maps}
    return dict(
        sources={MAIN_MAP: S, **maps},
        tiles=cands,
        name="tileset",
        template=as_project_maps(result.seamless.tile, result.seamless.maps),
        template_rect=result.rect,
        picks=result.picks,
        layout=result.layout,
        parameters={"tileset": s.to_dict()},
        project_seeds={"candidates": s.seed, "layout": s.layout_seed},
        bit_depth=depth,
        source_paths={MAIN_MAP: source_name(args), **{k: p for k, p in args.map}},
        map_weights=map_weights(weights),
        preview=as_project_maps(result.preview["main"], extra_maps),
        extra=mask_to_json(excluded),
    )
