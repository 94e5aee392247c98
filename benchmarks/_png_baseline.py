"""The hand-written exact PNG codec (zlib + a numba unfilter) the engine used before
``engine.png`` (libpng through imagecodecs): kept as the baseline of ``benchmarks/png.py``."""

from __future__ import annotations

import struct
import zlib

import numpy as np
from numba import njit

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_COLOR_TYPES = {1: 0, 2: 4, 3: 2, 4: 6}  # channels -> PNG colour type
_CHANNELS = {v: k for k, v in _COLOR_TYPES.items()}


class PNGError(ValueError):
    """The bytes are not a PNG this codec can read."""


def _chunk(tag: bytes, data: bytes) -> bytes:
    return (
        struct.pack(">I", len(data))
        + tag
        + data
        + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    )


def encode_png(q: np.ndarray) -> bytes:
    """uint8 or uint16 (H, W) / (H, W, C<=4) -> PNG bytes (deterministic; filter Up)."""
    a = np.asarray(q)
    if a.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"q must be uint8 or uint16, got {a.dtype}")
    if a.ndim == 2:
        a = a[:, :, None]
    if a.ndim != 3 or a.shape[2] not in _COLOR_TYPES or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"q must be (H, W) or (H, W, 1-4), got shape {np.shape(q)}")
    h, w, c = a.shape
    depth = 16 if a.dtype == np.uint16 else 8
    rows = np.ascontiguousarray(a.astype(">u2") if depth == 16 else a).view(np.uint8).reshape(h, -1)
    filtered = rows.copy()
    filtered[1:] = rows[1:] - rows[:-1]  # filter type 2 (Up), modulo 256
    raw = np.empty((h, rows.shape[1] + 1), np.uint8)
    raw[:, 0] = 2
    raw[0, 0] = 0
    raw[0, 1:] = rows[0]
    raw[1:, 1:] = filtered[1:]
    ihdr = struct.pack(">IIBBBBB", w, h, depth, _COLOR_TYPES[c], 0, 0, 0)
    return (
        _SIGNATURE
        + _chunk(b"IHDR", ihdr)
        + _chunk(b"IDAT", zlib.compress(raw.tobytes(), 6))
        + _chunk(b"IEND", b"")
    )


@njit(cache=True, nogil=True)
def _unfilter(raw, h, stride, bpp):  # pragma: no cover - compiled
    out = np.zeros((h, stride), np.uint8)
    prev = np.zeros(stride, np.uint8)
    for y in range(h):
        base = y * (stride + 1)
        ft = raw[base]
        if ft > 4:
            return out, False
        for x in range(stride):
            v = np.int32(raw[base + 1 + x])
            a = np.int32(out[y, x - bpp]) if x >= bpp else 0
            b = np.int32(prev[x])
            cc = np.int32(prev[x - bpp]) if x >= bpp else 0
            if ft == 1:
                v += a
            elif ft == 2:
                v += b
            elif ft == 3:
                v += (a + b) // 2
            elif ft == 4:
                p = a + b - cc
                pa = abs(p - a)
                pb = abs(p - b)
                pc = abs(p - cc)
                if pa <= pb and pa <= pc:
                    v += a
                elif pb <= pc:
                    v += b
                else:
                    v += cc
            out[y, x] = v & 0xFF
        prev = out[y]
    return out, True


def decode_png(data: bytes, *, max_pixels: int = 100_000_000) -> np.ndarray:
    """PNG bytes -> uint8/uint16 (H, W, C); non-interlaced 8/16-bit gray/GA/RGB/RGBA only."""
    if not data.startswith(_SIGNATURE):
        raise PNGError("not a PNG file")
    pos = len(_SIGNATURE)
    ihdr = None
    idat = []
    n = len(data)
    while True:
        if pos + 8 > n:
            raise PNGError("truncated PNG (no IEND chunk)")
        length, tag = struct.unpack(">I4s", data[pos : pos + 8])
        body = data[pos + 8 : pos + 8 + length]
        crc = data[pos + 8 + length : pos + 12 + length]
        if len(body) != length or len(crc) != 4:
            raise PNGError("truncated PNG chunk")
        if struct.unpack(">I", crc)[0] != zlib.crc32(tag + body) & 0xFFFFFFFF:
            raise PNGError(f"corrupt PNG ({tag.decode('latin-1')} chunk CRC mismatch)")
        pos += 12 + length
        if tag == b"IHDR":
            if length != 13:
                raise PNGError("bad IHDR chunk")
            ihdr = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat.append(body)
        elif tag == b"IEND":
            break
    if ihdr is None:
        raise PNGError("PNG has no IHDR chunk")
    w, h, depth, ctype, _comp, _filt, interlace = ihdr
    if ctype not in _CHANNELS or depth not in (8, 16) or interlace != 0:
        raise PNGError(
            f"unsupported PNG (colour type {ctype}, depth {depth}, interlace {interlace})"
        )
    if w < 1 or h < 1:
        raise PNGError(f"zero-sized PNG ({w}x{h})")
    if w * h > max_pixels:
        raise PNGError(f"PNG of {w}x{h} pixels is over the limit of {max_pixels:,}")
    c = _CHANNELS[ctype]
    bpp = c * depth // 8
    stride = w * bpp
    expected = h * (stride + 1)
    d = zlib.decompressobj()
    try:
        raw = d.decompress(b"".join(idat), expected + 1)
    except zlib.error as exc:
        raise PNGError(f"corrupt PNG data ({exc})") from None
    if len(raw) != expected:
        raise PNGError(f"PNG data has {len(raw)} bytes, expected {expected}")
    rows, ok = _unfilter(np.frombuffer(raw, np.uint8), h, stride, bpp)
    if not ok:
        raise PNGError("corrupt PNG (bad filter type)")
    if depth == 16:
        return rows.view(">u2").astype(np.uint16).reshape(h, w, c)
    return rows.reshape(h, w, c)
