"""End to end: ``quilt-studio tileset SOURCE --out DIR`` on small sources."""

import csv
import json
import subprocess
import sys

import numpy as np
import pytest

import resources
from engine.bitdepth import quantize
from engine.cli import main
from engine.io import load_image
from engine.png import decode_png, encode_png
from engine.project import load_project
from engine.tiles import assemble, candidates, make_seamless


@pytest.fixture(scope="module")
def src(tmp_path_factory):
    d = tmp_path_factory.mktemp("src")
    S = load_image(resources.sample_path("cobblestones")).pixels[:150, :160]
    q8 = np.round(S * 255).astype(np.uint8)
    gray = np.round(S[:, :, :1] * 65535).astype(np.uint16)
    rgb16 = np.round(S * 65535).astype(np.uint16)
    rgb16[::3, ::5] += 1  # values that 8 bits cannot hold
    paths = {
        "rgb8": d / "rgb8.png",
        "gray16": d / "gray16.png",
        "rgb16": d / "rgb16.png",
        "height": d / "height.png",
        "mask": d / "mask.png",
    }
    paths["rgb8"].write_bytes(encode_png(q8))
    paths["gray16"].write_bytes(encode_png(gray))
    paths["rgb16"].write_bytes(encode_png(rgb16))
    paths["height"].write_bytes(encode_png(q8[:, :, 1]))
    mask = np.zeros((150, 160), np.uint8)
    mask[:, 140:] = 255
    paths["mask"].write_bytes(encode_png(mask))
    return paths


ARGS = [
    "--candidates",
    "5",
    "--tile-min",
    "48",
    "--tile-max",
    "56",
    "--seed",
    "3",
    "--preview",
    "3x4",
]


def S_exact(paths):
    return load_image(paths["rgb8"]).pixels


def png(path):
    return decode_png(path.read_bytes())


def test_end_to_end_files_manifest_layout_and_determinism(src, tmp_path, capsys):
    out = tmp_path / "set"
    proj = tmp_path / "set.quiltproj"
    assert (
        main(["tileset", str(src["rgb8"]), "--out", str(out), *ARGS, "--project", str(proj)]) == 0
    )
    err = capsys.readouterr().err
    assert "template:" in err and err.count("candidate") >= 5 and "wrote" in err
    names = {p.name for p in out.iterdir()}
    assert {"template.png", "manifest.json", "layout.csv", "layout.json", "preview.png"} <= names
    assert {f"tile_{i:03d}.png" for i in range(5)} <= names
    man = json.loads((out / "manifest.json").read_text())
    assert man["seed"] == 3 and man["source"]["bit_depth"] == 8
    p = man["resolved"]
    assert p["tile_min"] == [48, 48] and p["tile_max"] == [56, 56] and p["seam"]["method"] == "dp"
    assert p["candidates"] == 5 and p["overlap"] == man["template"]["overlap"]
    assert len(man["tiles"]) == 5
    for t in man["tiles"]:
        assert set(t["scores"]) >= {"criterion", "peak", "changed"}
        x, y, w, h = t["source_rect"]
        assert (w, h) == tuple(man["template"]["rect"][2:]) and x >= 0 and y >= 0
    # the files hold exactly what the engine makes with the same parameters
    S = png(src["rgb8"]).astype(np.float32) / 255
    rect = tuple(man["template"]["rect"])
    st = make_seamless(S, rect, overlap=man["template"]["overlap"])
    np.testing.assert_array_equal(png(out / "template.png"), quantize(st.tile, 8, dither=False))
    cands = candidates(S, st, 5, rng=3, workers=1)
    for c in cands:
        np.testing.assert_array_equal(
            png(out / f"tile_{c.index:03d}.png"), quantize(c.tile, 8, dither=False)
        )
        assert man["tiles"][c.index]["source_rect"] == list(c.patch_rect)
    # layout CSV == JSON, no equal neighbours, preview assembled from it
    rows = [[int(v) for v in r] for r in csv.reader((out / "layout.csv").open())]
    lay = json.loads((out / "layout.json").read_text())
    assert rows == lay["cells"] and (lay["rows"], lay["cols"]) == (3, 4)
    cells = np.array(rows)
    assert (cells[:, 1:] != cells[:, :-1]).all() and (cells[1:] != cells[:-1]).all()
    tiles = [png(out / f"tile_{i:03d}.png") for i in range(5)]
    np.testing.assert_array_equal(png(out / "preview.png"), assemble(tiles, cells))
    # the project opens with the same tiles, picks and layout
    project = load_project(proj)
    assert len(project.candidates) == 5 and project.picks == list(range(5))
    assert project.template_rect == rect
    np.testing.assert_array_equal(project.layout, cells)
    # stored at the source's 8 bits (blended pixels of the cut are rounded)
    np.testing.assert_allclose(project.candidates[2].tile, cands[2].tile, atol=0.5 / 255 + 1e-6)


def test_sixteen_bit_and_gray_keep_their_depth(src, tmp_path):
    for key, channels in (("rgb16", 3), ("gray16", 1)):
        out = tmp_path / key
        assert main(["tileset", str(src[key]), "--out", str(out), *ARGS]) == 0
        for name in ("template.png", "tile_000.png", "preview.png"):
            q = png(out / name)
            assert q.dtype == np.uint16 and q.shape[2] == channels, (key, name)
        man = json.loads((out / "manifest.json").read_text())
        assert man["source"]["bit_depth"] == 16
        # away from the cuts the tile holds exact 16-bit source values
        x, y, w, h = man["template"]["rect"]
        wt = man["template"]["overlap"]
        s = png(src[key])
        np.testing.assert_array_equal(
            png(out / "template.png")[wt:, wt:], s[y + wt : y + h, x + wt : x + w]
        )


def test_picks_maps_exclusion_and_options(src, tmp_path):
    out = tmp_path / "opts"
    assert (
        main(
            [
                "tileset",
                str(src["rgb8"]),
                "--out",
                str(out),
                *ARGS,
                "--pick",
                "1,3",
                "--map",
                f"height={src['height']}",
                "--weight",
                "main=1",
                "--weight",
                "height=0.5",
                "--exclude-mask",
                str(src["mask"]),
                "--seam",
                "oscillating",
                "--seam-option",
                "o_max=2",
                "--blend",
                "feather",
                "--workers",
                "1",
            ]
        )
        == 0
    )
    man = json.loads((out / "manifest.json").read_text())
    assert man["picks"] == [1, 3]
    cells = np.array(json.loads((out / "layout.json").read_text())["cells"])
    assert set(np.unique(cells)) <= {1, 3}
    assert (out / "tile_000_height.png").exists() and (out / "preview_height.png").exists()
    assert png(out / "tile_000_height.png").shape[2] == 1
    x, y, w, h = man["template"]["footprint"]
    assert x + w <= 140
    for t in man["tiles"]:
        tx, ty, tw, th = t["source_rect"]
        assert tx + tw <= 140
    seam = man["resolved"]["seam"]
    assert seam["method"] == "oscillating" and seam["options"]["o_max"] == 2
    assert man["resolved"]["template_blend"] == "feather" and seam["blend"] == "feather"


def test_bad_input_gives_clear_errors(src, tmp_path, capsys):
    out = str(tmp_path / "bad")
    assert main(["tileset", str(src["rgb8"]), "--out", out, "--tile-min", "200"]) == 1
    err = capsys.readouterr().err  # the flag given, not the setting's name (ux13)
    assert "smaller than the minimum tile" in err and "a smaller --tile-min or" in err
    assert main(["tileset", str(src["rgb8"]), "--out", out, "--tile-size", "200"]) == 1
    err = capsys.readouterr().err
    assert "a smaller --tile-size or" in err and "tile_min" not in err
    assert main(["tileset", str(tmp_path / "missing.png"), "--out", out]) == 1
    assert "no such file" in capsys.readouterr().err
    assert main(["tileset", str(src["rgb8"]), "--out", out, *ARGS, "--pick", "9"]) == 1
    assert "out of range" in capsys.readouterr().err
    assert main(["tileset", str(src["rgb8"]), "--out", out, *ARGS, "--seam-option", "bogus=1"]) == 1
    assert "bogus" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["tileset", str(src["rgb8"]), "--out", out, "--tile-min", "big"])
    flat = tmp_path / "flat.png"
    flat.write_bytes(encode_png(np.full((90, 90, 3), 120, np.uint8)))
    assert main(["tileset", str(flat), "--out", out, "--candidates", "2", "--tile-min", "32"]) == 0
    assert "warning: the source is a single flat colour" in capsys.readouterr().err
    man = json.loads((tmp_path / "bad" / "manifest.json").read_text())
    assert any("flat" in w for w in man["warnings"])


def test_bad_sources_outputs_and_options_fail_before_any_work(src, tmp_path, capsys):
    """Every refusal names the file or the option; nothing is computed or left behind."""
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    argv = ["tileset", str(src["rgb8"]), *ARGS]
    assert main([*argv, "--out", str(blocker / "sub")]) == 1
    err = capsys.readouterr().err
    assert f"--out {blocker / 'sub'}: cannot write there ({blocker} is a file" in err
    assert "candidate" not in err  # refused before the work, not after it
    out = tmp_path / "o"
    assert main([*argv, "--out", str(out), "--pick", "1,7"]) == 1
    assert "--pick [7] out of range: --candidates is 5" in capsys.readouterr().err
    assert not out.exists()
    bad = {"empty.png": b"", "corrupt.png": encode_png(np.zeros((9, 9), np.uint8))[:40]}
    for name, data in bad.items():
        (tmp_path / name).write_bytes(data)
        assert main(["tileset", str(tmp_path / name), "--out", str(out)]) == 1
        err = capsys.readouterr().err
        assert f"{name}: the file is" in err and err.count("\n") == 1, err
        assert not out.exists()  # the folder made for the run is removed again
    assert main(["tileset", str(tmp_path), "--out", str(out)]) == 1
    assert "is a folder, not an image" in capsys.readouterr().err
    assert main([*argv, "--out", str(out), "--exclude-color", "0:1"]) == 1
    assert "--exclude-color / --exclude-mask exclude every pixel" in capsys.readouterr().err
    # a tile range that does not fit the source is clamped with a warning, printed once
    wide = ["--candidates", "2", "--tile-min", "40", "--tile-max", "400"]
    assert main(["tileset", str(src["rgb8"]), "--out", str(out), *wide]) == 0
    err = capsys.readouterr().err  # in the flags' words and syntax (HxW), not the settings'
    assert err.count("warning: --tile-max 400 plus overlap") == 1 and "tile_max" not in err
    assert "does not fit the 160x150 source; using --tile-max 130x140 (HxW)" in err


def test_small_source_gets_a_margin_that_fits_its_ring(tmp_path, capsys):
    """30 x 30 px with the defaults: tiles 8..15, w_T = w_P = 2, so the margin is 1."""
    rng = np.random.default_rng(0)
    (tmp_path / "s.png").write_bytes(encode_png(rng.integers(0, 256, (30, 30, 3), np.uint8)))
    out = tmp_path / "o"
    assert main(["tileset", str(tmp_path / "s.png"), "--out", str(out), "--candidates", "2"]) == 0
    man = json.loads((out / "manifest.json").read_text())
    assert man["resolved"]["patch_overlap"] == 2 and man["resolved"]["margin"] == 1
    assert main(["tileset", str(tmp_path / "s.png"), "--out", str(out), "--margin", "2"]) == 1
    assert "margin must be smaller than patch_overlap" in capsys.readouterr().err


def test_installed_command_runs(src, tmp_path):
    out = tmp_path / "cmd"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "quilt_gui",
            "tileset",
            str(src["rgb8"]),
            "--out",
            str(out),
            "--candidates",
            "2",
            "--tile-min",
            "48",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    assert "candidate" in r.stderr and (out / "tile_001.png").exists()


def test_fixed_rect_and_colour_exclusion(src, tmp_path):
    out = tmp_path / "rect"
    assert (
        main(
            [
                "tileset",
                str(src["rgb8"]),
                "--out",
                str(out),
                "--candidates",
                "2",
                "--rect",
                "10,12,50,48",
                "--overlap",
                "6",
                "--patch-overlap",
                "5",
                "--exclude-color",
                "0:0.15",
            ]
        )
        == 0
    )
    man = json.loads((out / "manifest.json").read_text())
    assert man["template"]["rect"] == [10, 12, 50, 48]
    from engine.tiles import template_cost

    expected = template_cost(
        S_exact(src), (10, 12, 50, 48), overlap=6, excluded=np.all(S_exact(src) <= 0.15, axis=2)
    )[0]
    assert man["template"]["cost"] == pytest.approx(expected)  # a fixed rectangle is scored too
    assert man["resolved"]["patch_overlap"] == 5
    assert png(out / "template.png").shape == (48, 50, 3)
    S = png(src["rgb8"]).astype(np.float32) / 255
    dark = np.all(S <= 0.15, axis=2)
    assert dark.sum() > 100
    for t in man["tiles"]:
        x, y, w, h = t["source_rect"]
        assert not dark[y : y + h, x : x + w].any()
    assert main(["tileset", str(src["rgb8"]), "--out", str(out), "--rect", "1,2,3"]) == 1


def test_joint_weight_is_passed_to_the_search_and_recorded(src, tmp_path):
    from engine.tiles import find_template

    S = S_exact(src)
    for weight in ("0", "2"):
        out = tmp_path / f"w{weight}"
        assert (
            main(["tileset", str(src["rgb8"]), "--out", str(out), *ARGS, "--joint-weight", weight])
            == 0
        )
        man = json.loads((out / "manifest.json").read_text())
        assert man["resolved"]["joint_weight"] == float(weight)
        t = find_template(S, tile_min=48, tile_max=56, joint_weight=float(weight))
        assert man["template"]["rect"] == list(t.rect)
    out = tmp_path / "k0"
    assert (
        main(["tileset", str(src["rgb8"]), "--out", str(out), *ARGS, "--detail-weight", "0"]) == 0
    )
    man = json.loads((out / "manifest.json").read_text())
    assert man["resolved"]["detail_weight"] == 0.0
    t = find_template(S, tile_min=48, tile_max=56, detail_weight=0)
    assert man["template"]["rect"] == list(t.rect)


def test_blend_poisson_reaches_the_template_and_the_patches(src, tmp_path):
    """--blend poisson: both cuts hard, then solved in the gradient domain (engine.poisson);
    the tiles still share the template's outer margin bit for bit."""
    out = tmp_path / "poisson"
    assert main(["tileset", str(src["rgb8"]), "--out", str(out), *ARGS, "--blend", "poisson"]) == 0
    man = json.loads((out / "manifest.json").read_text())
    assert man["resolved"]["template_blend"] == "poisson"
    assert man["resolved"]["seam"]["blend"] == "poisson"
    template = png(out / "template.png")
    for i in range(len(man["tiles"])):
        tile = png(out / f"tile_{i:03d}.png")
        np.testing.assert_array_equal(tile[0], template[0])
        np.testing.assert_array_equal(tile[:, -1], template[:, -1])


def test_default_patch_ring_is_the_engines(src, tmp_path):
    """Without --patch-overlap the CLI uses engine.tiles.default_patch_overlap(w_T) (w_T 20 ->
    w_P 10, not 20): the manifest says so and the tiles are the engine's defaults' tiles."""
    from engine.bitdepth import quantize
    from engine.tiles import default_patch_overlap

    out = tmp_path / "ring"
    argv = ["tileset", str(src["rgb8"]), "--out", str(out), "--candidates", "2", "--seed", "3"]
    assert main([*argv, "--rect", "10,12,50,48", "--overlap", "20"]) == 0
    man = json.loads((out / "manifest.json").read_text())
    assert man["resolved"]["patch_overlap"] == default_patch_overlap(20) == 10
    S = S_exact(src)
    st = make_seamless(S, (10, 12, 50, 48), overlap=20)
    cands = candidates(S, st, 2, rng=3)
    for c in cands:
        tile = png(out / f"tile_{c.index:03d}.png")
        np.testing.assert_array_equal(tile, quantize(c.tile, 8, dither=False))


def test_quality_warnings_do_not_suggest_flatten_lighting_when_it_is_on(
    tmp_path, capsys, monkeypatch
):
    """A set made with ``--flatten`` whose tiles show a frame (held at 1.52 at least, limit
    1.15, so that a better engine keeps the test meaningful): the warning says Flatten lighting
    is on rather than suggesting it (as the editor's do)."""
    from PIL import Image

    import engine.metrics as metrics

    measured = metrics.tileset_quality

    def framed(*args, **kwargs):
        q = measured(*args, **kwargs)
        q["frame"] = max(q["frame"], 1.52)
        return q

    monkeypatch.setattr(metrics, "tileset_quality", framed)

    photo = tmp_path / "brick.png"
    Image.open(resources.sample_path("brick")).convert("RGB").crop((0, 30, 96, 126)).save(photo)
    out = tmp_path / "set"
    args = ["--tile-size", "32", "--candidates", "3", "--flatten"]
    assert main(["tileset", str(photo), "--out", str(out), *args]) == 0
    err = capsys.readouterr().err
    (text,) = [w for w in err.splitlines() if "the tiles show a frame" in w]
    assert "although Flatten lighting is on: try a wider patch search" in text, text
    assert "try Flatten lighting" not in err
    assert (
        text.split("warning: ", 1)[1] in json.loads((out / "manifest.json").read_text())["warnings"]
    )
