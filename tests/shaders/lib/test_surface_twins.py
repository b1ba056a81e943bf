"""lib/surface.glsl (occlusion strength, opacity, the alpha mask) against its NumPy twin
skinlab/scene/optics/surface.py, hard cases included (strength and alpha at 0 and 1, values out of range)."""

import itertools

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import surface


def f32(a):
    return np.asarray(a, np.float32).astype(np.float64)


def grid(*axes):
    m = np.array(list(itertools.product(*axes)), dtype=np.float64)
    return [f32(m[:, i]) for i in range(m.shape[1])]


EDGES = [-0.5, 0.0, 1e-6, 0.25, 0.5, 0.999999, 1.0, 1.5]


def test_occlusion_at_strength(glsl):
    m, s = grid(EDGES, EDGES)
    gpu = glsl.evaluate("lib/surface.glsl", "occlusion_at_strength(m, s)", {"m": m, "s": s})[:, 0]
    want = surface.occlusion_at_strength(m, s)
    assert_close_fp32(gpu, want, what="occlusion_at_strength")
    assert np.all(want[s == 0] == 1.0) and np.allclose(
        want[(s == 1) & (m >= 0) & (m <= 1)], m[(s == 1) & (m >= 0) & (m <= 1)]
    )


def test_surface_alpha_and_mask(glsl):
    a, t, v = grid(EDGES, EDGES[1:7], [0.0, 0.5, 1.0])
    gpu = glsl.evaluate("lib/surface.glsl", "surface_alpha(a, t, v)", {"a": a, "t": t, "v": v})[:, 0]
    assert_close_fp32(gpu, surface.surface_alpha(a, t, v), what="surface_alpha")
    x, c = grid(EDGES, EDGES)
    gpu = glsl.evaluate("lib/surface.glsl", "alpha_kept(x, c) ? 1.0 : 0.0", {"x": x, "c": c})[:, 0]
    assert np.array_equal(gpu == 1.0, surface.alpha_kept(x, c))
    assert surface.alpha_kept(0.5, 0.5) and not surface.alpha_kept(0.4999, 0.5)  # the cutoff itself is kept


def test_texture_transform(glsl):
    rng = np.random.default_rng(5)
    uv = f32(np.concatenate([rng.uniform(-1, 2, (60, 2)), [[0, 0], [1, 1], [0, 1], [1, 0]]]))
    cases = [
        ((0, 0), (1, 1), 0.0),
        ((0.25, -0.5), (2, 0.5), 0.3),
        ((0, 1), (0.5, 0.5), np.pi / 2),
        ((1, 0), (-1, 1), -2.0),
    ]
    for off, sc, rot in cases:
        gpu = glsl.evaluate(
            "lib/surface.glsl",
            "texture_transform(uv, u_off, u_sc, u_rot)",
            {"uv": uv},
            2,
            uniforms={"u_off": ("vec2", f32(off)), "u_sc": ("vec2", f32(sc)), "u_rot": ("float", float(rot))},
        )
        assert_close_fp32(gpu, surface.texture_transform(uv, off, sc, rot), what=f"texture_transform {off} {sc} {rot}")
    # identity; the glTF spec's example: offset (0, 1), rotation pi/2, scale 0.5 reads the lower-left
    # quadrant of the image (glTF v down: v in [0.5, 1]; here, v up: [0, 0.5])
    assert surface.texture_transform(uv, (0, 0), (1, 1), 0.0) == pytest.approx(uv)
    q = surface.texture_transform(np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]), (0, 1), (0.5, 0.5), np.pi / 2)
    assert q[:, 0].min() == pytest.approx(0) and q[:, 0].max() == pytest.approx(0.5)
    assert q[:, 1].min() == pytest.approx(0, abs=1e-12) and q[:, 1].max() == pytest.approx(0.5)


def test_diffuse_transmission_btdf(glsl):
    nol, w = grid([-1.0, -0.5, -1e-6, 0.0, 1e-6, 0.5, 1.0], [0.0, 0.3, 1.0, 1.5])
    colour = np.tile([0.2, 0.6, 1.0], (len(nol), 1))
    gpu = glsl.evaluate(
        "lib/surface.glsl", "diffuse_transmission_btdf(NoL, w, c)", {"NoL": nol, "w": w, "c": f32(colour)}, 3
    )
    want = surface.diffuse_transmission_btdf(nol, w, colour)
    assert_close_fp32(gpu, want, what="diffuse_transmission_btdf")
    assert np.all(want[nol >= 0] == 0) and want[(nol < 0) & (w == 1.0)][0] == pytest.approx(
        np.array([0.2, 0.6, 1.0]) / np.pi
    )


MATERIAL = {"base_color": (0.8, 0.4, 0.1), "subsurface_color": (0.9, 0.5, 0.3), "alpha": 0.7, "roughness": 0.35,
            "metallic": 0.25, "subsurface": 0.6}  # fmt: skip


def set_material(values):
    from skinlab.gl.uniforms import set_uniform

    def setup(prog):
        for k, v in values.items():
            set_uniform(prog, f"u_{k}", v)

    return setup


# vertex colours: none (1), black, a colour with alpha 0 and one beyond 1
COLOURS = f32([[1, 1, 1, 1], [0, 0, 0, 1], [0.2, 0.6, 1.0, 0.0], [1.5, 1.0, 0.5, 2.0]])


@pytest.mark.parametrize("field,n", [("base", 3), ("sss_albedo", 3), ("alpha", 1), ("roughness", 1), ("metallic", 1)])
def test_material_sample_without_maps(glsl, field, n):
    """lib/material_sample.glsl: the plain values x the vertex colour (the colour rule), opacity clamped."""
    uv = f32(np.tile([[0.25, 0.75]], (len(COLOURS), 1)))
    gpu = glsl.evaluate(
        "lib/material_sample.glsl", f"material_sample(uv, c).{field}", {"uv": uv, "c": COLOURS}, n,
        setup=set_material(MATERIAL),
    )  # fmt: skip
    want = np.asarray(surface.material_sample(MATERIAL, COLOURS)[field]).reshape(len(COLOURS), n)
    assert_close_fp32(gpu, want, what=f"material_sample.{field}")
    uvs = glsl.evaluate("lib/material_sample.glsl", "material_sample(uv, c).uv", {"uv": uv, "c": COLOURS}, 2)
    assert np.array_equal(uvs, uv)  # no texture transform: the maps read at the mesh's uv
    occ = glsl.evaluate("lib/material_sample.glsl", "material_sample(uv, c).occlusion", {"uv": uv, "c": COLOURS})
    assert np.all(occ == 1.0)


@pytest.mark.parametrize("field,n", [("ng", 3), ("n", 3), ("tangent", 4), ("v", 3), ("NoV", 1), ("sss_weight", 1)])
def test_surface_inputs_without_maps(glsl, field, n):
    """lib/surface_inputs.glsl: the normal turned to the side seen (back faces), unnormalised and tiny
    normals, grazing and head-on views, the weight without its map (the plain subsurface value)."""
    rng = np.random.default_rng(3)
    m = 24
    world = f32(rng.uniform(-1, 1, (m, 3)))
    normal = f32(np.concatenate([rng.normal(size=(m - 4, 3)) * 3, [[0, 0, 1e-3], [0, 0, 5.0], [1, 0, 0], [0, 1, 0]]]))
    camera = world + f32(normal / np.linalg.norm(normal, axis=1, keepdims=True) * 2.0)
    camera[-2:] = world[-2:] + f32([[0, 0, 1.0], [0, 0, 1.0]])  # views at 90 degrees to the normal: NoV = 0
    tangent = f32(np.concatenate([rng.normal(size=(m, 3)), np.sign(rng.normal(size=(m, 1)))], 1))
    front = np.arange(m) % 2 == 0
    inputs = {"w": world, "nn": normal, "t": tangent, "cam": camera, "front": front.astype(np.float64)}
    gpu = glsl.evaluate(
        "lib/surface_inputs.glsl",
        f"surface_inputs(w, nn, vec2(0.5), t, vec4(1.0), cam, front > 0.5).{field}",
        inputs, n, setup=set_material(MATERIAL),
    )  # fmt: skip
    if field == "sss_weight":
        assert np.allclose(gpu, MATERIAL["subsurface"])
        return
    want = np.asarray(surface.surface_inputs(world, normal, tangent, camera, front)[field]).reshape(m, n)
    assert_close_fp32(gpu, want, what=f"surface_inputs.{field}")
    if field == "NoV":  # seen from the front side: toward the viewer; from the back: away (turned)
        assert np.all(want[front & (np.arange(m) < m - 2)] > 0) and np.all(want[~front & (np.arange(m) < m - 2)] < 0)
        assert np.allclose(want[-2:], 0.0, atol=1e-7)
