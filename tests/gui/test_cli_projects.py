"""Projects move between the CLI and the editor both ways (issue 6, editor side)."""

from __future__ import annotations

import json

import numpy as np

from engine.cli import main as cli_main
from engine.project import load_project
from resources import sample_path
from tests.gui.helpers import WAIT_MS, generate, make_window, open_sample, wait_idle


def test_cli_project_opens_in_the_editor(qtbot, tmp_path):
    proj = tmp_path / "cli.quiltproj"
    rc = cli_main(
        [
            "tileset",
            str(sample_path("cobblestones")),
            "--out",
            str(tmp_path / "out"),
            "--candidates",
            "4",
            "--tile-min",
            "96",
            "--tile-max",
            "128",
            "--pick",
            "0,2",
            "--preview",
            "3x3",
            "--project",
            str(proj),
        ]
    )
    assert rc == 0 and proj.is_file()
    cli = load_project(proj)
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.path_changed, timeout=WAIT_MS):
        w.files.open_path(str(proj), confirm=False)
    wait_idle(qtbot, w)
    d = w.doc.tileset
    assert len(d.candidates) == 4 and d.picks == cli.picks == [0, 2]
    assert d.template_rect == cli.template_rect
    assert w.gallery.model().rowCount() == 4 and d.seamless is not None
    assert np.array_equal(d.candidates[2].tile, cli.candidates[2].tile)
    assert d.preview is not None
    assert w.tabs.currentWidget() is w.source_view


def test_a_cli_wang_project_opens_on_the_wang_tab(qtbot, tmp_path):
    proj = tmp_path / "wang.quiltproj"
    src, out = str(sample_path("gravel")), str(tmp_path / "out")
    argv = ["tileset", src, "--out", out, "--wang", "2", "--tile-size", "48", "--project"]
    assert cli_main([*argv, str(proj)]) == 0
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.path_changed, timeout=WAIT_MS):
        w.files.open_path(str(proj), confirm=False)
    wait_idle(qtbot, w)
    assert w.doc.wang.complete and w.tabs.currentWidget() is w.wang_view
    assert "a Wang set of 16 tiles (Wang tiles tab)" in w.messages[-1][1]


def test_editor_project_exports_with_the_cli(qtbot, tmp_path):
    w = make_window(qtbot)
    open_sample(qtbot, w)
    generate(qtbot, w, 3)
    w.doc.tileset.set_picks([2, 0])
    wait_idle(qtbot, w)
    path = tmp_path / "editor.quiltproj"
    assert w.files.save_to(str(path), wait=True)
    out = tmp_path / "bundle"
    assert cli_main(["export", str(path), "--out", str(out)]) == 0
    manifest = json.loads((out / f"{w.doc.name}.json").read_text())
    assert len(manifest["tiles"]) == 2
