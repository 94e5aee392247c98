"""Image files in and out: float32 (H, W, C) in [0, 1], bit depth remembered.

Every failure to read raises :class:`ImageError`, whose message names the file
and the reason (not an image, truncated, empty, zero-sized, too many pixels,
unsupported mode).
"""

from __future__ import annotations

import os
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError

DEFAULT_MAX_PIXELS = 100_000_000  # 10k x 10k; larger files are refused as decompression bombs
READ_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")


class ImageError(ValueError):
    """An image file could not be read or written; the message says which and why."""


@dataclass(frozen=True, slots=True)
class LoadedImage:
    """Pixels plus what the file said about them.

    ``pixels`` is float32 (H, W, C) in [0, 1]; C is 1 (gray), 2 (gray+alpha),
    3 (RGB) or 4 (RGBA). ``bit_depth`` is 8 or 16 (bits per channel in the file).
    """

    pixels: np.ndarray
    bit_depth: int
    path: str
    mode: str

    @property
    def has_alpha(self) -> bool:
        return self.pixels.shape[2] in (2, 4)

    @property
    def rgb(self) -> np.ndarray:
        """Colour channels as (H, W, 3), gray replicated, alpha dropped."""
        return to_rgb(self.pixels)


def to_rgb(pixels: np.ndarray) -> np.ndarray:
    """(H, W, C) -> (H, W, 3): gray replicated, alpha dropped."""
    c = pixels.shape[2]
    if c in (1, 2):
        return np.repeat(pixels[:, :, :1], 3, axis=2)
    return pixels[:, :, :3]


def load_image(path, *, max_pixels: int = DEFAULT_MAX_PIXELS) -> LoadedImage:
    """Read an image file into float32 (H, W, C) in [0, 1], honouring EXIF orientation."""
    name = os.fspath(path)
    p = Path(name)
    if not p.exists():
        raise ImageError(f"{name}: no such file")
    if p.is_dir():
        raise ImageError(f"{name}: is a folder, not an image")
    if p.stat().st_size == 0:
        raise ImageError(f"{name}: the file is empty")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            old_limit = Image.MAX_IMAGE_PIXELS
            Image.MAX_IMAGE_PIXELS = None
            try:
                with Image.open(p) as im:
                    w, h = im.size
                    if w == 0 or h == 0:
                        raise ImageError(f"{name}: the image is zero-sized ({w}x{h})")
                    if w * h > max_pixels:
                        raise ImageError(
                            f"{name}: {w}x{h} = {w * h:,} pixels is over the limit of "
                            f"{max_pixels:,} pixels (possible decompression bomb)"
                        )
                    im.load()
                    im = ImageOps.exif_transpose(im)
                    pixels, depth = _to_array(im, name)
                    mode = im.mode
            finally:
                Image.MAX_IMAGE_PIXELS = old_limit
    except ImageError:
        raise
    except UnidentifiedImageError:
        raise ImageError(f"{name}: not an image file (or an unsupported format)") from None
    except (OSError, SyntaxError, ValueError, EOFError) as exc:
        msg = str(exc)
        reason = "the file is truncated or corrupt" if "truncat" in msg.lower() or isinstance(exc, EOFError) else f"cannot be read ({msg})"
        raise ImageError(f"{name}: {reason}") from None
    if pixels.shape[0] == 0 or pixels.shape[1] == 0:
        raise ImageError(f"{name}: the image is zero-sized")
    return LoadedImage(pixels=pixels, bit_depth=depth, path=name, mode=mode)


def _to_array(im: Image.Image, name: str) -> tuple[np.ndarray, int]:
    mode = im.mode
    if mode in ("I;16", "I;16B", "I;16L", "I;16N"):
        a = np.asarray(im, dtype=np.uint16).astype(np.float32) / 65535.0
        return a[:, :, None], 16
    if mode == "I":
        a = np.asarray(im)
        depth = 16 if a.max(initial=0) > 255 else 8
        return (np.clip(a, 0, 65535).astype(np.float32) / 65535.0 if depth == 16 else a.astype(np.float32) / 255.0)[:, :, None], depth
    if mode == "F":
        a = np.asarray(im, dtype=np.float32)
        lo, hi = float(a.min()), float(a.max())
        a = (a - lo) / (hi - lo) if hi > lo else np.zeros_like(a)
        return a[:, :, None], 16
    if mode in ("1", "L"):
        return np.asarray(im.convert("L"), dtype=np.float32)[:, :, None] / 255.0, 8
    if mode == "LA":
        return np.asarray(im, dtype=np.float32) / 255.0, 8
    if mode in ("P", "PA"):
        im = im.convert("RGBA") if ("transparency" in im.info or mode == "PA") else im.convert("RGB")
        return np.asarray(im, dtype=np.float32) / 255.0, 8
    if mode in ("RGB", "RGBA"):
        return np.asarray(im, dtype=np.float32) / 255.0, 8
    if mode in ("CMYK", "YCbCr", "LAB", "HSV", "RGBX", "RGBa", "La"):
        return np.asarray(im.convert("RGB"), dtype=np.float32) / 255.0, 8
    raise ImageError(f"{name}: unsupported image mode {mode!r}")



def save_image(path, pixels, *, bit_depth: int = 8) -> Path:
    """Write float (H, W[, C]) pixels in [0, 1] to PNG or TIFF (8 or 16 bit), atomically."""
    p = Path(os.fspath(path))
    if bit_depth not in (8, 16):
        raise ValueError(f"bit_depth must be 8 or 16, got {bit_depth}")
    a = np.asarray(pixels, dtype=np.float32)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in (2, 3, 4)):
        raise ValueError(f"pixels must be (H, W) or (H, W, 1-4), got {a.shape}")
    suffix = p.suffix.lower()
    if suffix not in (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".webp"):
        raise ImageError(f"{p}: unsupported output format {suffix or '(none)'}")
    a = np.clip(a, 0.0, 1.0)
    p.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=suffix)
    os.close(fd)
    try:
        if bit_depth == 16:
            q = np.round(a * 65535.0).astype(np.uint16)
            if suffix in (".tif", ".tiff"):
                import tifffile

                tifffile.imwrite(tmp, q, photometric="minisblack" if q.ndim == 2 else "rgb")
            elif suffix == ".png":
                _write_png16(tmp, q)
            else:
                raise ImageError(f"{p}: 16-bit output needs .png or .tif, not {suffix}")
        else:
            q = np.round(a * 255.0).astype(np.uint8)
            Image.fromarray(q).save(tmp, format=Image.registered_extensions()[suffix])
        os.replace(tmp, p)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return p


def _write_png16(path: str, q: np.ndarray) -> None:
    """16-bit PNG via Pillow (gray: I;16; colour: raw 16-bit RGB(A) data)."""
    if q.ndim == 2:
        Image.fromarray(q, mode="I;16").save(path, format="PNG")
        return
    import zlib
    import struct

    h, w, c = q.shape
    color_type = {2: 4, 3: 2, 4: 6}[c]
    raw = b"".join(b"\x00" + q[y].astype(">u2").tobytes() for y in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, color_type, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 6)))
        f.write(chunk(b"IEND", b""))
