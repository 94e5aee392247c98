import json

import numpy as np
import pytest
from scipy import ndimage

from engine import metrics
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


def test_synth_keeps_16_bit_exact_copies_and_tileable(tmp_path):
    """16-bit in, 16-bit out, every value an exact copy of a sample pixel (hard cuts); the
    tileable output tiled 2 x 2 shows no wrap joint; 8 bits only on request, dithered."""
    rng = np.random.default_rng(1)
    q = (ndimage.uniform_filter(rng.random((48, 48, 3)), (5, 5, 1)) * 65535).astype(np.uint16)
    src = tmp_path / "s16.png"
    save_image(src, q, bit_depth=16)
    out = tmp_path / "o16.png"
    argv = ["synth", str(src), "--size", "72x60", "--block", "16", "--tileable", "--seed", "2"]
    argv += ["--mode", "fast"]
    assert main([*argv, "-o", str(out)]) == 0
    assert png_bit_depth(out) == 16
    got = np.round(load_image(out).pixels * 65535).astype(np.uint16)
    sample_values = {tuple(v) for v in q.reshape(-1, 3)}
    assert all(tuple(v) in sample_values for v in got.reshape(-1, 3))
    assert len({tuple(v) for v in got.reshape(-1, 3)}) > 1000
    assert metrics.grid_border_ratio(np.tile(got / 65535, (2, 2, 1)), got.shape[:2]) < 1.4
    out8 = tmp_path / "o8.png"
    assert main([*argv, "--bit-depth", "8", "-o", str(out8)]) == 0
    assert png_bit_depth(out8) == 8
    got8 = np.round(load_image(out8).pixels * 255)
    rounded = np.round(got / 65535 * 255)
    assert np.abs(got8 - rounded).max() <= 1 and (got8 != rounded).mean() > 0.2  # dithered
    assert main([*argv, "--bit-depth", "8", "-o", str(tmp_path / "o8.jpg")]) == 0


def test_synth_checks_outputs_before_the_run_and_writes_seams_atomically(
    tmp_path, capsys, monkeypatch
):
    rng = np.random.default_rng(1)
    src = tmp_path / "s16.png"
    save_image(src, rng.random((40, 40, 3)), bit_depth=16)
    big = ["synth", str(src), "--size", "4000x4000", "--block", "16"]

    def no_synthesis(*args, **kwargs):
        raise AssertionError("the output should be refused before any synthesis")

    with monkeypatch.context() as m:
        m.setattr("engine.quilting.iter_quilt", no_synthesis)
        for out, message in (("x.xyz", "unsupported output format .xyz"), ("x.jpg", "16-bit")):
            assert main([*big, "-o", str(tmp_path / out)]) == 1
            assert message in capsys.readouterr().err
    blocker = tmp_path / "file"
    blocker.write_text("")
    seams = blocker / "seams.json"  # a folder that cannot exist: under a regular file
    small = ["synth", str(src), "--size", "40x40", "--block", "16", "-o", str(tmp_path / "o.png")]
    assert main([*small, "--save-seams", str(seams)]) == 1
    err = capsys.readouterr().err
    assert f"{seams}: cannot write" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "o.png", "s16.png"]


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
