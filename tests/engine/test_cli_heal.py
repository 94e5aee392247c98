"""``quilt-studio heal SRC MASK -o OUT``."""

from __future__ import annotations

import numpy as np

from engine.cli import main
from engine.io import load_image, save_image
from tests.engine.helpers import smooth_texture


def write_inputs(tmp_path, *, depth=8):
    img = smooth_texture((64, 72), 3, seed=3)
    yy, xx = np.mgrid[:64, :72]
    mask = (yy - 30) ** 2 + (xx - 36) ** 2 < 10**2
    src, m = tmp_path / "src.png", tmp_path / "mask.png"
    save_image(src, img, bit_depth=depth)
    save_image(m, np.where(mask[:, :, None], 1.0, 0.0).astype(np.float32))
    return src, m, mask


def test_heal_writes_the_healed_image_and_maps_exact_outside_the_mask(tmp_path, capsys):
    src, m, mask = write_inputs(tmp_path, depth=16)
    height = tmp_path / "height.png"
    save_image(height, smooth_texture((64, 72), 1, seed=4))
    out, hout = tmp_path / "out.png", tmp_path / "height_out.png"
    args = ["heal", str(src), str(m), "-o", str(out), "--map", f"{height}:{hout}", "--block", "12"]
    assert main([*args, "--seed", "2"]) == 0
    before, after = load_image(src), load_image(out)
    assert after.bit_depth == 16 and after.pixels.shape == before.pixels.shape
    np.testing.assert_array_equal(after.pixels[~mask], before.pixels[~mask])
    assert not np.array_equal(after.pixels[mask], before.pixels[mask])
    h0, h1 = load_image(height).pixels, load_image(hout).pixels
    np.testing.assert_array_equal(h1[~mask], h0[~mask])
    assert not np.array_equal(h1[mask], h0[mask])
    err = capsys.readouterr().err
    assert "heal:" in err and "wrote" in err and "blocks" in err


def test_heal_refuses_a_mask_of_another_size_and_a_bad_seam_option(tmp_path, capsys):
    src, _, _ = write_inputs(tmp_path)
    other = tmp_path / "other.png"
    save_image(other, np.ones((10, 10), np.float32))
    assert main(["heal", str(src), str(other), "-o", str(tmp_path / "o.png")]) == 1
    assert "the mask is 10x10" in capsys.readouterr().err
    args = ["heal", str(src), str(tmp_path / "mask.png"), "-o", str(tmp_path / "o.png")]
    assert main([*args, "--seam", "dp", "--seam-option", "o_max=3"]) == 1
    assert "o_max" in capsys.readouterr().err
