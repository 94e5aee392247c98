"""``quilt-studio export PROJECT --out DIR`` end to end."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from engine.cli import main
from engine.png import decode_png
from engine.project import project_from_tileset, save_project


@pytest.fixture
def project_file(tmp_path):
    g = np.random.default_rng(0)
    src = g.integers(0, 65536, (32, 32, 3)).astype(np.uint16)
    tiles = [src[i : i + 8, i : i + 8] for i in range(4)]
    p = project_from_tileset(
        sources=src,
        tiles=tiles,
        name="demo",
        bit_depth=16,
        picks=[3, 1, 0],
        layout=[[0, 1, 2], [2, 1, 0]],
        seeds=[5, 6, 7, 8],
        scores=[1, 2, 3, 4],
    )
    path = tmp_path / "demo.quiltproj"
    save_project(path, p)
    return path, src


def test_cli_export_writes_the_bundle(tmp_path, project_file, capsys):
    path, src = project_file
    out = tmp_path / "bundle"
    rc = main(
        [
            "export",
            str(path),
            "--out",
            str(out),
            "--atlas-columns",
            "2",
            "--spacing",
            "2",
            "--margin",
            "1",
            "--extrude",
            "1",
        ]
    )
    assert rc == 0
    assert "wrote 3 tiles" in capsys.readouterr().err
    man = json.loads((out / "demo.json").read_text())
    assert (
        man["atlas"]["columns"] == 2
        and man["atlas"]["spacing"] == 2
        and man["atlas"]["margin"] == 1
    )
    assert man["atlas"]["extrude"] == 1 and man["bit_depth"] == 16 and man["tile_count"] == 3
    tile0 = decode_png((out / "demo_000_albedo.png").read_bytes())
    assert tile0.dtype == np.uint16 and np.array_equal(
        tile0, src[3:11, 3:11]
    )  # pick 0 is candidate 3
    assert man["layout"]["cells"] == [[0, 1, 2], [2, 1, 0]]
    # 8-bit on request (dithered by default), refusing to overwrite without --overwrite
    assert main(["export", str(path), "--out", str(out), "--bit-depth", "8"]) == 1
    err = capsys.readouterr().err
    assert "not empty (pass --overwrite to replace it)" in err and "=True" not in err  # ux13
    assert main(["export", str(path), "--out", str(out), "--bit-depth", "8", "--overwrite"]) == 0
    man8 = json.loads((out / "demo.json").read_text())
    assert man8["bit_depth"] == 8 and man8["dithered"]
    assert decode_png((out / "demo_000_albedo.png").read_bytes()).dtype == np.uint8


def test_cli_export_errors_are_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.quiltproj"
    bad.write_text("not a zip")
    assert main(["export", str(bad), "--out", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert (
        err.startswith("quilt-studio export: error: ")
        and str(bad) in err
        and "Traceback" not in err
    )
    assert not (tmp_path / "o").exists()
    for option in ("--spacing", "--seed"):
        with pytest.raises(SystemExit):
            main(["export", str(bad), "--out", str(tmp_path / "o"), option, "-1"])
        assert f"argument {option}: must be >= 0" in capsys.readouterr().err


def test_cli_export_subprocess(tmp_path, project_file):
    path, _ = project_file
    res = subprocess.run(
        [sys.executable, "-m", "quilt_gui", "export", str(path), "--out", str(tmp_path / "b")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "b" / "demo.tsx").exists() and (tmp_path / "b" / "demo.tres").exists()


def test_project_option_helpers(tmp_path):
    import argparse

    from engine.cli.export import add_project_option, save_project_option
    from engine.project import load_project

    parser = argparse.ArgumentParser()
    add_project_option(parser)
    g = np.random.default_rng(1)
    src = g.random((16, 16, 3)).astype(np.float32)
    save_project_option(parser.parse_args([]), sources=src, tiles=[src[:8, :8]])  # no-op
    assert list(tmp_path.iterdir()) == []
    args = parser.parse_args(["--project", str(tmp_path / "p.quiltproj")])
    save_project_option(args, sources=src, tiles=[src[:8, :8], src[8:, 8:]], picks=[1])
    p = load_project(tmp_path / "p.quiltproj")
    assert len(p.candidates) == 2 and p.picks == [1]
    assert np.array_equal(p.candidates[1].tile, np.round(src[8:, 8:] * 255) / np.float32(255))


def test_sixteen_bit_source_to_bundle_end_to_end(tmp_path):
    """``tileset`` on a 16-bit PNG with a normal map, ``--project``, then ``export``: 16-bit
    tiles whose every value is a copy of a source pixel (hard cuts: no blend anywhere), in
    every map."""
    from scipy import ndimage

    from engine.io import save_image

    g = np.random.default_rng(3)
    smooth = ndimage.uniform_filter(g.random((96, 96, 3)), (7, 7, 1))
    src = (smooth * 65535).astype(np.uint16)
    normal = (np.clip(0.5 + (smooth - 0.5) * 0.4, 0, 1) * 65535).astype(np.uint16)
    normal[..., 2] = 65535
    save_image(tmp_path / "s.png", src, bit_depth=16)
    save_image(tmp_path / "n.png", normal, bit_depth=16)
    proj = tmp_path / "p.quiltproj"
    argv = ["tileset", str(tmp_path / "s.png"), "--out", str(tmp_path / "ts"), "--blend", "none"]
    argv += ["--candidates", "3", "--tile-min", "32", "--map", f"normal={tmp_path / 'n.png'}"]
    assert main([*argv, "--project", str(proj)]) == 0
    assert main(["export", str(proj), "--out", str(tmp_path / "b")]) == 0
    man = json.loads((tmp_path / "b" / "tileset.json").read_text())
    assert man["bit_depth"] == 16 and [m["name"] for m in man["maps"]] == ["albedo", "normal"]
    for m, source in (("albedo", src), ("normal", normal)):
        values = {tuple(v) for v in source.reshape(-1, 3)}
        for t in man["tiles"]:
            tile = decode_png((tmp_path / "b" / t["files"][m]).read_bytes())
            assert tile.dtype == np.uint16
            assert all(tuple(v) in values for v in tile.reshape(-1, 3)), (m, t["id"])
