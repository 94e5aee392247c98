"""numpy arrays -> QImage / QPixmap (GUI thread only) and small display helpers.

Converting a large image to 8 bits takes a noticeable time (about 0.25 s for 6144 x 6144
RGB), so :func:`display_uint8` remembers the conversion of large arrays for as long as the
array lives; a worker thread can call it ahead (``prepare_display``) so the GUI thread
only copies pixels.
"""

from __future__ import annotations

import threading
import weakref

import numpy as np
from PySide6.QtGui import QImage, QPixmap

#: Arrays with at least this many values keep their 8-bit display copy (see display_uint8).
CACHE_MIN_VALUES = 1 << 20
_cache: dict[int, tuple[weakref.ref, np.ndarray]] = {}
_cache_lock = threading.Lock()


def display_uint8(pixels: np.ndarray) -> np.ndarray:
    """:func:`to_uint8` of ``pixels``, remembered while a large array is alive (thread-safe)."""
    a = np.asarray(pixels)
    if a.size < CACHE_MIN_VALUES:
        return to_uint8(a)
    key = id(a)
    with _cache_lock:
        hit = _cache.get(key)
    if hit is not None and hit[0]() is a:
        return hit[1]
    out = to_uint8(a)
    try:
        ref = weakref.ref(a, lambda _r, k=key: _forget(k))
    except TypeError:  # not weak-referenceable: no caching
        return out
    with _cache_lock:
        _cache[key] = (ref, out)
    return out


def _forget(key: int) -> None:
    if _cache is None:  # interpreter shutdown: the module's globals are gone already
        return
    with _cache_lock:
        entry = _cache.get(key)
        if entry is not None and entry[0]() is None:
            del _cache[key]


def forget_display(pixels: np.ndarray) -> None:
    """Drop the remembered display copy of ``pixels`` (changed in place)."""
    with _cache_lock:
        _cache.pop(id(pixels), None)


def prepare_display(pixels: np.ndarray) -> None:
    """Compute the display copy of ``pixels`` now (call it in a worker thread)."""
    display_uint8(pixels)


def to_uint8(pixels: np.ndarray) -> np.ndarray:
    """float [0, 1] (H, W[, C]) or uint8/uint16 -> contiguous uint8 (H, W, 1|3|4)."""
    a = np.asarray(pixels)
    if a.ndim == 2:
        a = a[:, :, None]
    if a.dtype == np.uint8:
        out = a
    elif a.dtype == np.uint16:
        out = (a >> 8).astype(np.uint8)
    else:
        out = (np.clip(a, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    c = out.shape[2]
    if c == 2:  # gray + alpha -> RGBA
        out = np.concatenate([np.repeat(out[:, :, :1], 3, axis=2), out[:, :, 1:]], axis=2)
    elif c > 4:
        out = out[:, :, :3]
    return np.ascontiguousarray(out)


def _wrap(a: np.ndarray) -> QImage:
    """A QImage over the buffer of contiguous uint8 ``a`` (valid while ``a`` lives)."""
    h, w, c = a.shape
    fmt = {
        1: QImage.Format.Format_Grayscale8,
        3: QImage.Format.Format_RGB888,
        4: QImage.Format.Format_RGBA8888,
    }[c]
    return QImage(a.data, w, h, a.strides[0], fmt)


def to_qimage(pixels: np.ndarray) -> QImage:
    """A QImage that owns a copy of the pixels (gray, RGB or RGBA)."""
    return _wrap(display_uint8(pixels)).copy()


def to_pixmap(pixels: np.ndarray) -> QPixmap:
    a = display_uint8(pixels)
    return QPixmap.fromImage(_wrap(a))  # fromImage copies while ``a`` is alive


def _heat_lut() -> np.ndarray:
    """256-entry "inferno"-like colour map: black -> purple -> red -> orange -> pale yellow."""
    stops = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    colors = np.array(
        [[0, 0, 4], [87, 16, 110], [188, 55, 84], [249, 142, 9], [252, 255, 164]], dtype=np.float64
    )
    x = np.linspace(0.0, 1.0, 256)
    return np.stack([np.interp(x, stops, colors[:, k]) for k in range(3)], axis=1).astype(np.uint8)


HEAT_LUT = _heat_lut()


def normalize_error(error: np.ndarray, vmax: float | None = None) -> np.ndarray:
    """Error map scaled to [0, 1] by ``vmax`` (default: its 99th percentile)."""
    e = np.asarray(error, dtype=np.float64)
    if vmax is None:
        vmax = float(np.percentile(e, 99)) if e.size else 1.0
    if not vmax > 0:
        vmax = float(e.max()) if e.size and e.max() > 0 else 1.0
    return np.clip(e / vmax, 0.0, 1.0)


def heat_rgba(error: np.ndarray, *, alpha: int = 255, vmax: float | None = None) -> np.ndarray:
    """(h, w) error -> (h, w, 4) uint8 heat colours."""
    idx = (normalize_error(error, vmax) * 255.0 + 0.5).astype(np.intp)
    rgb = HEAT_LUT[idx]
    a = np.full(rgb.shape[:2] + (1,), alpha, dtype=np.uint8)
    return np.concatenate([rgb, a], axis=2)


def pixel_text(pixels: np.ndarray, row: int, col: int, bit_depth: int = 8) -> str:
    """The value of one pixel as the status bar shows it (in the file's integer range)."""
    if np.issubdtype(np.asarray(pixels).dtype, np.integer):  # a display copy: its own values
        return ", ".join(str(int(x)) for x in np.asarray(pixels[row, col]).ravel())
    v = np.asarray(pixels[row, col], dtype=np.float64).ravel()
    scale = 65535 if bit_depth == 16 else 255
    return ", ".join(str(int(round(x * scale))) for x in v)
