"""Image files in and out: float32 (H, W, C) in [0, 1], bit depth remembered.

Reading: PNG, JPEG, TIFF, BMP, WebP, GIF, 8 or 16 bits per channel; gray, gray + alpha, RGB,
RGBA and palette images stay distinct (C = 1, 2, 3, 4; palette images become RGB or RGBA with
``mode == "P"``); CMYK becomes RGB; the EXIF orientation is applied. 16-bit PNG and 16-bit or
floating-point TIFF are decoded exactly (Pillow would reduce 16-bit colour to 8 bits): PNG by
libpng (:mod:`engine.png`), TIFF by tifffile. Animated and multi-page files give their first
frame, with an :class:`ImageWarning`.

Writing: PNG and TIFF at 8 or 16 bits, JPEG / BMP / WebP at 8 bits; atomic (a temporary file
renamed over the target).

Every failure raises :class:`ImageError`, whose message names the file and the reason: no such
file, a folder / FIFO / device / socket / link loop, empty, too large, not an image, truncated
or corrupt, zero-sized, over the pixel limit (decompression bomb), over the memory available,
unsupported mode.
"""

from __future__ import annotations

import dataclasses
import io
import logging
import numbers
import os
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError

from engine._fs import (
    InputError,
    OutputError,
    atomic_path,
    check_writable,
    open_input,
    write_problem,
)

# tifffile reports odd tags on its logger; without a handler Python prints them raw on stderr.
logging.getLogger("tifffile").addHandler(logging.NullHandler())

DEFAULT_MAX_PIXELS = 100_000_000  # 10k x 10k; larger files are refused as decompression bombs
MAX_FILE_BYTES = 2**30
"""Largest image file read (an uncompressed 16-bit RGBA TIFF at the pixel limit is 800 MB):
larger files are refused from their size alone, before a byte is read."""
READ_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")
WRITE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".webp")
MODES = ("1", "L", "LA", "P", "PA", "RGB", "RGBA", "CMYK", "YCbCr", "LAB", "HSV")

_PNG = b"\x89PNG\r\n\x1a\n"
_TIFF = (b"II*\x00", b"MM\x00*")
_MAGIC = (_PNG, b"\xff\xd8\xff", b"BM", b"RIFF", b"GIF8", *_TIFF)
_FLIPS = {  # EXIF orientation -> numpy transform (what ImageOps.exif_transpose does)
    2: lambda a: a[:, ::-1],
    3: lambda a: a[::-1, ::-1],
    4: lambda a: a[::-1],
    5: lambda a: a.transpose(1, 0, 2),
    6: lambda a: np.rot90(a, -1),
    7: lambda a: a.transpose(1, 0, 2)[::-1, ::-1],
    8: lambda a: np.rot90(a, 1),
}

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "ImageError",
    "ImageWarning",
    "LoadedImage",
    "MAX_FILE_BYTES",
    "READ_SUFFIXES",
    "WRITE_SUFFIXES",
    "check_output",
    "load_image",
    "save_image",
    "to_rgb",
]


class ImageError(ValueError):
    """An image file could not be read or written; the message says which file and why."""


class ImageWarning(UserWarning):
    """An image was read with a caveat the user should hear (e.g. only its first frame)."""


@dataclass(frozen=True, slots=True)
class LoadedImage:
    """Pixels plus what the file said about them.

    Attributes
    ----------
    pixels : (H, W, C) float32 in [0, 1]
        C is 1 (gray), 2 (gray + alpha), 3 (RGB) or 4 (RGBA); orientation already applied.
    bit_depth : int
        8 or 16, bits per channel in the file.
    path : str
        The file that was read.
    mode : str
        The file's colour model (Pillow names, bit depth apart): ``"L"`` gray, ``"LA"``,
        ``"RGB"``, ``"RGBA"``, ``"P"`` / ``"PA"`` palette (pixels RGB / RGBA), ``"1"`` bilevel
        (pixels gray), ``"CMYK"``, ``"YCbCr"``, ``"LAB"``, ``"HSV"`` (pixels RGB).
    """

    pixels: np.ndarray
    bit_depth: int
    path: str
    mode: str
    notes: tuple[str, ...] = ()
    """Caveats to tell the user, e.g. "animated GIF with 3 frames; using the first frame"."""

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


# ----------------------------------------------------------------------------- reading
def load_image(path, *, max_pixels: int = DEFAULT_MAX_PIXELS) -> LoadedImage:
    """Read an image file into float32 (H, W, C) in [0, 1] (see the module docstring).

    Before a byte of pixel data is read: the path must be a regular file (not a folder, FIFO,
    device or socket) of at most :data:`MAX_FILE_BYTES`, start with the signature of a format
    we read, declare at most ``max_pixels`` pixels in its header and fit the memory available
    (:mod:`engine.budget`). An animated or multi-page file gives its first frame with an
    :class:`ImageWarning` saying so; the libraries' own warnings are not passed on.

    Parameters
    ----------
    path : str or PathLike
    max_pixels : int
        Files declaring more pixels (width × height) are refused before any decoding.
        Pillow's own hard limit (2 × ``PIL.Image.MAX_IMAGE_PIXELS``, about 179 million) also
        applies to the formats it decodes; the global is never changed (thread safety).

    Raises
    ------
    ImageError
        The message names the file and the reason.
    """
    if isinstance(max_pixels, bool) or not isinstance(max_pixels, numbers.Integral):
        raise TypeError(f"max_pixels must be an integer, got {max_pixels!r}")
    if max_pixels < 1:
        raise ValueError(f"max_pixels must be >= 1, got {max_pixels}")
    name = os.fspath(path)

    def fail(reason: str) -> ImageError:
        return ImageError(f"{name}: {reason}")

    def check_size(w: int, h: int) -> None:
        if w <= 0 or h <= 0:
            raise fail(f"the image is zero-sized ({w}x{h})")
        if w * h > max_pixels:
            raise fail(
                f"{w}x{h} = {w * h:,} pixels is over the limit of {max_pixels:,} pixels "
                "(possible decompression bomb)"
            )

    try:
        f = open_input(name, max_bytes=MAX_FILE_BYTES, what="an image")
    except InputError as exc:
        raise fail(str(exc)) from None
    with f, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Pillow's / tifffile's: our own messages say it
        try:
            head = f.read(64)
            if not head.startswith(_MAGIC):
                raise fail(
                    "not an image file (or an unsupported format; PNG, JPEG, TIFF, BMP, WebP "
                    "and GIF are read)"
                )
            w, h, frames, kind = _probe(f, head, fail, check_size)
            f.seek(0)
            data = f.read()
        except OSError as exc:
            raise fail(f"cannot be read ({exc.strerror or exc})") from None
        loaded = _decode(data, name, fail, check_size, max_pixels)
    if frames > 1:
        note = f"{kind} with {frames} frames; using the first frame"
        loaded = dataclasses.replace(loaded, notes=(note,))
        warnings.warn(ImageWarning(f"{name}: {note}"), stacklevel=2)
    return loaded


def _probe(f, head: bytes, fail, check_size) -> tuple[int, int, int, str]:
    """(width, height, frames, kind) from the file's headers, the size and the memory budget
    checked; reads only headers (PNG: the first 33 bytes)."""
    from engine.budget import MemoryBudgetError, check_memory

    w = h = 0
    frames, kind = 1, "image"
    if head.startswith(_PNG) and len(head) >= 33 and head[12:16] == b"IHDR":
        w, h = struct.unpack(">II", head[16:24])
        check_size(w, h)  # before Pillow or zlib inflate anything
    f.seek(0)
    try:
        with Image.open(f) as im:
            w, h = im.size
            check_size(w, h)
            frames = int(getattr(im, "n_frames", 1) or 1)
            kind = {"GIF": "animated GIF", "PNG": "animated PNG", "TIFF": "multi-page TIFF"}.get(
                im.format or "", "image"
            )
    except ImageError:
        raise
    except Image.DecompressionBombError as exc:  # over Pillow's own (larger) hard limit
        raise fail(f"over the pixel limit (possible decompression bomb: {exc})") from None
    except Exception:  # noqa: BLE001 - Pillow cannot read it: _decode says why
        if head.startswith(_TIFF):
            w, h, frames = _tiff_probe(f, fail, check_size)
            kind = "multi-page TIFF"
        elif not w:  # else the IHDR gave the size of a PNG Pillow cannot open
            return 0, 0, 1, "image"
    try:
        check_memory(
            w * h * 4 * 14 + f.seek(0, os.SEEK_END),  # float32 RGBA + decoded + converted copies
            what=f"reading this {w}x{h} image",
            way_out="downscale it, or free memory",
        )
    except MemoryBudgetError as exc:
        raise fail(str(exc)) from None
    return w, h, frames, kind


def _tiff_probe(f, fail, check_size) -> tuple[int, int, int]:
    import tifffile

    f.seek(0)
    try:
        with tifffile.TiffFile(f, name="image.tif") as tif:
            page = tif.pages[0]
            check_size(page.imagewidth, page.imagelength)
            return page.imagewidth, page.imagelength, len(tif.pages)
    except ImageError:
        raise
    except Exception as exc:  # noqa: BLE001 - tifffile raises many types on damage
        raise fail(f"the file is truncated or corrupt ({exc})") from None


def _decode(data: bytes, name: str, fail, check_size, max_pixels: int) -> LoadedImage:
    if data.startswith(_TIFF):
        tiff = _tiff_exact(data, fail, check_size)
        if tiff is not None:
            return LoadedImage(_oriented(tiff[0], tiff[1]), 16, name, tiff[2])
    exact = _png_exact(data, max_pixels, fail)
    if exact is not None:
        return LoadedImage(_oriented(exact[0], _png_orientation(data)), exact[1], name, exact[2])
    try:
        with Image.open(io.BytesIO(data)) as im:
            check_size(*im.size)
            im.load()
            im = ImageOps.exif_transpose(im)
            pixels, depth, mode = _to_array(im, fail)
    except ImageError:
        raise
    except Image.DecompressionBombError as exc:  # over Pillow's own (larger) hard limit
        raise fail(f"over the pixel limit (possible decompression bomb: {exc})") from None
    except UnidentifiedImageError:
        if data.startswith(_TIFF):
            raise fail(_tiff_problem(data)) from None
        raise fail("the file is truncated or corrupt (its header cannot be read)") from None
    except MemoryError:
        raise fail("there is not enough memory to decode it") from None
    except (OSError, SyntaxError, ValueError, EOFError, struct.error) as exc:
        raise fail(f"the file is truncated or corrupt ({exc})") from None
    return LoadedImage(pixels, depth, name, mode)


def _tiff_problem(data: bytes) -> str:
    """Why Pillow could not open a TIFF: an unsupported sample layout, or damage."""
    import tifffile

    try:
        with tifffile.TiffFile(io.BytesIO(data)) as tif:
            page = tif.pages[0]
            return (
                f"unsupported image mode ({page.samplesperpixel} samples of "
                f"{page.bitspersample}-bit {page.dtype}, photometric {page.photometric.name})"
            )
    except Exception:
        return "the file is truncated or corrupt (its header cannot be read)"


def _oriented(pixels: np.ndarray, orientation: int) -> np.ndarray:
    """Apply an EXIF orientation (1-8) to (H, W, C) pixels, as ImageOps.exif_transpose."""
    flip = _FLIPS.get(orientation)
    return pixels if flip is None else np.ascontiguousarray(flip(pixels))


def _orientation(im: Image.Image) -> int:
    try:
        return int(im.getexif().get(0x0112, 1))
    except Exception:  # a broken EXIF block is ignored, as ImageOps.exif_transpose does
        return 1


def _png_exact(data: bytes, max_pixels: int, fail):
    """(pixels, bit depth, mode) of an 8/16-bit gray / RGB(A) PNG decoded by libpng (exact at
    16 bits, where Pillow would drop colour to 8; tolerant of damaged ancillary chunks, which
    Pillow refuses); None for palette and 1/2/4-bit PNGs, which Pillow reads."""
    if not data.startswith(_PNG):
        return None
    from engine.png import PNGError, decode_png, read_header

    try:
        head = read_header(data)
        if head.colour_type not in (0, 2, 4, 6) or head.bit_depth not in (8, 16):
            return None
        q = decode_png(data, max_pixels=max_pixels)
    except PNGError as exc:
        raise fail(f"the file is truncated or corrupt ({exc})") from None
    except MemoryError:
        raise fail("there is not enough memory to decode it") from None
    pixels, mode = _from_uint16(q) if q.dtype == np.uint16 else _from_uint8(q)
    return pixels, head.bit_depth, mode


def _png_orientation(data: bytes) -> int:
    """The EXIF orientation of a PNG (its eXIf chunk), 1 if none or unreadable."""
    try:
        with Image.open(io.BytesIO(data)) as im:
            return _orientation(im)
    except Exception:  # noqa: BLE001 - Pillow is stricter than libpng: no orientation then
        return 1


def _from_uint8(q: np.ndarray) -> tuple[np.ndarray, str]:
    from engine.bitdepth import to_float

    return to_float(q), ("L", "LA", "RGB", "RGBA")[q.shape[2] - 1]


def _from_uint16(q: np.ndarray) -> tuple[np.ndarray, str]:
    from engine.bitdepth import to_float

    return to_float(q), ("L", "LA", "RGB", "RGBA")[q.shape[2] - 1]


def _tiff_exact(data: bytes, fail, check_size):
    """(float32 (H, W, C), EXIF orientation, mode) of a 16-bit or floating-point TIFF (gray,
    RGB(A), white-is-zero gray, CMYK), read by tifffile at full precision; None for the 8-bit
    ones Pillow reads."""
    import tifffile

    try:
        with tifffile.TiffFile(io.BytesIO(data)) as tif:
            page = tif.pages[0]
            if page.dtype not in (np.uint16, np.float32, np.float64, np.float16):
                return None
            check_size(page.imagewidth, page.imagelength)
            tag = page.tags.get(274)
            orientation = int(tag.value) if tag is not None else 1
            photometric = page.photometric.name
            q = page.asarray()
            if page.planarconfig == 2 and q.ndim == 3:  # separate planes -> samples last
                q = np.moveaxis(q, 0, 2)
    except ImageError:
        raise
    except MemoryError:
        raise fail("there is not enough memory to decode it") from None
    except Exception as exc:  # noqa: BLE001 - tifffile raises many types on damaged files
        raise fail(f"the file is truncated or corrupt ({exc})") from None
    q = q[:, :, None] if q.ndim == 2 else q
    kind = f"{q.dtype} samples, photometric {photometric}"
    if q.ndim != 3 or q.shape[2] > 5:
        raise fail(f"unsupported image mode ({kind}, shape {q.shape})")
    if q.dtype == np.uint16:
        a = q.astype(np.float32) / 65535.0
    else:
        a = q.astype(np.float32)
        if not np.all(np.isfinite(a)) or a.min(initial=0) < 0 or a.max(initial=0) > 1:
            raise fail(
                "unsupported image mode (floating-point values outside [0, 1], e.g. HDR: "
                "tone-map it to a 16-bit TIFF or PNG first)"
            )
    c = a.shape[2]
    if photometric == "SEPARATED" and c in (4, 5):  # CMYK (+ alpha)
        k = 1.0 - a[:, :, 3:4]
        rgb = (1.0 - a[:, :, :3]) * k
        return np.concatenate([rgb, a[:, :, 4:]], axis=2), orientation, "CMYK"
    if photometric == "MINISWHITE" and c in (1, 2):
        a[:, :, 0] = 1.0 - a[:, :, 0]
    elif photometric not in ("MINISBLACK", "RGB") or c > 4 or (photometric == "RGB" and c < 3):
        raise fail(f"unsupported image mode ({c} samples of {kind})")
    return a, orientation, ("L", "LA", "RGB", "RGBA")[c - 1]


def _to_array(im: Image.Image, fail) -> tuple[np.ndarray, int, str]:
    """Pillow image -> (float32 (H, W, C), bit depth, colour model)."""
    mode = im.mode
    if mode in ("I;16", "I;16B", "I;16L", "I;16N", "I"):
        a = np.asarray(im)
        if a.min(initial=0) < 0 or a.max(initial=0) > 65535:
            raise fail(f"unsupported image mode {mode!r} (values outside 0..65535)")
        return a.astype(np.float32)[:, :, None] / 65535.0, 16, "L"
    if mode == "F":
        a = np.asarray(im, dtype=np.float32)
        if not np.all(np.isfinite(a)) or a.min(initial=0) < 0 or a.max(initial=0) > 1:
            raise fail("unsupported image mode 'F' (32-bit float outside [0, 1])")
        return a[:, :, None].copy(), 16, "L"
    if mode in ("1", "L"):
        return np.asarray(im.convert("L"), dtype=np.float32)[:, :, None] / 255.0, 8, mode
    if mode in ("LA", "La"):
        return np.asarray(im.convert("LA"), dtype=np.float32) / 255.0, 8, "LA"
    if mode in ("P", "PA"):
        alpha = mode == "PA" or "transparency" in im.info
        rgb = im.convert("RGBA" if alpha else "RGB")
        return np.asarray(rgb, dtype=np.float32) / 255.0, 8, mode
    if mode in ("RGB", "RGBA"):
        return np.asarray(im, dtype=np.float32) / 255.0, 8, mode
    if mode in ("RGBa", "RGBX"):
        out = "RGBA" if mode == "RGBa" else "RGB"
        return np.asarray(im.convert(out), dtype=np.float32) / 255.0, 8, out
    if mode in ("CMYK", "YCbCr", "LAB", "HSV"):
        return np.asarray(im.convert("RGB"), dtype=np.float32) / 255.0, 8, mode
    raise fail(f"unsupported image mode {mode!r}")


# ----------------------------------------------------------------------------- writing
def check_output(path, *, bit_depth: int = 8, channels: int = 3) -> Path:
    """Refuse, before any work, an output that :func:`save_image` could not write in that
    format: an unknown suffix, 16 bits in anything but PNG / TIFF, alpha (``channels`` 2 or
    4) in JPEG / BMP, a folder in the way, a folder that cannot be written (read-only,
    permissions, a file on its path). Raises :class:`ImageError` naming the file; writes
    nothing."""
    p = Path(os.fspath(path))
    if isinstance(bit_depth, bool) or bit_depth not in (8, 16):
        raise ValueError(f"bit_depth must be 8 or 16, got {bit_depth!r}")
    suffix = p.suffix.lower()
    if suffix not in WRITE_SUFFIXES:
        raise ImageError(
            f"{p}: unsupported output format {suffix or '(no suffix)'} "
            f"(use one of {', '.join(WRITE_SUFFIXES)})"
        )
    if bit_depth == 16 and suffix not in (".png", ".tif", ".tiff"):
        raise ImageError(f"{p}: 16-bit output needs .png or .tif, not {suffix}")
    if channels in (2, 4) and suffix in (".jpg", ".jpeg", ".bmp"):
        raise ImageError(f"{p}: {suffix} cannot store an alpha channel; use .png or .tif")
    if p.is_dir():
        raise ImageError(f"{p}: is a folder; give a file name for the output")
    try:
        check_writable(p.parent)
    except OutputError as exc:
        raise ImageError(f"{p}: cannot write ({exc.reason})") from None
    return p


def save_image(path, pixels, *, bit_depth: int = 8) -> Path:
    """Write float (H, W[, C]) pixels in [0, 1] (or uint8/uint16) to an image file, atomically.

    PNG and TIFF take 8 or 16 bits per channel; JPEG, BMP and WebP 8 bits (JPEG and BMP no
    alpha). C is 1 (gray), 2 (gray + alpha), 3 (RGB) or 4 (RGBA). Values are rounded (no
    dither; see :func:`engine.bitdepth.quantize`). Returns the path written.
    """
    from engine.bitdepth import quantize

    p = Path(os.fspath(path))
    a = np.asarray(pixels)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in (2, 3, 4)) or 0 in a.shape:
        raise ValueError(f"pixels must be shaped (H, W) or (H, W, 1-4), got {np.shape(pixels)}")
    channels = 1 if a.ndim == 2 else a.shape[2]
    suffix = check_output(p, bit_depth=bit_depth, channels=channels).suffix.lower()
    q = quantize(a, bit_depth, dither=False)
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(p, suffix=suffix) as tmp:
            if suffix in (".tif", ".tiff"):
                import tifffile

                tifffile.imwrite(
                    tmp,
                    q,
                    photometric="minisblack" if channels < 3 else "rgb",
                    extrasamples=("unassalpha",) if channels in (2, 4) else None,
                    compression="zlib",
                )
            elif suffix == ".png":
                from engine.png import encode_png

                tmp.write_bytes(encode_png(q))
            else:
                Image.fromarray(q).save(tmp, format=Image.registered_extensions()[suffix])
    except OSError as exc:
        raise ImageError(f"{p}: cannot write ({write_problem(p.parent, exc)})") from None
    return p
