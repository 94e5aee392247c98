"""Argument types and the exclusion options shared by the sub-commands (engine/cli/_args.py)."""

import argparse

import numpy as np
import pytest

from engine.cli import main
from engine.cli._args import (
    colour_range,
    excluded_pixels,
    int_at_least,
    non_negative_float,
    seam_option,
)
from engine.io import load_image, save_image


def test_argument_types():
    assert int_at_least(2)("7") == 7
    assert non_negative_float("0.5") == 0.5
    assert colour_range("0:0.1") == (0.0, 0.1)
    assert colour_range("0,0,0:0.2,0.2,0.3") == ([0.0, 0.0, 0.0], [0.2, 0.2, 0.3])
    assert seam_option("o_max=5") == ("o_max", 5)
    assert seam_option("rho=0.5") == ("rho", 0.5)
    assert seam_option("variant=lm") == ("variant", "lm")
    for parse, text, message in [
        (int_at_least(2), "1", "must be >= 2, got 1"),
        (int_at_least(0), "x", "expected an integer"),
        (non_negative_float, "-1", "must be >= 0"),
        (non_negative_float, "nan", "must be >= 0"),
        (colour_range, "0.1", "expected LO:HI"),
        (seam_option, "o_max", "expected KEY=VALUE"),
    ]:
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)


def test_exclusion_mask_is_read_by_colour_not_alpha(tmp_path):
    pixels = np.zeros((10, 12, 3), np.float32)
    mask = np.zeros((10, 12, 4), np.float32)
    mask[..., 3] = 1.0  # an opaque black mask ...
    mask[:, 3:5, :3] = 1.0  # ... with a white stripe
    save_image(tmp_path / "mask.png", mask)
    args = argparse.Namespace(exclude_color=None, exclude_mask=str(tmp_path / "mask.png"))
    excluded = excluded_pixels(args, pixels, "sample")
    assert excluded[:, 3:5].all() and excluded.sum() == 20
    args.exclude_mask = None
    assert excluded_pixels(args, pixels, "sample") is None
    save_image(tmp_path / "small.png", mask[:5])
    args.exclude_mask = str(tmp_path / "small.png")
    with pytest.raises(ValueError, match="the mask is 12x5, the source 12x10"):
        excluded_pixels(args, pixels, "source")


def test_synth_with_an_opaque_rgba_exclusion_mask(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.uniform(0, 0.6, (48, 48, 3)).astype(np.float32)
    img[:, 20:24] = (1.0, 0.0, 0.0)  # a red stripe, painted white on the mask
    mask = np.zeros((48, 48, 4), np.float32)
    mask[..., 3] = 1.0
    mask[:, 20:24, :3] = 1.0
    save_image(tmp_path / "sample.png", img)
    save_image(tmp_path / "mask.png", mask)
    out = tmp_path / "out.png"
    args = ["--size", "60x50", "--block", "16", "--overlap", "4", "-o", str(out)]
    assert (
        main(
            [
                "synth",
                str(tmp_path / "sample.png"),
                *args,
                "--exclude-mask",
                str(tmp_path / "mask.png"),
            ]
        )
        == 0
    )
    px = load_image(out).pixels
    assert not (np.abs(px - (1.0, 0.0, 0.0)).sum(axis=2) < 1e-3).any()
