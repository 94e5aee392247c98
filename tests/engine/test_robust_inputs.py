"""Hostile and odd image inputs (issue 12: D4, D12, D14, D15, CMYK / float TIFF, animated and
multi-page files): each is refused with a message naming the file and the reason, before it is
read whole, with memory bounded — or read correctly with the caveat said once."""

from __future__ import annotations

import io
import os
import socket
import stat
import warnings

import numpy as np
import pytest
import tifffile
from PIL import Image

from engine.io import MAX_FILE_BYTES, ImageError, ImageWarning, load_image
from engine.png import encode_png
from tests.engine.hostile import cli, png_header, refused_by

MiB = 2**20


def refused(path, *reasons, peak_mib: float = 8):
    """load_image(path) raises ImageError naming the file and every reason, allocating at most
    ``peak_mib`` MiB on the way."""
    return refused_by(load_image, ImageError, path, reasons, peak_mib)


# ---------------------------------------------------------------- not regular files (D4, D12)


def test_fifo_is_refused_without_waiting_for_a_writer(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    refused(fifo, "is a named pipe (FIFO), not a regular file")


def test_fifo_as_cli_input_exits_at_once(tmp_path):
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    res = cli(
        "synth", fifo, "--size", "64x64", "--block", "16", "-o", tmp_path / "o.png", timeout=60
    )
    assert res.returncode == 1
    assert res.stderr.strip() == (
        f"quilt-studio synth: error: {fifo}: is a named pipe (FIFO), not a regular file"
    )
    assert not (tmp_path / "o.png").exists()


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom", "/dev/null"])
def test_devices_are_refused_unread(device):
    if not os.path.exists(device):
        pytest.skip(f"no {device} here")
    refused(device, "is a device, not a regular file")


def test_folder_socket_and_links(tmp_path):
    refused(tmp_path, "is a folder, not an image")
    sock = tmp_path / "s.png"
    server = socket.socket(socket.AF_UNIX)
    server.bind(str(sock))
    try:
        refused(sock, "is a socket, not a regular file")
    finally:
        server.close()
    loop = tmp_path / "loop.png"
    loop.symlink_to(tmp_path / "loop2.png")
    (tmp_path / "loop2.png").symlink_to(loop)
    refused(loop, "is a symbolic link loop")  # D15: not "no such file"
    dangling = tmp_path / "dangling.png"
    dangling.symlink_to(tmp_path / "gone.png")
    refused(dangling, "is a broken symbolic link (to ")
    refused(tmp_path / "missing.png", "no such file")
    (tmp_path / "afile").write_text("x")
    refused(tmp_path / "afile" / "x.png", "a part of the path is a file, not a folder")


def test_unreadable_file(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root reads every file")
    p = tmp_path / "locked.png"
    p.write_bytes(encode_png(np.zeros((4, 4), np.uint8)))
    p.chmod(0)
    refused(p, "permission denied")


def test_three_gigabyte_file_is_refused_from_its_size(tmp_path):
    """A sparse 3 GB file that starts like a PNG: refused by its size, not read."""
    big = tmp_path / "huge.png"
    with open(big, "wb") as f:
        f.write(png_header(64, 64))
        f.truncate(3 * 2**30)
    msg = refused(big, f"over the limit of {MAX_FILE_BYTES:,}", peak_mib=1)
    assert "3,221,225,472 bytes" in msg


def test_signature_is_checked_before_the_rest_is_read(tmp_path):
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"\0" * (64 * MiB))  # 64 MB that is no image: only its start is read
    refused(junk, "not an image file", peak_mib=2)


def test_declared_size_bomb_is_refused_from_the_header(tmp_path):
    for name, data in {
        "wide.png": png_header(100_000, 100_000),
        "wide16.png": png_header(20_000, 20_000, depth=16, ctype=6),
    }.items():
        (tmp_path / name).write_bytes(data)
        refused(tmp_path / name, "is over the limit of 100,000,000 pixels", peak_mib=2)


def test_image_too_large_for_the_memory_available(tmp_path, monkeypatch):
    """Within the pixel limit but not within memory (here a 64 MiB budget): refused before
    decoding, naming the budget and the way out."""
    monkeypatch.setenv("QUILT_MEMORY_LIMIT", "64M")
    (tmp_path / "big.png").write_bytes(png_header(4000, 4000, depth=16, ctype=6))
    refused(tmp_path / "big.png", "needs about", "more than the 64.0 MiB available", "downscale")


# ---------------------------------------------------------------- odd but valid formats


def test_cmyk_tiff_8_and_16_bit_become_rgb(tmp_path):
    cmyk = np.zeros((6, 5, 4), np.uint8)
    cmyk[:, :, 0] = 255  # full cyan
    cmyk[3:, :, 3] = 255  # black lower half
    Image.fromarray(cmyk, "CMYK").save(tmp_path / "c8.tif")
    a = load_image(tmp_path / "c8.tif")
    assert a.mode == "CMYK" and a.bit_depth == 8 and a.pixels.shape == (6, 5, 3)
    np.testing.assert_allclose(a.pixels[0, 0], [0, 1, 1], atol=1 / 255)
    np.testing.assert_allclose(a.pixels[5, 0], [0, 0, 0], atol=1 / 255)
    c16 = cmyk.astype(np.uint16) * 257
    c16[:, :, 1] = 32768  # half magenta
    tifffile.imwrite(tmp_path / "c16.tif", c16, photometric="separated")
    b = load_image(tmp_path / "c16.tif")
    assert b.mode == "CMYK" and b.bit_depth == 16 and b.pixels.shape == (6, 5, 3)
    np.testing.assert_allclose(b.pixels[0, 0], [0, 1 - 32768 / 65535, 1], atol=1e-6)
    np.testing.assert_allclose(b.pixels[5, 0], [0, 0, 0], atol=1e-6)


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.float16])
@pytest.mark.parametrize("channels", [1, 3, 4])
def test_float_tiff_is_read_at_full_precision(tmp_path, dtype, channels):
    g = np.random.default_rng(channels)
    a = g.random((7, 6, channels)).astype(dtype)
    photometric = "rgb" if channels >= 3 else "minisblack"
    extras = ("unassalpha",) if channels == 4 else None
    tifffile.imwrite(tmp_path / "f.tif", a, photometric=photometric, extrasamples=extras)
    img = load_image(tmp_path / "f.tif")
    assert img.bit_depth == 16 and img.pixels.dtype == np.float32
    assert img.mode == {1: "L", 3: "RGB", 4: "RGBA"}[channels]
    np.testing.assert_array_equal(img.pixels, a.astype(np.float32))


def test_float_tiff_outside_zero_one_is_refused_with_the_way_out(tmp_path):
    tifffile.imwrite(tmp_path / "hdr.tif", np.full((4, 4, 3), 7.5, np.float32), photometric="rgb")
    refused(tmp_path / "hdr.tif", "values outside [0, 1]", "tone-map it")
    nan = np.zeros((4, 4), np.float32)
    nan[1, 1] = np.nan
    tifffile.imwrite(tmp_path / "nan.tif", nan)
    refused(tmp_path / "nan.tif", "values outside [0, 1]")


def frames(n: int, size=(8, 10)):
    g = np.random.default_rng(0)
    out = []
    for i in range(n):
        a = g.integers(0, 30, size + (3,)).astype(np.uint8) + np.uint8(40 * (i + 1))
        a[0, 0] = 40 * (i + 1)
        out.append(Image.fromarray(a))
    return out


@pytest.mark.parametrize(
    "kind, save",
    [
        ("animated GIF", lambda f, p: f[0].save(p, "GIF", save_all=True, append_images=f[1:])),
        ("animated PNG", lambda f, p: f[0].save(p, "PNG", save_all=True, append_images=f[1:])),
        ("multi-page TIFF", lambda f, p: f[0].save(p, "TIFF", save_all=True, append_images=f[1:])),
    ],
)
def test_animated_and_multi_page_files_say_the_first_frame_is_used(tmp_path, kind, save):
    path = tmp_path / f"anim.{ {'animated GIF': 'gif', 'animated PNG': 'png'}.get(kind, 'tif') }"
    save(frames(3), path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        img = load_image(path)
    assert [str(w.message) for w in caught] == [
        f"{path}: {kind} with 3 frames; using the first frame"
    ]
    assert all(issubclass(w.category, ImageWarning) for w in caught)
    assert abs(float(img.pixels[0, 0, 0]) - 40 / 255) < 2 / 255  # the first frame


def test_multi_page_16_bit_tiff(tmp_path):
    with tifffile.TiffWriter(tmp_path / "pages.tif") as tif:
        for i in range(2):
            tif.write(np.full((5, 4), 1000 * (i + 1), np.uint16))
    with pytest.warns(ImageWarning, match="multi-page TIFF with 2 frames; using the first frame"):
        img = load_image(tmp_path / "pages.tif")
    assert img.bit_depth == 16 and float(img.pixels[0, 0, 0]) == pytest.approx(1000 / 65535)


def test_cli_says_first_frame_once_on_one_line(tmp_path):
    path = tmp_path / "anim.gif"
    f = frames(3, (64, 64))
    f[0].save(path, "GIF", save_all=True, append_images=f[1:])
    res = cli("synth", path, "--size", "48x48", "--block", "16", "-o", tmp_path / "o.png")
    assert res.returncode == 0, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if "warning" in ln]
    assert lines == [
        f"quilt-studio synth: warning: {path}: animated GIF with 3 frames; using the first frame"
    ]


# ---------------------------------------------------------------- D14: no raw library noise


def test_library_warnings_never_reach_stderr(tmp_path):
    """libpng's warning about a damaged text chunk, Pillow's about a broken EXIF block: the
    images load, and the CLI prints nothing but its own lines."""
    good = encode_png(np.random.default_rng(0).integers(0, 65535, (64, 64, 3), np.uint16))
    bad_text = b"\x00\x00\x00\x05tEXta\x00bcd\x00\x00\x00\x00"  # wrong CRC
    (tmp_path / "text.png").write_bytes(good[:33] + bad_text + good[33:])
    buf = io.BytesIO()
    Image.fromarray(np.zeros((64, 64, 3), np.uint8)).save(
        buf, "JPEG", exif=b"Exif\x00\x00II*\x00junk"
    )
    (tmp_path / "exif.jpg").write_bytes(buf.getvalue())
    for name in ("text.png", "exif.jpg"):
        res = cli("seam", tmp_path / name, tmp_path / name, "--json")
        assert res.returncode == 0, res.stderr
        assert res.stderr == "", name


def test_regular_file_checks_do_not_depend_on_the_suffix(tmp_path):
    """A PNG named .jpg or a file without suffix is read by its signature."""
    data = encode_png(np.full((3, 4, 3), 200, np.uint8))
    for name in ("odd.jpg", "nosuffix"):
        (tmp_path / name).write_bytes(data)
        assert load_image(tmp_path / name).pixels.shape == (3, 4, 3)
    assert stat.S_ISREG(os.stat(tmp_path / "nosuffix").st_mode)
