"""Bhatia's quilting cuts its bands with the published minimum resistance construction."""

import json

import numpy as np
import pytest
from scipy import ndimage

from engine.cli import main
from engine.errormap import error_map
from engine.io import load_image, save_image
from engine.quilting import quilt
from engine.quilting.options import BHATIA_SEAM
from resources import sample_path
from tests.engine.helpers import cut
from tests.engine.test_seams_resistance import paper_cut

BAND = 6


@pytest.fixture(scope="module")
def cobbles():
    return load_image(sample_path("cobblestones")).pixels[:96, :96].copy()


def expected_left_cut(S, rec, left):
    """The paper's cut of a block's left band, literally (tests/…/test_seams_resistance):
    line 1 from the corner shared with the earlier blocks (the band's top, since blocks grow
    from the top-left here, from the bottom-left in the paper), steps by the colour difference
    inside the new block."""
    Sp = np.pad(S, ((0, BAND), (0, BAND), (0, 0)), mode="reflect").astype(np.float32)
    x, y, w, h = rec.source
    lx, ly, lw, _ = left.source
    own = Sp[y : y + h, x : x + BAND]
    ext = Sp[ly : ly + h, lx + lw : lx + lw + BAND]
    e = error_map(ext, own, metric="ssd")
    *_, cut = paper_cut(e[::-1], 5, image=own[::-1].astype(np.float64))
    return [(h - 1 - r, c) for r, c in cut][::-1]


def test_quilting_bhatia_cuts_with_the_published_construction(cobbles):
    kw = dict(block=20, overlap=BAND, rng=4, select="bhatia")
    res = quilt(cobbles, (60, 60), seam=cut("resistance"), **kw)
    grid = {r.position: r for r in res.blocks}
    checked = 0
    for r in res.blocks:
        y0, x0 = r.position
        if x0 == 0:
            continue
        expected = expected_left_cut(cobbles, r, grid[(y0, x0 - 20)])
        assert [tuple(p) for p in r.path[: len(expected)].tolist()] == expected
        t = r.territory
        # the left cut splits the block: its left territory and the rest, each in one piece
        left = (t & 1).astype(bool)
        assert ndimage.label(left)[1] == 1 and left[:, 0].all()
        assert ndimage.label(~left)[1] == 1
        checked += 1
    assert checked == 6
    walk = quilt(cobbles, (60, 60), seam=cut("resistance", options={"variant": "walk"}), **kw)
    assert any(
        not np.array_equal(a.path, b.path) for a, b in zip(res.blocks, walk.blocks, strict=True)
    )


def test_bhatia_cuts_by_resistance_and_blends_around_its_cuts_by_default(cobbles):
    kw = dict(block=20, overlap=BAND, rng=4, select="bhatia")
    soft = quilt(cobbles, (60, 60), **kw)
    hard = quilt(cobbles, (60, 60), seam=cut("resistance"), **kw)
    assert soft.seam == BHATIA_SEAM == cut("resistance", blend="feather")
    assert soft.seam.options["variant"] == "published"
    assert quilt(cobbles, (60, 60), block=20, rng=0).seam.blend == "none"
    changed = np.abs(soft.image - hard.image).max(axis=2) > 1e-6
    r = next(b for b in hard.blocks if b.position == (20, 20))
    near = ndimage.binary_dilation(r.territory > 0, iterations=9)  # 4 sigma (sigma = 2 px)
    # inside the block, the blend only touches pixels near the territories it cuts off
    assert changed[20:40, 20:40].any() and not changed[20:40, 20:40][~near].any()


def test_synth_cli_select_bhatia_uses_it(tmp_path, cobbles):
    src = save_image(tmp_path / "s.png", cobbles[:48, :48])
    sample = load_image(src).pixels

    def synth(*extra):
        out, seams = tmp_path / "o.png", tmp_path / "o.json"
        argv = ["synth", str(src), "--size", "64x64", "--block", "16", "--select", "bhatia"]
        argv += ["--seam", "resistance", "--seed", "5", *extra]
        assert main([*argv, "-o", str(out), "--save-seams", str(seams)]) == 0
        return load_image(out).pixels, json.loads(seams.read_text())

    img, doc = synth()
    walk_img, walk_doc = synth("--seam-option", "variant=walk")
    ref = quilt(sample, (64, 64), block=16, select="bhatia", seam=cut("resistance"), rng=5)
    assert [b["path"] for b in doc["blocks"]] == [r.path.tolist() for r in ref.blocks]
    assert [b["path"] for b in doc["blocks"]] != [b["path"] for b in walk_doc["blocks"]]
    assert not np.array_equal(img, walk_img)
