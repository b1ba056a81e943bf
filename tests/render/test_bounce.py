"""Interreflection on the GPU (skinlab/render/bounce.py): the exitance and gather passes against their
NumPy twin (skinlab/scene/interreflection.py), the bounce light in the frame of a plain and a scattering
technique, the plan (skipped where nothing sees anything) and reuse across frames."""

import math

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.interreflection import build_transfer, gather, sender_albedo, smooth, world_geometry
from skinlab.scene.materials import Material
from skinlab.scene.primitives import box_mesh
from tests.scene.test_interreflection import grid_mesh
from tests.tsd_scenes import light_from, skin

GREY = {"base_color": (0.8, 0.6, 0.4), "specular": 0.5, "roughness": 0.5}
N = 24  # quads per plate side


def open_book_scene(material_b=None, light=(0.2, 0.0, -1.0), shadow=False, mm_per_unit=20.0) -> Scene:
    """Plate A in z = 0 (normal +z) lit by a directional light; plate B in x = 0 (normal +x) facing
    away from the light, so that only A's light reaches it. The camera looks at B's middle from +x
    with a field that holds B alone."""
    s = Scene("open-book", mm_per_unit)
    s.environment.ambient = np.zeros(3)
    s.add(MeshNode("A", grid_mesh(N, (0, 0, 0), (1, 0, 0), (0, 1, 0), "A"), Material("grey", GREY)))
    s.add(MeshNode("B", grid_mesh(N, (0, 0, 0), (0, 1, 0), (0, 0, 1), "B"), material_b or Material("grey", GREY)))
    s.add(light_from(light, shadow=shadow))
    cam = CameraNode("cam", yfov=2 * math.atan(0.25 / 3.0), znear=1.0, zfar=10.0)
    cam.look_at((3.0, 0.5, 0.5), (0.0, 0.5, 0.5), up=(0.0, 0.0, 1.0))  # image rows follow z
    s.add(cam)
    return s


def settings(technique="none", **kw) -> RenderSettings:
    return RenderSettings.for_technique(technique, 32, 32, shadow_size=256, **kw)


def test_exitance_and_gather_passes_match_numpy(renderer):
    """The exitance pass leaves sender albedo x irradiance per vertex, the gather sums the ray records
    over it, the one-ring average smooths that: each within 1e-4 of NumPy."""
    s = open_book_scene()
    renderer.render(s, settings(bounces=1))
    bp = renderer.passes["bounce"]
    nodes = s.mesh_nodes()
    tr = build_transfer(nodes, 64)
    v = tr.total_vertices
    gpu_m = np.frombuffer(bp.exitance[0].read(), np.float32).reshape(-1, 4)[:v, :3].astype(np.float64)
    sun = s.lights()[0]
    want = []
    for node in nodes:
        _, nrm = world_geometry(node)
        cos = np.maximum(nrm @ -sun.direction, 0.0)
        want.append(cos[:, None] * sun.radiance * sender_albedo(GREY["base_color"], 0.0, GREY["specular"]))
    assert_close_fp32(gpu_m, np.concatenate(want), rtol=1e-4, atol=1e-6, what="bounce exitance")
    gpu_g = np.frombuffer(bp.gathered[0].read(), np.float32).reshape(-1, 4)[:v, :3].astype(np.float64)
    ref = gather(tr, gpu_m)
    assert ref[tr.offsets[nodes[1].uid] :].max() > 0.1  # B receives A's light
    assert_close_fp32(gpu_g, ref, rtol=1e-4, atol=1e-5 * ref.max(), what="bounce gather")
    gpu_e = np.frombuffer(bp.targets[1][0].read(), np.float32).reshape(-1, 4)[:v, :3].astype(np.float64)
    ref = smooth(tr, gpu_g)
    assert not np.allclose(ref, gpu_g)  # the average changes something
    assert_close_fp32(gpu_e, ref, rtol=1e-4, atol=1e-5 * ref.max(), what="bounce one-ring average")


def test_plain_frame_shows_bounce_light_where_no_light_reaches(renderer):
    """B faces away from the light: black without interreflection; with it, B's middle shows the
    gathered irradiance times (albedo + F0) / pi, the ambient term's reflectance."""
    s = open_book_scene()
    off = renderer.render(s, settings(bounces=0)).hdr
    on = renderer.render(s, settings(bounces=1)).hdr
    assert off[..., 3].min() > 0.99  # B fills the frame
    assert np.abs(off[..., :3]).max() < 1e-6
    tr = build_transfer(s.mesh_nodes(), 64)
    b = s.find("B")
    # B's vertex at (y, z) = (0.5, 0.5): index i * (N + 1) + j with u = y, v = z
    i = j = N // 2
    sun = s.lights()[0]
    m = np.zeros((tr.total_vertices, 3))
    a = s.find("A")
    m[: tr.counts[a.uid]] = -sun.direction[2] * sun.radiance * sender_albedo(GREY["base_color"], 0.0, 0.5)
    e = smooth(tr, gather(tr, m))[tr.offsets[b.uid] + i * (N + 1) + j]
    want = e * sender_albedo(GREY["base_color"], 0.0, GREY["specular"]) / math.pi
    centre = on[14:18, 14:18, :3].reshape(-1, 3).mean(0)
    assert np.allclose(centre, want, rtol=0.03), (centre, want)
    # lower on B (nearer A) is brighter: the image's bottom rows (row 0 = top)
    assert on[-2, 16, 0] > on[1, 16, 0] * 1.2


def test_bounce_light_enters_a_scattering_medium(renderer):
    """Texture-space diffusion shades bounce light in its irradiance pass (it enters the medium and
    is blurred with the rest): B, lit by nothing else, shows it; and the pass is re-run when the
    bounce changes (its plan entry reads the last bounce pass)."""
    s = open_book_scene(skin(radius=(0.5, 0.3, 0.2), color=(0.8, 0.6, 0.4)))
    off = renderer.render(s, settings("tsd", bounces=0)).hdr
    res = renderer.render(s, settings("tsd", bounces=2))
    plain = renderer.render(s, settings("none", bounces=2)).hdr
    assert np.abs(off[..., :3]).max() < 1e-6
    irradiance = next(p for p in res.plan.passes if p.name.startswith("tsd_irradiance[B"))
    assert "bounce[2]" in irradiance.after
    centre = res.hdr[12:20, 12:20, :3].reshape(-1, 3).mean(0)
    flat = plain[12:20, 12:20, :3].reshape(-1, 3).mean(0)
    assert np.all(np.isfinite(res.hdr))
    # a slowly varying irradiance leaves a diffusing medium nearly as it leaves a diffuse surface of
    # the same albedo (the plain frame shows base colour 1, the medium its subsurface colour)
    flat = flat * np.array([0.8, 0.6, 0.4])
    assert np.all(np.abs(centre / flat - 1) < 0.2), centre / flat


def test_plan_skips_interreflection_where_nothing_is_seen():
    from skinlab.render.plan import plan_frame

    s = Scene("box", 1.0)
    s.add(MeshNode("box", box_mesh((1.0, 1.0, 1.0)), Material("grey", GREY)))
    s.add(light_from((0, 0, -1)))
    cam = CameraNode("cam")
    cam.look_at((0, 0, 5), (0, 0, 0))
    s.add(cam)
    plan = plan_frame(s, settings())
    assert "bounce[1]" not in plan.names()
    assert any(w == "bounce" and "no surface sees another" in why for w, why in plan.skipped)
    book = plan_frame(open_book_scene(), settings())
    assert book.names()[:2] == ["bounce[1]", "bounce[2]"]
    assert "64 rays" in book.passes[0].reason
    off = plan_frame(open_book_scene(), settings(bounces=0))
    assert not any(n.startswith("bounce") for n in off.names())
    assert ("bounce", "interreflection off (bounces = 0)") in off.skipped


def test_orbit_reuses_the_bounce_and_a_moved_light_does_not(renderer):
    s = open_book_scene(shadow=True)
    rs = settings(bounces=2)
    renderer.render(s, rs)
    s.camera.look_at((3.0, 0.6, 0.5), (0.0, 0.5, 0.5), up=(0.0, 0.0, 1.0))
    again = renderer.render(s, rs)
    assert {"bounce[1]", "bounce[2]"} <= set(again.plan.reused())
    s.lights()[0].rotation = light_from((0.3, 0.1, -1.0)).rotation
    moved = renderer.render(s, rs)
    assert {"bounce[1]", "bounce[2]"} <= set(moved.plan.ran())


def test_higher_orders_add_light_that_bounced_again(renderer):
    """B, lit only through A, sends A's light back to A, which sends it to B again: the third order
    (A -> B -> A -> B) adds a little to B (albedo^2 x the form factors), the second nothing (B has
    no direct light of its own to send)."""
    s = open_book_scene()
    one, two, three = (renderer.render(s, settings(bounces=n)).hdr[..., :3].sum((0, 1)) for n in (1, 2, 3))
    assert np.allclose(two, one, rtol=1e-6)
    gain = three / one - 1
    assert np.all(gain > 0.002) and np.all(gain < 0.1), gain
    assert gain[0] > gain[2]  # red, the most reflected, gains most


@pytest.mark.parametrize("base", [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)])
def test_black_and_white_senders_stay_finite(renderer, base):
    mat = Material("m", {**GREY, "base_color": base, "specular": 0.0})
    s = open_book_scene(mat)
    s.find("A").material = mat
    img = renderer.render(s, settings(bounces=4)).hdr
    assert np.all(np.isfinite(img))
    if base[0] == 0.0:
        assert np.abs(img[..., :3]).max() < 1e-6


def test_sender_albedo_twin(glsl):
    rng = np.random.default_rng(2)
    n = 200
    base = rng.uniform(0, 1, (n, 3))
    metallic = rng.uniform(0, 1, n)
    spec = rng.uniform(0, 1, n)
    metallic[:10], spec[10:20] = 0.0, 0.0
    metallic[20:30] = 1.0
    gpu = glsl.evaluate(
        "lib/bounce.glsl", "bounce_sender_albedo(b, m, s)", {"b": base, "m": metallic, "s": spec}, out_components=3
    )
    assert_close_fp32(gpu, sender_albedo(base, metallic, spec), rtol=1e-4, atol=1e-6, what="bounce_sender_albedo")


def test_a_mesh_too_large_for_the_ray_budget_casts_fewer_rays_then_none(monkeypatch):
    """Casting time and the records' memory grow with vertices x rays: past the budget each vertex
    casts fewer rays (a warning says how many), and below MIN_RAYS the pass is skipped with a warning."""
    from skinlab.render import bounce
    from skinlab.render.plan import plan_frame

    s = open_book_scene()  # 1250 vertices
    monkeypatch.setattr(bounce, "MAX_RAYS", 20_000)
    plan = plan_frame(s, settings())
    first = next(p for p in plan.passes if p.name == "bounce[1]")
    assert first.params.transfer.rays == 16 and "16 rays" in first.reason
    assert any("16 rays per vertex instead of 64" in w for w in plan.warnings)
    monkeypatch.setattr(bounce, "MAX_RAYS", 4_000)
    plan = plan_frame(s, settings())
    assert not any(n.startswith("bounce") for n in plan.names())
    assert any("interreflection skipped: 1250 vertices" in w for w in plan.warnings)


def test_a_vertex_exitance_does_not_depend_on_its_neighbours_in_the_target(renderer):
    """The head (colour maps) with its vertices in another order: each vertex leaves the same exitance.
    Neighbouring texels of the vertex-space target are unrelated vertices, so their UVs' differences
    must not reach the maps' filtering (llvmpipe's anisotropic filter takes them as derivatives even
    at an explicit level: the maps are read trilinearly at the vertex's level)."""
    from skinlab.scene.mesh import Mesh
    from skinlab.scene.scenefile import load_scene

    def exitance(scene) -> np.ndarray:
        renderer.render(scene, RenderSettings(32, 32, shadow_size=256, bounces=1), readback=False)
        n = len(scene.mesh_nodes()[0].mesh.positions)
        return np.frombuffer(renderer.passes["bounce"].exitance[0].read(), np.float32).reshape(-1, 4)[:n, :3]

    scene = load_scene("head")
    node = scene.mesh_nodes()[0]
    m = node.mesh
    assert m.uvs is not None and node.material.textures()  # textured
    before = exitance(scene).copy()
    order = np.random.default_rng(7).permutation(len(m.positions))  # new vertex k is old vertex order[k]
    where = np.argsort(order)
    node.mesh = Mesh(
        m.name,
        m.positions[order],
        where[m.indices].astype(np.uint32),
        normals=m.normals[order],
        uvs=m.uvs[order],
    )
    after = exitance(scene)
    assert before.max() > 0.1
    np.testing.assert_allclose(after, before[order], rtol=1e-5, atol=1e-6)
