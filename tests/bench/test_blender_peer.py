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
from skinlab.scene.optics.tsd import material_medium
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

    grey = Material("grey", {"base_color": (0.5, 0.5, 0.5), "specular": 0.0, "roughness": 1.0, "subsurface": 0.0})
    cam = CameraNode("cam", yfov=math.radians(1.0), znear=0.1, zfar=10.0)
    cam.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0))
    sun = light_from((0.0, math.sin(math.radians(60)), -math.cos(math.radians(60))), intensity=2.0)
    bulb = LightNode("bulb", "point", intensity=3.0, translation=(0.0, 0.0, 0.5))
    for light, want, tol in ((sun, 0.5 * 2.0 * 0.5 / math.pi, 2e-3), (bulb, 0.5 * 3.0 / 0.5**2 / math.pi, 5e-3)):
        s = Scene("plate", 1000.0)
        s.environment.ambient = np.zeros(3)
        s.add(MeshNode("plate", box_mesh((1.0, 1.0, 0.01)), grey, translation=(0.0, 0.0, -0.005)))
        s.add(light)
        s.add(cam)
        blender.load(bs.blender_spec(s, 4, 4))
        img, _ = blender.render("cycles", 16, (4, 4))
        np.testing.assert_allclose(img[1:3, 1:3, :3], want, rtol=tol, err_msg=light.kind)


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
