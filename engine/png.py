"""PNG bytes in and out, exact at 8 and 16 bits, through libpng (``imagecodecs``).

Pillow reduces 16-bit colour PNGs to 8 bits when reading, so every PNG whose bits must survive
(16-bit sources, project files, export bundles) goes through here. :func:`read_header` reads the
signature and the IHDR chunk from the first 33 bytes, so a caller can refuse a file by what it
declares before anything is inflated; :func:`decode_png` does so itself.

Why imagecodecs rather than our own codec or Pillow: ``benchmarks/png.py`` (README, "PNG").
"""

from __future__ import annotations

import logging
import struct
from dataclasses import dataclass

import numpy as np

# libpng's warnings (e.g. a damaged text chunk) go to the "imagecodecs" logger; without a handler
# Python would print them raw on stderr. The image still decodes; damage that matters raises.
logging.getLogger("imagecodecs").addHandler(logging.NullHandler())

SIGNATURE = b"\x89PNG\r\n\x1a\n"
HEADER_BYTES = 33  # signature, IHDR length and tag, 13 bytes of IHDR, its CRC
_CHANNELS = {0: 1, 4: 2, 2: 3, 6: 4}  # PNG colour type -> channels (palette excluded)
_COLOUR_TYPES = {c: t for t, c in _CHANNELS.items()}
ENCODE_LEVEL = 6
"""zlib level of :func:`encode_png` (the libpng default): see the README's PNG table."""

__all__ = [
    "HEADER_BYTES",
    "PNGError",
    "PNGHeader",
    "SIGNATURE",
    "check_header",
    "decode_png",
    "encode_png",
    "read_header",
]


class PNGError(ValueError):
    """The bytes are not a PNG this codec reads; the message says why."""


@dataclass(frozen=True, slots=True)
class PNGHeader:
    """What a PNG's IHDR chunk declares."""

    width: int
    height: int
    bit_depth: int
    colour_type: int
    interlace: int

    @property
    def channels(self) -> int:
        """Samples per pixel after decoding (a palette decodes to RGB or RGBA: 3 here)."""
        return _CHANNELS.get(self.colour_type, 3)

    @property
    def pixels(self) -> int:
        return self.width * self.height

    @property
    def decoded_bytes(self) -> int:
        """Bytes of the decoded uint8/uint16 array."""
        return self.pixels * self.channels * (2 if self.bit_depth == 16 else 1)

    @property
    def max_file_bytes(self) -> int:
        """An upper bound on the size of a PNG file with this header written by a sane encoder:
        the filtered rows stored without compression (deflate's worst case adds 5 bytes per
        16 KiB block), plus 1 MiB for chunk overheads and ancillary chunks."""
        raw = self.height * (self.width * self.channels * max(self.bit_depth, 8) // 8 + 1)
        return raw + raw // 3000 + 2**20


def read_header(data: bytes) -> PNGHeader:
    """The IHDR of PNG ``data`` (only its first :data:`HEADER_BYTES` bytes are needed)."""
    if not data.startswith(SIGNATURE):
        raise PNGError("not a PNG file (bad signature)")
    if len(data) < HEADER_BYTES or data[12:16] != b"IHDR":
        raise PNGError("truncated PNG (no IHDR chunk at the start)")
    w, h, depth, ctype, _comp, _filt, interlace = struct.unpack(">IIBBBBB", data[16:29])
    if w < 1 or h < 1:
        raise PNGError(f"zero-sized PNG ({w}x{h})")
    return PNGHeader(w, h, depth, ctype, interlace)


def check_header(head: PNGHeader, *, max_pixels: int) -> PNGHeader:
    """``head`` if :func:`decode_png` reads such a PNG within ``max_pixels``, else PNGError."""
    if head.colour_type not in _CHANNELS or head.bit_depth not in (8, 16):
        raise PNGError(
            f"unsupported PNG (colour type {head.colour_type}, bit depth {head.bit_depth})"
        )
    if head.pixels > max_pixels:
        raise PNGError(
            f"PNG of {head.width}x{head.height} pixels is over the limit of {max_pixels:,}"
        )
    return head


def encode_png(q: np.ndarray) -> bytes:
    """uint8 or uint16 (H, W) / (H, W, C<=4) -> PNG bytes (deterministic for the same input)."""
    import imagecodecs

    a = np.asarray(q)
    if a.dtype not in (np.uint8, np.uint16):
        raise TypeError(f"q must be uint8 or uint16, got {a.dtype}")
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in _COLOUR_TYPES) or 0 in a.shape:
        raise ValueError(f"q must be (H, W) or (H, W, 1-4), got shape {np.shape(q)}")
    return bytes(imagecodecs.png_encode(np.ascontiguousarray(a), level=ENCODE_LEVEL))


def decode_png(data: bytes, *, max_pixels: int = 100_000_000) -> np.ndarray:
    """PNG bytes -> uint8/uint16 (H, W, C): 8/16-bit gray, gray+alpha, RGB or RGBA, interlaced
    or not. The header is checked against ``max_pixels`` before anything is inflated."""
    import imagecodecs

    head = check_header(read_header(data), max_pixels=max_pixels)
    try:
        q = imagecodecs.png_decode(data)
    except imagecodecs.PngError as exc:
        raise PNGError(f"corrupt PNG ({exc})") from None
    q = q[:, :, None] if q.ndim == 2 else q
    if q.shape != (head.height, head.width, head.channels):  # pragma: no cover - libpng's job
        raise PNGError(f"PNG decoded to shape {q.shape}, its header declares another")
    return q
