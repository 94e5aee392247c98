"""Settings, parameters table, document and undo commands (no windows)."""

from __future__ import annotations

import numpy as np
import pytest

from engine.candidate import CandidateTile
from quilt_gui import params, project_io, settings
from quilt_gui.commands import new_merge_id
from quilt_gui.document import Document
from quilt_gui.model import Source


def test_settings_typed_defaults_and_unknown_keys():
    assert settings.get("theme") == "dark"
    assert settings.get("recent_files") == []
    settings.set("autosave_seconds", "42")
    assert settings.get("autosave_seconds") == 42
    settings.set("heat_overlay", False)
    assert settings.get("heat_overlay") is False
    settings.set("parameters", {"block": 32})
    assert settings.get("parameters") == {"block": 32}
    with pytest.raises(KeyError):
        settings.get("no_such_key")
    with pytest.raises(KeyError):
        settings.set("no_such_key", 1)
    settings.reset()
    assert settings.get("autosave_seconds") == settings.DEFAULTS["autosave_seconds"]


def test_recent_files_unique_newest_first_bounded():
    for i in range(settings.MAX_RECENT + 3):
        settings.add_recent_file(f"/f{i}.png")
    settings.add_recent_file("/f5.png")
    files = settings.get("recent_files")
    assert files[0] == "/f5.png" and len(files) == settings.MAX_RECENT
    assert len(set(files)) == len(files)
    settings.add_recent_file("/only.png")
    settings.set("recent_files", ["/only.png"])
    assert settings.get("recent_files") == ["/only.png"]  # one-element list survives INI


def test_param_coercion():
    p = params.BY_KEY["overlap"]
    assert p.coerce(10_000) == p.maximum
    assert p.coerce("12") == 12
    with pytest.raises(ValueError, match="Seam shape"):
        params.BY_KEY["method"].coerce("nope")
    assert params.coerce_all({"overlap": 20, "bogus": 1, "method": "nope"})["overlap"] == 20
    assert params.coerce_all({"method": "nope"})["method"] == params.DEFAULTS["method"]


def make_doc(h=64, w=80) -> Document:
    doc = Document()
    img = np.random.default_rng(0).random((h, w, 3), dtype=np.float32)
    doc.set_source(Source(maps={"albedo": img}, paths={"albedo": "/x/My Image.png"}))
    return doc


def entry(v: float) -> CandidateTile:
    return CandidateTile(index=0, tile=np.full((8, 8, 3), v, np.float32), seed=int(v * 10))


def test_slider_drag_is_one_undo_step(qtbot):
    doc = make_doc()
    seen = []
    doc.params_changed.connect(seen.append)
    mid = new_merge_id()
    for v in (10, 12, 14, 20):
        doc.set_param("overlap", v, merge_id=mid)
    doc.set_param("rho", 5)
    assert doc.undo_stack.count() == 2
    assert doc.undo_stack.text(0) == "Change Seam search width"  # the label, not the key
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert doc.params["overlap"] == params.DEFAULTS["overlap"]
    doc.undo_stack.redo()
    assert doc.params["overlap"] == 20
    assert all(isinstance(s, frozenset) for s in seen)
    assert doc.name == "My_Image"


def test_rect_drag_merges_and_is_clamped():
    doc = make_doc()
    mid = new_merge_id()
    doc.tileset.set_template_rect((0, 0, 30, 30), merge_id=mid)
    doc.tileset.set_template_rect((5, 5, 30, 30), merge_id=mid)
    doc.tileset.set_template_rect(
        (500, -3, 30, 30)
    )  # footprint (rect + overlap) clamped into 80x64
    ov = doc.tileset.overlap()
    assert doc.tileset.template_rect == (80 - ov - 30, 0, 30, 30)
    assert doc.undo_stack.count() == 2
    doc.undo_stack.undo()
    assert doc.tileset.template_rect == (5, 5, 30, 30)
    doc.undo_stack.undo()
    assert doc.tileset.template_rect is None


def test_picks_waypoints_candidates_undo(qtbot):
    doc = make_doc()
    old = (list(doc.tileset.candidates), list(doc.tileset.picks))
    for v in (0.1, 0.2, 0.3):
        doc.tileset.append_candidate(entry(v))
    doc.tileset.set_candidates(
        list(doc.tileset.candidates), [], text="Generate", old=old, already_applied=True
    )
    assert len(doc.tileset.candidates) == 3 and doc.modified
    doc.tileset.toggle_pick(2)
    doc.tileset.toggle_pick(0)
    assert doc.tileset.picks == [2, 0]
    doc.tileset.toggle_pick(2)
    assert doc.tileset.picks == [0]
    doc.tileset.add_waypoint("horizontal", (3, 4))
    doc.tileset.add_waypoint("horizontal", (3, 4))  # no duplicate step
    doc.tileset.remove_waypoint("horizontal", (3, 4))
    doc.tileset.set_locked(1, True)
    assert doc.tileset.candidates[1].locked
    n = doc.undo_stack.count()
    for _ in range(n):
        doc.undo_stack.undo()
    assert (
        doc.tileset.candidates == []
        and doc.tileset.picks == []
        and doc.tileset.waypoints["horizontal"] == []
    )
    for _ in range(n):
        doc.undo_stack.redo()
    assert (
        len(doc.tileset.candidates) == 3
        and doc.tileset.picks == [0]
        and doc.tileset.candidates[1].locked
    )


def test_project_round_trip_of_document(tmp_path):
    from engine.project import load_project, save_project

    doc = make_doc()
    doc.tileset.set_template_rect((4, 4, 8, 8))
    for v in (0.1, 0.2, 0.3):
        doc.tileset.append_candidate(entry(v))
    doc.tileset.set_picks([2, 1])
    doc.tileset.apply_layout(np.array([[0, 1], [1, 0]]))
    doc.tileset.add_waypoint("vertical", (1, 2))
    doc.set_param("overlap", 9)
    path = save_project(tmp_path / "p.quiltproj", project_io.to_project(doc))
    other = Document()
    project_io.apply_project(other, load_project(path), str(path))
    assert other.tileset.template_rect == (4, 4, 8, 8)
    assert other.tileset.picks == [2, 1] and other.params["overlap"] == 9
    assert other.tileset.waypoints["vertical"] == [(1, 2)]
    assert np.array_equal(other.tileset.layout, [[0, 1], [1, 0]])
    assert np.allclose(other.tileset.candidates[2].tile, 0.3, atol=1 / 255)
    assert not other.modified and other.project_path == str(path)
