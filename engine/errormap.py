"""Per-pixel error of two equally sized regions (the input of every seam search).

Three metrics (ALGORITHMS.md §1.1, §2.3, §7.7):

* ``"euclid"`` — Euclidean distance of the colour vectors, ``‖a − b‖₂`` (Somol & Haindl);
* ``"ssd"`` — its square, ``‖a − b‖²`` (Efros & Freeman's minimum error boundary cut);
* ``"lab"`` — CIE76 ΔE, the Euclidean distance in CIELAB (scikit-image ``rgb2lab``), a
  perceptual option; gray is treated as R = G = B.

Images are (H, W) or (H, W, C) with C = 1 (gray), 2 (gray + alpha), 3 (RGB) or 4 (RGBA),
any integer or float dtype (integers are scaled by their range). Alpha never enters the
distance. A gray region may be compared with an RGB one (gray is replicated).
"""

from __future__ import annotations

import numpy as np

from engine._validate import as_image, choice
from engine.seams.spec import METRICS

__all__ = ["METRICS", "colour_channels", "error_map", "error_map_of"]


def colour_channels(image: np.ndarray) -> np.ndarray:
    """The colour channels of a float (H, W, C) image: alpha (C = 2 or 4) dropped."""
    c = image.shape[2]
    return image[:, :, :1] if c == 2 else image[:, :, :3] if c == 4 else image


def error_map(r1, r2, *, metric: str = "euclid") -> np.ndarray:
    """Per-pixel error of ``r1`` against ``r2``.

    Parameters
    ----------
    r1, r2 : (h, w[, C]) array
        Two co-registered regions of equal height and width.
    metric : {"euclid", "ssd", "lab"}
        Euclidean RGB distance, its square, or CIELAB ΔE (CIE76).

    Returns
    -------
    (h, w) float32 ndarray
        Non-negative errors; 0 where the colours are equal.

    Examples
    --------
    >>> a = np.zeros((2, 3, 3), np.float32); b = a.copy(); b[0, 0] = (0.3, 0.4, 0.0)
    >>> error_map(a, b)[0, 0].round(6), error_map(a, b, metric="ssd")[0, 0].round(6)
    (np.float32(0.5), np.float32(0.25))
    """
    choice(metric, "metric", METRICS)
    a = colour_channels(as_image(r1, "r1"))
    b = colour_channels(as_image(r2, "r2"))
    if a.shape[:2] != b.shape[:2]:
        raise ValueError(
            f"r1 and r2 must have the same height and width, got {a.shape[1]}x{a.shape[0]} "
            f"and {b.shape[1]}x{b.shape[0]}"
        )
    if a.shape[2] != b.shape[2]:
        if 1 not in (a.shape[2], b.shape[2]):
            raise ValueError(
                f"r1 and r2 must have compatible channels, got {a.shape[2]} and {b.shape[2]}"
            )
        a, b = _rgb(a), _rgb(b)
    return error_map_of(a, b, metric)


def error_map_of(a: np.ndarray, b: np.ndarray, metric: str) -> np.ndarray:
    """:func:`error_map` of two float (h, w, C) arrays of one shape, already checked (the
    engine's inner loops call it once per block, where the checks cost more than the map)."""
    if metric == "lab":
        from skimage.color import rgb2lab

        a = rgb2lab(np.clip(_rgb(a), 0.0, 1.0))
        b = rgb2lab(np.clip(_rgb(b), 0.0, 1.0))
    d = a - b
    d2 = np.einsum("ijk,ijk->ij", d, d)
    out = d2 if metric == "ssd" else np.sqrt(d2)
    return out.astype(np.float32, copy=False)


def _rgb(x: np.ndarray) -> np.ndarray:
    return np.repeat(x, 3, axis=2) if x.shape[2] == 1 else x
