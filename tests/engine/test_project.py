"""Project files: exact round trip, atomic save, and every way a file can be hostile or broken."""

from __future__ import annotations

import json
import os
import struct
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest

import engine.project.archive as project_mod
from engine.candidate import CandidateTile
from engine.png import encode_png
from engine.project import (
    Project,
    ProjectError,
    export_project,
    load_project,
    newer_recovery,
    project_from_tileset,
    recovery_path,
    save_project,
)


def make_project(bit_depth=16, rng=0) -> Project:
    g = np.random.default_rng(rng)
    top = 65535 if bit_depth == 16 else 255
    dt = np.uint16 if bit_depth == 16 else np.uint8
    albedo = g.integers(0, top + 1, (48, 40, 3)).astype(dt)
    normal = g.integers(0, top + 1, (48, 40, 3)).astype(dt)
    height = g.integers(0, top + 1, (48, 40, 1)).astype(dt)
    src = {"albedo": albedo, "normal": normal, "height": height}
    tiles = [{m: a[i : i + 16, 2 * i : 2 * i + 12] for m, a in src.items()} for i in range(5)]
    return project_from_tileset(
        sources=src,
        tiles=tiles,
        name="rock",
        template={m: a[:16, :12] for m, a in src.items()},
        template_rect=(3, 4, 12, 16),
        patch_origins=[(i, i + 1) for i in range(5)],
        seeds=[10, 11, 12, 13, 14],
        scores=[0.5, 0.25, 1.0, 2.0, 0.125],
        locked=[False, True, False, False, True],
        picks=[4, 0, 2],
        layout=[[0, 1, 2], [2, -1, 0]],
        parameters={"tileset": {"n": 5, "method": "dp", "rho": 3.0}},
        project_seeds={"template": 1, "candidates": 2},
        bit_depth=bit_depth,
        source_paths={"albedo": "/photos/rock.png"},
        map_weights={"albedo": 1.0, "height": 0.5},
        normal_convention="directx",
        waypoints={"candidate:1": [(3, 4), (9, 5)]},
        extra={"editor": {"zoom": 2.0}},
    )


def assert_same(a: Project, b: Project):
    for f in (
        "name",
        "version",
        "source_paths",
        "map_kinds",
        "map_weights",
        "normal_convention",
        "bit_depth",
        "parameters",
        "seeds",
        "template_rect",
        "picks",
        "waypoints",
        "extra",
    ):
        assert getattr(a, f) == getattr(b, f), f
    assert list(a.sources) == list(b.sources)
    for m in a.sources:
        assert a.sources[m].dtype == b.sources[m].dtype == np.float32
        assert np.array_equal(a.sources[m], b.sources[m]), m
        assert np.array_equal(a.template[m], b.template[m])
    assert np.array_equal(a.layout, b.layout)
    assert len(a.candidates) == len(b.candidates)
    for ca, cb in zip(a.candidates, b.candidates, strict=True):
        fields = ("index", "patch_origin", "patch_rect", "target_rect", "seed", "locked")
        fields += ("weight", "scores", "score")
        assert [getattr(ca, f) for f in fields] == [getattr(cb, f) for f in fields]
        assert (ca.loop is None) == (cb.loop is None)
        assert ca.loop is None or np.array_equal(ca.loop, cb.loop)
        assert list(ca.maps) == list(cb.maps) and np.array_equal(ca.tile, cb.tile)
        for m in ca.maps:
            assert np.array_equal(ca.maps[m], cb.maps[m])


@pytest.mark.parametrize("bit_depth", [8, 16])
def test_round_trip_is_exact(tmp_path, bit_depth):
    p = make_project(bit_depth)
    save_project(tmp_path / "a.quiltproj", p)
    q = load_project(tmp_path / "a.quiltproj")
    assert_same(p, q)
    top = 65535 if bit_depth == 16 else 255
    k = np.round(q.sources["albedo"] * top)
    assert np.array_equal(k, np.round(p.sources["albedo"] * top)) and k.max() > 255 * (
        bit_depth == 16
    )
    # saving the loaded project gives the same bytes (deterministic archive)
    save_project(tmp_path / "b.quiltproj", q)
    assert (tmp_path / "a.quiltproj").read_bytes() == (tmp_path / "b.quiltproj").read_bytes()


def test_save_load_export_gives_byte_identical_tiles(tmp_path):
    p = make_project(16)
    direct, reloaded = tmp_path / "a" / "bundle", tmp_path / "b" / "bundle"
    m1 = export_project(p, direct, spacing=1, extrude=1)
    save_project(tmp_path / "p.quiltproj", p)
    m2 = export_project(load_project(tmp_path / "p.quiltproj"), reloaded, spacing=1, extrude=1)
    assert m1 == m2
    files = sorted(os.listdir(direct))
    assert files == sorted(os.listdir(reloaded)) and len(files) > 15
    for f in files:
        assert (direct / f).read_bytes() == (reloaded / f).read_bytes(), f
    assert m1["bit_depth"] == 16 and m1["tile_count"] == 3
    assert [t["source_rect"]["candidate"] for t in m1["tiles"]] == [4, 0, 2]
    assert m1["seeds"]["tiles"] == [14, 10, 12] and m1["scores"] == [0.125, 0.5, 1.0]
    assert m1["normal_convention"] == "directx"


def test_save_is_atomic(tmp_path, monkeypatch):
    path = tmp_path / "p.quiltproj"
    save_project(path, make_project(8, rng=1))
    before = path.read_bytes()

    def fail_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail_replace)
    with pytest.raises(ProjectError, match="cannot save") as info:
        save_project(path, make_project(8, rng=2))
    assert str(path) in str(info.value)
    assert path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["p.quiltproj"]  # no temporary file left


def test_invalid_project_is_refused_before_writing(tmp_path):
    p = make_project(8)
    p.picks = [0, 9]
    with pytest.raises(ProjectError, match="picks"):
        save_project(tmp_path / "x.quiltproj", p)
    assert not (tmp_path / "x.quiltproj").exists()
    with pytest.raises(ValueError, match="one entry per tile"):
        project_from_tileset(sources=np.zeros((8, 8)), tiles=[np.zeros((4, 4))], seeds=[1, 2])


# ------------------------------------------------------------------ hostile and broken files


def rewrite(src: Path, dst: Path, *, doc_edit=None, entries=None, drop=()):
    """Copy a project zip changing project.json and/or adding raw entries."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            if info.filename in drop:
                continue
            data = zin.read(info)
            if info.filename == "project.json" and doc_edit is not None:
                doc = json.loads(data)
                doc_edit(doc)
                data = json.dumps(doc).encode()
            zout.writestr(info.filename, data)
        for name, data in (entries or {}).items():
            zout.writestr(name, data)
    return dst


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    path = tmp_path_factory.mktemp("good") / "good.quiltproj"
    save_project(path, make_project(8))
    return path


def expect_refused(path, *patterns):
    with pytest.raises(ProjectError) as info:
        load_project(path)
    msg = str(info.value)
    assert msg.startswith(str(path)), msg
    for pat in patterns:
        assert pat in msg, msg
    return msg


@pytest.mark.parametrize(
    "entry",
    [
        "../evil.png",
        "/abs/evil.png",
        "images/../../evil.png",
        "C:/evil.png",
        "images\\evil.png",
        "./x.png",
    ],
)
def test_entries_escaping_the_archive_are_refused(tmp_path, good, entry):
    bad = rewrite(good, tmp_path / "bad.quiltproj", entries={entry: b"x"})
    expect_refused(bad, "unsafe path")


def test_json_image_reference_escaping_is_refused(tmp_path, good):
    def edit(doc):
        doc["sources"]["albedo"] = "../../etc/passwd"

    expect_refused(
        rewrite(good, tmp_path / "b.quiltproj", doc_edit=edit), "not a safe archive path"
    )


def test_truncated_zip_is_refused(tmp_path, good):
    data = good.read_bytes()
    for cut in (len(data) // 2, len(data) - 10, 100):
        bad = tmp_path / f"t{cut}.quiltproj"
        bad.write_bytes(data[:cut])
        expect_refused(bad, "truncated")


def test_corrupt_entry_is_refused(tmp_path, good):
    data = bytearray(good.read_bytes())
    with zipfile.ZipFile(good) as zf:
        info = zf.getinfo("images/source_albedo.png")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra) + 40
    data[start : start + 20] = bytes(20)  # flip payload bytes: CRC no longer matches
    bad = tmp_path / "c.quiltproj"
    bad.write_bytes(bytes(data))
    expect_refused(bad, "images/source_albedo.png")


@pytest.mark.parametrize(
    "edit,pattern",
    [
        (lambda d: d.pop("candidates"), "missing key 'candidates'"),
        (lambda d: d.pop("maps"), "missing key 'maps'"),
        (lambda d: d["candidates"][0].pop("images"), "missing key candidates[0].images"),
        (lambda d: d.__setitem__("picks", ["a"]), "picks"),
        (lambda d: d.__setitem__("bit_depth", "16"), "bit_depth must be int"),
        (lambda d: d.__setitem__("bit_depth", 12), "bit_depth must be 8 or 16"),
        (lambda d: d["candidates"][1].__setitem__("locked", "yes"), "candidates[1].locked"),
        (lambda d: d["candidates"][1].__setitem__("seed", 1.5), "candidates[1].seed"),
        (lambda d: d["candidates"][1].__setitem__("seed", -1), "candidates[1].seed"),
        (lambda d: d["candidates"][1].__setitem__("seed", 2**64), "candidates[1].seed"),
        (lambda d: d["candidates"][1].__setitem__("score", 10**400), "candidates[1].score"),
        (lambda d: d["candidates"][1].__setitem__("score", float("nan")), "NaN is not a JSON"),
        (lambda d: d["parameters"].__setitem__("x", float("-inf")), "-Infinity is not a JSON"),
        (lambda d: d.__setitem__("map_weights", {"albedo": 10**400}), "map_weights"),
        (lambda d: d.__setitem__("layout", [[0, 1], [2]]), "layout"),
        (lambda d: d.__setitem__("layout", [[0, 7]]), "layout cells"),
        (lambda d: d.__setitem__("template_rect", [1, 2, 3]), "template_rect"),
        (lambda d: d.__setitem__("normal_convention", "vulkan"), "normal_convention"),
        (lambda d: d.__setitem__("version", 99), "newer Quilt Studio"),
        (lambda d: d.__setitem__("format", "zip"), "format"),
        (lambda d: d.__setitem__("maps", ["albedo", "normal"]), "sources must map exactly"),
        (
            lambda d: d["sources"].__setitem__("normal", "images/missing.png"),
            "missing from the archive",
        ),
        (
            lambda d: d["candidates"][0]["images"].__setitem__(
                "albedo", "images/source_albedo.png"
            ),
            "candidates[0]",
        ),
    ],
)
def test_wrong_types_and_missing_keys_are_refused(tmp_path, good, edit, pattern):
    expect_refused(rewrite(good, tmp_path / "b.quiltproj", doc_edit=edit), pattern)


def test_not_json_and_not_zip(tmp_path, good):
    bad = tmp_path / "nj.quiltproj"
    with zipfile.ZipFile(bad, "w") as zf:
        zf.writestr("project.json", b"{not json")
    expect_refused(bad, "not valid JSON")
    deep = tmp_path / "deep.quiltproj"  # 1 MB of brackets: Python's parser would recurse out
    with zipfile.ZipFile(deep, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("project.json", b"[" * 2**19 + b"]" * 2**19)
    expect_refused(deep, "nested too deeply")
    (tmp_path / "plain.quiltproj").write_text("hello")
    expect_refused(tmp_path / "plain.quiltproj", "not a zip")
    (tmp_path / "empty.quiltproj").write_bytes(b"")
    expect_refused(tmp_path / "empty.quiltproj", "empty")
    expect_refused(tmp_path / "missing.quiltproj", "no such file")
    expect_refused(
        rewrite(good, tmp_path / "nojson.quiltproj", drop=("project.json",)), "missing project.json"
    )


def test_oversized_entries_are_refused(tmp_path, good, monkeypatch):
    # a real zip bomb in miniature: 64 MB of zeros deflates to ~64 kB
    bomb = rewrite(
        good, tmp_path / "bomb.quiltproj", entries={"images/bomb.bin": b"\0" * (64 * 2**20)}
    )
    assert bomb.stat().st_size < 2**20
    monkeypatch.setattr(project_mod, "MAX_ENTRY_BYTES", 16 * 2**20)
    with pytest.raises(ProjectError, match="over the limit"):
        load_project(bomb, max_entry_bytes=16 * 2**20)
    with pytest.raises(ProjectError, match="uncompressed bytes, over the limit"):
        load_project(good, max_total_bytes=1000)


def test_lying_declared_size_is_refused(tmp_path, good):
    """An entry whose central directory claims a small size but inflates to more is refused."""
    data = bytearray(good.read_bytes())
    with zipfile.ZipFile(good) as zf:
        info = zf.getinfo("project.json")
    # patch the uncompressed size (offset 24) in the central directory record of project.json
    pos = data.find(b"PK\x01\x02")
    while pos >= 0:
        n = struct.unpack("<H", data[pos + 28 : pos + 30])[0]
        if data[pos + 46 : pos + 46 + n] == b"project.json":
            data[pos + 24 : pos + 28] = struct.pack("<I", 50)
            break
        pos = data.find(b"PK\x01\x02", pos + 4)
    assert pos >= 0 and info.file_size > 50
    bad = tmp_path / "lie.quiltproj"
    bad.write_bytes(bytes(data))
    expect_refused(bad, "project.json")


def test_png_declaring_a_huge_image_is_refused_before_inflating(tmp_path, good):
    ihdr = struct.pack(">IIBBBBB", 60000, 60000, 8, 2, 0, 0, 0)

    def chunk(tag, body):
        return (
            struct.pack(">I", len(body))
            + tag
            + body
            + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)
        )

    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", ihdr)
        + chunk(b"IDAT", zlib.compress(b"\0" * 1000))
        + chunk(b"IEND", b"")
    )

    def edit(doc):
        doc["sources"]["albedo"] = "images/huge.png"

    bad = rewrite(
        good, tmp_path / "huge.quiltproj", doc_edit=edit, entries={"images/huge.png": png}
    )
    expect_refused(bad, "images/huge.png", "over the limit")


def test_image_of_wrong_size_or_channels_is_refused(tmp_path, good):
    def edit(doc):
        doc["sources"]["height"] = "images/odd.png"

    bad = rewrite(
        good,
        tmp_path / "odd.quiltproj",
        doc_edit=edit,
        entries={"images/odd.png": encode_png(np.zeros((5, 5), np.uint8))},
    )
    expect_refused(bad, "height")


def test_candidate_defaults_and_what_a_project_keeps_of_it(tmp_path):
    c = CandidateTile(index=0, tile=np.zeros((2, 2, 3), np.float32))
    assert c.patch_origin is None and not c.locked and c.weight == 1.0 and c.score is None
    p = make_project(8)
    made = p.candidates[1].replace(
        scores={"criterion": 6.0, "peak": 1.5},
        loop=np.array([[0, 0], [0, 1], [1, 1]]),
        patch_rect=(1, 2, 12, 16),
        target_rect=(0, 0, 12, 16),
        mask=np.ones((16, 12), bool),
        weight=2.5,
    )
    assert made.score == 2.0  # mean error per loop pixel
    p.candidates[1] = made
    save_project(tmp_path / "c.quiltproj", p)
    back = load_project(tmp_path / "c.quiltproj").candidates[1]
    assert back.mask is None and back.alpha is None  # not kept
    assert (back.score, back.weight, back.patch_rect) == (2.0, 2.5, (1, 2, 12, 16))
    assert np.array_equal(back.loop, made.loop) and back.scores == made.scores


def test_recovery_file(tmp_path):
    path = tmp_path / "work.quiltproj"
    assert recovery_path(path) == tmp_path / ".work.recovery.quiltproj"
    assert newer_recovery(path) is None
    save_project(path, make_project(8))
    assert newer_recovery(path) is None
    save_project(recovery_path(path), make_project(8, rng=5))
    os.utime(path, ns=(1, 1))
    assert newer_recovery(path) == recovery_path(path)
    assert_same(load_project(newer_recovery(path)), make_project(8, rng=5))
    os.utime(recovery_path(path), ns=(0, 0))
    assert newer_recovery(path) is None


def test_candidate_weights_become_tile_probabilities(tmp_path):
    p = make_project(8)
    p.candidates = [c.replace(weight=i + 0.5) for i, c in enumerate(p.candidates)]
    man = export_project(p, tmp_path / "w")
    assert [t["weight"] for t in man["tiles"]] == [4.5, 0.5, 2.5]  # picks 4, 0, 2
    assert 'probability="4.5"' in (tmp_path / "w" / "rock.tsx").read_text()
