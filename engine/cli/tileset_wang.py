"""``quilt-studio tileset SOURCE --out DIR --wang K --tile-size N``: a Wang tile set.

Writes into DIR: ``tile_000.png`` ... (``tile_000_<map>.png`` for material maps), one per tile
in the order of :func:`engine.tiles.wang.canonical_signatures` (variant after variant);
``manifest.json`` (settings as given and as used, the edge samples, every tile with its
``"wang": {"n", "e", "s", "w"}`` colours, variant, seed, interior window and scores);
``layout.csv`` / ``layout.json`` and ``preview.png``: a random valid Wang layout. With
``--project P`` the set is saved as a project; ``quilt-studio export P`` writes it for Tiled
(an edge Wang set) and Godot (a "match sides" terrain set).
"""

from __future__ import annotations

import json
from pathlib import Path

from engine.cli._args import int_at_least, non_negative_float

__all__ = [
    "AUTO",
    "add_wang_options",
    "check_tile_size_auto",
    "check_wang_args",
    "run_wang",
    "wang_changes",
]

AUTO = "auto"  # --tile-size auto: engine.tiles.wang_size.auto_tile_size


def add_wang_options(p, size) -> None:
    """The Wang flags of ``quilt-studio tileset`` (``size`` parses N or HxW)."""
    g = p.add_argument_group(
        "Wang tile set (instead of the template and candidates; Cohen et al. 2003)"
    )
    g.add_argument(
        "--wang",
        type=int_at_least(1),
        metavar="K",
        help="make a complete Wang set: K colours per edge direction, K^4 tiles (16 for K=2)",
    )
    g.add_argument(
        "--tile-size",
        type=lambda text: AUTO if text.strip().lower() == AUTO else size(text),
        metavar="N|auto",
        help="the tile size (square; sets --tile-min and --tile-max; default: a quarter of the "
        "source's shorter side); auto (--wang sets): that size moved to the nearest one within "
        "25%% that holds whole periods of a periodic texture (boards, courses), so the pattern "
        "continues across the tile lines; a line says which",
    )
    g.add_argument(
        "--variants", type=int_at_least(1), metavar="V", help="tiles per edge signature (1)"
    )
    g.add_argument(
        "--interior",
        choices=("patch", "diamonds"),
        help="each tile's inside: a matched source window stitched in (patch, default) or "
        "the four edge diamonds alone (Cohen's construction)",
    )
    g.add_argument(
        "--interior-blend",
        choices=("auto", "none", "feather", "adaptive", "poisson"),
        help="how the interior patch is blended into the tile's shared ring: auto (default) "
        "in the gradient domain (tone continues across the tile lines) unless --blend none; "
        "else this blend for the interior alone",
    )
    g.add_argument(
        "--wang-band",
        type=int_at_least(1),
        metavar="N",
        help="half-width of the diagonal bands the corner cuts run in (default: tile/10)",
    )
    g.add_argument(
        "--outward",
        type=non_negative_float,
        metavar="X",
        help="bias of the interior's cut towards the tile edge (default 1; 0 = none)",
    )
    g.add_argument(
        "--wang-min-distance",
        type=non_negative_float,
        metavar="PX",
        help="least distance between edge samples and interior windows (default: tile/2); "
        "without --wang: between the candidates' patch sources and from the template's "
        "position (--patch-search global; default: a quarter tile, less on small sources)",
    )
    g.add_argument(
        "--wang-tolerance",
        type=non_negative_float,
        metavar="X",
        help="samples and interiors are drawn within (1 + X) of the best match (default 0.1)",
    )


#: flag -> settings field
_FIELDS = {
    "wang": "wang",
    "variants": "wang_variants",
    "interior": "wang_interior",
    "interior_blend": "wang_interior_blend",
    "wang_band": "wang_band",
    "outward": "wang_outward",
    "wang_min_distance": "wang_min_distance",
    "wang_tolerance": "wang_tolerance",
}


def wang_changes(args) -> dict:
    """The settings the Wang flags change (``--tile-size N`` fixes both tile_min and tile_max)."""
    changes = {f: getattr(args, a) for a, f in _FIELDS.items() if getattr(args, a) is not None}
    if args.tile_size is not None:
        if args.tile_min is not None or args.tile_max is not None:
            raise ValueError("--tile-size is one size: give it or --tile-min/--tile-max, not both")
        if args.tile_size == AUTO:
            return changes  # resolved on the source (run_wang); checked by check_tile_size_auto
        changes["tile_min"] = changes["tile_max"] = args.tile_size
    return changes


def check_tile_size_auto(args, settings) -> None:
    """``--tile-size auto`` needs a Wang set: ``settings`` merged from --settings (a Wang
    manifest) and the flags (--wang)."""
    if getattr(args, "tile_size", None) == AUTO and settings.wang is None:
        raise ValueError(
            "--tile-size auto is for --wang sets (the template search's range keeps "
            "whole periods by itself: --whole-structures)"
        )


def check_wang_args(args) -> None:
    """Flags of the template workflow that a Wang set has no use for."""
    for flag, given in (("--rect", args.rect), ("--pick", args.pick)):
        if given is not None:
            raise ValueError(f"{flag} belongs to the template workflow, not to --wang sets")
    if getattr(args, "flatten", None):  # the batch's refusal; the set was made from the photo
        raise ValueError(
            "--flatten is not available for Wang sets (the Wang workflow does not flatten)"
        )


def _events(say, count: int):
    from engine.events import Progress
    from engine.tiles.wang import WangSamples, WangTile

    done = [0]

    def on_event(ev):
        if isinstance(ev, WangSamples):
            for s in ev.samples:
                say(f"edge sample {s.axis}{s.colour}: origin {s.origin}, error {s.error:.4f}")
        elif isinstance(ev, WangTile):
            done[0] += 1
            say(
                f"tile {ev.index:3d} ({done[0]}/{count}) n{ev.signature[0]} e{ev.signature[1]} "
                f"s{ev.signature[2]} w{ev.signature[3]}: interior {ev.patch_origin}, corner "
                f"cuts {ev.scores['criterion']:.2f}"
            )
        elif isinstance(ev, Progress) and ev.message.endswith("cancelled"):
            say(ev.message)

    return on_event


def run_wang(args, settings, rect=None) -> int:
    """Make the Wang set, write its files and (``--project``) the project."""
    from engine.cli.tileset_output import (
        FORMAT,
        VERSION,
        Reporter,
        check_sizes,
        csv_text,
        load_inputs,
        source_name,
        write_images,
        write_set,
        write_text,
    )
    from engine.events import drain
    from engine.tiles.wang_pipeline import iter_wang_tileset, resolve_wang

    say = Reporter()
    S, depth, maps, weights, excluded = load_inputs(args, settings, say)
    s = resolve_wang(settings, S.shape[:2])
    auto = None
    if getattr(args, "tile_size", None) == AUTO:
        from engine.tiles.wang_size import auto_tile_size

        n, what = auto_tile_size(
            S, s.tile_min[0], band=s.wang_band, seam=s.seam, patch_overlap=s.patch_overlap
        )
        say(f"tile size (auto): {what}")
        auto = {"asked": AUTO, "from": s.tile_min[0], "used": n, "why": what}
        settings = settings.replace(tile_min=(n, n), tile_max=(n, n))
        s = resolve_wang(settings, S.shape[:2])
    count = s.wang_variants * s.wang**4
    settings = check_sizes(args, settings, S, s.tile_min, maps, tiles=count)
    s = s.replace(preview=settings.preview)  # a default preview may have shrunk to fit
    say(f"Wang set: {s.wang} colours per edge direction, {count} tiles of {s.tile_min[0]} px")
    result = drain(
        iter_wang_tileset(
            S,
            settings,
            maps=maps or None,
            weights=weights,
            excluded=excluded,
            workers=args.workers,
        ),
        _events(say, count),
    )
    ws = result.wang
    rows, cols = s.preview

    def write(out: Path) -> dict:
        tiles = []
        for t in ws.tiles:
            files = write_images(out, f"tile_{t.index:03d}", {"main": t.tile, **t.maps}, depth)
            tiles.append(
                {
                    "index": t.index,
                    "file": files["main"],
                    "maps": files,
                    "wang": t.wang,
                    "variant": t.variant,
                    "seed": t.seed,
                    "patch_origin": None if t.patch_origin is None else list(t.patch_origin),
                    "junction": list(t.junction),
                    "scores": {k: float(v) for k, v in t.scores.items()},
                }
            )
        preview = write_images(out, "preview", result.preview, depth)
        write_text(out / "layout.csv", csv_text(result.layout))
        layout_doc = {
            "tile_w": ws.tile_size,
            "tile_h": ws.tile_size,
            "rows": rows,
            "cols": cols,
            "cells": result.layout.tolist(),
            "cells_are": "tile indices (tile_NNN.png); every pair of touching edges has one colour",
        }
        write_text(out / "layout.json", json.dumps(layout_doc, indent=1) + "\n")
        return {
            "format": FORMAT,
            "version": VERSION,
            "kind": "wang",
            "seed": s.seed,
            "settings": settings.to_dict(),
            "resolved": s.to_dict(),
            **({"tile_size_auto": auto} if auto else {}),
            "wang": ws.record(),
            "tiles": tiles,
            "layout": {"csv": "layout.csv", "json": "layout.json"},
            "preview": {"file": preview["main"], "maps": preview},
            "warnings": list(result.warnings),
            "source": {
                "path": source_name(args),
                "width": int(S.shape[1]),
                "height": int(S.shape[0]),
                "channels": int(S.shape[2]),
                "bit_depth": depth,
                "maps": {k: p for k, p in args.map},
                "exclude_mask": args.exclude_mask or None,
            },
            "workers": args.workers,
            "weights": weights,
        }

    project = (
        project_arguments(result, S, maps, depth, args, weights)
        if getattr(args, "project", None)
        else {}
    )
    write_set(args, write, project)
    say(f"wrote {len(ws.tiles)} Wang tiles, manifest, layout and preview to {args.out}")
    return 0


def project_arguments(result, S, maps, depth, args, weights) -> dict:
    """The keyword arguments of :func:`engine.project.project_from_tileset` for a Wang set."""
    from engine.cli.tileset_output import MAIN_MAP, map_weights, source_name

    s, ws = result.settings, result.wang
    record = ws.record()
    record["layout"] = result.layout.tolist()
    return dict(
        sources={MAIN_MAP: S, **maps},
        tiles=[],
        name="tileset",
        parameters={"tileset": s.to_dict()},
        project_seeds={"wang": s.seed, "layout": s.layout_seed},
        bit_depth=depth,
        source_paths={MAIN_MAP: source_name(args), **{k: p for k, p in args.map}},
        map_weights=map_weights(weights),
        wang=record,
        wang_tiles=[t.to_candidate() for t in ws.tiles],
    )
