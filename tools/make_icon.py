"""Regenerate resources/icons/quilt-studio.png: a 3x3 quilt of patches joined by a seam line.

Run: python tools/make_icon.py  (deterministic, CC0)
"""

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

OUT = Path(__file__).resolve().parent.parent / "resources" / "icons" / "quilt-studio.png"
SIZE = 256
PALETTE = [(196, 120, 64), (92, 128, 160), (214, 178, 96), (120, 150, 90), (170, 92, 96)]


def main() -> None:
    rng = np.random.default_rng(3)
    img = Image.new("RGBA", (SIZE, SIZE), (0, 0, 0, 0))
    draw = ImageDraw.Draw(img)
    pad, cell = 16, (SIZE - 32) // 3
    for r in range(3):
        for c in range(3):
            colour = PALETTE[int(rng.integers(len(PALETTE)))]
            x0, y0 = pad + c * cell, pad + r * cell
            draw.rounded_rectangle((x0 + 3, y0 + 3, x0 + cell - 3, y0 + cell - 3), 14, fill=colour)
    # a winding seam across the quilt, as the editor draws it
    xs = np.linspace(pad + 8, SIZE - pad - 8, 40)
    ys = SIZE / 2 + 34 * np.sin(xs / 22.0)
    draw.line(list(zip(xs.tolist(), ys.tolist(), strict=True)), fill=(250, 240, 120), width=9)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    img.save(OUT)


if __name__ == "__main__":
    main()
