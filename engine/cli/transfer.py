"""``quilt-studio transfer SAMPLE TARGET --block B -o OUT.png``: texture transfer.

Quilts SAMPLE into TARGET's size with blocks chosen by an α-weighted overlap vs correspondence
cost, over N iterations with blocks shrinking by a third (:func:`engine.transfer.iter_transfer`).
Progress goes to stderr; the output keeps the sample's bit depth.
"""

from __future__ import annotations

import argparse
import sys

from engine.cli import SUBCOMMANDS
from engine.cli._args import int_at_least, non_negative_float
from engine.cli.synth import (
    ProgressPrinter,
    add_cut_arguments,
    cut_options,
    drive,
    load_sample_and_exclusion,
    save_output,
    start,
)


def alpha_arg(text: str):
    """``A`` (every iteration) or ``A0:A1`` (linear from the first to the last iteration)."""
    try:
        parts = [float(v) for v in text.split(":")]
    except ValueError:
        parts = []
    if len(parts) not in (1, 2) or not all(0 <= v <= 1 for v in parts):
        raise argparse.ArgumentTypeError(f"expected A or A0:A1 with values in [0, 1], got {text!r}")
    return parts[0] if len(parts) == 1 else tuple(parts)


def add_parser(subparsers) -> argparse.ArgumentParser:
    from engine.quilting.names import CORRESPONDENCES

    p = subparsers.add_parser(
        "transfer",
        help=SUBCOMMANDS["transfer"],
        description="Texture transfer (Efros & Freeman): quilt SAMPLE into TARGET's size, each "
        "block chosen by alpha * texture cost + (1 - alpha) * correspondence cost, iterated "
        "with blocks shrinking by a third.",
    )
    p.add_argument("sample", metavar="SAMPLE", help="the texture")
    p.add_argument("target", metavar="TARGET", help="the image to imitate (sets the output size)")
    p.add_argument(
        "--block",
        type=int_at_least(4),
        required=True,
        metavar="B",
        help="block size of the first iteration",
    )
    p.add_argument(
        "--overlap",
        type=int_at_least(1),
        default=None,
        metavar="O",
        help="overlap of the first iteration (default B/6), scaled with the block",
    )
    p.add_argument(
        "--alpha",
        type=alpha_arg,
        default=None,
        metavar="A|A0:A1",
        help="texture weight: one value for every iteration or a ramp "
        "(default 0.1 rising to 0.9; 0.1 for one iteration)",
    )
    p.add_argument(
        "--iterations",
        type=int_at_least(1),
        default=3,
        metavar="N",
        help="number of passes (default 3)",
    )
    p.add_argument(
        "--correspondence",
        choices=CORRESPONDENCES,
        default="luminance",
        help="correspondence maps (default luminance)",
    )
    p.add_argument(
        "--sigma",
        type=non_negative_float,
        default=2.0,
        help="blur of --correspondence blurred (default 2)",
    )
    add_cut_arguments(p)
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    from engine.io import load_image
    from engine.transfer import iter_transfer

    sample, depth, excluded = load_sample_and_exclusion(args)
    target = load_image(args.target).pixels
    gen = start(
        iter_transfer,
        sample,
        target,
        block=args.block,
        overlap=args.overlap,
        alpha=args.alpha,
        iterations=args.iterations,
        correspondence=args.correspondence,
        sigma=args.sigma,
        excluded=excluded,
        **cut_options(args),
    )
    res = drive(gen, ProgressPrinter("transfer"))
    save_output(args, res.image, depth)
    errs = ", ".join(f"{it.correspondence_error:.4f}" for it in res.iterations)
    print(
        f"quilt-studio transfer: wrote {args.output} ({res.image.shape[1]}x{res.image.shape[0]}, "
        f"{depth}-bit); correspondence error per iteration: {errs}",
        file=sys.stderr,
    )
    return 0
