"""PNG codec benchmark: libpng through imagecodecs (``engine.png``) against the hand-written
numba codec it replaced (``benchmarks/_png_baseline.py``), and Pillow where it keeps the bits.

Run ``python -m benchmarks.png`` (``--quick`` skips 4096²). Images: the cobblestones sample
scaled to 512² and 4096² with 1.5 LSB of Gaussian grain (as a photo has; a smooth upscale would
compress unrealistically well), RGB, at 8 and 16 bits. Each row: median encode and decode time,
the file size, and whether the round trip is exact. Writes ``benchmarks/results/png.txt``.
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import numpy as np

if __package__ in (None, ""):  # run as a script: make the repository importable
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import resources  # noqa: E402
from benchmarks import _png_baseline as baseline  # noqa: E402
from benchmarks._util import format_table, median_time, provenance  # noqa: E402
from engine import png  # noqa: E402
from engine.io import load_image  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "png.txt"


def test_image(size: int, bit_depth: int) -> np.ndarray:
    from skimage.transform import resize

    src = load_image(resources.sample_path("cobblestones")).rgb
    a = resize(src, (size, size, 3), order=1, anti_aliasing=False)
    top = 255 if bit_depth == 8 else 65535
    grain = np.random.default_rng(0).normal(0.0, 1.5 / 255, a.shape)
    return np.round(np.clip(a + grain, 0, 1) * top).astype(
        np.uint8 if bit_depth == 8 else np.uint16
    )


def pillow_encode(q: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(q).save(buf, format="PNG")
    return buf.getvalue()


def pillow_decode(data: bytes) -> np.ndarray:
    from PIL import Image

    with Image.open(io.BytesIO(data)) as im:
        return np.asarray(im)


CODECS = {  # name -> (encode, decode, bit depths it keeps)
    "hand-written (numba, zlib 6, filter Up)": (baseline.encode_png, baseline.decode_png, (8, 16)),
    "imagecodecs libpng (engine.png)": (png.encode_png, png.decode_png, (8, 16)),
    "Pillow (reference)": (pillow_encode, pillow_decode, (8,)),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="512² only")
    args = ap.parse_args(argv)
    baseline.decode_png(baseline.encode_png(np.zeros((8, 8, 3), np.uint8)))  # compile numba
    sizes = (512,) if args.quick else (512, 4096)
    rows = []
    for size in sizes:
        for depth in (8, 16):
            q = test_image(size, depth)
            times = {}
            for name, (enc, dec, depths) in CODECS.items():
                if depth not in depths:
                    continue
                reps = {"min_repeats": 3 if size > 512 else 5, "max_time": 60.0}
                t_enc, data = median_time(lambda enc=enc, q=q: enc(q), **reps)
                t_dec, back = median_time(lambda dec=dec, data=data: dec(data), **reps)
                exact = np.array_equal(np.asarray(back).reshape(q.shape), q)
                times[name] = (t_enc, t_dec)
                base = times.get(next(iter(CODECS)))
                ratio = f"{base[0] / t_enc:.2f}x / {base[1] / t_dec:.2f}x" if base else ""
                rows.append(
                    (
                        f"{size}²",
                        depth,
                        name,
                        f"{t_enc * 1e3:.1f}",
                        f"{t_dec * 1e3:.1f}",
                        ratio,
                        f"{len(data) / 2**20:.2f}",
                        "yes" if exact else "NO",
                    )
                )
                print(rows[-1], file=sys.stderr)
    table = format_table(
        (
            "image",
            "bits",
            "codec",
            "encode ms",
            "decode ms",
            "speed vs hand-written (enc / dec)",
            "MiB",
            "exact",
        ),
        rows,
    )
    print(table)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(f"{provenance()}\npython -m benchmarks.png\n\n{table}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
