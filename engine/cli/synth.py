"""``quilt-studio synth SAMPLE --size WxH --block B -o OUT.png``: image quilting from a sample.

Selection (``--select``), boundary (``--seam``), blending, exclusion, tileable output and the
fast search all map onto :func:`engine.quilting.iter_quilt`. Progress goes to stderr; the output
keeps the sample's bit depth (16-bit in, 16-bit out). ``--save-seams F`` writes the cuts: a JSON
record of every block for ``.json``, otherwise the output with every cut drawn in red.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from pathlib import Path

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

MAX_OUTPUT_PIXELS = 2**28
"""Largest synthesized output (16384 x 16384): 3 GiB as float32 RGB before the search's own
memory (which the engine estimates and checks against what is available)."""
MAX_OUTPUT_SIDE = 65535


def parse_wxh(text: str) -> tuple[int, int]:
    """``WxH`` (width x height) -> (height, width)."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise argparse.ArgumentTypeError(f"expected WxH like 512x384, got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    if w < 1 or h < 1:
        raise argparse.ArgumentTypeError(f"width and height must be >= 1, got {text!r}")
    if w * h > MAX_OUTPUT_PIXELS or max(w, h) > MAX_OUTPUT_SIDE:
        raise argparse.ArgumentTypeError(
            f"{w}x{h} is over the output limit of {MAX_OUTPUT_PIXELS:,} pixels "
            f"({MAX_OUTPUT_SIDE} px per side at most)"
        )
    return h, w


def add_cut_arguments(p: argparse.ArgumentParser) -> None:
    """Options shared by ``synth`` and ``transfer``: the cut, blending, search, seed, threads."""
    from engine.quilting.names import MODES, SEAMS
    from engine.seams.spec import BLEND_MODES, METRICS

    p.add_argument(
        "--seam",
        choices=SEAMS,
        default=None,
        help="boundary: straight overlap or a seam method (default dp; resistance with "
        "--select bhatia)",
    )
    add_seam_options(p)
    p.add_argument(
        "--blend",
        choices=BLEND_MODES,
        default=None,
        help="softening of the cut (default none; feather with --select bhatia, whose paper "
        "blends the pixels around its cut lines)",
    )
    p.add_argument(
        "--blend-width",
        type=non_negative_float,
        default=4.0,
        metavar="PX",
        help="feather width in pixels (default 4)",
    )
    p.add_argument("--rho", type=int_at_least(0), default=3, help="adaptive blending ρ (default 3)")
    p.add_argument(
        "--metric", choices=METRICS, default="ssd", help="error map the cut runs on (default ssd)"
    )
    p.add_argument(
        "--tolerance",
        type=non_negative_float,
        default=0.1,
        help="draw among windows within 1+T of the best (default 0.1)",
    )
    p.add_argument(
        "--mode",
        choices=MODES,
        default="auto",
        help="block search: exact (every sample position, FFT), fast (coarse-to-fine, exact "
        "re-ranking) or auto: exact where its estimate is under 10 s (default auto)",
    )
    add_exclusion(p, "sample")
    p.add_argument("--seed", type=int_at_least(0), default=0, help="random seed (default 0)")
    p.add_argument(
        "--threads", type=thread_count, default=None, help="worker threads (default: every core)"
    )
    add_bit_depth(p, "sample")
    p.add_argument("-o", "--output", required=True, metavar="OUT.png", help="output image")


def add_parser(subparsers) -> argparse.ArgumentParser:
    from engine.quilting.names import SELECTIONS

    p = subparsers.add_parser(
        "synth",
        help=SUBCOMMANDS["synth"],
        description="Image quilting (Efros & Freeman; Long & Mould; Bhatia; CS194; Core S2): "
        "blocks of SAMPLE placed with overlaps and cut along minimum-error seams.",
    )
    p.add_argument("sample", metavar="SAMPLE", help="sample texture (PNG, JPEG, TIFF, BMP, WebP)")
    p.add_argument("--size", type=parse_wxh, required=True, metavar="WxH", help="output size")
    p.add_argument("--block", type=int_at_least(2), required=True, metavar="B", help="block size")
    p.add_argument(
        "--overlap",
        type=int_at_least(0),
        default=None,
        metavar="O",
        help="overlap (default B/6; B/2 for minimax; Bhatia's cut band B/4)",
    )
    p.add_argument(
        "--select", choices=SELECTIONS, default="best", help="block selection (default best)"
    )
    p.add_argument(
        "--candidates",
        type=int_at_least(1),
        default=None,
        metavar="K",
        help="windows per block for --select sampled (default 200), or re-ranked "
        "exactly in --mode fast (default 32)",
    )
    p.add_argument(
        "--tileable", action="store_true", help="wrap-around overlaps: the output tiles seamlessly"
    )
    p.add_argument(
        "--adaptive-threshold",
        type=non_negative_float,
        default=None,
        metavar="T",
        help="split blocks whose best overlap error per pixel and channel exceeds T",
    )
    p.add_argument(
        "--min-block",
        type=int_at_least(2),
        default=None,
        metavar="B",
        help="smallest block of adaptive splitting",
    )
    add_cut_arguments(p)
    p.add_argument(
        "--save-seams",
        default=None,
        metavar="F",
        help="write the cuts: F.json (every block's record) or an image (cuts in red)",
    )
    p.set_defaults(func=run)
    return p


class ProgressPrinter:
    """Progress events as stderr lines with the time left, at most a few per second (and the
    last one); the run's plan (search, estimated time and memory) before the first."""

    def __init__(self, command: str):
        self.command = command
        self.t0 = time.perf_counter()
        self.last = -1.0
        self.estimate = None  # seconds, from the plan

    def plan(self, plan) -> None:
        self.estimate = plan.seconds
        print(f"{self.command}: {plan.describe()}", file=sys.stderr, flush=True)

    def __call__(self, ev) -> None:
        from engine.quilting.estimate import format_duration

        now = time.perf_counter() - self.t0
        if ev.done < ev.total and now - self.last < 0.25:
            return
        self.last = now
        left = ""
        if ev.done < ev.total:
            f = ev.fraction
            secs = now * (1 - f) / f if f > 0 else self.estimate
            left = "" if secs is None else f", about {format_duration(secs)} left"
        print(
            f"[{now:7.2f}s] {self.command}: {ev.done}/{ev.total} {ev.message}{left}",
            file=sys.stderr,
            flush=True,
        )


def drive(gen, printer):
    """Run an engine generator, printing its plan and Progress events; returns its value."""
    from engine.events import Progress, drain
    from engine.quilting.estimate import Estimated

    def on_event(ev) -> None:
        if isinstance(ev, Progress):
            printer(ev)
        elif isinstance(ev, Estimated):
            printer.plan(ev.plan)

    return drain(gen, on_event)


def load_sample_and_exclusion(args):
    """(pixels, output bit depth, excluded mask or None) from SAMPLE, --bit-depth and
    --exclude-color/--exclude-mask; the output paths are checked first (not after the run).
    Sets ``args.dither`` when a 16-bit sample is written at 8 bits."""
    from engine.io import load_image

    loaded = load_image(args.sample)
    depth = args.bit_depth or loaded.bit_depth
    args.dither = depth < loaded.bit_depth
    check_output(args.output, depth, loaded.pixels.shape[2])
    seams = getattr(args, "save_seams", None)
    if seams and Path(seams).suffix.lower() != ".json":
        check_output(seams, 8, 3)
    return loaded.pixels, depth, excluded_pixels(args, loaded.pixels, "sample")


def check_output(path: str, depth: int, channels: int) -> None:
    """Refuse an output :func:`engine.io.save_image` could not write, before any work."""
    from engine.io import ImageError
    from engine.io import check_output as check

    try:
        check(path, bit_depth=depth, channels=channels)
    except ImageError as exc:
        hint = " (or pass --bit-depth 8)" if "16-bit" in str(exc) else ""
        raise ImageError(f"{exc}{hint}") from None


def save_output(args, image, depth: int) -> None:
    """Write the result at ``depth`` bits; a 16-bit sample reduced to 8 bits is dithered."""
    from engine.bitdepth import quantize
    from engine.io import save_image

    if args.dither:
        image = quantize(image, 8, dither=True, rng=args.seed)
    save_image(args.output, image, bit_depth=depth)


def start(iter_fn, *args, **kwargs):
    """Call an engine ``iter_*`` function; a bad ``--seam-option`` (TypeError there) becomes a
    one-line ValueError for the CLI."""
    try:
        return iter_fn(*args, **kwargs)
    except TypeError as exc:
        raise ValueError(str(exc)) from None


def cut_options(args) -> dict:
    """``seam`` (a SeamSpec: a bad ``--seam-option`` raises here), tolerance, seed, threads."""
    from engine.quilting.options import BHATIA_SEAM, QUILT_SEAM
    from engine.seams import SeamSpec

    default = BHATIA_SEAM if getattr(args, "select", None) == "bhatia" else QUILT_SEAM
    try:
        seam = SeamSpec(
            args.seam or default.method,
            dict(args.seam_option),
            metric=args.metric,
            blend=args.blend or default.blend,
            width=args.blend_width,
            rho=args.rho,
        )
    except TypeError as exc:  # a bad --seam-option: a one-line message
        raise ValueError(str(exc)) from None
    return dict(
        seam=seam, tolerance=args.tolerance, mode=args.mode, rng=args.seed, threads=args.threads
    )


def run(args) -> int:
    from engine.metrics import block_grid_border_ratio
    from engine.quilting.synthesis import iter_quilt

    sample, depth, excluded = load_sample_and_exclusion(args)
    gen = start(
        iter_quilt,
        sample,
        args.size,
        block=args.block,
        overlap=args.overlap,
        select=args.select,
        candidates=args.candidates,
        tileable=args.tileable,
        adaptive_threshold=args.adaptive_threshold,
        min_block=args.min_block,
        excluded=excluded,
        **cut_options(args),
    )
    res = drive(gen, ProgressPrinter("synth"))
    save_output(args, res.image, depth)
    if args.save_seams:
        save_seams(args.save_seams, res)
    fits = min(res.image.shape[:2]) > max(res.step)
    ratio = block_grid_border_ratio(res) if fits else float("nan")
    print(
        f"quilt-studio synth: wrote {args.output} ({res.image.shape[1]}x{res.image.shape[0]}, "
        f"{depth}-bit, {len(res.blocks)} blocks, grid border ratio {ratio:.3f})",
        file=sys.stderr,
    )
    return 0


def save_seams(path: str, res) -> None:
    """Every block's cut: JSON records, or the output with the cut pixels in red."""
    import numpy as np

    from engine.io import save_image, to_rgb

    p = Path(path)
    if p.suffix.lower() == ".json":
        blocks = [
            {
                "index": r.index,
                "position": list(r.position),
                "size": list(r.size),
                "source": list(r.source),
                "arms": list(r.arms),
                "criterion": None if np.isnan(r.criterion) else r.criterion,
                "peak": None if np.isnan(r.peak) else r.peak,
                "match_error": None if np.isnan(r.match_error) else r.match_error,
                "depth": r.depth,
                "path": np.asarray(r.path).tolist(),
            }
            for r in res.blocks
        ]
        doc = {
            "block": list(res.block),
            "overlap": res.overlap,
            "select": res.select,
            "seam": res.seam.method,
            "seam_spec": res.seam.to_dict(),
            "blocks": blocks,
        }
        from engine._fs import write_bytes_atomically

        try:
            p.parent.mkdir(parents=True, exist_ok=True)
            write_bytes_atomically(p, json.dumps(doc).encode("utf-8"))  # atomic: all or nothing
        except OSError as exc:
            raise OSError(f"{p}: cannot write ({exc.strerror or exc})") from None
        return
    img = to_rgb(res.image).copy()
    h, w = img.shape[:2]
    for r in res.blocks:
        if len(r.path):
            rows = (r.path[:, 0] + r.position[0]) % h
            cols = (r.path[:, 1] + r.position[1]) % w
            img[rows, cols] = (1.0, 0.0, 0.0)
    save_image(p, img)
