"""Outputs and options (issue 12: D2, D6, D7, D9, D10, D11, D13, D15, D17): the user's files
are never deleted or replaced, every output size is checked before any work, folders appear
whole or not at all, leftovers of killed runs are cleaned, messages name what is wrong."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import engine.cli.tileset as tileset_cli
import resources
from engine._fs import atomic_path, clean_stale
from engine.cli import main
from engine.io import load_image, save_image
from engine.png import encode_png
from tests.engine.hostile import peak_traced

MiB = 2**20
TILESET = ["--candidates", "3", "--tile-min", "24", "--preview", "2x2", "--seed", "1"]


@pytest.fixture(scope="module")
def sample(tmp_path_factory):
    d = tmp_path_factory.mktemp("sample")
    S = load_image(resources.sample_path("cobblestones")).pixels[:72, :80]
    path = d / "sample.png"
    path.write_bytes(encode_png(np.round(S * 255).astype(np.uint8)))
    return path


@pytest.fixture(scope="module")
def project(sample, tmp_path_factory):
    d = tmp_path_factory.mktemp("project")
    assert main(["tileset", str(sample), "--out", str(d / "set"), *TILESET,
                 "--project", str(d / "set.quiltproj")]) == 0  # fmt: skip
    return d / "set.quiltproj"


def run(capsys, *argv) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def snapshot(folder):
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


# ---------------------------------------------------------------- D2: overwrite


def test_d2_export_never_touches_the_project_or_unknown_files(project, tmp_path, capsys):
    home = tmp_path / "home"
    home.mkdir()
    proj = home / "set.quiltproj"
    proj.write_bytes(project.read_bytes())
    (home / "notes.txt").write_text("mine")
    before = snapshot(home)
    # the folder holding the project: refused even with --overwrite
    code, err = run(capsys, "export", proj, "--out", home, "--overwrite")
    assert code == 1 and f"it holds the input {proj}, which must never be replaced" in err
    assert snapshot(home) == before
    # a bundle folder a user added a file to: refused, both kept
    out = tmp_path / "bundle"
    assert run(capsys, "export", proj, "--out", out)[0] == 0
    (out / "readme.txt").write_text("my notes")
    bundle = snapshot(out)
    code, err = run(capsys, "export", proj, "--out", out, "--overwrite")
    assert code == 1 and "it holds readme.txt, not written by Quilt Studio" in err
    assert err.count("\n") == 1 and snapshot(out) == bundle
    # only an earlier bundle there: replaced, and files of the old bundle not in the new go
    (out / "readme.txt").unlink()
    assert run(capsys, "export", proj, "--out", out, "--overwrite", "--name", "other")[0] == 0
    names = set(os.listdir(out))
    assert "other.json" in names and not any(n.startswith("tileset") for n in names)
    assert json.loads((out / "other.json").read_text())["files"] == sorted(names)


def test_d2_gui_style_export_into_a_folder_of_user_files(project, tmp_path):
    from engine.export import ExportError
    from engine.project import export_project, load_project

    (tmp_path / "photo.png").write_bytes(b"precious")
    with pytest.raises(ExportError, match="it holds photo.png, not written by Quilt Studio"):
        export_project(load_project(project), tmp_path, overwrite=True)
    assert (tmp_path / "photo.png").read_bytes() == b"precious"


# ---------------------------------------------------------------- D6: output sizes


@pytest.mark.parametrize("option", ["--spacing", "--margin", "--extrude"])
def test_d6_export_atlas_size_is_checked_before_any_work(project, tmp_path, capsys, option):
    with peak_traced() as mem:
        code, err = run(capsys, "export", project, "--out", tmp_path / "b", option, "100000")
    assert code == 1 and "over the limit of 16384 px per side" in err and err.count("\n") == 2
    assert mem["peak"] < 64 * MiB and not (tmp_path / "b").exists()


def test_d6_tileset_preview_and_synth_size(sample, tmp_path, capsys):
    with peak_traced() as mem:
        code, err = run(capsys, "tileset", sample, "--out", tmp_path / "t", "--preview",
                        "100000x100000")  # fmt: skip
    assert code == 1 and "--preview 100000x100000: a preview of tiles up to" in err
    assert "over the limit of 67,108,864 pixels" in err and "candidate" not in err
    assert mem["peak"] < 64 * MiB and not (tmp_path / "t").exists()
    with pytest.raises(SystemExit) as info:
        main(["synth", str(sample), "--size", "100000x100000", "--block", "16", "-o", "x.png"])
    assert info.value.code == 2
    assert "100000x100000 is over the output limit of 268,435,456 pixels" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["synth", str(sample), "--size", "64x64", "--block", "16", "--threads", "100000",
              "-o", "x.png"])  # fmt: skip
    assert "--threads: must be at most 256" in capsys.readouterr().err


def test_d6_wang_preview_and_memory_are_checked_before_any_work(
    sample, tmp_path, capsys, monkeypatch
):
    args = ["tileset", sample, "--out", tmp_path / "t", "--wang", "2", "--tile-size", "32"]
    code, err = run(capsys, *args, "--preview", "100000x100000")
    assert code == 1 and "--preview 100000x100000: a preview of tiles up to 32x32" in err
    assert "edge sample" not in err and not (tmp_path / "t").exists()
    monkeypatch.setenv("QUILT_MEMORY_LIMIT", "1M")
    code, err = run(capsys, *args)
    assert code == 1 and "a tile set from this" in err and "fewer tiles" in err
    assert "edge sample" not in err and not (tmp_path / "t").exists()


def test_d6_default_preview_shrinks_to_the_limit_with_a_warning(
    sample, tmp_path, capsys, monkeypatch
):
    monkeypatch.setattr("engine.export.MAX_PREVIEW_PIXELS", 60 * 60)
    code, err = run(capsys, "tileset", sample, "--out", tmp_path / "t", "--candidates", "2",
                    "--tile-min", "24")  # fmt: skip
    assert code == 0 and "warning: the 8x8 preview of tiles up to 24x24 would be" in err
    assert "using 2x2 (--preview sets it)" in err


# ---------------------------------------------------------------- D7 / D9 / D13: whole folders


def test_d7_full_disk_while_writing_the_set_keeps_the_previous_one(sample, tmp_path, capsys,
                                                                   monkeypatch):  # fmt: skip
    out = tmp_path / "set"
    assert run(capsys, "tileset", sample, "--out", out, *TILESET)[0] == 0
    before = snapshot(out)
    real = tileset_cli.write_images
    calls = []

    def full_after_two(folder, stem, images, depth):
        calls.append(stem)
        if len(calls) > 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(folder, stem, images, depth)

    monkeypatch.setattr(tileset_cli, "write_images", full_after_two)
    code, err = run(capsys, "tileset", sample, "--out", out, *TILESET, "--seed", "2")
    assert code == 1
    assert err.splitlines()[-1] == (
        f"quilt-studio tileset: error: cannot write the tile set to {out}: the disk is full; "
        "nothing was written"
    )
    assert snapshot(out) == before
    assert sorted(os.listdir(tmp_path)) == ["set"]  # no temporary folder left


def test_d9_fewer_candidates_leave_no_stale_tiles(sample, tmp_path, capsys):
    out = tmp_path / "set"
    proj = out / "set.quiltproj"
    assert run(capsys, "tileset", sample, "--out", out, *TILESET, "--candidates", "5",
               "--project", proj)[0] == 0  # fmt: skip
    assert {f"tile_{i:03d}.png" for i in range(5)} <= set(os.listdir(out)) and proj.exists()
    assert run(capsys, "tileset", sample, "--out", out, *TILESET, "--candidates", "2")[0] == 0
    names = set(os.listdir(out))
    assert names == set(json.loads((out / "manifest.json").read_text())["files"])
    assert "tile_002.png" not in names and "set.quiltproj" not in names
    # a user file in the folder: the set is not written there, and the file stays
    (out / "mine.txt").write_text("x")
    code, err = run(capsys, "tileset", sample, "--out", out, *TILESET)
    assert code == 1 and "it holds mine.txt, not written by Quilt Studio" in err
    assert "template:" not in err and (out / "mine.txt").read_text() == "x"


def test_d13_the_current_folder_is_never_swapped(project, sample, tmp_path, capsys, monkeypatch):
    out = tmp_path / "b"
    assert run(capsys, "export", project, "--out", out)[0] == 0
    before = snapshot(out)
    monkeypatch.chdir(out)
    code, err = run(capsys, "export", project, "--out", ".", "--overwrite")
    assert code == 1 and "cannot export to .: it is the current folder" in err
    assert snapshot(out) == before and sorted(os.listdir(tmp_path)) == ["b"]
    code, err = run(capsys, "tileset", sample, "--out", ".", *TILESET)
    assert code == 1 and "it is the current folder" in err
    assert snapshot(out) == before and sorted(os.listdir(tmp_path)) == ["b"]


def test_d13_out_inside_the_source_folder_is_refused(sample, tmp_path, capsys):
    code, err = run(capsys, "tileset", sample, "--out", sample.parent, *TILESET)
    assert code == 1 and f"it holds the input {sample}" in err


# ---------------------------------------------------------------- D10: leftovers of kill -9


def dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_d10_stale_temporaries_of_killed_runs_are_cleaned(project, tmp_path, capsys):
    pid = dead_pid()
    out = tmp_path / "b"
    (tmp_path / f".b.tmp-{pid}-abcd1234").mkdir()  # a killed export's half-written bundle
    (tmp_path / f".b.tmp-{pid}-abcd1234" / "x_000_albedo.png").write_bytes(b"half")
    live = tmp_path / f".b.tmp-{os.getpid()}-live0000"  # a running export's: kept
    live.mkdir()
    other = tmp_path / ".notes.txt.swp"  # not ours: kept
    other.write_text("x")
    assert run(capsys, "export", project, "--out", out)[0] == 0
    assert sorted(os.listdir(tmp_path)) == sorted(["b", live.name, other.name])
    # killed between the two renames of a swap: the old bundle comes back
    old = tmp_path / f".c.old-{pid}-efgh5678"
    (old / "bundle").mkdir(parents=True)
    (old / "bundle" / "c.json").write_text("{}")
    clean_stale(tmp_path, "c")
    assert (tmp_path / "c" / "c.json").exists() and not old.exists()


def test_d10_stale_temporary_files_of_atomic_writes(tmp_path):
    pid = dead_pid()
    stale = tmp_path / f".o.png.{pid}-k2j4h5g6.png"
    stale.write_bytes(b"half an image")
    aged = tmp_path / f".o.png.{os.getpid() + 1}-aaaaaaaa.png"  # any pid, older than a day
    aged.write_bytes(b"x")
    os.utime(aged, (time.time() - 2 * 86400,) * 2)
    save_image(tmp_path / "o.png", np.zeros((4, 4, 3)))
    assert sorted(os.listdir(tmp_path)) == ["o.png"]
    with atomic_path(tmp_path / "o.png") as tmp:  # our own temporary is ours, not stale
        assert tmp.name.startswith(f".o.png.{os.getpid()}-")
        assert clean_stale(tmp_path, "o.png") == []
        tmp.write_bytes(b"new")
    assert (tmp_path / "o.png").read_bytes() == b"new"


# ---------------------------------------------------------------- D11: unwritable outputs


def test_d11_unwritable_output_is_found_before_the_work(sample, tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    for argv in (
        ["synth", sample, "--size", "64x64", "--block", "16"],
        ["transfer", sample, sample, "--block", "16"],
        ["heal", sample, sample],
    ):
        t0 = time.perf_counter()
        code, err = run(capsys, *argv, "-o", blocker / "out.png")
        assert code == 1, err
        assert err.strip().endswith(
            f"{blocker / 'out.png'}: cannot write ({blocker} is a file, not a folder)"
        )
        assert err.count("\n") == 1  # no progress line: refused before the work
        assert time.perf_counter() - t0 < 30
    (tmp_path / "dir.png").mkdir()
    code, err = run(capsys, "synth", sample, "--size", "64x64", "--block", "16", "-o",
                    tmp_path / "dir.png")  # fmt: skip
    assert code == 1 and "dir.png: is a folder; give a file name for the output" in err


def test_d11_read_only_file_system(sample, tmpfs, capsys):
    ro = tmpfs("ro", "size=64k,ro")
    code, err = run(capsys, "synth", sample, "--size", "64x64", "--block", "16", "-o", ro / "o.png")
    assert code == 1 and "cannot write (read-only file system)" in err and err.count("\n") == 1
    code, err = run(capsys, "tileset", sample, "--out", ro / "set", *TILESET)
    assert code == 1 and "cannot write there (read-only file system)" in err


# ---------------------------------------------------------------- D17 and other options


def test_d17_min_block_larger_than_block(sample, tmp_path, capsys):
    code, err = run(capsys, "synth", sample, "--size", "64x64", "--block", "16", "--min-block",
                    "20", "-o", tmp_path / "o.png")  # fmt: skip
    assert code == 1
    assert "min_block (20) is larger than the block (16x16)" in err and err.count("\n") == 1
    assert not (tmp_path / "o.png").exists()


# ---------------------------------------------------------------- D15: messages


def test_d15_output_folder_that_is_a_link_loop(project, tmp_path, capsys):
    loop = tmp_path / "loop"
    loop.symlink_to(tmp_path / "loop2")
    (tmp_path / "loop2").symlink_to(loop)
    code, err = run(capsys, "export", project, "--out", loop)
    assert code == 1 and err.strip().endswith(
        f"cannot export to {loop}: it is a symbolic link loop"
    )


def test_d15_a_bug_is_one_line_naming_it_and_debug_shows_the_traceback(
    sample, tmp_path, capsys, monkeypatch
):
    import engine.cli.seam as seam_cli

    def broken(args):
        raise KeyError("albedo")

    monkeypatch.setattr(seam_cli, "run", broken)
    code, err = run(capsys, "seam", sample, sample)
    assert code == 1 and err.count("\n") == 1
    assert "quilt-studio seam: internal error, please report it: KeyError: 'albedo'" in err
    monkeypatch.setenv("QUILT_DEBUG", "1")
    with pytest.raises(KeyError):
        main(["seam", str(sample), str(sample)])
