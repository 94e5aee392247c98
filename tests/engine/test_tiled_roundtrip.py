"""The exported .tsx/.tmx load in the real Tiled: convert them headless to JSON and compare."""

from __future__ import annotations

import json
import os
import shutil
import subprocess

import numpy as np
import pytest

from engine.export import export_bundle
from engine.png import decode_png

TILED = shutil.which("tiled")
RASTERIZER = shutil.which("tmxrasterizer")  # Tiled's own map renderer, same Debian package


@pytest.fixture(autouse=True)
def needs_tiled():
    """Skip, with the reason in the summary, where Tiled is absent (.ci/run installs it)."""
    if TILED is None or RASTERIZER is None:
        pytest.skip("Tiled is not installed (Debian package 'tiled'; .ci/run installs it)")


def tiled(*args, cwd, program=None):
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", XDG_RUNTIME_DIR=str(cwd))
    os.chmod(cwd, 0o700)  # Qt wants a private runtime directory
    res = subprocess.run(
        [program or TILED, *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=60
    )
    assert res.returncode == 0, f"{program or TILED} {' '.join(args)} failed: {res.stderr}"


@pytest.mark.parametrize(
    "count,columns,spacing,margin,extrude", [(6, 3, 2, 1, 1), (8, None, 0, 0, 0), (5, 2, 1, 3, 2)]
)
def test_tiled_reads_the_tileset_and_map(tmp_path, count, columns, spacing, margin, extrude):
    g = np.random.default_rng(count)
    tiles = [{"albedo": g.random((12, 10, 3)).astype(np.float32)} for _ in range(count)]
    cells = g.integers(-1, count, (5, 7))
    out = tmp_path / "bundle"
    man = export_bundle(
        out,
        name="set",
        tiles=tiles,
        index_matrix=cells,
        columns=columns,
        spacing=spacing,
        margin=margin,
        extrude=extrude,
        weights=list(range(1, count + 1)),
    )
    tiled(
        "--export-map",
        "json",
        str(out / man["tiled"]["tmx"]),
        str(tmp_path / "map.json"),
        cwd=tmp_path,
    )
    tiled(
        "--export-tileset",
        "json",
        str(out / man["tiled"]["tsx"]),
        str(tmp_path / "tileset.json"),
        cwd=tmp_path,
    )
    ts = json.loads((tmp_path / "tileset.json").read_text())
    mp = json.loads((tmp_path / "map.json").read_text())

    at = man["atlas"]
    assert (ts["tilewidth"], ts["tileheight"]) == (man["tile_w"], man["tile_h"])
    assert (ts["imagewidth"], ts["imageheight"]) == (at["width"], at["height"])
    assert (ts["margin"], ts["spacing"], ts["columns"]) == (
        man["tiled"]["margin"],
        man["tiled"]["spacing"],
        at["columns"],
    )
    # Tiled counts every cell of the atlas grid; blank cells only appear when the grid is not full
    assert ts["tilecount"] == at["columns"] * at["rows"]
    if count % at["columns"] == 0:
        assert ts["tilecount"] == man["tile_count"]
    probs = {t["id"]: t["probability"] for t in ts.get("tiles", [])}
    assert [probs.get(i, 1.0) for i in range(count)] == [
        float(i + 1) for i in range(count)
    ]  # 1 is Tiled's default
    # the tile regions Tiled computes hold exactly our tiles
    atlas = decode_png((out / at["images"]["albedo"]).read_bytes())
    for i, entry in enumerate(man["tiles"]):
        c, r = i % ts["columns"], i // ts["columns"]
        x = ts["margin"] + c * (ts["tilewidth"] + ts["spacing"])
        y = ts["margin"] + r * (ts["tileheight"] + ts["spacing"])
        tile = decode_png((out / entry["files"]["albedo"]).read_bytes())
        assert np.array_equal(atlas[y : y + ts["tileheight"], x : x + ts["tilewidth"]], tile)

    assert (mp["width"], mp["height"], mp["tilewidth"], mp["tileheight"]) == (
        7,
        5,
        man["tile_w"],
        man["tile_h"],
    )
    assert len(mp["tilesets"]) == 1 and mp["tilesets"][0]["firstgid"] == 1
    (layer,) = mp["layers"]
    gids = np.array(layer["data"]).reshape(5, 7)
    expected = np.where(
        np.array(man["layout"]["cells"]) >= 0, np.array(man["layout"]["cells"]) + 1, 0
    )
    assert np.array_equal(gids, expected)
    assert np.array_equal(gids, np.where(cells >= 0, cells + 1, 0))
    # Tiled's renderer draws the map pixel for pixel like our preview (empty cells transparent)
    png = tmp_path / "map.png"
    tiled(str(out / man["tiled"]["tmx"]), str(png), cwd=tmp_path, program=RASTERIZER)
    drawn = decode_png(png.read_bytes())
    preview = decode_png((out / man["preview"]["albedo"]).read_bytes())
    assert drawn.shape == (*preview.shape[:2], 4)
    full = np.repeat(np.repeat(cells >= 0, 12, axis=0), 10, axis=1)
    assert np.array_equal(drawn[..., 3] == 255, full) and (drawn[..., 3][~full] == 0).all()
    assert np.array_equal(drawn[..., :3][full], preview[full])


def test_cli_project_exports_a_bundle_tiled_reads(tmp_path):
    """As a user would: ``quilt-studio tileset SOURCE --project P`` then ``quilt-studio export P
    --out DIR``; Tiled converts the .tmx and .tsx and renders the map exactly as our preview."""
    from engine.cli import main
    from engine.io import save_image

    g = np.random.default_rng(0)
    src = np.clip(0.5 + np.cumsum(g.normal(0, 0.05, (96, 96, 3)), axis=1) % 0.5, 0, 1).astype(
        np.float32
    )
    save_image(tmp_path / "src.png", src)
    proj = tmp_path / "p.quiltproj"
    argv = ["tileset", str(tmp_path / "src.png"), "--out", str(tmp_path / "ts")]
    argv += ["--candidates", "4", "--tile-min", "24", "--tile-max", "32", "--preview", "3x4"]
    assert main([*argv, "--project", str(proj)]) == 0
    assert main(["export", str(proj), "--out", str(tmp_path / "b"), "--spacing", "1"]) == 0
    b = tmp_path / "b"
    man = json.loads((b / "tileset.json").read_text())
    tiled("--export-map", "json", str(b / "tileset.tmx"), str(tmp_path / "m.json"), cwd=tmp_path)
    mp = json.loads((tmp_path / "m.json").read_text())
    assert np.array_equal(
        np.array(mp["layers"][0]["data"]).reshape(3, 4), np.array(man["layout"]["cells"]) + 1
    )
    tiled(str(b / "tileset.tmx"), str(tmp_path / "m.png"), cwd=tmp_path, program=RASTERIZER)
    drawn = decode_png((tmp_path / "m.png").read_bytes())
    preview = decode_png((b / man["preview"]["albedo"]).read_bytes())
    assert np.array_equal(drawn[..., :3], preview) and (drawn[..., 3] == 255).all()
