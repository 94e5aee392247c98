"""``quilt-studio seam R1 R2 --method M``: one seam through the overlap of two images.

R1 is kept on the left, R2 on the right; the seam runs top to bottom through their error map.
Prints the criterion (sum of the error on the path), the peak (its maximum) and the time of the
seam search (kernels loaded beforehand, so it is the search alone); ``--json`` prints the same
as one JSON object with the path.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from engine.cli import SUBCOMMANDS
from engine.cli._args import add_seam_options, int_at_least, non_negative_float
from engine.seams.spec import BLEND_MODES, METHODS, METRICS, SeamSpec


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "seam",
        help=SUBCOMMANDS["seam"],
        description="Find a top-to-bottom seam through the overlap of R1 (kept on the left) and "
        "R2 (kept on the right). Prints criterion (sum of the error on the path), peak (its "
        "largest error) and the time of the seam search.",
    )
    p.add_argument("r1", metavar="R1", help="left overlap image (kept left of the seam)")
    p.add_argument("r2", metavar="R2", help="right overlap image, same size as R1")
    p.add_argument("--method", choices=METHODS, default="dp", help="seam method (default: dp)")
    p.add_argument(
        "--o-max",
        type=int_at_least(1),
        default=None,
        metavar="N",
        help="largest block of control points moved at once (oscillating only; default 3)",
    )
    add_seam_options(p)
    p.add_argument(
        "--start", type=int_at_least(0), metavar="COL", help="pin the path's column in the top row"
    )
    p.add_argument(
        "--end", type=int_at_least(0), metavar="COL", help="pin the path's column in the bottom row"
    )
    p.add_argument(
        "--waypoint",
        type=_point,
        action="append",
        default=[],
        metavar="ROW,COL",
        help="a pixel the path must pass through (repeatable)",
    )
    p.add_argument("--metric", choices=METRICS, default="euclid", help="error metric")
    p.add_argument("--blend", choices=BLEND_MODES, default="none", help="blend of --save-composite")
    p.add_argument(
        "--rho", type=int_at_least(0), default=3, help="rho of adaptive blending (default 3)"
    )
    p.add_argument(
        "--width", type=non_negative_float, default=4, help="feather width in pixels (default 4)"
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--save-mask", metavar="FILE", help="write the mask (white = R1) as a PNG")
    p.add_argument("--save-composite", metavar="FILE", help="write the stitched overlap")
    p.add_argument(
        "--save-error",
        metavar="FILE",
        help="write the error map, scaled so its maximum is white (16-bit PNG/TIFF)",
    )
    p.set_defaults(func=run)
    return p


def _point(text: str) -> tuple[int, int]:
    try:
        row, col = (int(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected ROW,COL like 12,3, got {text!r}") from None
    return row, col


def run(args) -> int:
    import numpy as np

    from engine.blend import blend_weights, composite
    from engine.budget import check_memory, seam_bytes
    from engine.errormap import error_map
    from engine.io import check_output, load_image, save_image, to_rgb
    from engine.seams import find_seam

    if args.o_max is not None and args.method != "oscillating":
        raise ValueError(f"--o-max applies to --method oscillating only, not {args.method}")
    options = dict(args.seam_option)
    if args.o_max is not None:
        options["o_max"] = args.o_max
    spec = SeamSpec(
        args.method, options, metric=args.metric, blend=args.blend, width=args.width, rho=args.rho
    )
    a = load_image(args.r1)
    b = load_image(args.r2)
    (h, w), (h2, w2) = a.pixels.shape[:2], b.pixels.shape[:2]
    if (h, w) != (h2, w2):
        raise ValueError(
            f"R1 and R2 must have the same size: {args.r1} is {w}x{h}, {args.r2} is {w2}x{h2}"
        )
    r1, r2 = a.pixels, b.pixels
    check_memory(
        seam_bytes(h, w, max(r1.shape[2], r2.shape[2])),
        what=f"a seam through this {w}x{h} overlap",
        way_out="use smaller overlap images",
    )
    if r1.shape[2] != r2.shape[2]:
        r1, r2 = to_rgb(r1), to_rgb(r2)
    depth = max(a.bit_depth, b.bit_depth)
    for path, bits, channels in (
        (args.save_mask, 8, 1),
        (args.save_composite, depth, r1.shape[2]),
        (args.save_error, 16, 1),
    ):
        if path:
            check_output(path, bit_depth=bits, channels=channels)  # before the search
    if not args.json:  # --json keeps stderr for errors only
        print(f"quilt-studio seam: {args.method} through a {w}x{h} overlap", file=sys.stderr)
    err = error_map(r1, r2, metric=spec.metric)
    # a fresh process loads (or compiles) the method's numba kernels on first use, ~0.2 s:
    # do that on a tiny map so the time printed is the search's own
    find_seam(np.ones((3, 3)), seam=spec).mask  # noqa: B018
    t0 = time.perf_counter()
    seam = find_seam(err, seam=spec, start=args.start, end=args.end, waypoints=tuple(args.waypoint))
    elapsed = time.perf_counter() - t0
    if args.save_mask:
        save_image(args.save_mask, seam.mask.astype(np.float32))
    if args.save_composite:
        alpha = blend_weights(seam, err, spec=spec)
        save_image(args.save_composite, composite(alpha, r1, r2), bit_depth=depth)
    top = float(err.max())
    if args.save_error:
        save_image(args.save_error, err / top if top > 0 else err, bit_depth=16)
    if args.json:
        out = {
            "method": args.method,
            "metric": args.metric,
            "criterion": seam.criterion,
            "peak": seam.peak,
            "time": elapsed,
            "shape": [h, w],
            "path": seam.path.tolist(),
            "error_max": top,
        }
        print(json.dumps(out))
    else:
        print(
            f"method {args.method}  metric {args.metric}  criterion {seam.criterion:.6g}  "
            f"peak {seam.peak:.6g}  time {elapsed * 1e3:.3f} ms  "
            f"({w}x{h} overlap, {len(seam.path)} path pixels)"
        )
    for flag, path in (
        ("mask", args.save_mask),
        ("composite", args.save_composite),
        ("error", args.save_error),
    ):
        if path:
            print(f"quilt-studio seam: wrote {flag} {path}", file=sys.stderr)
    return 0
