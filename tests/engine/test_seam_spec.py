"""SeamSpec: one frozen value for method, options, metric and blend, validated once."""

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.seams import OPTIONS, SeamSpec, find_seam
from engine.seams.spec import (
    BLEND_MODES,
    INITS,
    METHODS,
    METRICS,
    MINIMAX_VARIANTS,
    OSCILLATING_VARIANTS,
    RESISTANCE_VARIANTS,
    as_seam_spec,
)

_OPTION_VALUES = {
    "connectivity": st.sampled_from((4, 8)),
    "levels": st.integers(1, 256),
    "o_max": st.integers(1, 64),
    "max_run": st.integers(1, 64),
    "init": st.sampled_from(INITS),
}


@st.composite
def specs(draw):
    method = draw(st.sampled_from(("straight", *METHODS)))
    options = {}
    for key in OPTIONS.get(method, {}):
        if not draw(st.booleans()):
            continue  # left at its default
        if key == "variant":
            pool = {"minimax": MINIMAX_VARIANTS, "resistance": RESISTANCE_VARIANTS}.get(
                method, OSCILLATING_VARIANTS
            )
            options[key] = draw(st.sampled_from(pool))
        else:
            options[key] = draw(_OPTION_VALUES[key])
    return SeamSpec(
        method,
        options,
        metric=draw(st.sampled_from(METRICS)),
        blend=draw(st.sampled_from(BLEND_MODES)),
        width=draw(st.floats(0, 64, allow_nan=False)),
        rho=draw(st.integers(0, 16)),
    )


@given(specs())
def test_round_trip_through_json(spec):
    data = json.loads(json.dumps(spec.to_dict()))
    again = SeamSpec.from_dict(data)
    assert again == spec and hash(again) == hash(spec)
    assert set(again.options) == set(OPTIONS.get(spec.method, {}))  # defaults filled in


def test_defaults_are_filled_so_equal_specs_compare_equal():
    assert SeamSpec("oscillating") == SeamSpec("oscillating", {"o_max": 3, "init": "dp"})
    assert SeamSpec("oscillating") != SeamSpec("oscillating", {"o_max": 4})
    assert dict(SeamSpec("minimax").options) == OPTIONS["minimax"]
    assert SeamSpec(width=4) == SeamSpec(width=4.0) and isinstance(SeamSpec(width=4).width, float)


def test_the_spec_is_frozen_and_its_options_read_only():
    spec = SeamSpec("oscillating")
    with pytest.raises(AttributeError):
        spec.method = "dp"
    with pytest.raises(TypeError):
        spec.options["o_max"] = 9


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        (dict(method="magic"), ValueError, "method must be one of"),
        (dict(method="dp", options={"o_max": 3}), TypeError, "unexpected option.*o_max"),
        (dict(method="oscillating", options={"o_max": 0}), ValueError, "o_max must be >= 1"),
        (dict(method="oscillating", options={"variant": "lm"}), ValueError, "variant"),
        (dict(method="minimax", options={"variant": "resume"}), ValueError, "variant"),
        (dict(method="dijkstra", options={"connectivity": 6}), ValueError, "connectivity"),
        (dict(method="resistance", options={"max_run": 2.5}), TypeError, "max_run"),
        (dict(metric="l1"), ValueError, "metric must be one of"),
        (dict(blend="smooth"), ValueError, "blend must be one of"),
        (dict(width=-1), ValueError, "width must be a finite number >= 0"),
        (dict(width=True), TypeError, "width"),
        (dict(rho=-2), ValueError, "rho must be >= 0"),
        (dict(rho=1.5), TypeError, "rho must be an integer"),
        (dict(options=[("o_max", 3)]), TypeError, "options must be a mapping"),
    ],
)
def test_bad_values_are_named_at_construction(kwargs, error, match):
    with pytest.raises(error, match=match):
        SeamSpec(**kwargs)


def test_from_dict_names_unknown_keys_and_fills_missing_ones():
    assert SeamSpec.from_dict({"method": "dijkstra"}) == SeamSpec("dijkstra")
    assert SeamSpec.from_dict({"options": None}) == SeamSpec()
    with pytest.raises(ValueError, match="unknown seam spec key.*blend_width"):
        SeamSpec.from_dict({"method": "dp", "blend_width": 4})
    with pytest.raises(TypeError, match="mapping"):
        SeamSpec.from_dict("dp")


def test_replace_keeps_the_options_the_new_method_takes():
    spec = SeamSpec("oscillating", {"o_max": 5}, blend="adaptive")
    assert spec.replace(method="dp") == SeamSpec("dp", blend="adaptive")
    assert spec.replace(blend="none").options["o_max"] == 5
    with pytest.raises(TypeError, match="o_max"):
        spec.replace(method="dp", options={"o_max": 5})


def test_find_searches_with_the_spec_like_find_seam():
    e = np.random.default_rng(0).random((20, 9))
    spec = SeamSpec("oscillating", {"o_max": 2, "init": "argmin"})
    a = find_seam(e, seam=spec, start=3)
    b = find_seam(e, method="oscillating", o_max=2, init="argmin", start=3)
    np.testing.assert_array_equal(a.path, b.path)
    with pytest.raises(TypeError, match="image"):  # a per-call input of 'resistance' only
        find_seam(e, seam=SeamSpec("dp"), image=np.zeros((20, 9)))


def test_as_seam_spec_default_type_and_straight():
    assert as_seam_spec(None) == SeamSpec()
    custom = SeamSpec(blend="feather")
    assert as_seam_spec(None, default=custom) is custom
    with pytest.raises(TypeError, match="seam must be an engine.seams.SeamSpec"):
        as_seam_spec("dp")
    with pytest.raises(ValueError, match="straight"):
        as_seam_spec(SeamSpec("straight"))
