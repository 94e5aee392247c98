"""Materials: one cut for every map; normals stay unit length; exact copies off the blend."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

from engine.bitdepth import quantize
from engine.materials import (
    apply_cut,
    blend_normals,
    convert_normal_convention,
    decode_normals,
    encode_normals,
    infer_kind,
    make_material,
    material_error,
)
from engine.seams import SeamSpec, find_seam


def random_normals(shape, rng, *, tilt=1.2):
    """Encoded unit normals with strongly varying directions (z > 0)."""
    g = np.random.default_rng(rng)
    theta = g.uniform(0, tilt, shape)
    phi = g.uniform(0, 2 * np.pi, shape)
    v = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)
    return encode_normals(v)


def feather(mask: np.ndarray, half_width: float) -> np.ndarray:
    """Alpha ramp across the mask boundary (1 deep inside R1, 0 deep inside R2)."""
    d_in = distance_transform_edt(mask)
    d_out = distance_transform_edt(~mask)
    signed = np.where(mask, d_in - 0.5, 0.5 - d_out)
    return np.clip(0.5 + signed / (2 * half_width), 0, 1).astype(np.float32)


@pytest.fixture
def overlap():
    g = np.random.default_rng(0)
    h, w = 40, 24

    # quantized like an 8-bit file so "exact copy" has a meaning
    def q(a):
        return quantize(a, 8, dither=False).astype(np.float32) / 255

    r1 = {
        "albedo": q(g.random((h, w, 3))),
        "normal": q(random_normals((h, w), 1)),
        "height": q(g.random((h, w, 1))),
    }
    r2 = {
        "albedo": q(g.random((h, w, 3))),
        "normal": q(random_normals((h, w), 2)),
        "height": q(g.random((h, w, 1))),
    }
    return r1, r2


def test_one_cut_lands_on_the_same_pixels_in_every_map(overlap):
    r1, r2 = overlap
    err = material_error(r1, r2)  # default: the main (first) map only
    seam = find_seam(err)
    alpha = feather(seam.mask, 3)
    out = apply_cut(r1, r2, alpha)
    assert list(out) == ["albedo", "normal", "height"]
    from_r1 = {m: np.all(out[m] == r1[m], axis=2) for m in out}
    from_r2 = {m: np.all(out[m] == r2[m], axis=2) for m in out}
    for m in out:
        assert out[m].dtype == np.float32 and out[m].shape == r1[m].shape
        differ = np.any(
            r1[m] != r2[m], axis=2
        )  # where R1 and R2 differ, the source is identifiable
        assert differ.mean() > 0.99
        assert np.all(from_r1[m][alpha == 1]) and np.all(from_r2[m][alpha == 0]), m  # exact copies
        assert np.array_equal(from_r1[m] & differ, (alpha == 1) & differ), m  # ... and nowhere else
        assert np.array_equal(from_r2[m] & differ, (alpha == 0) & differ), m
    assert (
        (alpha == 1).sum() > 100
        and (alpha == 0).sum() > 100
        and ((alpha > 0) & (alpha < 1)).sum() > 50
    )
    # a hard cut: the partition of every map equals the seam mask exactly
    hard = apply_cut(r1, r2, seam.mask.astype(np.float32))
    for m in hard:
        differ = np.any(r1[m] != r2[m], axis=2)
        assert np.array_equal(np.all(hard[m] == r1[m], axis=2) & differ, seam.mask & differ)
        assert np.all(np.all(hard[m] == r2[m], axis=2)[~seam.mask])


def test_blended_normals_are_unit_length_where_plain_averaging_is_not(overlap):
    r1, r2 = overlap
    alpha = feather(find_seam(material_error(r1, r2)).mask, 4)
    band = (alpha > 0) & (alpha < 1)
    out = apply_cut(r1, r2, alpha)
    length = np.linalg.norm(decode_normals(out["normal"]), axis=2)
    assert np.abs(length[band] - 1).max() < 1e-5  # float output: unit vectors
    # after 8-bit quantization: unit within quantization (each component off by <= 1/255)
    q8 = quantize(out["normal"], 8, dither=False).astype(np.float64) / 255
    assert np.abs(np.linalg.norm(decode_normals(q8), axis=2) - 1).max() < np.sqrt(3) / 255 + 1e-6
    # the naive colour average would shorten the vectors a lot (so the test can fail)
    naive = alpha[..., None] * r1["normal"] + (1 - alpha[..., None]) * r2["normal"]
    assert np.abs(np.linalg.norm(decode_normals(naive), axis=2) - 1)[band].max() > 0.1


def test_blend_normals_opposite_vectors_and_alpha_channel():
    up = encode_normals(np.array([[[0.0, 0.0, 1.0]]]))
    down = encode_normals(np.array([[[0.0, 0.0, -1.0]]]))
    out = blend_normals(up, down, np.array([[0.5]], np.float32))
    assert abs(np.linalg.norm(decode_normals(out)) - 1) < 1e-6  # no zero vector
    rgba1 = np.concatenate([up, [[[0.2]]]], axis=2).astype(np.float32)
    rgba2 = np.concatenate([encode_normals(np.array([[[1.0, 0, 0]]])), [[[0.6]]]], axis=2).astype(
        np.float32
    )
    mixed = blend_normals(rgba1, rgba2, np.array([[0.5]], np.float32))
    assert mixed.shape == (1, 1, 4) and abs(mixed[0, 0, 3] - 0.4) < 1e-6
    v = decode_normals(mixed)[0, 0]
    assert np.allclose(v, [np.sqrt(0.5), 0, np.sqrt(0.5)], atol=1e-6)


def test_material_error_weights(overlap):
    r1, r2 = overlap
    main_only = material_error(r1, r2)
    d = r1["albedo"].astype(np.float64) - r2["albedo"]
    assert (
        main_only.shape == d.shape[:2]
        and np.corrcoef(main_only.ravel(), np.sqrt((d * d).sum(axis=2)).ravel())[0, 1] > 0.9
    )
    assert np.array_equal(
        material_error(r1, r2, main="height"),
        material_error({"h": r1["height"]}, {"h": r2["height"]}),
    )
    mix = material_error(r1, r2, weights={"albedo": 1.0, "height": 2.0})
    ea = material_error(r1, r2, main="albedo")
    eh = material_error(r1, r2, main="height")
    assert np.allclose(mix, ea / ea.mean() + 2 * eh / eh.mean())
    with pytest.raises(ValueError, match="unknown map"):
        material_error(r1, r2, weights={"roughness": 1.0})
    with pytest.raises(ValueError, match="positive weight"):
        material_error(r1, r2, weights={"albedo": 0.0})


def test_make_material_and_kinds():
    g = np.random.default_rng(0)
    m = make_material(
        g.random((8, 9, 3)),
        extra={"rock_Normal": random_normals((8, 9), 0), "Roughness": g.random((8, 9))},
        normal_convention="directx",
    )
    assert m.names == ("albedo", "rock_Normal", "Roughness") and m.shape == (8, 9)
    assert m.kinds == {"albedo": "color", "rock_Normal": "normal", "Roughness": "roughness"}
    assert m.normal_convention == "directx"
    assert set(m.crop(1, 2, 3, 4)) == set(m.names) and m.crop(1, 2, 3, 4)["Roughness"].shape == (
        3,
        4,
        1,
    )
    with pytest.raises(ValueError, match="co-registered"):
        make_material(g.random((8, 9)), extra={"height": g.random((8, 8))})
    with pytest.raises(ValueError, match="normal_convention"):
        make_material(g.random((8, 9)), normal_convention="metal")
    with pytest.raises(ValueError, match="3 channels"):
        make_material(g.random((8, 9)), extra={"normal": g.random((8, 9))})
    assert (
        infer_kind("AO") == "ao"
        and infer_kind("displacement") == "height"
        and infer_kind("foo") == "other"
    )


def test_convert_normal_convention_flips_green_only():
    n = random_normals((4, 5), 3)
    dx = convert_normal_convention(n, source="opengl", target="directx")
    assert np.allclose(dx[..., 1], 1 - n[..., 1]) and np.array_equal(
        dx[..., [0, 2]], n[..., [0, 2]]
    )
    assert np.allclose(convert_normal_convention(dx, source="directx", target="opengl"), n)
    assert np.array_equal(convert_normal_convention(n, source="opengl", target="opengl"), n)


def test_apply_cut_validates(overlap):
    r1, r2 = overlap
    a = np.full((40, 24), 0.5, np.float32)
    with pytest.raises(ValueError, match="same maps"):
        apply_cut(r1, {"albedo": r2["albedo"]}, a)
    with pytest.raises(ValueError, match="alpha"):
        apply_cut(r1, r2, a[:-1])
    with pytest.raises(ValueError, match="alpha"):
        apply_cut(r1, r2, a + 1)
    with pytest.raises(ValueError, match="kinds"):
        apply_cut(r1, r2, a, kinds={"albedo": "paint"})
    # declaring a 3-channel map as "color" blends it linearly instead
    lin = apply_cut(r1, r2, a, kinds={"normal": "color"})
    assert np.allclose(lin["normal"], 0.5 * r1["normal"] + 0.5 * r2["normal"], atol=1e-6)


# ------------------------------------------------------------------ through the tile pipeline


def test_exported_material_tiles_share_every_cut_and_keep_unit_normals(tmp_path):
    """Seamless tile + candidates with a normal and a height map, exported as a bundle: every
    exported normal has unit length within 8-bit quantization, and every map is cut at the
    same pixels. The maps are functions of the albedo pixel (normal = f(rgb), height = g(rgb)),
    so with hard cuts f(albedo) == normal holds at every exported pixel exactly iff every map
    took each pixel from the same place; with the patches' cut blended it fails only inside
    their blend bands (the template is cut hard in both runs)."""
    from engine.export import export_bundle
    from engine.png import decode_png
    from engine.tiles.candidates import candidates
    from engine.tiles.seamless import make_seamless

    def q8(a):
        return quantize(a, 8, dither=False).astype(np.float32) / 255

    def f_normal(rgb):
        v = 2 * rgb.astype(np.float64) - 1
        v[..., 2] = np.abs(v[..., 2]) + 0.3
        return q8(encode_normals(v / np.linalg.norm(v, axis=-1, keepdims=True)))

    def g_height(rgb):
        return q8(rgb.mean(axis=-1, keepdims=True))

    g = np.random.default_rng(4)
    albedo = q8(np.clip(g.normal(0.5, 0.15, (72, 72, 3)), 0, 1))
    maps = {"normal": f_normal(albedo), "height": g_height(albedo)}
    tmpl = make_seamless(albedo, (8, 8, 40, 36), overlap=8, maps=maps)
    for blend in ("none", "adaptive"):  # the patches' cut: hard, or blended
        cands = candidates(albedo, tmpl, 4, maps=maps, seam=SeamSpec(blend=blend), rng=1, workers=1)
        tiles = [{"albedo": c.tile, **c.maps} for c in cands]
        out = tmp_path / blend
        man = export_bundle(out, name="m", tiles=tiles, normal_convention="opengl")
        assert man["normal_convention"] == "opengl"
        for c, entry in zip(cands, man["tiles"], strict=True):
            codes = {m: decode_png((out / entry["files"][m]).read_bytes()) for m in tiles[0]}
            read = {m: (v / np.float32(255)).astype(np.float32) for m, v in codes.items()}
            length = np.linalg.norm(decode_normals(read["normal"]), axis=2)
            assert np.abs(length - 1).max() < np.sqrt(3) / 255 + 2e-3  # source's own rounding
            same = np.all(codes["normal"] == quantize(f_normal(read["albedo"]), 8), axis=2)
            same &= np.all(codes["height"] == quantize(g_height(read["albedo"]), 8), axis=2)
            assert (~np.all(read["albedo"] == tmpl.tile, axis=2)).mean() > 0.2  # a real patch
            if blend == "none":
                assert same.all()
            else:
                band = (c.alpha > 0) & (c.alpha < 1)
                assert band.any() and same[~band].all() and not same[band].all()
