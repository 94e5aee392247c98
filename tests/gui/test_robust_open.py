"""The editor opening hostile files (issue 12): the banner shows the engine's own message, the
current document stays as it was, and the editor stays usable; a file read with a caveat (only
its first frame) says so in the banner."""

from __future__ import annotations

import os

import numpy as np
import pytest
from PIL import Image

from engine.io import ImageError, load_image
from engine.project import ProjectError, load_project
from tests.engine.hostile import candidate, png_header, project_doc, project_zip
from tests.gui.helpers import WAIT_MS, make_window, open_sample


@pytest.fixture
def win(qtbot):
    w = make_window(qtbot)
    open_sample(qtbot, w, "brick")
    return w


def amplifier(tmp_path):
    big = png_header(10_000, 10_000)
    doc = project_doc([candidate("images/big.png") for _ in range(40)])
    small = png_header(8, 8, idat=b"\0" * (8 * 25))
    return project_zip(
        tmp_path / "amp.quiltproj", doc, {"images/big.png": big, "images/s.png": small}
    )


def zip_version_ff(tmp_path):
    from engine.png import encode_png

    path = project_zip(
        tmp_path / "v.quiltproj",
        project_doc([candidate("images/s.png")]),
        {"images/s.png": encode_png(np.zeros((8, 8, 3), np.uint8))},
    )
    data = bytearray(path.read_bytes())
    for sig, off in ((b"PK\x01\x02", 6), (b"PK\x03\x04", 4)):
        i = data.find(sig)
        while i >= 0:
            data[i + off] = 0xFF
            i = data.find(sig, i + 4)
    path.write_bytes(bytes(data))
    return path


def fifo(tmp_path):
    path = tmp_path / "pipe.png"
    os.mkfifo(path)
    return path


@pytest.mark.parametrize(
    "make, loader, error",
    [
        (amplifier, load_project, ProjectError),  # D1: 44.7 GiB declared, refused unread
        (zip_version_ff, load_project, ProjectError),  # D18: NotImplementedError in zipfile
        (fifo, load_image, ImageError),  # D12: would hang a reader
    ],
)
def test_hostile_file_shows_the_engine_message_and_keeps_the_document(
    qtbot, win, tmp_path, make, loader, error
):
    path = make(tmp_path)
    with pytest.raises(error) as info:
        loader(path)
    source, name = win.doc.source, win.doc.name
    win.files.open_path(str(path), confirm=False)
    qtbot.waitUntil(lambda: win.last_message("error") != "", timeout=WAIT_MS)
    assert win.last_message("error") == f"Could not open the file. {info.value}"
    assert win.message_bar.isVisible() and win.message_bar.level == "error"
    assert win.doc.source is source and win.doc.name == name  # nothing lost
    win.act_find.trigger()  # still usable
    qtbot.waitUntil(lambda: not win.pipeline.busy(), timeout=WAIT_MS)
    assert win.doc.tileset.seamless is not None


def test_animated_gif_says_the_first_frame_is_used(qtbot, win, tmp_path):
    g = np.random.default_rng(0)
    frames = [Image.fromarray(g.integers(0, 256, (60, 70, 3), np.uint8)) for _ in range(3)]
    path = tmp_path / "anim.gif"
    frames[0].save(path, "GIF", save_all=True, append_images=frames[1:])
    with qtbot.waitSignal(win.doc.source_changed, timeout=WAIT_MS):
        win.files.open_path(str(path), confirm=False)
    text = win.last_message()
    assert text.startswith("Animated GIF with 3 frames; using the first frame. Opened anim.gif")
    assert win.message_bar.level == "warning" and win.doc.source.shape == (60, 70)
