import json

import numpy as np
import pytest

from engine.cli import main
from engine.io import load_image, save_image


@pytest.fixture
def sample_png(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.uniform(0, 0.6, (48, 48, 3)).astype(np.float32)
    img[:, 20:24] = (1.0, 0.0, 0.0)  # a red stripe to exclude
    path = tmp_path / "sample.png"
    save_image(path, img)
    return path


def png_bit_depth(path) -> int:
    return path.read_bytes()[24]


def test_synth_writes_output_seams_and_progress(sample_png, tmp_path, capsys):
    def synth(out, seams):
        args = [
            "--size",
            "70x50",
            "--block",
            "16",
            "--overlap",
            "4",
            "--seam",
            "minimax",
            "--seed",
            "3",
        ]
        return main(["synth", str(sample_png), *args, "-o", str(out), "--save-seams", str(seams)])

    out, seams = tmp_path / "out.png", tmp_path / "seams.json"
    assert synth(out, seams) == 0
    img = load_image(out)
    assert img.pixels.shape == (50, 70, 3) and img.bit_depth == 8
    doc = json.loads(seams.read_text())
    assert doc["seam"] == "minimax" and doc["overlap"] == 4
    assert len(doc["blocks"]) == 4 * 6
    # every block after the first is cut, unless old and new agree exactly (peak 0, no cut)
    assert all(len(b["path"]) > 0 or b["peak"] == 0 for b in doc["blocks"][1:])
    assert sum(len(b["path"]) > 0 for b in doc["blocks"]) > 12
    err = capsys.readouterr().err
    assert "synth: 24/24 blocks" in err and "wrote" in err
    # same seed, same output; the seams image marks the cuts in red
    out2, overlay = tmp_path / "out2.png", tmp_path / "seams.png"
    assert synth(out2, overlay) == 0
    np.testing.assert_array_equal(load_image(out2).pixels, img.pixels)
    assert (np.abs(load_image(overlay).pixels - (1, 0, 0)).sum(axis=2) == 0).sum() > 50


def test_synth_exclude_color_and_bhatia(sample_png, tmp_path):
    out = tmp_path / "out.png"
    rc = main(
        [
            "synth",
            str(sample_png),
            "--size",
            "64x64",
            "--block",
            "16",
            "--select",
            "bhatia",
            "--seam",
            "resistance",
            "--seam-option",
            "max_run=3",
            "--exclude-color",
            "0.9,0,0:1,0.1,0.1",
            "-o",
            str(out),
        ]
    )
    assert rc == 0
    px = load_image(out).pixels
    assert not ((px[..., 0] > 0.9) & (px[..., 1] < 0.1)).any()


def test_synth_keeps_16_bit_and_tileable(tmp_path):
    rng = np.random.default_rng(1)
    src = tmp_path / "s16.png"
    save_image(src, rng.random((40, 40, 3)), bit_depth=16)
    out = tmp_path / "o16.png"
    assert (
        main(
            [
                "synth",
                str(src),
                "--size",
                "60x60",
                "--block",
                "16",
                "--tileable",
                "--mode",
                "fast",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    assert png_bit_depth(out) == 16


def test_transfer_cli(sample_png, tmp_path, capsys):
    target = tmp_path / "target.png"
    save_image(target, np.tile(np.linspace(0, 1, 60, dtype=np.float32), (40, 1)))
    out = tmp_path / "t.png"
    rc = main(
        [
            "transfer",
            str(sample_png),
            str(target),
            "--block",
            "12",
            "--alpha",
            "0.2:0.8",
            "--iterations",
            "2",
            "--correspondence",
            "blurred",
            "-o",
            str(out),
        ]
    )
    assert rc == 0
    assert load_image(out).pixels.shape == (40, 60, 3)
    err = capsys.readouterr().err
    assert "iteration 2" in err and "correspondence error per iteration" in err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--size", "70x50", "--block", "64"], "smaller than the block"),
        (["--size", "10x50", "--block", "16"], "larger than the output"),
        (["--size", "70x50", "--block", "16", "--overlap", "16"], "overlap"),
        (["--size", "70x50", "--block", "16", "--seam-option", "o_max=2"], "o_max"),
    ],
)
def test_synth_errors_are_one_line(sample_png, tmp_path, capsys, argv, message):
    rc = main(["synth", str(sample_png), *argv, "-o", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert rc == 1 and message in err and "Traceback" not in err


def test_synth_rejects_bad_size(sample_png, tmp_path):
    with pytest.raises(SystemExit):
        main(["synth", str(sample_png), "--size", "0x5", "--block", "4", "-o", "x.png"])
