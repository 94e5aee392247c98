"""One TilesetSettings between the command line and the editor (issue 13 item 4, issue 14).

A project made by ``quilt-studio tileset`` with every option away from its default reopens in
the editor with all of them: the parameters show them, and the editor's own seamless tile and
regenerated candidates are the command line's, pixel for pixel. Projects written before the
settings type (the CLI's and the editor's old keys) still open with their options.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

import numpy as np

from engine.bitdepth import quantize
from engine.cli import build_parser
from engine.cli import main as cli_main
from engine.io import load_image
from engine.png import encode_png
from engine.project import load_project, project_from_tileset, save_project
from engine.seams import SeamSpec
from engine.tiles import TilesetSettings
from quilt_gui import params
from resources import sample_path
from tests.gui.helpers import WAIT_MS, make_window, wait_idle

#: every tile-set option of the command line away from its default
FLAGS = {
    "--seam": "oscillating",
    "--seam-option": ["o_max=5", "variant=faithful", "init=argmin"],
    "--metric": "lab",
    "--blend": "feather",
    "--rho": "5",
    "--width": "6",
    "--seed": "7",
    "--candidates": "4",
    "--tile-min": "88",
    "--tile-max": "104",
    "--overlap": "12",
    "--joint-weight": "1.5",
    "--detail-weight": "0.5",
    "--patch-overlap": "9",
    "--patch-size": "80",
    "--margin": "3",
    "--neighbourhood": "2",
    "--preview": "3x4",
    "--exclude-color": "0,0,0:0.12,0.12,0.12",
    "--patch-search": "local",  # the editor has no control for these two yet: they are
    "--min-distance": "7",  # kept with the project and used as they are
    "--flatten": None,
    "--cut-structures": None,
}


def _q(pixels):
    """8 bits, rounded as the project stores them."""
    return quantize(pixels, 8, dither=False)


def _argv(flags: dict) -> list[str]:
    out = []
    for flag, value in flags.items():
        if value is None:  # a switch
            out.append(flag)
        for v in value if isinstance(value, list) else [] if value is None else [value]:
            out += [flag, v]
    return out


def _cli_project(tmp_path):
    """A 200 x 200 crop of a sample with a height map, an excluded colour and a painted mask,
    through ``quilt-studio tileset`` with :data:`FLAGS`."""
    S = load_image(sample_path("cobblestones")).pixels[100:300, 120:320]
    src, height, mask = tmp_path / "src.png", tmp_path / "height.png", tmp_path / "mask.png"
    src.write_bytes(encode_png(_q(S)))
    height.write_bytes(encode_png(_q(S.mean(axis=2))))
    painted = np.zeros(S.shape[:2], np.uint8)
    painted[20:40, 150:190] = 255
    mask.write_bytes(encode_png(painted))
    proj = tmp_path / "cli.quiltproj"
    argv = ["tileset", str(src), "--out", str(tmp_path / "out"), *_argv(FLAGS)]
    argv += ["--exclude-mask", str(mask), "--map", f"height={height}", "--weight", "height=0.5"]
    argv += ["--equal-neighbours", "--pick", "0,2", "--project", str(proj)]
    assert cli_main(argv) == 0
    return proj, json.loads((tmp_path / "out" / "manifest.json").read_text())


def test_cli_project_with_every_option_reopens_in_the_editor_with_all_of_them(qtbot, tmp_path):
    proj, manifest = _cli_project(tmp_path)
    cli = load_project(proj)
    settings = TilesetSettings.from_dict(manifest["resolved"])
    assert settings.flatten and settings.patch_search == "local" and settings.min_distance == 7
    assert settings.seam == SeamSpec(
        "oscillating",
        {"o_max": 5, "variant": "faithful", "init": "argmin"},
        metric="lab",
        blend="feather",
        width=6,
        rho=5,
    )
    w = make_window(qtbot)
    with qtbot.waitSignal(w.doc.path_changed, timeout=WAIT_MS):
        w.files.open_path(str(proj), confirm=False)
    wait_idle(qtbot, w)
    p = w.doc.params
    shown = {
        "method": "oscillating",
        "o_max": 5,
        "osc_variant": "faithful",
        "osc_init": "argmin",
        "metric": "lab",
        "blend": "feather",
        "template_blend": "feather",
        "rho": 5,
        "width": 6,
        "seed": 7,
        "layout_seed": 7,
        "n_candidates": 4,
        "tile_min": 88,
        "tile_max": 104,
        "overlap": 12,
        "joint_weight": 1.5,
        "patch_overlap": 9,
        "patch_size": 80,
        "margin": 3,
        "neighbourhood": 2,
        "preview_rows": 3,
        "preview_cols": 4,
        "no_equal_neighbours": False,
    }
    assert {k: p[k] for k in shown} == shown
    # the excluded colour and the painted mask arrive as the excluded pixels the CLI used
    ts = w.doc.tileset
    assert ts.map_weights == {"albedo": 0.0, "height": 0.5}  # only the height map counted
    excluded = w.doc.exclude_painted
    source = w.doc.source.main
    dark = np.all(source <= 0.12, axis=2)
    assert excluded is not None and excluded[20:40, 150:190].all() and (excluded >= dark).all()
    # everything but the excluded colour (now excluded pixels) is the same settings value
    assert params.tileset_settings(p) == settings.replace(exclude_color=None)
    # ... and the editor computes the CLI's tiles from them: its own seamless tile, then the
    # same candidates when it generates them again
    assert ts.template_rect == cli.template_rect and ts.seamless is not None
    main = cli.main_map
    assert np.array_equal(_q(ts.seamless.tile), _q(cli.template[main]))
    assert np.array_equal(_q(ts.seamless.maps["height"]), _q(cli.template["height"]))
    assert ts.picks == [0, 2]
    w.act_generate.trigger()
    wait_idle(qtbot, w, timeout=WAIT_MS)
    assert len(ts.candidates) == 4
    for mine, theirs in zip(ts.candidates, cli.candidates, strict=True):
        assert mine.patch_origin == theirs.patch_origin
        assert np.array_equal(_q(mine.tile), _q(theirs.tile))
        assert np.array_equal(_q(mine.maps["height"]), _q(theirs.maps["height"]))


#: tileset options the test above does not put in FLAGS, and why
NOT_IN_FLAGS = {
    "--out": "the output folder",
    "--project": "the project file itself",
    "--settings": "reads a whole earlier run's settings (tests/engine/test_settings.py)",
    "--workers": "threads of this run, not a setting of the set",
    "--source-name": "hidden: the batch's source path in the manifest",
    "--rect": "a fixed template rectangle: arrives as the project's template rectangle",
    "--map": "given above (a height map)",
    "--weight": "given above",
    "--exclude-mask": "given above (the painted mask)",
    "--pick": "given above",
    "--equal-neighbours": "given above",
    "--no-flatten": "the same field as --flatten (given above), set to False",
    # a Wang set is another workflow; its settings fields are in EVERY_FIELD below
    "--wang": "Wang",
    "--tile-size": "Wang",
    "--variants": "Wang",
    "--interior": "Wang",
    "--interior-blend": "Wang",
    "--wang-band": "Wang",
    "--outward": "Wang",
    "--wang-min-distance": "Wang",
    "--wang-tolerance": "Wang",
}


def test_the_round_trip_above_gives_every_tileset_option():
    """A new ``tileset`` option must join FLAGS (or say here why not)."""
    parser = build_parser(command="tileset")
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    options = {
        o
        for a in sub.choices["tileset"]._actions
        for o in a.option_strings
        if o.startswith("--") and o != "--help"
    }
    assert options - set(FLAGS) - set(NOT_IN_FLAGS) == set()
    assert set(FLAGS) <= options and set(NOT_IN_FLAGS) <= options  # no stale names


#: every TilesetSettings field away from its default (the Wang fields too)
EVERY_FIELD = TilesetSettings(
    tile_size=(128, 128),
    tile_min=(88, 88),
    tile_max=(104, 104),
    overlap=12,
    joint_weight=1.5,
    detail_weight=0.5,
    whole_structures=False,
    seam=SeamSpec("oscillating", {"o_max": 5}, metric="lab", blend="feather", width=6, rho=5),
    template_blend="adaptive",
    candidates=4,
    seed=7,
    patch_size=(80, 80),
    patch_overlap=9,
    margin=3,
    neighbourhood=2,
    patch_search="local",
    min_distance=7,
    flatten=True,
    preview=(3, 4),
    no_equal_neighbours=False,
    layout_seed=9,
    exclude_color=((0.0, 0.0, 0.0), (0.12, 0.12, 0.12)),
    wang=3,
    wang_variants=2,
    wang_interior="diamonds",
    wang_interior_blend="adaptive",
    wang_band=5,
    wang_outward=0.5,
    wang_tolerance=0.2,
    wang_min_distance=4.0,
)


def test_every_settings_field_travels_project_to_editor_to_project():
    """Each field, whether the editor shows it or only keeps it (params.KEPT); the excluded
    colour arrives as excluded pixels instead (the first test)."""
    default = TilesetSettings()
    names = [f.name for f in dataclasses.fields(TilesetSettings)]
    assert [n for n in names if getattr(EVERY_FIELD, n) == getattr(default, n)] == []
    expected = EVERY_FIELD.replace(exclude_color=None)
    p = params.from_project_parameters({"tileset": EVERY_FIELD.to_dict()}, {})
    assert params.tileset_settings(p) == expected
    again = params.from_project_parameters(params.project_parameters(p), {})
    assert params.tileset_settings(again) == expected


def test_editor_project_keeps_its_settings_and_own_parameters(qtbot, tmp_path):
    """Saved and reopened by the editor: the tile set's settings and the quilting tab's
    parameters come back (the project holds them as settings plus the editor's own)."""
    w = make_window(qtbot)
    w.files.open_path(str(sample_path("cobblestones")), confirm=False)
    wait_idle(qtbot, w)
    changes = {
        "method": "minimax",
        "minimax_variant": "lm",
        "connectivity": "4",
        "template_blend": "none",
        "joint_weight": 0.25,
        "n_candidates": 9,
        "q_method": "resistance",
        "block": 40,
        "exclude_color": "#102030",
        "exclude_tolerance": 0.05,
    }
    w.doc.set_params(changes)
    wait_idle(qtbot, w)
    path = tmp_path / "e.quiltproj"
    assert w.files.save_to(str(path), wait=True)
    saved = load_project(path)
    assert saved.parameters["tileset"]["seam"]["options"] == {
        "variant": "lm",
        "levels": 32,
        "connectivity": 4,
    }
    assert saved.parameters["editor"]["block"] == 40
    other = make_window(qtbot)
    with qtbot.waitSignal(other.doc.path_changed, timeout=WAIT_MS):
        other.files.open_path(str(path), confirm=False)
    wait_idle(qtbot, other)
    assert {k: other.doc.params[k] for k in changes} == changes


#: version-1 CLI keys the editor spells the same way
SAME_NAMES = ("tile_min", "tile_max", "overlap", "patch_overlap", "margin", "neighbourhood")
SAME_NAMES += ("rho", "width", "no_equal_neighbours")


def test_projects_of_the_previous_version_open_with_their_options(tmp_path):
    """Version-1 files kept the options as flat keys, spelled differently by the CLI and the
    editor; both are read."""
    old_cli = {
        "tile_min": 96,
        "tile_max": 128,
        "overlap": 10,
        "patch_overlap": 7,
        "margin": 1,
        "neighbourhood": 3,
        "seam": "resistance",
        "seam_options": {"max_run": 9},
        "metric": "ssd",
        "template_blend": "none",
        "candidate_blend": "feather",
        "rho": 4,
        "width": 5,
        "candidates": 12,
        "workers": 2,
        "weights": None,
        "preview": [5, 7],
        "no_equal_neighbours": False,
    }
    old_editor = {
        **params.DEFAULTS,
        "method": "oscillating",
        "o_max": 6,
        "osc_init": "smoothed",
        "blend": "none",
        "n_candidates": 11,
        "seed": 4,
        "layout_seed": 9,
        "preview_rows": 2,
        "preview_cols": 3,
        "block": 36,
    }
    old_editor.pop("joint_weight")
    old_editor.pop("template_blend")
    tile = np.zeros((40, 40, 3), np.float32)
    for name, old in (("cli", old_cli), ("editor", old_editor)):
        path = tmp_path / f"{name}.quiltproj"
        project = project_from_tileset(
            sources=np.zeros((64, 64, 3), np.float32),
            tiles=[tile],
            parameters=old,
            project_seeds={"candidates": 8, "layout": 8} if name == "cli" else None,
        )
        save_project(path, project)
        loaded = load_project(path)
        p = params.from_project_parameters(loaded.parameters, loaded.seeds)
        if name == "cli":
            expect = {
                "method": "resistance",
                "max_run": 9,
                "metric": "ssd",
                "blend": "feather",
                "template_blend": "none",
                "n_candidates": 12,
                "seed": 8,
                "layout_seed": 8,
                "preview_rows": 5,
                "preview_cols": 7,
                **{k: old_cli[k] for k in SAME_NAMES},
            }
        else:
            expect = {
                "method": "oscillating",
                "o_max": 6,
                "osc_init": "smoothed",
                "blend": "none",
                "template_blend": params.SAME,
                "n_candidates": 11,
                "seed": 4,
                "layout_seed": 9,
                "preview_rows": 2,
                "preview_cols": 3,
                "block": 36,
            }
        assert {k: p[k] for k in expect} == expect, name
