"""Export the seamless tile alone: the usual "make it tile" deliverable, one file per map.

:func:`export_seamless` writes the main map's tile to ``path`` and every other material map's
tile beside it as ``{stem}_{map}{suffix}`` (``tile.png``, ``tile_normal.png`` ...), at the
source's bit depth or the one asked for (16 → 8 bits is dithered). Each file is written
atomically (:func:`engine.io.save_image`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

__all__ = ["export_seamless", "seamless_paths"]


def seamless_paths(maps, path) -> dict[str, Path]:
    """Where :func:`export_seamless` writes each map: the first at ``path``, the others as
    ``{stem}_{map}{suffix}`` beside it."""
    p = Path(os.fspath(path))
    names = list(maps)
    return {m: p if i == 0 else p.with_name(f"{p.stem}_{m}{p.suffix}") for i, m in enumerate(names)}


def export_seamless(
    maps: Mapping[str, np.ndarray],
    path,
    *,
    bit_depth: int = 8,
    dither: bool | None = None,
    source_bit_depth: int | None = None,
    rng=0,
) -> list[Path]:
    """Write the seamless tile of every map (main map first) and return the paths written.

    Parameters
    ----------
    maps : mapping of str to (h, w[, C]) array
        The tile per material map, the main map first (``Project.template``).
    path : path-like
        The main map's file (PNG or TIFF for 16 bits; JPEG, BMP, WebP at 8 bits).
    bit_depth : {8, 16}
        Bits per channel of the files.
    dither : bool, optional
        Dither when rounding (default: when ``bit_depth`` is below ``source_bit_depth``).
    rng : int or Generator
        Seed of the dither noise.
    """
    from engine.bitdepth import quantize
    from engine.io import check_output, save_image

    if not maps:
        raise ValueError("there is no seamless tile to export: make one first")
    targets = seamless_paths(maps, path)
    for m, p in targets.items():  # every file checked before any is written
        a = np.asarray(maps[m])
        check_output(p, bit_depth=bit_depth, channels=a.shape[2] if a.ndim == 3 else 1)
    if dither is None:
        dither = source_bit_depth is not None and bit_depth < source_bit_depth
    written = []
    for m, p in targets.items():
        image = np.asarray(maps[m])
        if dither:
            image = quantize(image, bit_depth, dither=True, rng=rng)
        written.append(save_image(p, image, bit_depth=bit_depth))
    return written
