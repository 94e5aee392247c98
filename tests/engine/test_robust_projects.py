"""Hostile project files (issue 12: D1, D5, D8, D16, D18): every one is refused as a
ProjectError naming the file and the problem, with memory bounded (tracemalloc in-process, an
address-space limit on the CLI), and the CLI exits 1 with one line."""

from __future__ import annotations

import json
import os
import struct
import zipfile

import numpy as np
import pytest

import engine.project.archive as archive
from engine.png import encode_png
from engine.project import ProjectError, load_project
from tests.engine.hostile import (
    candidate,
    cli,
    png_header,
    project_doc,
    project_zip,
    refused_by,
)

MiB = 2**20
SMALL = encode_png(np.zeros((8, 8, 3), np.uint8))


def refused(path, *reasons, peak_mib: float = 16) -> str:
    return refused_by(load_project, ProjectError, path, reasons, peak_mib)


# ---------------------------------------------------------------- D1: amplification


def amplifier(tmp_path, refs: int = 40):
    """A 43 KB-class project: ``refs`` candidates all naming one PNG entry that declares a
    10000 x 10000 RGB image (it holds a few bytes)."""
    big = png_header(10_000, 10_000)
    doc = project_doc([candidate("images/big.png") for _ in range(refs)], source="images/s.png")
    return project_zip(
        tmp_path / "amp.quiltproj", doc, {"images/big.png": big, "images/s.png": SMALL}
    )


def test_d1_total_decoded_size_is_bounded_before_decoding(tmp_path, monkeypatch):
    path = amplifier(tmp_path)
    assert path.stat().st_size < 50_000
    decoded = []
    monkeypatch.setattr(archive, "decode_png", lambda *a, **k: decoded.append(a) or 1 / 0)
    msg = refused(path, "41 image references (2 distinct images)", "decoded, over the limit")
    assert "44.7 GiB" in msg and not decoded  # nothing was inflated, let alone decoded


def test_d1_cli_refuses_it_under_a_memory_limit(tmp_path):
    path = amplifier(tmp_path)
    res = cli("export", path, "--out", tmp_path / "b", rlimit_as=3 * 2**30)
    assert res.returncode == 1
    assert res.stderr.count("\n") == 1 and "decoded, over the limit of 16.0 GiB" in res.stderr
    assert "Traceback" not in res.stderr and not (tmp_path / "b").exists()


def test_d1_each_entry_is_decoded_once(tmp_path, monkeypatch):
    """Five candidates sharing one image entry: one decode, five independent arrays."""
    doc = project_doc([candidate("images/t.png") for _ in range(5)], source="images/s.png")
    doc["picks"] = [0, 1]
    path = project_zip(
        tmp_path / "shared.quiltproj", doc, {"images/t.png": SMALL, "images/s.png": SMALL}
    )
    calls = []
    real = archive.decode_png
    monkeypatch.setattr(archive, "decode_png", lambda data, **k: calls.append(1) or real(data, **k))
    p = load_project(path)
    assert len(calls) == 2  # the tile and the source entry, once each
    tiles = [c.tile for c in p.candidates]
    assert all(np.array_equal(t, tiles[0]) for t in tiles)
    tiles[0][0, 0, 0] = 0.5  # editing one never changes another
    assert tiles[1][0, 0, 0] == 0.0


def test_d1_budget_of_the_machine_is_respected(tmp_path, monkeypatch):
    """Under the decoded-size limit but over the memory available (a 1 MiB budget here)."""
    monkeypatch.setenv("QUILT_MEMORY_LIMIT", "1M")
    doc = project_doc([candidate("images/t.png")], source="images/t.png")
    big = encode_png(np.zeros((300, 300, 3), np.uint8))
    path = project_zip(tmp_path / "p.quiltproj", doc, {"images/t.png": big})
    refused(path, "opening p.quiltproj needs about", "more than the 1.0 MiB available")


# ---------------------------------------------------------------- D5: zip bombs


def bomb_entry(path, name: str, head: bytes, zeros: int):
    """A zip whose entry ``name`` is ``head`` then ``zeros`` zero bytes, written in chunks."""
    doc = project_doc([candidate(name)], source=name)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("project.json", json.dumps(doc))
        with zf.open(name, "w", force_zip64=True) as f:
            f.write(head)
            block = b"\0" * MiB
            for _ in range(zeros // MiB):
                f.write(block)
    return path


def test_d5_bomb_that_is_not_a_png_is_refused_from_its_first_bytes(tmp_path):
    path = bomb_entry(tmp_path / "bomb.quiltproj", "images/x.png", b"", 64 * MiB)
    assert path.stat().st_size < 1 * MiB
    refused(path, "entry 'images/x.png': not a PNG file (bad signature)", peak_mib=4)


def test_d5_png_header_then_a_flood_is_refused_before_inflating(tmp_path):
    path = bomb_entry(tmp_path / "flood.quiltproj", "images/x.png", SMALL[:33], 64 * MiB)
    refused(path, "more than a 8x8 PNG can hold (possible zip bomb)", peak_mib=4)


def test_d5_entry_inflating_beyond_its_declared_size(tmp_path):
    """The directory says 400 bytes, the deflate stream holds more: the read stops at the cap."""
    path = project_zip(
        tmp_path / "lie.quiltproj",
        project_doc([candidate("images/x.png")], source="images/x.png"),
        {"images/x.png": SMALL + b"\0" * (4 * MiB)},
    )
    data = bytearray(path.read_bytes())
    real = len(SMALL) + 4 * MiB
    for fmt, off in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):
        i = data.rfind(fmt)
        assert struct.unpack("<I", data[i + off : i + off + 4])[0] == real
        data[i + off : i + off + 4] = struct.pack("<I", 400)
    path.write_bytes(bytes(data))
    refused(path, "images/x.png", peak_mib=4)


# ---------------------------------------------------------------- D16: huge JSON lists


def test_d16_huge_json_list_is_refused_before_python_builds_it(tmp_path):
    doc = json.dumps(project_doc([])).encode()
    flood = doc[:-1] + b', "extra": {"list": [' + b"0," * (8 * 2**20) + b"0]}}"
    path = tmp_path / "list.quiltproj"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("project.json", flood)
        zf.writestr("images/s.png", SMALL)
    assert path.stat().st_size < 200_000
    # the parsed list would take 64 MiB of pointers alone; counting needs the 16 MB text and
    # a copy of it with its strings blanked (and bytes for the UTF-8 check), never the list
    refused(
        path, "project.json: it holds about 8,388,6", "over the limit of 2,000,000", peak_mib=56
    )


# ---------------------------------------------------------------- D18: the zip module's ways


def patched_zip(tmp_path, name: str, edit) -> str:
    path = project_zip(
        tmp_path / name, project_doc([candidate("images/s.png")]), {"images/s.png": SMALL}
    )
    data = bytearray(path.read_bytes())
    edit(data)
    path.write_bytes(bytes(data))
    return path


def test_d18_unsupported_zip_version_is_a_project_error(tmp_path):
    def version_ff(data):
        for sig, off in ((b"PK\x01\x02", 6), (b"PK\x03\x04", 4)):
            i = data.find(sig)
            while i >= 0:
                data[i + off] = 0xFF
                i = data.find(sig, i + 4)

    path = patched_zip(tmp_path, "v.quiltproj", version_ff)
    refused(
        path, "the archive is damaged or uses an unsupported zip feature", "NotImplementedError"
    )


def test_d18_empty_entry_name_is_a_project_error(tmp_path):
    def empty_name(data):
        i = data.find(b"PK\x01\x02")  # the central entry of project.json: name length 0
        data[i + 28 : i + 30] = struct.pack("<H", 0)
        data[i + 46 : i + 46 + len("project.json")] = b""

    path = patched_zip(tmp_path, "e.quiltproj", empty_name)
    refused(path)


def test_d18_corrupt_deflate_data_and_memory_error(tmp_path, monkeypatch):
    def flip(data):
        i = data.find(b"project.json") + len("project.json")
        for k in range(i + 5, i + 25):
            data[k] ^= 0x5A

    refused(patched_zip(tmp_path, "z.quiltproj", flip))
    good = project_zip(
        tmp_path / "ok.quiltproj", project_doc([candidate("images/s.png")]), {"images/s.png": SMALL}
    )

    def no_memory(*a, **k):
        raise MemoryError

    monkeypatch.setattr(archive, "decode_png", no_memory)
    refused(good, "there is not enough memory to read it")


@pytest.mark.parametrize(
    "kind, reason",
    [
        ("fifo", r"is a named pipe \(FIFO\)"),
        ("dir", "is a folder, not a project file"),
        ("dev", "is a device"),
    ],
)
def test_project_path_that_is_not_a_file(tmp_path, kind, reason):
    path = tmp_path / "x.quiltproj"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dir":
        path.mkdir()
    else:
        path = "/dev/zero"
    with pytest.raises(ProjectError, match=reason):
        load_project(path)


# ---------------------------------------------------------------- D8: numbers out of range


@pytest.mark.parametrize(
    "field, value, reason",
    [
        ("weight", "1" + "0" * 400, "params.weight must be a finite number >= 0"),  # 10**400
        ("weight", "-1", "params.weight must be a finite number >= 0"),
        ("score", "1e400", "must be finite"),
        ("seed", "1" + "0" * 40, "seed must be an integer in [0, 2**64)"),
    ],
)
def test_d8_numbers_out_of_range_are_refused(tmp_path, field, value, reason):
    doc = project_doc([candidate("images/s.png")])
    text = json.dumps(doc).replace('"locked": false', f'"locked": false, "{field}": {value}')
    if field == "weight":
        text = text.replace(
            '"locked": false,', '"locked": false, "params": {"weight": ' + value + "},"
        )
        text = text.replace(f', "weight": {value}', "")
    path = tmp_path / "n.quiltproj"
    with zipfile.ZipFile(path, "w") as zf:
        zf.writestr("project.json", text)
        zf.writestr("images/s.png", SMALL)
    refused(path, reason)
    if value != "1" + "0" * 400:
        return
    res = cli("export", path, "--out", tmp_path / "b")
    assert res.returncode == 1 and res.stderr.count("\n") == 1, res.stderr
    assert "OverflowError" not in res.stderr and "Traceback" not in res.stderr
