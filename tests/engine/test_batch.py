"""The batch's parts without processes: inputs, settings hash, one photo's folder, the index."""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import pytest

from engine.batch import BatchSettings, clean_library, find_photos, photo_seed, plan
from engine.batch.index import index_csv, write_index
from engine.batch.inputs import expand_inputs
from engine.batch.library import COLUMNS, read_library
from engine.batch.task import photo_files, run_photo, store_files
from tests.engine.batch_helpers import SMALL, photo_folders, small, write_bad_photos, write_photos


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A library of 3 photos, a corrupt and a tiny one, made by the local task in-process."""
    root = tmp_path_factory.mktemp("batch")
    paths = [*write_photos(root / "in"), *write_bad_photos(root / "in")]
    photos, _, _ = find_photos([str(root / "in")])
    lib = root / "lib"
    lib.mkdir()
    records = {ph.name: run_photo(ph, SMALL, lib, threads=2) for ph in photos}
    return root, lib, photos, records, paths


def test_inputs_files_folders_globs_once_each(tmp_path):
    a, b, c = write_photos(tmp_path / "in")
    (tmp_path / "in" / "notes.txt").write_text("not a photo")
    files, unmatched = expand_inputs(
        [str(tmp_path / "in"), str(a), str(tmp_path / "in" / "*.png"), str(tmp_path / "x*.jpg")]
    )
    assert sorted(files) == sorted([a, b, c])  # each once, the .txt left out
    assert unmatched == [str(tmp_path / "x*.jpg")]
    assert expand_inputs([str(tmp_path / "missing.png")])[1] == [str(tmp_path / "missing.png")]


def test_photo_key_and_seed_come_from_the_content(tmp_path):
    (a,) = write_photos(tmp_path / "one", names=("brick",))
    copy = tmp_path / "two" / "brick.png"
    copy.parent.mkdir()
    copy.write_bytes(a.read_bytes())
    photos, _, dupes = find_photos([str(a), str(copy)])
    assert len(photos) == 1 and dupes == [(str(copy), str(a))]
    ph = photos[0]
    assert ph.key.startswith("brick-") and ph.key[6:] == ph.digest[:8]
    assert photo_seed(ph.digest, 0) == photo_seed(ph.digest, 0) != photo_seed(ph.digest, 1)


def test_settings_hash_changes_with_what_changes_the_result():
    import pickle

    assert SMALL.digest() == BatchSettings.from_dict(SMALL.to_dict()).digest()
    assert pickle.loads(pickle.dumps(SMALL)) == SMALL  # to worker processes
    assert SMALL.digest() != small(candidates=4).digest()


def test_each_photo_gets_a_complete_folder_or_a_reason(made):
    _, lib, photos, records, _ = made
    assert {r.status for n, r in records.items() if n not in ("corrupt.png", "tiny.png")} == {
        "done"
    }
    assert "truncated or corrupt" in records["corrupt.png"].error
    assert "too small (20x20)" in records["tiny.png"].error
    folders = photo_folders(lib)  # every listed file is there: no torn folder
    assert len(folders) == 5
    done = [b for b in folders.values() if b["status"] == "done"]
    for b in done:
        assert b["settings_hash"] == SMALL.digest()
        assert {"wrap", "detail", "frame", "ring_tone", "duplicates", "lattice"} <= set(
            b["metrics"]
        )
        assert b["metrics"]["tiles"] == 3
        assert {"tile", "thumbnail", "project"} <= set(b["files"])
    assert not [p for p in lib.iterdir() if p.name.startswith(".")]  # no temporaries


def test_project_opens_and_thumbnail_is_small(made):
    from PIL import Image

    from engine.project import load_project

    _, lib, photos, records, _ = made
    e = next(e for e in read_library(lib) if e.name == "brick.png")
    project = load_project(e.file("project"))
    assert len(project.candidates) == 3
    assert max(Image.open(e.file("thumbnail")).size) <= SMALL.thumbnail


def test_plan_skips_done_redoes_changed_keeps_edited(made):
    _, lib, photos, _, _ = made
    work = plan(photos, SMALL, lib)
    assert sorted(p.name for p in work.todo) == ["corrupt.png", "tiny.png"]  # failed: retried
    assert len(work.done) == 3 and not work.edited
    other = small(candidates=4)
    assert len(plan(photos, other, lib).todo) == 5
    e = next(e for e in read_library(lib) if e.name == "gravel.png")
    project = e.file("project")
    saved = project.read_bytes()
    try:
        project.write_bytes(saved + b" ")  # saved from the editor
        work = plan(photos, other, lib)
        assert [p.name for p in work.edited] == ["gravel.png"]
        assert len(plan(photos, other, lib, force=True).todo) == 5
    finally:
        project.write_bytes(saved)


def test_remote_task_makes_the_same_bytes(made, tmp_path):
    _, lib, photos, _, _ = made
    ph = next(p for p in photos if p.name == "lichen.png")
    record, files = photo_files(ph, SMALL, Path(ph.path).read_bytes())
    assert record.status == "done"
    store_files(tmp_path, ph.key, files)
    for name in files:
        if name.endswith((".png", ".quiltproj")):
            assert (tmp_path / ph.key / name).read_bytes() == (lib / ph.key / name).read_bytes()


def test_a_wang_set_per_photo(tmp_path):
    (p,) = write_photos(tmp_path / "in", names=("gravel",))
    (ph,) = find_photos([str(p)])[0]
    record = run_photo(ph, small(wang=2), tmp_path / "lib")
    assert record.status == "done", record.error
    b = photo_folders(tmp_path / "lib")[ph.key]
    assert b["metrics"]["tiles"] == 16 and b["files"]["tile"] == "tile_000.png"
    assert {"frame", "lattice", "duplicates", "detail"} <= set(b["metrics"])
    doc = json.loads((tmp_path / "lib" / ph.key / "manifest.json").read_text())
    assert doc["kind"] == "wang" and len(doc["tiles"]) == 16


def test_flatten_lighting_is_a_setting_of_the_folder(tmp_path):
    (p,) = write_photos(tmp_path / "in", names=("lichen",))
    (ph,) = find_photos([str(p)])[0]
    flat = small(flatten=True)
    assert flat.digest() != SMALL.digest()
    assert run_photo(ph, flat, tmp_path / "lib").status == "done"
    doc = json.loads((tmp_path / "lib" / ph.key / "manifest.json").read_text())
    assert doc["resolved"]["flatten"] is True
    assert doc["batch"]["settings_hash"] == flat.digest()


def test_index_csv_and_html_sorted_failed_and_warned_first(made):
    _, lib, _, _, _ = made
    entries = read_library(lib)
    assert [e.failed for e in entries[:2]] == [True, True]
    warnings = [len(e.warnings) for e in entries[2:]]
    assert warnings == sorted(warnings, reverse=True)
    csv_path, html_path = write_index(lib)
    rows = list(csv.DictReader(csv_path.open()))
    assert [r["photo"] for r in rows] == [e.name for e in entries]
    assert set(k for k, _, _ in COLUMNS) <= set(rows[0])
    assert rows[0]["status"] == "failed" and rows[0]["error"]
    html = html_path.read_text()
    assert "http://" not in html and "https://" not in html  # works offline
    for e in entries:
        assert e.name in html
        if not e.failed:
            assert f'href="{e.key}/{e.key}.quiltproj"' in html
            assert f'src="{e.key}/thumbnail.png"' in html
    assert index_csv([]).startswith("photo,status")


def test_stale_temporaries_of_a_killed_run_are_removed(tmp_path):
    dead = 2**22 + 12345  # no such process
    (tmp_path / f".brick-1234.tmp-{dead}-abc123").mkdir()
    (tmp_path / f".brick-1234.tmp-{dead}-abc123" / "tile_000.png").write_bytes(b"x")
    (tmp_path / f".index.csv.{dead}-k2j3h4.tmp").write_bytes(b"x")
    live = tmp_path / f".other.tmp-{os.getpid()}-zz"
    live.mkdir()
    removed = clean_library(tmp_path)
    assert len(removed) == 2 and live.exists()


def test_manifest_records_the_photo_and_settings(made):
    _, lib, photos, _, _ = made
    ph = next(p for p in photos if p.name == "brick.png")
    doc = json.loads((lib / ph.key / "manifest.json").read_text())
    b = doc["batch"]
    assert b["photo"]["sha256"] == ph.digest and b["photo"]["path"] == ph.path
    assert b["settings"] == SMALL.to_dict()
    assert b["seed"] == photo_seed(ph.digest, SMALL.tileset.seed)


def test_a_zombie_process_counts_as_gone(tmp_path):
    """A worker killed with its batch stays a zombie until reaped: its temporary is stale."""
    import subprocess
    import sys
    import time

    from engine._fs import clean_stale

    child = subprocess.Popen([sys.executable, "-c", "pass"])
    try:
        while (
            not Path(f"/proc/{child.pid}").exists()
            or b") Z" not in Path(f"/proc/{child.pid}/stat").read_bytes()
        ):
            time.sleep(0.01)
            if not Path("/proc/self/stat").exists():
                pytest.skip("no /proc")
        (tmp_path / f".photo.tmp-{child.pid}-abc").mkdir()
        assert clean_stale(tmp_path, "photo") == [tmp_path / f".photo.tmp-{child.pid}-abc"]
    finally:
        child.wait()


def test_a_photo_changed_since_replaces_its_old_folder(tmp_path):
    from engine.batch import remove_superseded

    a, _ = write_photos(tmp_path / "in", names=("brick", "gravel"))
    lib = tmp_path / "lib"
    old = {p.name: p.key for p in find_photos([str(tmp_path / "in")])[0]}
    for ph in find_photos([str(tmp_path / "in")])[0]:
        run_photo(ph, SMALL, lib)
    a.write_bytes(write_photos(tmp_path / "other", names=("lichen",))[0].read_bytes())
    photos = find_photos([str(tmp_path / "in")])[0]
    new = next(p for p in photos if p.name == "brick.png")
    assert new.key != old["brick.png"]
    run_photo(new, SMALL, lib)
    assert remove_superseded(lib, photos) == [old["brick.png"]]
    assert sorted(photo_folders(lib)) == sorted([new.key, old["gravel.png"]])


def test_a_non_stationary_photo_is_done_and_flagged(tmp_path):
    import numpy as np
    from PIL import Image

    from engine.batch.quality import detail_spread
    from engine.io import load_image
    from engine.tiles.stationarity import DETAIL_LIMIT
    from resources import SAMPLE_NAMES, sample_path

    for name in SAMPLE_NAMES:  # stationary textures stay under the limit
        assert detail_spread(load_image(sample_path(name)).pixels) < DETAIL_LIMIT
    (p,) = write_photos(tmp_path / "in", names=("gravel",))
    a = np.asarray(Image.open(p).convert("RGB")).copy()
    a[:, a.shape[1] // 2 :] = np.linspace(90, 110, a.shape[1] - a.shape[1] // 2)[None, :, None]
    Image.fromarray(a).save(p)  # half gravel, half a smooth wall
    (ph,) = find_photos([str(p)])[0]
    record = run_photo(ph, SMALL, tmp_path / "lib")
    assert record.status == "done", record.error  # the set is made, the photo flagged
    assert record.metrics["spread"] > DETAIL_LIMIT
    assert any("sharpness varies" in w for w in record.warnings)  # the search's warning
    (e,) = read_library(tmp_path / "lib")
    assert e.text("spread") == f"{record.metrics['spread']:.1f}"
    write_index(tmp_path / "lib")
    html = (tmp_path / "lib" / "index.html").read_text()
    assert "Detail spread" in html and "sharpness varies" in html
    assert 'data-k="warning_count"' not in html  # listed in the warnings column: fits 1400 px
