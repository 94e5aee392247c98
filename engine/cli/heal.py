"""``quilt-studio heal SRC MASK -o OUT``: fill the masked region of an image from the rest of it.

MASK is an image of SRC's size whose non-black pixels mark the region to replace (a leaf, a
logo, a blemish). The region is quilted from the rest of SRC with minimum-error cuts
(:func:`engine.heal.iter_heal`); every pixel outside it is written unchanged. ``--map IN:OUT``
heals a material map of the same size with the same blocks and cuts. Progress goes to stderr;
the output keeps SRC's bit depth.
"""

from __future__ import annotations

import sys

from engine.cli import SUBCOMMANDS
from engine.cli._args import (
    add_bit_depth,
    add_exclusion,
    add_seam_options,
    excluded_pixels,
    int_at_least,
    non_negative_float,
    thread_count,
)


def map_pair(text: str) -> tuple[str, str]:
    """``IN:OUT`` -> (in path, out path)."""
    import argparse

    src, sep, out = text.rpartition(":")
    if not sep or not src or not out:
        raise argparse.ArgumentTypeError(f"expected IN:OUT like h.png:healed.png, got {text!r}")
    return src, out


def add_parser(subparsers):
    from engine.seams.spec import BLEND_MODES, METHODS, METRICS

    p = subparsers.add_parser(
        "heal",
        help=SUBCOMMANDS["heal"],
        description="Heal: replace the pixels MASK marks by quilting from the rest of SRC, "
        "blocks matched by masked SSD, cut along minimum-error seams and blended; pixels "
        "outside the mask are kept exactly.",
    )
    p.add_argument("source", metavar="SRC", help="the image to heal")
    p.add_argument("mask", metavar="MASK", help="image of SRC's size; non-black = replace")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="the healed image")
    p.add_argument(
        "--map",
        type=map_pair,
        action="append",
        default=[],
        metavar="IN:OUT",
        help="a material map of SRC's size healed with the same cuts (repeatable)",
    )
    p.add_argument(
        "--block", type=int_at_least(6), default=None, metavar="B", help="block size (default auto)"
    )
    p.add_argument("--overlap", type=int_at_least(1), default=None, metavar="O", help="default B/4")
    p.add_argument("--seam", choices=METHODS, default="dp", help="seam method (default dp)")
    add_seam_options(p)
    p.add_argument(
        "--blend", choices=BLEND_MODES, default="feather", help="across the cut (default feather)"
    )
    p.add_argument("--blend-width", type=non_negative_float, default=4.0, metavar="PX")
    p.add_argument("--rho", type=int_at_least(0), default=3, help="adaptive blending ρ")
    p.add_argument("--metric", choices=METRICS, default="ssd", help="cut error (default ssd)")
    p.add_argument("--tolerance", type=non_negative_float, default=0.1)
    p.add_argument(
        "--no-refine", action="store_true", help="skip re-healing the mask's rim with small blocks"
    )
    add_exclusion(p, "source")
    p.add_argument("--seed", type=int_at_least(0), default=0, help="random seed (default 0)")
    p.add_argument("--threads", type=thread_count, default=None, help="FFT workers")
    add_bit_depth(p, "source")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    from engine.bitdepth import quantize
    from engine.budget import check_memory, heal_bytes
    from engine.cli.synth import ProgressPrinter, check_output, drive
    from engine.errormap import colour_channels
    from engine.heal import iter_heal
    from engine.io import load_image, save_image
    from engine.seams import SeamSpec

    loaded = load_image(args.source)
    depth = args.bit_depth or loaded.bit_depth
    check_output(args.output, depth, loaded.pixels.shape[2])
    m = load_image(args.mask).pixels
    if m.shape[:2] != loaded.pixels.shape[:2]:
        raise ValueError(
            f"{args.mask}: the mask is {m.shape[1]}x{m.shape[0]}, the source "
            f"{loaded.pixels.shape[1]}x{loaded.pixels.shape[0]}"
        )
    mask = colour_channels(m).max(axis=2) > 0
    maps = {}
    for i, (src, out) in enumerate(args.map):
        extra = load_image(src)
        check_output(out, args.bit_depth or extra.bit_depth, extra.pixels.shape[2])
        maps[str(i)] = extra
    h, w, c = loaded.pixels.shape
    check_memory(
        heal_bytes(h, w, c + sum(e.pixels.shape[2] for e in maps.values())),
        what=f"healing this {w}x{h} image",
        way_out="heal a crop of it, or free memory",
    )
    seam = SeamSpec(
        args.seam,
        dict(args.seam_option),
        metric=args.metric,
        blend=args.blend,
        width=args.blend_width,
        rho=args.rho,
    )
    gen = iter_heal(
        loaded.pixels,
        mask,
        maps={k: v.pixels for k, v in maps.items()},
        block=args.block,
        overlap=args.overlap,
        tolerance=args.tolerance,
        seam=seam,
        excluded=excluded_pixels(args, loaded.pixels, "source"),
        refine=not args.no_refine,
        rng=args.seed,
        threads=args.threads,
    )
    res = drive(gen, ProgressPrinter("heal"))

    def write(path, image, source_depth):
        d = args.bit_depth or source_depth
        if d < source_depth:
            image = quantize(image, 8, dither=True, rng=args.seed)
        save_image(path, image, bit_depth=d)

    write(args.output, res.image, loaded.bit_depth)
    for i, (_, out) in enumerate(args.map):
        write(out, res.maps[str(i)], maps[str(i)].bit_depth)
    print(
        f"quilt-studio heal: wrote {args.output} ({int(mask.sum())} pixels healed with "
        f"{len(res.blocks)} blocks of {res.block} px, {depth}-bit)",
        file=sys.stderr,
    )
    return 0
