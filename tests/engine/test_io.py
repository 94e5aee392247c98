"""Image I/O: modes and bit depths kept, exact 16-bit round trips, EXIF orientation, bad input."""

import numpy as np
import pytest
import tifffile
from PIL import Image

from engine.io import ImageError, load_image, save_image
from engine.png import encode_png
from tests.engine.hostile import chunk, png_header

MODES = {1: "L", 2: "LA", 3: "RGB", 4: "RGBA"}


def random_uint(shape, depth, seed=0):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 2**depth, shape, dtype=np.uint16 if depth == 16 else np.uint8)


# ----------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("suffix", [".png", ".tif"])
@pytest.mark.parametrize("depth", [8, 16])
@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_round_trip_every_mode_and_depth_exactly(tmp_path, suffix, depth, channels):
    q = random_uint((7, 9, channels), depth, seed=channels)
    scale = 255.0 if depth == 8 else 65535.0
    path = save_image(tmp_path / f"img{suffix}", q.astype(np.float32) / scale, bit_depth=depth)
    loaded = load_image(path)
    assert loaded.bit_depth == depth
    assert loaded.mode == MODES[channels]
    assert loaded.pixels.dtype == np.float32 and loaded.pixels.shape == (7, 9, channels)
    np.testing.assert_array_equal(np.round(loaded.pixels * scale).astype(q.dtype), q)
    np.testing.assert_array_equal(loaded.pixels, q.astype(np.float32) / scale)
    assert loaded.has_alpha == (channels in (2, 4))
    assert loaded.rgb.shape == (7, 9, 3)


def test_16_bit_rgb_png_round_trips_exactly(tmp_path):
    q = random_uint((33, 17, 3), 16, seed=5)
    q[0, 0] = (0, 1, 65535)  # values Pillow's 8-bit reading would lose
    path = save_image(tmp_path / "deep.png", q.astype(np.float32) / 65535.0, bit_depth=16)
    head = path.read_bytes()[:29]
    assert head[24] == 16 and head[25] == 2  # a real 16-bit RGB PNG
    loaded = load_image(path)
    assert loaded.bit_depth == 16 and loaded.mode == "RGB"
    np.testing.assert_array_equal(np.round(loaded.pixels * 65535).astype(np.uint16), q)
    # saving the loaded pixels again gives the same file content
    again = save_image(tmp_path / "again.png", loaded.pixels, bit_depth=16)
    assert again.read_bytes() == path.read_bytes()


def test_palette_images_are_kept_distinct(tmp_path):
    idx = random_uint((6, 8), 8) % 4
    im = Image.fromarray(idx.astype(np.uint8), mode="P")
    palette = [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 0]
    im.putpalette(palette)
    im.save(tmp_path / "p.png")
    loaded = load_image(tmp_path / "p.png")
    assert loaded.mode == "P" and loaded.bit_depth == 8 and loaded.pixels.shape == (6, 8, 3)
    colours = np.array(palette, np.float32).reshape(4, 3) / 255
    np.testing.assert_array_equal(loaded.pixels, colours[idx])
    im.info["transparency"] = 0
    im.save(tmp_path / "pt.png", transparency=0)
    loaded = load_image(tmp_path / "pt.png")
    assert loaded.mode == "P" and loaded.pixels.shape == (6, 8, 4)
    np.testing.assert_array_equal(loaded.pixels[..., 3] == 0, idx == 0)


@pytest.mark.parametrize(
    ("suffix", "fmt", "kw"),
    [
        (".jpg", "JPEG", {"quality": 95, "subsampling": 0}),
        (".bmp", "BMP", {}),
        (".webp", "WEBP", {"lossless": True}),
    ],
)
def test_jpeg_bmp_webp_in(tmp_path, suffix, fmt, kw):
    q = np.zeros((16, 24, 3), np.uint8)
    q[:, :12] = (200, 30, 60)
    q[:, 12:] = (20, 180, 90)
    Image.fromarray(q).save(tmp_path / f"x{suffix}", format=fmt, **kw)
    loaded = load_image(tmp_path / f"x{suffix}")
    assert loaded.bit_depth == 8 and loaded.mode == "RGB" and loaded.pixels.shape == (16, 24, 3)
    tol = 6 if fmt == "JPEG" else 0
    assert np.abs(np.round(loaded.pixels * 255) - q).max() <= tol
    gray = Image.fromarray(q[..., 0])
    gray.save(tmp_path / f"g{suffix}", format=fmt, **kw)
    assert load_image(tmp_path / f"g{suffix}").pixels.shape[2] in (1, 3)  # WebP has no gray


def test_exif_rotated_jpeg_is_turned_upright(tmp_path):
    q = np.zeros((16, 32, 3), np.uint8)
    q[:8, :16] = (255, 0, 0)  # red top-left quadrant marks the orientation
    for orientation, expected in [(6, np.rot90(q, -1)), (8, np.rot90(q, 1)), (3, q[::-1, ::-1])]:
        exif = Image.Exif()
        exif[0x0112] = orientation
        path = tmp_path / f"o{orientation}.jpg"
        Image.fromarray(q).save(path, quality=95, subsampling=0, exif=exif)
        loaded = load_image(path)
        assert loaded.pixels.shape[:2] == expected.shape[:2]
        assert np.abs(np.round(loaded.pixels * 255) - expected).max() <= 40


@pytest.mark.parametrize("orientation", range(1, 9))
def test_exif_orientation_of_exact_16_bit_png_matches_pillow(tmp_path, orientation):
    q8 = random_uint((5, 7, 3), 8, seed=orientation)
    exif = Image.Exif()
    exif[0x0112] = orientation
    Image.fromarray(q8).save(tmp_path / "p8.png", exif=exif)
    raw = encode_png(q8.astype(np.uint16) * 257)
    exif_chunk = chunk(b"eXIf", exif.tobytes())
    cut = raw.index(b"IDAT") - 4  # put eXIf before the image data
    (tmp_path / "p16.png").write_bytes(raw[:cut] + exif_chunk + raw[cut:])
    a8 = load_image(tmp_path / "p8.png")
    a16 = load_image(tmp_path / "p16.png")
    assert a16.bit_depth == 16
    np.testing.assert_array_equal(np.round(a16.pixels * 65535 / 257), np.round(a8.pixels * 255))


# ----------------------------------------------------------------------------- bad input
def test_missing_folder_and_empty(tmp_path):
    with pytest.raises(ImageError, match=r"nope\.png: no such file"):
        load_image(tmp_path / "nope.png")
    with pytest.raises(ImageError, match=f"{tmp_path.name}: is a folder"):
        load_image(tmp_path)
    (tmp_path / "empty.png").write_bytes(b"")
    with pytest.raises(ImageError, match=r"empty\.png: the file is empty"):
        load_image(tmp_path / "empty.png")


def test_not_an_image(tmp_path):
    (tmp_path / "notes.png").write_text("just some text, no pixels here\n")
    with pytest.raises(ImageError, match=r"notes\.png: not an image file"):
        load_image(tmp_path / "notes.png")


@pytest.mark.parametrize("kind", ["png8", "png16", "jpeg", "tiff16", "header"])
def test_truncated(tmp_path, kind):
    q = random_uint((40, 50, 3), 16 if kind in ("png16", "tiff16") else 8)
    path = tmp_path / "cut.bin"
    if kind == "jpeg":
        Image.fromarray(q).save(path, format="JPEG")
    elif kind == "tiff16":
        tifffile.imwrite(path, q, photometric="rgb")
    else:
        path.write_bytes(encode_png(q))
    data = path.read_bytes()
    path.write_bytes(data[:20] if kind == "header" else data[: len(data) // 2])
    with pytest.raises(ImageError, match=r"cut\.bin: the file is truncated or corrupt"):
        load_image(path)


def test_zero_sized(tmp_path):
    (tmp_path / "zero.png").write_bytes(png_header(0, 5))
    with pytest.raises(ImageError, match=r"zero\.png: the image is zero-sized \(0x5\)"):
        load_image(tmp_path / "zero.png")


def test_over_the_pixel_limit(tmp_path):
    save_image(tmp_path / "big.png", np.zeros((30, 40, 3)))
    with pytest.raises(
        ImageError,
        match=r"big\.png: 40x30 = 1,200 pixels is over the limit of "
        r"1,000 pixels \(possible decompression bomb\)",
    ):
        load_image(tmp_path / "big.png", max_pixels=1000)
    assert load_image(tmp_path / "big.png", max_pixels=1200).pixels.shape == (30, 40, 3)
    # a bomb: 50000 x 50000 declared, a few bytes of data; refused before decoding
    (tmp_path / "bomb.png").write_bytes(png_header(50000, 50000, idat=b"\x00" * 100))
    with pytest.raises(ImageError, match=r"bomb\.png: 50000x50000 .* decompression bomb"):
        load_image(tmp_path / "bomb.png")
    tifffile.imwrite(tmp_path / "big16.tif", np.zeros((30, 40, 3), np.uint16), photometric="rgb")
    with pytest.raises(ImageError, match=r"big16\.tif: 40x30 .* over the limit"):
        load_image(tmp_path / "big16.tif", max_pixels=1000)


@pytest.mark.parametrize("kind", ["5 samples", "float rgb hdr", "negative int"])
def test_unsupported_mode(tmp_path, kind):
    path = tmp_path / "odd.tif"
    a = random_uint((4, 5, 5), 8)
    if kind == "5 samples":
        tifffile.imwrite(path, a, photometric="minisblack", planarconfig="contig")
    elif kind == "float rgb hdr":  # float in [0, 1] is read (test_robust_inputs); HDR is not
        tifffile.imwrite(path, a[..., :3].astype(np.float32) / 64, photometric="rgb")
    else:
        tifffile.imwrite(path, a[..., 0].astype(np.int32) - 100)
    with pytest.raises(ImageError, match=r"odd\.tif: unsupported image mode"):
        load_image(path)


def test_check_output_refuses_before_any_work(tmp_path):
    from engine.io import check_output

    assert check_output(tmp_path / "a.TIF", bit_depth=16, channels=4) == tmp_path / "a.TIF"
    for name, kw, reason in (
        ("x.gif", {}, r"unsupported output format \.gif"),
        ("x", {}, r"unsupported output format \(no suffix\)"),
        ("x.webp", {"bit_depth": 16}, r"16-bit output needs \.png or \.tif, not \.webp"),
        ("x.bmp", {"channels": 2}, r"\.bmp cannot store an alpha channel"),
    ):
        with pytest.raises(ImageError, match=f"{name}: {reason}"):
            check_output(tmp_path / name, **kw)
    with pytest.raises(ValueError, match="bit_depth must be 8 or 16"):
        check_output(tmp_path / "x.png", bit_depth=12)
    assert list(tmp_path.iterdir()) == []


def test_save_errors(tmp_path):
    px = np.zeros((4, 4, 3))
    with pytest.raises(ImageError, match=r"x\.gif: unsupported output format \.gif"):
        save_image(tmp_path / "x.gif", px)
    with pytest.raises(ImageError, match=r"x\.jpg: 16-bit output needs \.png or \.tif"):
        save_image(tmp_path / "x.jpg", px, bit_depth=16)
    with pytest.raises(ImageError, match=r"x\.jpg: \.jpg cannot store an alpha channel"):
        save_image(tmp_path / "x.jpg", np.zeros((4, 4, 4)))
    with pytest.raises(ValueError, match="bit_depth must be 8 or 16, got 12"):
        save_image(tmp_path / "x.png", px, bit_depth=12)
    with pytest.raises(ValueError, match="pixels must be shaped"):
        save_image(tmp_path / "x.png", np.zeros((4, 4, 5)))
    (tmp_path / "file").write_text("")
    with pytest.raises(ImageError, match=r"x\.png: cannot write \(.*file is a file, not a folder"):
        save_image(tmp_path / "file" / "sub" / "x.png", px)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]  # nothing left behind


def test_save_8_bit_formats_and_clipping(tmp_path):
    px = np.linspace(-0.5, 1.5, 4 * 6 * 3).reshape(4, 6, 3)
    for suffix in (".png", ".tif", ".bmp", ".webp", ".jpg"):
        loaded = load_image(save_image(tmp_path / f"c{suffix}", px))
        assert loaded.pixels.shape == (4, 6, 3) and loaded.bit_depth == 8
        assert loaded.pixels.min() >= 0 and loaded.pixels.max() <= 1
    gray = load_image(save_image(tmp_path / "g.png", np.full((3, 3), 0.5)))
    assert gray.mode == "L" and gray.pixels.shape == (3, 3, 1)
    np.testing.assert_array_equal(gray.pixels, np.float32(128) / 255)
