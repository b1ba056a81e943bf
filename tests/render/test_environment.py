"""Environment maps in the frame (skinlab/render/environment.py): a uniform map lights like the same
ambient radiance; the scene hides part of the map's light (the sky-occlusion pass against its NumPy
twin); the plan; reuse when the map turns; the background; a sun that neither flickers nor rings;
every technique lit through the shared ambient code."""

import math

import numpy as np
import pytest

from skinlab.render.environment import SKY_LOD, brdf_table, sky_share
from skinlab.render.registry import technique_names
from skinlab.render.settings import RenderSettings
from skinlab.scene import envmap
from skinlab.scene.envmap import write_map
from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.interreflection import build_transfer, sky_visible_share
from skinlab.scene.materials import Material
from skinlab.scene.optics import split_sum
from skinlab.scene.primitives import sphere_mesh
from tests.render.test_bounce import N, open_book_scene
from tests.tsd_scenes import skin

MATTE = {"base_color": (0.8, 0.6, 0.4), "specular": 0.0, "roughness": 0.5}


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))


def settings(technique="none", size=32, **kw) -> RenderSettings:
    return RenderSettings.for_technique(technique, size, size, shadow_size=256, **kw)


def uniform_map(tmp_path, value=0.25, name="uniform.exr"):
    return write_map(tmp_path / name, np.full((16, 32, 3), value, np.float32))


def sky_map(tmp_path, sun=0.0, name="sky.exr"):
    """A smooth sky brighter above (a gradient in y), optionally with a sun texel toward +X, up."""
    from skinlab.scene.optics.split_sum import texel_directions

    d = texel_directions(64, 32)
    px = (0.3 + 0.5 * np.maximum(d[..., 1:2], 0.0) * np.array([0.8, 0.9, 1.0])).astype(np.float32)
    if sun:
        px[10, 16] = sun
    return write_map(tmp_path / name, px)


def sphere_nov(scene, size):
    """n.v at each pixel centre of the unit sphere at the origin seen by the scene's camera, and
    where a pixel centre's ray meets it."""
    cam = scene.camera
    inv = np.linalg.inv(cam.projection_matrix(1.0) @ cam.view_matrix())
    c = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(c, -c)
    far = np.stack([x, y, np.ones_like(x), np.ones_like(x)], -1) @ inv.T
    eye = cam.world_position
    d = far[..., :3] / far[..., 3:] - eye
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ eye
    disc = b * b - (eye @ eye - 1.0)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    p = eye + t[..., None] * d
    return np.clip(-(p * d).sum(-1), 0.0, 1.0), disc > 0


def sphere_scene(material=None) -> Scene:
    s = Scene("sphere", 20.0)
    s.environment.ambient = np.zeros(3)
    s.add(MeshNode("sphere", sphere_mesh(1.0, 3), material or Material("matte", MATTE)))
    cam = CameraNode("cam", yfov=math.radians(30.0), znear=1.0, zfar=20.0)
    cam.look_at((0.0, 0.5, 5.0), (0.0, 0.0, 0.0))
    s.add(cam)
    return s


@pytest.mark.parametrize("technique, material", [("none", None), ("tsd", "skin")])
def test_a_uniform_map_lights_like_the_same_ambient_radiance(tmp_path, renderer, technique, material):
    """Diffuse (and light entering a medium) from a map of radiance L everywhere is pi L on every
    normal, what a uniform ambient of L gives: at specular 0 (no interface: F0 = F90 = 0) the two
    frames agree; at specular 0.5 the map adds its split-sum specular L (F0 A + B) where the uniform
    ambient adds F0 L."""
    mat = skin(radius=(2.0, 1.0, 0.5)) if material else None
    a = sphere_scene(mat)
    a.environment.ambient = np.full(3, 0.25)
    b = sphere_scene(mat)
    b.environment.map = uniform_map(tmp_path)
    rs = settings(technique, bounces=0, sky_occlusion=False)
    ia, res = renderer.render(a, rs).hdr, renderer.render(b, rs)
    ib = res.hdr
    assert "uniform map: one radiance, no prefilter" in res.plan.passes[0].reason
    lit = ia[..., 3] > 0.5
    assert ia[lit, :3].min() > 0.01
    assert np.allclose(ib[lit, :3], ia[lit, :3], rtol=2e-3, atol=1e-5), np.abs(ib - ia).max()
    if material:
        return
    for s in (a, b):
        s.find("sphere").material = Material("shiny", {**MATTE, "specular": 0.5})
    ia, ib = renderer.render(a, rs).hdr, renderer.render(b, rs).hdr
    nov, hit = sphere_nov(b, 32)
    inner = lit & hit & (nov > 0.3)  # away from the silhouette, where the mesh's normals are the sphere's
    ab = split_sum.table_lookup(brdf_table(), nov, 0.5)
    f0 = 0.04
    want = ia[..., :3] + 0.25 * (f0 * ab[..., 0] + ab[..., 1] - f0)[..., None]
    assert np.allclose(ib[inner, :3], want[inner], rtol=3e-3, atol=1.5e-3), np.abs(ib - want)[inner].max()


def test_the_scene_hides_part_of_the_map(tmp_path, renderer):
    """Plate B stands on plate A: under a uniform map of radiance 1 (no bounce) each vertex of B
    receives pi (1 - the share of its cosine-weighted rays that meet A), from the sky-occlusion pass;
    the frame's middle of B shows albedo x that / pi."""
    s = open_book_scene(Material("matte", MATTE), light=(0.2, 0.0, -1.0))
    for l in list(s.lights()):
        l.visible = False
    s.find("A").material = Material("matte", MATTE)
    s.environment.map = uniform_map(tmp_path, 1.0)
    res = renderer.render(s, settings(bounces=0))
    assert "sky_occlusion" in res.plan.names()
    tr = build_transfer(s.mesh_nodes(), 64)
    b = s.find("B")
    i = j = N // 2
    record = sky_visible_share(tr, np.ones(tr.sky_directions.shape))[tr.offsets[b.uid] + i * (N + 1) + j]
    assert np.allclose(record[:3], record[3])  # under a uniform map the share of the light is the rays'
    blocked = 1.0 - record[3]
    assert 0.05 < blocked < 0.5  # the middle of B sees some of A below it
    want = np.asarray(MATTE["base_color"]) * (1.0 - blocked)
    centre = res.hdr[14:18, 14:18, :3].reshape(-1, 3).mean(0)
    assert np.allclose(centre, want, rtol=0.03), (centre, want)
    # lower on B (nearer A) is darker; without sky occlusion B is evenly lit
    assert res.hdr[-2, 16, 0] < res.hdr[1, 16, 0] * 0.85
    flat = renderer.render(s, settings(bounces=0, sky_occlusion=False)).hdr
    assert np.allclose(flat[14:18, 14:18, :3].reshape(-1, 3).mean(0), MATTE["base_color"], rtol=0.01)
    # with interreflection on, A's light comes back from where the sky was hidden
    bounced = renderer.render(s, settings(bounces=2)).hdr
    assert bounced[-2, 16, 0] > res.hdr[-2, 16, 0] * 1.05


@pytest.mark.parametrize("rotation", [0.0, 30.0, -135.0])
def test_sky_record_reads_the_turned_map_along_each_ray(tmp_path, rotation):
    """The sky occlusion's record (sky_share: the map's level SKY_LOD along each ray, the turn applied
    as a shift in u) is the share computed from the map looked up as the frame looks it up
    (lib/environment.glsl: the world direction turned into the map's frame, u_env_to_map)."""
    s = open_book_scene(Material("matte", MATTE))
    d = split_sum.texel_directions(64, 32)
    px = 0.2 + np.maximum(d, 0.0) * [1.0, 0.5, 0.25]  # brighter toward +x, +y, +z by channel: not turn-symmetric
    prepared = envmap.prepare(write_map(tmp_path / "sides.exr", px.astype(np.float32)))
    tr = build_transfer(s.mesh_nodes(), 32)
    to_map = envmap.rotation_y(rotation).T
    lit = split_sum.sample_levels(prepared.levels, tr.sky_directions.astype(np.float64) @ to_map.T, SKY_LOD)
    want = sky_visible_share(tr, lit)
    got = sky_share(tr, prepared, rotation)
    assert np.allclose(got, want, atol=2e-6), np.abs(got - want).max()
    assert got[:, :3].min() < 0.9  # some vertex sees less than the whole of the map's light
    if rotation:
        assert np.abs(got - sky_share(tr, prepared, 0.0)).max() > 0.02  # the turn matters


def open_book_visible(w):
    """Whether direction w (N, 3) from B's middle (0, 0.5, 0.5) of the open book misses plate A."""
    t = 0.5 / np.maximum(-w[:, 2], 1e-12)
    y = 0.5 + t * w[:, 1]
    return ~((w[:, 2] < 0.0) & (t * w[:, 0] <= 1.0) & (y >= 0.0) & (y <= 1.0))


def test_a_small_source_left_in_the_smooth_part_is_hidden_by_a_ray_of_its_own(tmp_path):
    """Three lamps: the two brightest become shadowed lights, the third stays in the smooth part, placed
    where plate A hides it from B's middle. With a ray per vertex toward it (sky_share with the meshes)
    the share B's middle sees is the exact one, a sum over the smooth part's texels of L cos and the
    open book's own geometry (no ray record); its 64 rays alone cannot be relied on to meet it."""
    from skinlab.render.environment import smooth_sources
    from skinlab.scene.interreflection import open_toward

    s = open_book_scene(Material("matte", MATTE))
    px = np.full((32, 64, 3), 0.05, np.float32)
    px[2:4, 40:42] = 2000.0  # up
    px[8:10, 20:22] = 2000.0  # up, toward -x
    px[15:17, 5:7] = 1000.0  # on the horizon, 30 degrees from -z toward +x: toward A from B
    prepared = envmap.prepare(write_map(tmp_path / "lamps.exr", px))
    assert len(prepared.sources) == 2
    directions, irradiances, _, _ = smooth_sources(prepared)
    lamp = split_sum.texel_directions(64, 32)[15:17, 5:7].reshape(-1, 3).mean(0)
    assert np.degrees(np.arccos(np.clip(directions @ (lamp / np.linalg.norm(lamp)), -1, 1))).min() < 3.0
    nodes = s.mesh_nodes()
    tr = build_transfer(nodes, 64)
    b = s.find("B")
    mid = tr.offsets[b.uid] + (N // 2) * (N + 1) + N // 2
    assert not open_toward(nodes, tr.key, directions @ envmap.rotation_y(0.0).T)[mid].all()
    got = sky_share(tr, prepared, 0.0, nodes)[mid, :3]
    rest = prepared.levels[0].astype(np.float64)
    h, w = rest.shape[:2]
    d = split_sum.texel_directions(w, h).reshape(-1, 3)
    weight = split_sum.texel_solid_angles(w, h).reshape(-1, 1) * np.maximum(d[:, 0], 0.0)[:, None]  # n = +x
    lit = rest.reshape(-1, 3) * weight
    want = (lit * open_book_visible(d)[:, None]).sum(0) / lit.sum(0)
    assert want.max() < 0.7  # the hidden lamp is most of B's light
    assert np.allclose(got, want, atol=0.05), (got, want)


def test_plan_and_reuse_when_the_map_turns(tmp_path, renderer):
    """Turning the map re-runs what depends on light (the source's shadow map, the share of the map's
    light each vertex sees, the interreflection, texture-space irradiance and what follows) and nothing
    that does not (the upload of the prepared map, the stretch map, the rays: the sky occlusion's
    record is recomputed from the cached rays); an orbiting camera re-runs only the per-view passes;
    the intensity leaves the visible share as it is."""
    s = open_book_scene(skin(radius=(1.0, 0.5, 0.3)))
    for l in list(s.lights()):
        l.visible = False
    s.environment.map = sky_map(tmp_path, sun=20000.0)
    # fixed texture size: with fit_size the camera's move below (a new distance) resizes the chain
    rs = settings("tsd", bounces=1, fit_size=False)
    first = renderer.render(s, rs).plan
    names = first.names()
    assert names[:3] == ["environment", "sky_occlusion", "shadow[sky:source1]"], names
    assert "1 bright source(s) lit as directional lights with shadows" in first.passes[0].reason
    s.environment.rotation_deg = 30.0
    turned = renderer.render(s, rs).plan
    ran = set(turned.ran())
    assert "environment" in turned.reused() and "sky_occlusion" in ran
    assert not any(n.startswith(("tsd_stretch", "tsd_seams")) for n in ran), ran
    assert {"shadow[sky:source1]", "bounce[1]"} <= ran and any(n.startswith("tsd_irradiance") for n in ran)
    s.camera.look_at((3.0, 0.6, 0.5), (0.0, 0.5, 0.5), up=(0.0, 0.0, 1.0))
    orbit = renderer.render(s, rs).plan
    assert set(orbit.ran()) == {"forward", "tonemap"}, orbit.ran()
    s.environment.intensity = 2.0
    brighter = renderer.render(s, rs).plan
    assert {"environment", "sky_occlusion"} <= set(brighter.reused()) and "bounce[1]" in brighter.ran()


def test_black_map_plans_nothing_and_bad_settings_stop_the_frame(tmp_path, renderer):
    from skinlab.render.plan import plan_frame
    from skinlab.scene.envmap import EnvironmentMapError

    s = sphere_scene()
    s.environment.map = write_map(tmp_path / "black.exr", np.zeros((16, 32, 3), np.float32))
    plan = plan_frame(s, settings())
    assert "environment" not in plan.names()
    assert ("environment", "map 'black' is black: no light from it") in plan.skipped
    assert np.abs(renderer.render(s, settings()).hdr[..., :3]).max() == 0.0
    s.environment.map = uniform_map(tmp_path)
    s.environment.intensity = -1.0
    with pytest.raises(EnvironmentMapError, match="intensity"):
        plan_frame(s, settings())


def test_the_background_shows_the_map_and_alpha_stays_coverage(tmp_path, renderer):
    s = sphere_scene()
    s.environment.map = sky_map(tmp_path)
    hidden = renderer.render(s, settings())
    s.environment.show_background = True
    shown = renderer.render(s, settings())
    out = shown.hdr[..., 3] == 0
    assert out.any() and np.array_equal(out, hidden.hdr[..., 3] == 0)
    # behind the sphere the map's radiance (0.3 .. 0.8), none of it where the sphere is
    assert shown.hdr[out, :3].min() > 0.25 and shown.hdr[out, :3].max() < 0.85
    assert np.allclose(shown.hdr[~out], hidden.hdr[~out])
    # the top rows look up into the brighter sky
    assert shown.hdr[0, 0, 2] > shown.hdr[-1, 0, 2]
    assert not np.array_equal(shown.ldr[out], hidden.ldr[out])


def test_a_sun_in_the_map_is_a_shadowed_light_not_noise(tmp_path, renderer):
    """A texel at 20,000 among texels near 0.5: lit as a directional light with a shadow map (the
    prefiltered rest has no such texel), the frame is smooth: no pixel stands out from its
    neighbours, and the side toward the sun is brighter."""
    s = sphere_scene(Material("shiny", {**MATTE, "specular": 0.5, "roughness": 0.3}))
    s.environment.map = sky_map(tmp_path, sun=20000.0)
    res = renderer.render(s, settings(size=64))
    assert "shadow[sky:source1]" in res.plan.names()
    img = res.hdr[..., :3].mean(-1)
    inside = res.hdr[..., 3] > 0.5
    from scipy.ndimage import median_filter, minimum_filter

    core = minimum_filter(inside, 5)  # away from the silhouette
    med = median_filter(img, 3)
    assert core.sum() > 500
    assert (img[core] < 2.0 * med[core] + 1e-3).all(), (img[core] / med[core]).max()
    x = np.arange(64)[None, :].repeat(64, 0)
    assert img[inside & (x > 40)].mean() > 2 * img[inside & (x < 24)].mean()  # the sun is toward +X


@pytest.mark.parametrize("technique", technique_names())
def test_every_technique_takes_the_map_as_light_entering_the_medium(tmp_path, renderer, technique):
    s = sphere_scene(skin(radius=(2.0, 1.0, 0.5)))
    dark = renderer.render(s, settings(technique, size=24, bounces=0)).hdr
    s.environment.map = sky_map(tmp_path)
    lit = renderer.render(s, settings(technique, size=24, bounces=0)).hdr
    inside = lit[..., 3] > 0.5
    assert np.isfinite(lit).all() and lit[..., :3].min() >= 0.0
    assert np.abs(dark[..., :3]).max() == 0.0 and lit[inside, :3].mean() > 0.1
