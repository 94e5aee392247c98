"""Argument types and options shared by the sub-commands.

The ``type=`` callables raise :class:`argparse.ArgumentTypeError`, so argparse reports a bad
value as a usage error naming the option.
"""

from __future__ import annotations

import argparse
import re


def int_at_least(minimum: int):
    """An argument type: an integer >= ``minimum``."""

    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if v < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {v}")
        return v

    return parse


MAX_THREADS = 256
"""Most worker threads a command takes (more only exhausts the system's threads)."""


def thread_count(text: str) -> int:
    """An argument type: a number of threads in 1..MAX_THREADS."""
    v = int_at_least(1)(text)
    if v > MAX_THREADS:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_THREADS}, got {v}")
    return v


def non_negative_float(text: str) -> float:
    """An argument type: a number >= 0."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not v >= 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text!r}")
    return v


def colour_range(text: str):
    """``LO:HI`` with LO/HI one number or comma-separated per-channel numbers in [0, 1]."""
    try:
        lo, hi = text.split(":")
        lo_v = [float(v) for v in lo.split(",")]
        hi_v = [float(v) for v in hi.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected LO:HI like 0,0,0:0.2,0.2,0.25 or 0:0.1, got {text!r}"
        ) from None
    return (lo_v[0] if len(lo_v) == 1 else lo_v, hi_v[0] if len(hi_v) == 1 else hi_v)


def seam_option(text: str):
    """``KEY=VALUE``; the value is read as an int, a float, or kept as text."""
    key, sep, value = text.partition("=")
    if not sep or not re.fullmatch(r"[a-z_]+", key):
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE like o_max=5, got {text!r}")
    for cast in (int, float):
        try:
            return key, cast(value)
        except ValueError:
            pass
    return key, value


def add_seam_options(p: argparse.ArgumentParser) -> None:
    """``--seam-option KEY=VALUE`` (repeatable), collected as (key, value) pairs."""
    p.add_argument(
        "--seam-option",
        type=seam_option,
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="option of the seam method, e.g. o_max=5, max_run=3, variant=lm",
    )


def add_bit_depth(p: argparse.ArgumentParser, source: str) -> None:
    """``--bit-depth 8|16``: output bits per channel, by default those of ``source``."""
    p.add_argument(
        "--bit-depth",
        type=int,
        choices=(8, 16),
        default=None,
        help=f"output bits per channel (default: the {source}'s; 16 -> 8 is dithered)",
    )


def add_exclusion(p: argparse.ArgumentParser, image: str) -> None:
    """``--exclude-color LO:HI`` and ``--exclude-mask FILE`` for the pixels of ``image``."""
    p.add_argument(
        "--exclude-color",
        type=colour_range,
        default=None,
        metavar="LO:HI",
        help=f"never use {image} colours in [LO, HI] per channel, e.g. 0,0,0:0.2,0.2,0.3",
    )
    p.add_argument(
        "--exclude-mask",
        default=None,
        metavar="FILE",
        help=f"image whose non-black pixels mark {image} pixels not to use",
    )


def excluded_pixels(args, pixels, image: str):
    """The (H, W) bool mask of ``--exclude-color`` / ``--exclude-mask`` over ``pixels`` (of the
    ``image`` named in messages), or None. The mask image's colour decides, not its alpha."""
    if args.exclude_color is None and not args.exclude_mask:
        return None
    from engine.errormap import colour_channels
    from engine.exclusion import exclusion_mask
    from engine.io import load_image

    painted = None
    if args.exclude_mask:
        m = load_image(args.exclude_mask).pixels
        if m.shape[:2] != pixels.shape[:2]:
            raise ValueError(
                f"{args.exclude_mask}: the mask is {m.shape[1]}x{m.shape[0]}, the {image} "
                f"{pixels.shape[1]}x{pixels.shape[0]}"
            )
        painted = colour_channels(m).max(axis=2) > 0
    return exclusion_mask(pixels, color_range=args.exclude_color, painted=painted)
