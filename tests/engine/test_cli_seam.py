"""``quilt-studio seam``: output, saved files, errors; once through the installed entry point."""

import json
import shutil
import subprocess
import sys

import numpy as np
import pytest

from engine.cli import main
from engine.errormap import error_map
from engine.io import load_image, save_image
from engine.seams import METHODS, find_seam
from resources import sample_path


@pytest.fixture
def overlap(tmp_path):
    src = load_image(sample_path("cobblestones")).pixels
    r1 = save_image(tmp_path / "r1.png", src[100:164, 40:56])
    r2 = save_image(tmp_path / "r2.png", src[100:164, 200:216])
    return tmp_path, str(r1), str(r2)


def run(capsys, *argv):
    code = main(["seam", *map(str, argv)])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("method", METHODS)
def test_json_output_matches_the_engine(capsys, overlap, method):
    _, r1, r2 = overlap
    code, out, err = run(capsys, r1, r2, "--method", method, "--json")
    assert code == 0 and err == ""
    res = json.loads(out)
    e = error_map(load_image(r1).pixels, load_image(r2).pixels)
    seam = find_seam(e, method=method)
    assert res["method"] == method and res["shape"] == [64, 16]
    assert res["criterion"] == pytest.approx(seam.criterion)
    assert res["peak"] == pytest.approx(seam.peak)
    assert res["path"] == seam.path.tolist()
    assert res["time"] >= 0


def test_text_output_options_and_files(capsys, overlap):
    tmp, r1, r2 = overlap
    code, out, err = run(
        capsys,
        r1,
        r2,
        "--method",
        "oscillating",
        "--o-max",
        2,
        "--metric",
        "lab",
        "--save-mask",
        tmp / "m.png",
        "--save-composite",
        tmp / "c.png",
        "--save-error",
        tmp / "e.png",
    )
    assert code == 0
    assert "criterion" in out and "peak" in out and " ms" in out and "oscillating" in out
    assert out.count("\n") == 1 and "wrote mask" in err
    a, b = load_image(r1).pixels, load_image(r2).pixels
    e = error_map(a, b, metric="lab")
    seam = find_seam(e, method="oscillating", o_max=2)
    assert f"criterion {seam.criterion:.6g}" in out
    mask = load_image(tmp / "m.png").pixels[..., 0] > 0.5
    np.testing.assert_array_equal(mask, seam.mask)
    comp = load_image(tmp / "c.png").pixels
    np.testing.assert_array_equal(comp[mask], a[mask])  # hard cut: exact copies
    np.testing.assert_array_equal(comp[~mask], b[~mask])
    saved_e = load_image(tmp / "e.png")
    assert saved_e.bit_depth == 16 and saved_e.pixels.max() == 1.0
    np.testing.assert_allclose(saved_e.pixels[..., 0] * e.max(), e, rtol=1e-3, atol=1e-3)


def test_blended_composite(capsys, overlap):
    tmp, r1, r2 = overlap
    code, *_ = run(capsys, r1, r2, "--blend", "adaptive", "--save-composite", tmp / "c.png")
    assert code == 0
    comp = load_image(tmp / "c.png").pixels
    a, b = load_image(r1).pixels, load_image(r2).pixels
    assert comp.shape == a.shape and not (np.all(comp == a) or np.all(comp == b))


def test_errors_are_one_clear_line(capsys, overlap):
    tmp, r1, r2 = overlap
    small = save_image(tmp / "small.png", np.zeros((10, 16, 3)))
    code, out, err = run(capsys, r1, small)
    assert code == 1 and out == ""
    assert err.count("\n") == 1 and "must have the same size" in err
    assert "r1.png is 16x64" in err and "small.png is 16x10" in err
    (tmp / "bad.png").write_text("not really a png")
    code, _, err = run(capsys, r1, tmp / "bad.png")
    assert code == 1 and err.count("\n") == 1 and "bad.png: not an image file" in err
    code, _, err = run(capsys, tmp / "missing.png", r2)
    assert code == 1 and "missing.png: no such file" in err
    code, out, err = run(
        capsys, r1, r2, "--save-mask", tmp / "m.png", "--save-error", tmp / "e.jpg"
    )
    assert code == 1 and out == "" and "e.jpg: 16-bit output needs .png or .tif" in err
    assert not (tmp / "m.png").exists()  # refused before the search, nothing written
    code, _, err = run(capsys, r1, r2, "--method", "dp", "--o-max", 3)
    assert code == 1 and "--o-max applies to --method oscillating only" in err
    with pytest.raises(SystemExit):
        main(["seam", r1, r2, "--method", "magic"])


def test_installed_entry_point(overlap):
    _, r1, r2 = overlap
    exe = shutil.which("quilt-studio")
    cmd = [exe] if exe else [sys.executable, "-m", "quilt_gui"]
    done = subprocess.run(
        [*cmd, "seam", r1, r2, "--method", "dp", "--json"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    res = json.loads(done.stdout)
    assert res["method"] == "dp" and len(res["path"]) == 64
    # the time is the search's (~0.02 ms), not numba's kernel load in a fresh process (~0.2 s)
    assert res["time"] < 0.05


def test_seam_cli_pins_waypoints_and_method_options(tmp_path, capsys):
    import json

    import numpy as np

    from engine.cli import main
    from engine.io import save_image

    rng = np.random.default_rng(5)
    r1, r2 = tmp_path / "a.png", tmp_path / "b.png"
    save_image(r1, rng.random((30, 10, 3)))
    save_image(r2, rng.random((30, 10, 3)))
    argv = [str(r1), str(r2), "--json", "--start", "2", "--end", "7", "--waypoint", "15,4"]
    assert main(["seam", *argv, "--method", "oscillating", "--seam-option", "init=argmin"]) == 0
    path = json.loads(capsys.readouterr().out)["path"]
    assert [0, 2] in path  # pinned top (an oscillating row may hold a horizontal run)
    assert [15, 4] in path
    assert path[-1][0] == 29 and [29, 7] in path
    assert main(["seam", str(r1), str(r2), "--seam-option", "bogus=1"]) == 1
    assert "bogus" in capsys.readouterr().err
