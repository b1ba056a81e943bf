"""Blender as a peer: the scene mapping (numerics without bpy; the bpy data read back without
rendering), one tiny Cycles render of an index-matched slab against Chandrasekhar's exact albedo,
the light units on a Lambertian plate, and one tiny EEVEE frame with its subsurface scattering on.
Blender runs in a child process (skinlab/bench/blender_child.py); the tests that need it are
skipped where bpy is not installed (`make test` installs it into .venv-blender)."""

import math

import numpy as np
import pytest

from skinlab.bench import blender_scene as bs
from skinlab.bench.sweep import resolve_scene
from skinlab.scene.graph import CameraNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.optics.boundary import albedo_isotropic
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.primitives import box_mesh
from skinlab.scene.scenefile import load_scene
from skinlab.truth.export import describe
from tests.tsd_scenes import light_from, skin, sky_slab

# -- the mapping's numerics (no Blender) ----------------------------------------------------------------


@pytest.mark.parametrize("g", [0.0, 0.4])
def test_base_colour_inverts_cycles_albedo_remap(g):
    alpha = np.array([0.0, 1e-4, 0.05, 0.2, 0.5, 0.9, 0.99, 0.9999, 0.999999])
    A = bs.cycles_base_color(alpha, g)
    assert np.all((A >= 0) & (A <= 1)) and np.all(np.diff(A) > 0)
    np.testing.assert_allclose(bs.cycles_rw_alpha(A, g), alpha, atol=1e-9)
    a = bs.cycles_rw_alpha(np.linspace(0, 1, 201), g)  # the remap rises from 0 and clamps below 1
    assert a[0] == 0 and np.all(np.diff(a) >= 0) and a[-1] == bs.CYCLES_MAX_ALPHA


def test_remap_is_chiangs_fit_at_g0():
    """Chiang et al. 2016, eq. 3 at g = 0: alpha = 1 - (4.09712 + 4.20863 A - sqrt(9.59217 + 41.6808 A
    + 17.7126 A^2))^2 is the older form of the same fit; the two agree within a few per cent."""
    A = np.linspace(0.05, 0.95, 19)
    old = 1 - (4.09712 + 4.20863 * A - np.sqrt(9.59217 + 41.6808 * A + 17.7126 * A * A)) ** 2
    assert np.max(np.abs(bs.cycles_rw_alpha(A) - old)) < 0.03


def test_dipole_inversion_and_skin_radius():
    eta = 1.3
    rd = np.array([0.0, 5e-5, 0.01, 0.3, 0.7, 0.99, 0.995, 1.0])
    ap = bs.cycles_dipole_alpha_prime(rd, eta)
    assert ap[0] == 0 and ap[1] == 0 and ap[-1] == ap[-2] == 0.999999
    inv = 1 / eta
    f_dr = inv * (-1.44 * inv + 0.71) + 0.668 + 0.0636 * eta
    k = 4 / 3 * (1 + f_dr) / (1 - f_dr)
    mid, want = ap[2:5], rd[2:5]  # 12 bisection steps: alpha' within 1/4096 of the root
    assert np.all((bs.dipole_rd(mid - 2**-12, k) <= want) & (want <= bs.dipole_rd(np.minimum(mid + 2**-12, 1), k)))
    assert ap[5] > 0.999  # beyond the dipole's largest reflectance: alpha' goes to 1
    mfp = np.array([1.2, 0.8, 0.3])
    base = np.array([0.5, 0.3, 0.1])
    r = bs.cycles_skin_radius(mfp, base, eta)
    np.testing.assert_allclose(r * np.sqrt(3 * (1 - bs.cycles_dipole_alpha_prime(base, eta))), mfp, rtol=1e-12)
    assert bs.clamp_sss_ior(1.0) == 1.01 and bs.clamp_sss_ior(9.0) == 3.8


def test_light_units():
    col, s = bs.sun_strength([3.0, 2.88, 2.7])
    assert s == 3.0 and col == pytest.approx([1.0, 0.96, 0.9])
    col, p = bs.point_power([2.0e6, 1.0e6, 0.0])
    assert p == pytest.approx(4 * math.pi * 2.0e6) and col == pytest.approx([1.0, 0.5, 0.0])
    assert bs.sun_strength([0.0, 0.0, 0.0]) == ([1.0, 1.0, 1.0], 0.0)


def place(light, position, direction):
    from skinlab.scene import transform as tf

    light.translation = position
    light.rotation = tf.look_at_rotation(np.zeros(3), np.asarray(direction, np.float64))
    return light


def lit_scene(*lights, env=None) -> Scene:
    """A 1 m Lambertian plate (albedo 0.5, no specular) in z = 0 seen straight down through a 1 degree
    camera from 2 m, lit by `lights` (and `env`: (map path, rotation_deg, intensity)); metres."""
    grey = Material("grey", {"base_color": (0.5, 0.5, 0.5), "specular": 0.0, "roughness": 1.0, "subsurface": 0.0})
    s = Scene("plate", 1000.0)
    s.environment.ambient = np.zeros(3)
    if env is not None:
        s.environment.map, s.environment.rotation_deg, s.environment.intensity = env
    s.add(MeshNode("plate", box_mesh((1.0, 1.0, 0.01)), grey, translation=(0.0, 0.0, -0.005)))
    for light in lights:
        s.add(light)
    cam = CameraNode("cam", yfov=math.radians(1.0), znear=0.1, zfar=10.0)
    cam.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0))
    s.add(cam)
    return s


def new_lights():
    from skinlab.scene.graph import LightNode

    return (
        place(LightNode("spot", "spot", intensity=3.0, inner_deg=20.0, outer_deg=40.0), (0.1, 0, 0.5), (0.1, 0, -1)),
        place(LightNode("ball", "sphere", intensity=2.0, radius=0.1), (-0.2, 0.1, 0.6), (0.0, 0.0, -1.0)),
        place(LightNode("box", "rect", intensity=4.0, width=0.4, height=0.2), (0.0, -0.3, 0.5), (0.0, 0.5, -1.0)),
    )


def test_spot_rect_sphere_and_environment_map():
    """Spot, rect and sphere lights and the environment map in the Blender spec: a spot of the point
    light's power, cone 2 x outer, the blend that puts Blender's smoothstep between the inner and outer
    half-angles; a rect as an Area light of power pi A L with its extents and the way it shines; a sphere
    as a point of that radius with power 4 pi^2 r^2 L; the map's pixels, intensity and the turn onto
    Blender's equirectangular axes."""
    from skinlab.scene import envmap

    spot, ball, box = new_lights()
    desc = describe(lit_scene(spot, ball, box), 8, 8)
    spec = bs.blender_spec(lit_scene(spot, ball, box), 8, 8)
    es = {e["light"]: e for e in desc.emitters}
    ls = {light["name"]: light for light in spec.lights}
    sp = ls["spot"]
    assert sp["type"] == "SPOT" and sp["strength"] == pytest.approx(4 * math.pi * 3.0e6)
    assert sp["spot_size"] == pytest.approx(math.radians(80.0))
    m = np.asarray(sp["matrix"])
    np.testing.assert_allclose(-m[:3, 2], spot.direction, atol=1e-12)  # a Spot shines along its -Z
    np.testing.assert_allclose(m[:3, 3], es["spot"]["position"], atol=1e-9)
    mit, ble = bs.spot_falloffs([0.0, 19.9, 20.0, 30.0, 40.0, 40.1, 80.0], 20.0, 40.0)
    np.testing.assert_allclose(ble[[0, 1, 2, 4, 5, 6]], [1, 1, 1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(mit, [1, 1, 1, 0.5, 0, 0, 0], atol=1e-12)
    assert 0 < ble[3] < 1 and abs(ble[3] - mit[3]) > 0.01  # the two ramps differ between the cone angles
    # Blender's smoothstep is 1/2 where cos theta is halfway between cos inner and cos outer
    half = math.degrees(math.acos((math.cos(math.radians(20)) + math.cos(math.radians(40))) / 2))
    assert bs.spot_falloffs([half], 20.0, 40.0)[1][0] == pytest.approx(0.5)
    assert bs.spot_blend(40.0, 40.0) == 0 and bs.spot_blend(0.0, 40.0) == 1
    b = ls["ball"]
    assert b["type"] == "POINT" and b["radius"] == pytest.approx(100.0)
    assert b["strength"] == pytest.approx(4 * math.pi**2 * 100.0**2 * 2.0)
    np.testing.assert_allclose(np.asarray(b["matrix"])[:3, 3], es["ball"]["centre"])
    r = ls["box"]
    assert r["type"] == "AREA" and r["shape"] == "RECTANGLE" and (r["size"], r["size_y"]) == pytest.approx((400, 200))
    assert r["strength"] == pytest.approx(math.pi * 400 * 200 * 4.0)
    m = np.asarray(r["matrix"])
    np.testing.assert_allclose(m[:3, :3].T @ m[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(m[:3, :3]) == pytest.approx(1.0)
    np.testing.assert_allclose(-m[:3, 2], box.direction, atol=1e-12)
    ex, ey = box.half_extents()
    assert abs(m[:3, 0] @ ex) == pytest.approx(200.0 / 1000) and abs(m[:3, 1] @ ey) == pytest.approx(100.0 / 1000)
    assert spec.environment is None and any("sphere lights" in n for n in spec.notes)
    # the map: b = M w reads, in Blender's convention, the texel Mitsuba's envmap reads for w
    rng = np.random.default_rng(3)
    w = rng.normal(size=(64, 3))
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    for rot in (0.0, 37.0, -120.0):
        mm = bs.environment_matrix(rot)
        bv = w @ mm.T
        u_b, v_b = 0.5 - np.arctan2(bv[:, 1], bv[:, 0]) / (2 * math.pi), np.arccos(bv[:, 2]) / math.pi
        mv = w @ envmap.rotation_y(rot)  # R_y(-rot) w
        u_m, v_m = np.arctan2(mv[:, 0], -mv[:, 2]) / (2 * math.pi), np.arccos(mv[:, 1]) / math.pi
        np.testing.assert_allclose(np.mod(u_b - u_m + 0.5, 1.0) - 0.5, 0, atol=1e-12)
        np.testing.assert_allclose(v_b, v_m, atol=1e-12)
        np.testing.assert_allclose(bs.euler_matrix(bs.euler_xyz(mm)), mm, atol=1e-12)
    for k in range(20):  # the Euler decomposition, also near gimbal lock
        e = rng.uniform(-3, 3, 3) if k < 18 else [0.4, (-1) ** k * math.pi / 2, 0.0]
        np.testing.assert_allclose(bs.euler_matrix(bs.euler_xyz(bs.euler_matrix(e))), bs.euler_matrix(e), atol=1e-9)


def environment_map(tmp_path, texel=None, value=1.0):
    """A 32 x 16 map: uniform `value`, or black but for one texel (row, column) of `value`."""
    from skinlab.scene import envmap

    img = np.full((16, 32, 3), 0.0 if texel else value, np.float32)
    if texel:
        img[texel] = value
    return envmap.write_map(tmp_path / f"env-{texel}.exr", img)


def test_environment_map_in_the_spec(tmp_path):
    spec = bs.blender_spec(lit_scene(env=(environment_map(tmp_path, (3, 16), 50.0), 90.0, 1.5)), 8, 8)
    assert spec.environment["strength"] == 1.5 and spec.world is None
    np.testing.assert_allclose(spec.environment["matrix"], bs.environment_matrix(90.0))
    assert spec.environment_pixels.shape == (16, 32, 3) and spec.environment_pixels[3, 16, 0] == 50.0
    assert spec.environment_pixels.sum() == pytest.approx(150.0)


def test_spec_is_the_truths_scene():
    """The Blender spec of a reference scene holds the truth's geometry, camera, light and medium:
    Base Color maps back to the medium's albedo through Cycles' remap, Radius x Scale / 4 pi is the mean
    free path, the Sun shines along the light's direction, the camera looks where the truth's does."""
    scene = load_scene(resolve_scene("slab-edge-skin1"))
    desc = describe(scene, 40, 30)
    spec = bs.blender_spec(scene, 40, 30)
    assert (spec.width, spec.height) == (40, 30) and len(spec.objects) == len(desc.shapes) == 2
    for o, s in zip(spec.objects, desc.shapes):
        assert o.name == s.name
        np.testing.assert_array_equal(o.positions, s.positions)
        np.testing.assert_array_equal(o.normals, s.normals)
        np.testing.assert_array_equal(o.faces, s.faces)
    slab, plate = spec.objects
    inp, rw = slab.material["inputs"], slab.material["subsurface"]["RANDOM_WALK"]
    interior = desc.shapes[0].interior
    np.testing.assert_allclose(bs.cycles_rw_alpha(inp["Base Color"][:3]), interior["albedo"]["value"], atol=1e-9)
    mfp = 1 / (np.asarray(interior["sigma_t"]["value"]) * interior["scale"])
    np.testing.assert_allclose(np.asarray(rw["Subsurface Radius"]) * rw["Subsurface Scale"] / (4 * math.pi), mfp)
    slab_node = next(n for n in scene.mesh_nodes() if n.material.has_subsurface)
    np.testing.assert_allclose(mfp, material_medium(slab_node.material.values).mfp_arr, rtol=1e-9)
    assert inp["Subsurface Weight"] == 1 and inp["Subsurface Anisotropy"] == 0
    assert inp["IOR"] == 1.0 and inp["Specular IOR Level"] == 0.0  # index-matched: no specular layer
    assert plate.material["subsurface"] is None and plate.material["inputs"]["Base Color"][:3] == [0, 0, 0]
    (sun,) = spec.lights
    m = np.asarray(sun["matrix"])
    np.testing.assert_allclose(-m[:3, 2], desc.emitters[0]["direction"], atol=1e-12)  # a Sun shines along -Z
    assert sun["type"] == "SUN" and sun["strength"] == pytest.approx(3.0) and sun["angle"] == 0
    cam = np.asarray(spec.camera["matrix"])
    # Blender's camera looks down its -Z: the truth's (Mitsuba's) +Z; its +X is the truth's -X
    np.testing.assert_allclose(-cam[:3, 2], desc.camera_to_world[:3, 2], atol=1e-12)
    np.testing.assert_allclose(cam[:3, 0], -desc.camera_to_world[:3, 0], atol=1e-12)
    assert spec.camera["fov_y_deg"] == pytest.approx(16.0) and spec.world is None


def test_skin_and_metallic_values_map():
    s = Scene("rough", 1.0)
    mat = skin(radius=(2.0, 1.0, 0.5), color=(0.6, 0.4, 0.3), specular=0.5, roughness=0.3)
    s.add(MeshNode("cube", box_mesh((10.0, 10.0, 10.0)), mat))
    s.add(MeshNode("metal", box_mesh((1.0, 1.0, 1.0)), Material("m", {"metallic": 1.0, "roughness": 0.2}),
                   translation=(20.0, 0, 0)))  # fmt: skip
    s.add(light_from((0, 0, -1)))
    cam = CameraNode("cam", yfov=math.radians(30), znear=1.0, zfar=200.0)
    cam.look_at((0.0, 0.0, 60.0), (0.0, 0.0, 0.0))
    s.add(cam)
    spec = bs.blender_spec(s, 8, 8)
    inp = spec.objects[0].material["inputs"]
    eta = material_medium(mat.values).eta
    assert inp["IOR"] == pytest.approx(eta) and inp["Specular IOR Level"] == 0.5 and inp["Roughness"] == 0.3
    skin_r = spec.objects[0].material["subsurface"]["RANDOM_WALK_SKIN"]
    mfp = material_medium(mat.values).mfp_arr
    r = np.asarray(skin_r["Subsurface Radius"]) * skin_r["Subsurface Scale"]
    np.testing.assert_allclose(r, bs.cycles_skin_radius(mfp, inp["Base Color"][:3], eta))
    assert spec.objects[1].material["inputs"]["Metallic"] == 1.0


# -- Blender itself (a child process) ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def blender():
    from skinlab.bench.blender_peer import BlenderSession, BlenderUnavailable

    try:
        s = BlenderSession()
    except BlenderUnavailable as exc:
        pytest.skip(str(exc))
    yield s
    s.close()


def test_bpy_holds_the_mapped_scene(blender):
    """Read back from bpy without rendering: every vertex, corner normal and UV, the camera, the light
    and each material input are what the spec says."""
    scene = load_scene(resolve_scene("slab-thin-backlit-skin1"))
    spec = bs.blender_spec(scene, 24, 16)
    blender.load(spec)
    info, arr = blender.readback()
    (o,) = spec.objects
    np.testing.assert_allclose(arr[f"{o.name}_positions"], o.positions, atol=1e-5)
    corners = arr[f"{o.name}_corners"]
    np.testing.assert_array_equal(corners, o.faces.ravel())
    np.testing.assert_allclose(arr[f"{o.name}_corner_normals"], o.normals[corners], atol=1e-4)
    if o.uvs is not None:
        np.testing.assert_allclose(arr[f"{o.name}_uvs"], o.uvs[corners], atol=1e-6)
    (ob,) = info["objects"]
    for k, v in o.material["inputs"].items():
        np.testing.assert_allclose(ob["inputs"][k], v, rtol=1e-6, atol=1e-7, err_msg=k)
    np.testing.assert_allclose(ob["matrix_world"], np.eye(4), atol=1e-12)
    cam = info["camera"]
    np.testing.assert_allclose(cam["matrix_world"], spec.camera["matrix"], atol=1e-5)
    assert cam["sensor_fit"] == "VERTICAL" and math.degrees(cam["angle_y"]) == pytest.approx(30.0, abs=1e-4)
    np.testing.assert_allclose(cam["clip"], spec.camera["clip"], rtol=1e-6)
    (light,) = info["lights"]
    assert light["type"] == "SUN" and light["energy"] == pytest.approx(3.0) and light["angle"] == 0
    np.testing.assert_allclose(light["matrix_world"], spec.lights[0]["matrix"], atol=1e-6)
    assert info["render"]["size"] == [24, 16] and info["render"]["film_transparent"]


def test_bpy_holds_the_new_lights_and_the_environment(blender, tmp_path):
    """Spot, area and sphere lights and the World's environment texture read back from bpy: types,
    powers, cones, sizes, placements; the Mapping node's rotation, turned into a matrix by Blender's own
    Euler, is the spec's; the image holds the map's pixels; nothing rendered."""
    env = (environment_map(tmp_path, (3, 16), 50.0), 90.0, 1.5)
    spec = bs.blender_spec(lit_scene(*new_lights(), env=env), 8, 8)
    blender.load(spec)
    info, arr = blender.readback()
    got = {light["name"]: light for light in info["lights"]}
    for want in spec.lights:
        g = got[want["name"]]
        assert g["type"] == want["type"] and g["energy"] == pytest.approx(want["strength"], rel=1e-6)
        np.testing.assert_allclose(g["color"], want["color"], atol=1e-6)
        np.testing.assert_allclose(g["matrix_world"], want["matrix"], atol=1e-4)
        assert g["visible_camera"] is False
    assert got["spot"]["spot_size"] == pytest.approx(spec.lights[0]["spot_size"], rel=1e-6)
    assert got["spot"]["spot_blend"] == pytest.approx(spec.lights[0]["spot_blend"], rel=1e-6)
    assert got["spot"]["radius"] == 0 and got["spot"]["soft_falloff"] is False
    assert got["ball"]["radius"] == pytest.approx(100.0) and got["ball"]["soft_falloff"] is False
    assert got["box"]["shape"] == "RECTANGLE" and got["box"]["size"] == pytest.approx([400.0, 200.0])
    e = info["environment"]
    assert e["strength"] == pytest.approx(1.5) and e["projection"] == "EQUIRECTANGULAR"
    assert e["vector_type"] == "VECTOR" and e["coordinates"] == "Generated" and e["output"] == "ShaderNodeAddShader"
    assert e["size"] == [32, 16] and e["colorspace"] == "Linear Rec.709"
    np.testing.assert_allclose(e["matrix"], spec.environment["matrix"], atol=1e-6)
    np.testing.assert_array_equal(arr["environment"], spec.environment_pixels)


def plate_reading(blender, scene, spp=16, engine="cycles"):
    """The plate's centre (the 2 x 2 middle pixels of 4 x 4) in `engine`; scene None: the one loaded."""
    if scene is not None:
        blender.load(bs.blender_spec(scene, 4, 4))
    img, _ = blender.render(engine, spp if engine == "cycles" else 1, (4, 4))
    return img[1:3, 1:3, :3].reshape(-1, 3).mean(0)


def test_new_light_units_on_a_lambertian_plate(blender, tmp_path):
    """The plate's centre read by Cycles under each new kind, against its irradiance E: 0.5 E / pi.
    A spot of intensity 3 straight above at 0.5 m: E = 3 / 0.25; tilted to where Blender's smoothstep is
    at half (cos theta halfway between the cone's cosines): half that. A sphere of radiance 2 and radius
    0.1 m at 0.5 m: E = pi L (r / d)^2. A rect of radiance 3, 0.4 x 0.2 m, 0.5 m above and facing the
    plate: E from Lambert's polygon formula (skinlab/scene/optics/lighting.py). The lights hang between
    the camera and the plate: hidden from the camera, as the truth's emitters are. A uniform map of
    radiance 0.8 at intensity 1.5: E = pi 0.8 1.5."""
    from skinlab.scene.graph import LightNode
    from skinlab.scene.optics.lighting import rect_vector_irradiance

    half = math.acos((math.cos(math.radians(20)) + math.cos(math.radians(40))) / 2)
    rect = place(LightNode("box", "rect", intensity=3.0, width=0.4, height=0.2), (0.0, 0.0, 0.5), (0, 0, -1))
    ex, ey = rect.half_extents()
    e_rect = float(rect_vector_irradiance((0, 0, 0.5), ex, ey, rect.direction, [[0.0, 0.0, 0.0]])[0, 2]) * 3.0
    cases = (
        (place(LightNode("spot", "spot", intensity=3.0, inner_deg=20.0, outer_deg=40.0), (0, 0, 0.5), (0, 0, -1)),
         None, 12.0, 2e-3),
        (place(LightNode("spot", "spot", intensity=3.0, inner_deg=20.0, outer_deg=40.0), (0, 0, 0.5),
               (math.sin(half), 0.0, -math.cos(half))), None, 6.0, 2e-3),
        (place(LightNode("ball", "sphere", intensity=2.0, radius=0.1), (0, 0, 0.5), (0, 0, -1)), None,
         math.pi * 2.0 * (0.1 / 0.5) ** 2, 0.02),
        (rect, None, e_rect, 0.02),
        (None, (environment_map(tmp_path, value=0.8), 30.0, 1.5), math.pi * 0.8 * 1.5, 0.02),
    )  # fmt: skip
    eevee = {}
    for light, env, e, tol in cases:
        name = light.kind if light else "environment"
        got = plate_reading(blender, lit_scene(*([light] if light else []), env=env), spp=64)
        np.testing.assert_allclose(got, 0.5 * e / math.pi, rtol=tol, err_msg=name)
        eevee[name] = plate_reading(blender, None, engine="eevee")[0] / (0.5 * e / math.pi)
    # EEVEE (1 sample) on the same plates: the spot and the map as Cycles reads them; the rect and the sphere
    # about a fifth darker (measured 0.79 and 0.81 of the exact irradiance; the same with their shadows off)
    assert abs(eevee["spot"] - 1) < 0.01 and abs(eevee["environment"] - 1) < 0.02, eevee
    assert 0.7 < eevee["rect"] < 0.9 and 0.7 < eevee["sphere"] < 0.9, eevee


def test_environment_orientation_in_cycles(blender, tmp_path):
    """A black map with one bright texel up and toward the map's +Z (row 3 of 16, column 16 of 32),
    turned 90 degrees about +Y: by Mitsuba's convention (skinlab/scene/envmap.py) its light comes from
    world l = R_y(90) m, up and toward +X. Cycles' grey sphere seen from +Z (image +X right, +Y up) shares
    its light among the image's quadrants as a Lambertian sphere lit from l does (orthographic, a point
    source at the texel's centre: 0.68, 0.19, 0.12, 0.00 upper right, upper left, lower right, lower
    left; measured 0.676, 0.195, 0.130, 0.0001), and so does EEVEE's. A mirrored u, a flipped v or the
    turn's sign would light another quadrant."""
    from skinlab.scene import envmap
    from skinlab.scene.primitives import sphere_mesh

    grey = Material("grey", {"base_color": (0.5, 0.5, 0.5), "specular": 0.0, "roughness": 1.0, "subsurface": 0.0})
    s = Scene("ball", 1000.0)
    s.environment.ambient = np.zeros(3)
    s.environment.map, s.environment.rotation_deg = environment_map(tmp_path, (3, 16), 2000.0), 90.0
    s.add(MeshNode("ball", sphere_mesh(0.1, 3), grey))
    cam = CameraNode("cam", yfov=math.radians(8.0), znear=0.1, zfar=10.0)
    cam.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0))
    s.add(cam)
    blender.load(bs.blender_spec(s, 16, 16))

    def shares(lum):  # row 0 at the top
        h = lum.shape[0] // 2
        q = np.array([lum[:h, h:].mean(), lum[:h, :h].mean(), lum[h:, h:].mean(), lum[h:, :h].mean()])
        return q / q.sum()

    theta, phi = 3.5 / 16 * math.pi, 16.5 / 32 * 2 * math.pi  # the texel's centre: v = theta / pi, u = phi / 2 pi
    m = np.array([math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi)])
    lx, ly, lz = envmap.rotation_y(90.0) @ m
    n = 256
    y, x = np.mgrid[0:n, 0:n]
    x, y = (x + 0.5) / n * 2 - 1, 1 - (y + 0.5) / n * 2
    z = np.sqrt(np.clip(1 - x * x - y * y, 0, 1))
    want = shares(np.where(x * x + y * y < 1, np.clip(x * lx + y * ly + z * lz, 0, None), 0.0))
    assert want[0] > 0.6 and want[3] < 0.01
    for engine, spp in (("cycles", 16), ("eevee", 1)):  # EEVEE reads the same map the same way (0.678, 0.192, ...)
        img, _ = blender.render(engine, spp, (16, 16))
        np.testing.assert_allclose(shares(img[..., :3].mean(2)), want, atol=0.03, err_msg=engine)


def test_cycles_random_walk_slab_reflects_chandrasekhars_albedo(blender):
    """Cycles' random walk at an index-matched boundary continues the camera ray into the medium and
    leaves through a Lambertian exit: under a uniform sky of radiance 1 it reads, by reciprocity,
    the albedo for the view's incidence, 1 - H(1) sqrt(1 - alpha), if it walks the truth's medium
    (the Base Color from inverting its remap). Random Walk (Skin) enters half of its paths diffusely:
    the mean of that albedo and the diffuse one."""
    from skinlab.scene.optics.boundary import hemispherical

    s = sky_slab((0.2, 0.5, 0.8), (4.0, 1.0, 0.5))
    alpha = material_medium(s.find("slab").material.values).alpha_arr
    blender.load(bs.blender_spec(s, 8, 8))
    a1 = np.array([float(albedo_isotropic(a, 1.0)) for a in alpha])
    ad = np.array([hemispherical(lambda m, a=a: albedo_isotropic(a, m)) for a in alpha])
    for method, want in (("RANDOM_WALK", a1), ("RANDOM_WALK_SKIN", 0.5 * (a1 + ad))):
        x, _ = blender.render("cycles", 64, (8, 8), method=method, seed=1)
        y, _ = blender.render("cycles", 64, (8, 8), method=method, seed=2)
        got = 0.5 * (x + y)[..., :3].reshape(-1, 3).mean(0)
        se = np.abs(x - y)[..., :3].reshape(-1, 3).mean(0) / 2 / 8  # of the 64-pixel mean
        assert np.all(np.abs(got - want) < 0.005 + 4 * se), (method, got, want, se)
        assert np.all(x[..., 3] > 0.99)
    assert np.all(np.abs(a1 - ad) > 0.02)  # the two entries are told apart


def test_light_units_on_a_lambertian_plate(blender):
    """A Lambertian plate (albedo 0.5, no specular) seen from above: a sun of irradiance 2 at 60 degrees
    reads 0.5 * 2 cos 60 / pi, a point light of intensity I at d metres 0.5 (I / d^2) cos / pi (Skinlab's
    units: the frame is in millimetres, the power 4 pi I 1000^2)."""
    from skinlab.scene.graph import LightNode

    sun = light_from((0.0, math.sin(math.radians(60)), -math.cos(math.radians(60))), intensity=2.0)
    bulb = LightNode("bulb", "point", intensity=3.0, translation=(0.0, 0.0, 0.5))
    for light, want, tol in ((sun, 0.5 * 2.0 * 0.5 / math.pi, 2e-3), (bulb, 0.5 * 3.0 / 0.5**2 / math.pi, 5e-3)):
        np.testing.assert_allclose(plate_reading(blender, lit_scene(light)), want, rtol=tol, err_msg=light.kind)


def test_eevee_frame_with_subsurface_scattering(blender):
    """One tiny EEVEE frame (1 sample) of the shadow-edge slab: it completes, covers the slab, reads the
    lit side as Lambertian with the Base Color (EEVEE's diffusion conserves energy on a flat surface;
    the Sun's units as Cycles'), and its subsurface scattering carries red light past the shadow edge,
    where no light arrives directly."""
    scene = load_scene(resolve_scene("slab-edge-skin1"))
    spec = bs.blender_spec(scene, 16, 16)
    blender.load(spec)
    img, rep = blender.render("eevee", 1, (16, 16))
    assert rep["image_ms"] > 0 and img.shape == (16, 16, 4)
    assert np.all(img[..., 3] > 0.99)  # the slab fills the frame
    base = np.asarray(spec.objects[0].material["inputs"]["Base Color"][:3])
    lit = img[1:5, 4:12, :3].reshape(-1, 3).mean(0)
    np.testing.assert_allclose(lit, 3.0 * math.cos(math.radians(45)) * base / math.pi, rtol=0.05)
    below = img[8, 4:12, :3].mean(0)  # the first row past the shadow edge (y = 20 mm, the frame's centre)
    assert below[0] > 0.01 * lit[0] and below[0] > 3 * below[2], (below, lit)
    assert np.all(img[13:, :, :3] < 0.01 * lit)  # far into the shadow: dark


def test_ledger_rows_of_the_peers(blender, tmp_path):
    """`skinlab bench accuracy --blender` on the tests' tiny sweep: the peer rows carry the ledger's truth
    columns and their own, appear in the tables, the error maps and ledger.md's peer section with the
    interleaved ratio, and stay out of the Pareto fronts and the recommended defaults."""
    import json

    from skinlab.bench.accuracy import TINY, run_sweep
    from skinlab.bench.blender_peer import PeerSetting

    blender.close()  # the ledger starts its own session
    peers = (PeerSetting("eevee", 1), PeerSetting("cycles", 4, timed=False))
    res = run_sweep(TINY, tmp_path, peer=False, progress=False, images=False, references=True, blender=peers)
    rows = [r for r in res["rows"] if r.get("peer")]
    assert [r["setting"] for r in rows] == ["eevee 1 spp", "cycles rw 4 spp"]
    for r in rows:
        assert r["status"] == "ok", r["error"]
        assert np.isfinite(r["truth_rel_l1_block"]) and np.isfinite(r["truth_flip"]) and r["frame_ms_median"] > 0
        assert (tmp_path / "error_maps" / f"head-skin1-matched-{r['setting'].replace(' ', '-')}.png").is_file()
    ee, cy = rows
    assert ee["width"] == TINY.size[0] and np.isfinite(ee["first_frame_ms"]) and np.isfinite(ee["image_rel_l1"])
    assert cy["width"] == TINY.truth.size[0] and np.isfinite(cy["peer_noise_block"]) and cy["samples"] == 4
    fronts = {r["setting"] for f in res["fronts"].values() for r in f}
    assert not fronts & {"eevee 1 spp", "cycles rw 4 spp"}
    meta = json.loads((tmp_path / "ledger.json").read_text())["meta"]["blender"]
    ratio = meta["ratios"]["head-skin1-matched"]
    assert ratio["ratio"] > 0 and ratio["skinlab_setting"] == "tsd K6 512 auto"
    md = (tmp_path / "ledger.md").read_text()
    assert "## Peers: Blender (EEVEE, Cycles)" in md and "| head-skin1-matched | eevee 1 spp |" in md
    header = (tmp_path / "ledger.csv").read_text().splitlines()[0].split(",")
    assert {"samples", "first_frame_ms", "peer_noise_block"} <= set(header)


def test_anisotropic_medium_maps_to_cycles_anisotropy():
    """A material with a Henyey-Greenstein g: the truth holds the real coefficients and the hg phase;
    Blender gets that g, the Base Color whose remap at g is the real albedo, and the radius Cycles turns
    into the same sigma_t = 1 / (d (1 - g))."""
    s = Scene("aniso", 1.0)
    s.environment.ambient = np.zeros(3)
    mat = skin(radius=(8.0, 4.0, 2.0), color=(0.6, 0.4, 0.3), specular=0.0)
    mat.values["subsurface_scatter_anisotropy"] = 0.5
    s.add(MeshNode("cube", box_mesh((20.0, 20.0, 20.0)), mat))
    s.add(light_from((0, 0, -1)))
    cam = CameraNode("cam", yfov=math.radians(30), znear=1.0, zfar=200.0)
    cam.look_at((0.0, 0.0, 60.0), (0.0, 0.0, 0.0))
    s.add(cam)
    interior = describe(s, 8, 8).shapes[0].interior
    assert interior["phase"] == {"type": "hg", "g": 0.5}
    o = bs.blender_spec(s, 8, 8).objects[0].material
    inp, rw = o["inputs"], o["subsurface"]["RANDOM_WALK"]
    assert inp["Subsurface Anisotropy"] == 0.5
    np.testing.assert_allclose(bs.cycles_rw_alpha(inp["Base Color"][:3], 0.5), interior["albedo"]["value"], atol=1e-9)
    d = np.asarray(rw["Subsurface Radius"]) * rw["Subsurface Scale"] / (4 * math.pi)
    sigma_t = np.asarray(interior["sigma_t"]["value"]) * interior["scale"]
    np.testing.assert_allclose(1 / (d * (1 - 0.5)), sigma_t, rtol=1e-9)
