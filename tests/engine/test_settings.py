"""TilesetSettings: the tile-set workflow's options in one frozen, serialisable type."""

import inspect
import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.bitdepth import quantize
from engine.cli import main
from engine.png import encode_png
from engine.seams import SeamSpec
from engine.settings import DEFAULT_SEAM, TilesetSettings, settings_from_parameters
from engine.tiles import iter_candidates
from engine.tiles.detail import DETAIL_WEIGHT
from engine.tiles.pipeline import resolve
from engine.tiles.template import JOINT_WEIGHT
from tests.engine.helpers import smooth_texture

sizes = st.one_of(st.integers(8, 512), st.tuples(st.integers(8, 512), st.integers(8, 512)))


@st.composite
def settings(draw):
    lo = draw(st.none() | sizes)
    hi = None
    if lo is not None and draw(st.booleans()):
        lo_hw = (lo, lo) if isinstance(lo, int) else lo
        hi = (lo_hw[0] + draw(st.integers(0, 64)), lo_hw[1] + draw(st.integers(0, 64)))
    unit = st.floats(0, 1, allow_nan=False)
    return TilesetSettings(
        tile_min=lo,
        tile_max=hi,
        overlap=draw(st.none() | st.integers(2, 64)),
        joint_weight=draw(st.floats(0, 4, allow_nan=False)),
        seam=SeamSpec(
            draw(st.sampled_from(("dp", "oscillating", "resistance"))),
            blend=draw(st.sampled_from(("none", "feather", "adaptive"))),
            rho=draw(st.integers(0, 9)),
        ),
        template_blend=draw(st.sampled_from((None, "none", "feather", "adaptive"))),
        candidates=draw(st.integers(1, 500)),
        seed=draw(st.integers(0, 2**62)),
        patch_size=draw(st.none() | sizes),
        patch_overlap=draw(st.none() | st.integers(2, 64)),
        margin=draw(st.none() | st.integers(0, 8)),
        neighbourhood=draw(st.integers(0, 20)),
        preview=draw(st.tuples(st.integers(1, 20), st.integers(1, 20))),
        no_equal_neighbours=draw(st.booleans()),
        layout_seed=draw(st.none() | st.integers(0, 2**31)),
        exclude_color=draw(st.none() | st.tuples(unit, unit)),
    )


@given(settings())
def test_round_trip_through_json(s):
    again = TilesetSettings.from_dict(json.loads(json.dumps(s.to_dict())))
    assert again == s


def test_defaults_are_the_engines():
    s = TilesetSettings()
    assert s.joint_weight == JOINT_WEIGHT
    assert s.detail_weight == DETAIL_WEIGHT
    assert s.seam == DEFAULT_SEAM == SeamSpec(blend="adaptive")
    assert s.template_seam == SeamSpec()  # the template's cuts stay hard
    defaults = inspect.signature(iter_candidates).parameters
    assert (
        s.candidates == defaults["n"].default
        and s.neighbourhood == defaults["neighbourhood"].default
    )
    assert TilesetSettings(template_blend=None).template_seam == s.seam


@pytest.mark.parametrize(
    ("changes", "error", "match"),
    [
        (dict(tile_min=0), ValueError, "tile_min must be >= 1"),
        (dict(tile_min=(10, 20, 30)), TypeError, "tile_min must be an int or an"),
        (dict(tile_min=64, tile_max=32), ValueError, "must not exceed tile_max"),
        (dict(overlap=1), ValueError, "overlap must be >= 2"),
        (dict(joint_weight=-1), ValueError, "joint_weight"),
        (dict(seam="dp"), TypeError, "seam must be a SeamSpec"),
        (dict(seam=SeamSpec("straight")), TypeError, "seam must be a SeamSpec"),
        (dict(template_blend="smooth"), ValueError, "template_blend must be one of"),
        (dict(candidates=0), ValueError, "candidates must be >= 1"),
        (dict(seed=-1), ValueError, "seed must be >= 0"),
        (dict(preview=(0, 3)), ValueError, "preview must be >= 1"),
        (dict(no_equal_neighbours=1), TypeError, "no_equal_neighbours must be True or False"),
        (dict(exclude_color=(0, 2)), ValueError, "exclude_color bounds"),
        (dict(exclude_color=0.5), TypeError, "exclude_color must be a"),
    ],
)
def test_bad_values_are_named(changes, error, match):
    with pytest.raises(error, match=match):
        TilesetSettings(**changes)


def test_from_dict_reads_the_seam_as_a_dict_and_names_unknown_keys():
    s = TilesetSettings.from_dict({"seam": {"method": "minimax"}, "preview": [2, 3]})
    assert s.seam == SeamSpec("minimax") and s.preview == (2, 3)
    with pytest.raises(ValueError, match="unknown tile-set setting.*wang_k"):
        TilesetSettings.from_dict({"wang_k": 2})
    assert TilesetSettings.from_dict({"wang_k": 2}, unknown="ignore") == TilesetSettings()


def test_resolve_fills_in_what_comes_from_the_source():
    r = resolve(TilesetSettings(seed=4), (300, 200))
    assert (r.tile_min, r.tile_max) == ((50, 50), (100, 100))
    assert r.overlap == 8 and r.patch_overlap == 8 and r.margin == 1 and r.layout_seed == 4
    assert r.template_blend == "none"
    fixed = resolve(TilesetSettings(tile_min=64, template_blend=None), (300, 200), overlap=20)
    assert (fixed.tile_min, fixed.tile_max) == ((64, 64), (64, 64))
    assert fixed.overlap == 20 and fixed.patch_overlap == 10 and fixed.template_blend == "adaptive"


def test_unreadable_values_of_a_project_fall_back_to_their_defaults():
    s = settings_from_parameters({"tileset": {"candidates": -3, "seed": 9, "bogus": 1}})
    assert s.candidates == 30 and s.seed == 9


def test_the_cli_runs_the_settings_of_an_earlier_run_again(tmp_path):
    """``--settings manifest.json`` repeats a run; flags given on top change it."""
    src = tmp_path / "s.png"
    src.write_bytes(encode_png(quantize(smooth_texture((120, 130), seed=3), 8, dither=False)))
    first = tmp_path / "a"
    argv = ["tileset", str(src), "--candidates", "3", "--seam", "oscillating"]
    argv += ["--seam-option", "o_max=2", "--tile-min", "40", "--seed", "5"]
    assert main([*argv, "--out", str(first)]) == 0
    again = tmp_path / "b"
    assert (
        main(["tileset", str(src), "--settings", str(first / "manifest.json"), "--out", str(again)])
        == 0
    )
    m1, m2 = (json.loads((d / "manifest.json").read_text()) for d in (first, again))
    assert m1["settings"] == m2["settings"] and m1["tiles"] == m2["tiles"]
    changed = tmp_path / "c"
    flags = ["--settings", str(first / "manifest.json"), "--seed", "6", "--out", str(changed)]
    assert main(["tileset", str(src), *flags]) == 0
    m3 = json.loads((changed / "manifest.json").read_text())
    assert m3["settings"] == {**m1["settings"], "seed": 6}
    assert m3["resolved"]["layout_seed"] == 6 and m3["resolved"]["seam"]["options"]["o_max"] == 2
