"""The Mitsuba exporter (skinlab/truth/export.py) without rendering: units, transforms, media values,
interface choice, lights, camera, closed media, bad input; the cache and pass plan of the reference."""

import math
import subprocess
import sys

import numpy as np
import pytest

from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.mesh_topology import boundary_loops, weld
from skinlab.scene.optics.material_medium import eta_from_specular, material_medium
from skinlab.scene.optics.media import preset
from skinlab.scene.primitives import box_mesh
from skinlab.truth import export as ex
from skinlab.truth.description import chunk_plan
from skinlab.truth.reference import ReferenceRequest
from tests.tsd_scenes import light_from, skin, slab_scene


def _box_scene(mat=None, mm_per_unit=1.0, node_kw=None) -> Scene:
    s = Scene("box", mm_per_unit)
    s.environment.ambient = np.zeros(3)
    s.add(MeshNode("box", box_mesh((2.0, 2.0, 2.0)), mat or skin(), **(node_kw or {})))
    s.add(light_from((0, 0, -1), intensity=2.0))
    cam = CameraNode("cam", yfov=math.radians(40), znear=0.1, zfar=100)
    cam.look_at((0, 0, 10), (0, 0, 0))
    s.add(cam)
    return s


def test_medium_is_the_one_skinlab_derives_in_millimetres():
    mat = skin(radius=(8.0, 4.0, 2.0), color=(0.8, 0.6, 0.5))
    for mm in (1.0, 20.0, 45.0):
        d = ex.describe(_box_scene(mat, mm), 8, 8)
        med = d.shapes[0].interior
        m = material_medium(mat.values)
        sigma_t = np.asarray(med["sigma_t"]["value"]) * med["scale"]
        assert np.allclose(sigma_t, 1.0 / m.mfp_arr)  # the reference frame's unit is the millimetre
        assert d.frame_scale == mm
        assert np.allclose(med["albedo"]["value"], m.alpha_arr)
        assert max(med["sigma_t"]["value"]) == pytest.approx(1.0)  # Mitsuba wants RGB in [0, 1]
        assert med["phase"] == {"type": "isotropic"}


def test_a_preset_medium_round_trips_at_its_own_index():
    """A material made from a Jensen preset at its index exports that preset's coefficients."""
    from skinlab.scene.materials import medium_values

    mat = Material("m", medium_values(preset("skin1")))
    d = ex.describe(_box_scene(mat, 1.0), 8, 8)
    med = d.shapes[0].interior
    p = preset("skin1")
    assert np.allclose(np.asarray(med["sigma_t"]["value"]) * med["scale"], p.sigma_t, rtol=2e-3)
    assert np.allclose(med["albedo"]["value"], p.alpha_arr, atol=2e-3)


def test_radius_zero_channel_is_a_dense_finite_medium():
    d = ex.describe(_box_scene(skin(radius=(5.0, 0.0, 1.0))), 8, 8)
    med = d.shapes[0].interior
    assert np.isfinite(med["scale"]) and np.isfinite(med["sigma_t"]["value"]).all()
    assert med["sigma_t"]["value"][1] == pytest.approx(1.0)  # the densest channel


@pytest.mark.parametrize(
    "specular, roughness, kind",
    [(0.0, 0.5, "null"), (0.35, 0.45, "roughdielectric"), (0.5, 0.0, "dielectric"), (1.0, 1.0, "roughdielectric")],
)
def test_interface_follows_the_index(specular, roughness, kind):
    d = ex.describe(_box_scene(skin(specular=specular, roughness=roughness)), 8, 8)
    b = d.shapes[0].bsdf
    assert b["type"] == kind
    if kind != "null":
        assert b["int_ior"] == pytest.approx(eta_from_specular(specular)) and b["int_ior"] > 1
        assert b["ext_ior"] == 1.0
    if kind == "roughdielectric":
        assert b["alpha"] == pytest.approx(roughness**2) and b["distribution"] == "ggx"


def test_surfaces_without_scattering_are_two_sided_principled():
    plain = Material("grey", {"base_color": (0.2, 0.4, 0.6), "roughness": 0.3, "metallic": 0.1, "specular": 0.6})
    d = ex.describe(_box_scene(plain), 8, 8)
    s = d.shapes[0]
    assert s.interior is None and s.bsdf["type"] == "twosided"
    inner = s.bsdf["bsdf"]
    assert inner["type"] == "principled" and inner["base_color"]["value"] == pytest.approx([0.2, 0.4, 0.6])
    assert (inner["roughness"], inner["metallic"], inner["specular"]) == pytest.approx((0.3, 0.1, 0.6))


def test_geometry_is_in_the_centred_millimetre_frame_with_transformed_normals():
    kw = {"translation": (1.0, 2.0, 3.0), "scale": (2.0, 1.0, 0.5)}
    s = _box_scene(node_kw=kw, mm_per_unit=45.0)
    node = s.find("box")
    d = ex.describe(s, 8, 8)
    w = node.world_matrix
    p = node.mesh.positions @ w[:3, :3].T + w[:3, 3]
    assert np.allclose(d.frame_origin, (1.0, 2.0, 3.0)) and d.frame_scale == 45.0
    assert np.allclose(d.shapes[0].positions, (p - (1.0, 2.0, 3.0)) * 45.0, atol=1e-4)
    # centred: the bounds are symmetric about 0, in millimetres (the box is 4 x 2 x 1 units)
    q = d.shapes[0].positions
    assert np.allclose(q.max(0), -q.min(0), atol=1e-4) and np.allclose(q.max(0) - q.min(0), (180.0, 90.0, 45.0))
    n = d.shapes[0].normals
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    # each face's normal stays perpendicular to the (scaled) face
    tri = d.shapes[0].positions[d.shapes[0].faces[0]]
    e = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    assert abs(np.dot(e / np.linalg.norm(e), n[d.shapes[0].faces[0][0]])) == pytest.approx(1.0, abs=1e-5)


def test_camera_frame_looks_down_skinlab_minus_z_with_x_mirrored():
    s = _box_scene(mm_per_unit=2.0)
    s.camera.look_at((3.0, 1.0, 10.0), (0.0, 0.0, 0.0))
    d = ex.describe(s, 32, 16)
    m = d.camera_to_world
    fwd = -s.camera.world_matrix[:3, 2]
    assert np.allclose(m[:3, 2], fwd / np.linalg.norm(fwd))  # Mitsuba looks along +Z
    assert np.allclose(m[:3, 0], -s.camera.world_matrix[:3, 0])  # Mitsuba's +X points left
    assert np.allclose(m[:3, 3], (6.0, 2.0, 20.0))  # the box is centred at 0: millimetres
    assert d.fov_y_deg == pytest.approx(40.0) and (d.width, d.height) == (32, 16)
    assert (d.near, d.far) == pytest.approx((0.2, 200.0))


def test_lights_keep_their_irradiance_and_intensity():
    s = _box_scene(mm_per_unit=45.0)
    point = LightNode("bulb", "point", color=(1.0, 0.5, 0.25), intensity=4.0)
    point.translation = (0.0, 5.0, 0.0)
    s.add(point)
    s.find("box").translation = (1.0, 0.0, 0.0)  # the frame's origin: the box's centre
    d = ex.describe(s, 8, 8)
    sun, bulb = d.emitters
    key = s.find("sun")
    assert sun["kind"] == "directional" and np.allclose(sun["direction"], key.direction)
    assert np.allclose(sun["irradiance"], key.radiance)
    # Skinlab: E = I / d_m^2; Mitsuba measures d in the frame's millimetres
    assert np.allclose(bulb["intensity"], np.array([4.0, 2.0, 1.0]) / 0.001**2)
    assert np.allclose(bulb["position"], (-45.0, 225.0, 0.0))


def test_sun_disk_keeps_the_irradiance():
    d = ex.describe(_box_scene(), 8, 8, sun_deg=0.53)
    (e,) = d.emitters
    half = math.radians(0.53) / 2
    dist = np.linalg.norm(np.asarray(e["centre"]))
    assert e["radius"] / dist == pytest.approx(math.tan(half), rel=1e-3)
    assert np.allclose(np.asarray(e["radiance"]) * math.pi * math.sin(half) ** 2, 2.0)


def test_ambient_becomes_an_environment_with_a_note():
    s = _box_scene()
    s.environment.ambient = np.array([0.1, 0.2, 0.3])
    d = ex.describe(s, 8, 8)
    assert {"kind": "constant", "radiance": [0.1, 0.2, 0.3]} in d.emitters
    assert any("unshadowed" in n for n in d.notes)


def test_open_mesh_is_closed_for_the_medium_and_wound_outward():
    box = box_mesh((2.0, 4.0, 6.0))
    keep = np.ones(len(box.indices), bool)
    keep[:2] = False  # drop the top face: a hole of four edges
    faces = box.indices[keep]
    assert len(boundary_loops(weld(box.positions, faces).first_faces())) == 1
    p, n, f, closed = ex.close_holes(box.positions, box.normals, faces)
    assert closed == 1 and boundary_loops(weld(p, f).first_faces()) == []
    assert ex.signed_volume(p, f) == pytest.approx(48.0, rel=1e-5)
    # UV seams (vertices repeated per face) are not holes
    assert boundary_loops(weld(box.positions, box.indices).first_faces()) == []


def test_inward_wound_mesh_is_turned_outward():
    box = box_mesh((2.0, 2.0, 2.0))
    box.indices = box.indices[:, ::-1].copy()
    s = Scene("inv", 1.0)
    s.add(MeshNode("box", box, skin()))
    s.add(light_from((0, 0, -1)))
    s.add(ex_camera())
    d = ex.describe(s, 8, 8)
    assert ex.signed_volume(d.shapes[0].positions, d.shapes[0].faces) > 0


def ex_camera():
    cam = CameraNode("cam", yfov=math.radians(40), znear=0.1, zfar=100)
    cam.look_at((0, 0, 10), (0, 0, 0))
    return cam


def test_unrepresentable_scenes_name_the_problem():
    s = _box_scene()
    s.find("sun").kind = "laser"  # a light type the reference cannot draw
    with pytest.raises(ex.ReferenceError, match="light 'sun'.*laser"):
        ex.describe(s, 8, 8)
    dark = Scene("dark", 1.0)
    dark.add(MeshNode("box", box_mesh((1, 1, 1)), skin()))
    dark.add(ex_camera())
    dark.environment.ambient = np.zeros(3)
    with pytest.raises(ex.ReferenceError, match="no light"):
        ex.describe(dark, 8, 8)
    with pytest.raises(ex.ReferenceError, match="sun_deg"):
        ex.describe(_box_scene(), 8, 8, sun_deg=45.0)


def test_cli_reports_bad_input_in_one_line(tmp_path):
    bad = tmp_path / "x.png"
    r = subprocess.run(
        [sys.executable, "-m", "skinlab.cli", "reference", "--out", str(bad), "--size", "8x8", "--spp", "4"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and ".exr" in r.stderr
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "skinlab.cli",
            "reference",
            "--out",
            str(tmp_path / "x.exr"),
            "--spp",
            "4",
            "--passes",
            "8",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and "spp" in r.stderr and not (tmp_path / "x.exr").exists()


def test_chunks_split_every_sample_between_the_passes():
    for spp, passes in ((1024, 4), (7, 2), (100, 3), (33, 2)):
        plan = chunk_plan(spp, passes)
        assert sum(n for _, n in plan) == spp
        per = [sum(n for p, n in plan if p == k) for k in range(passes)]
        assert max(per) - min(per) <= 1 and all(n >= 1 for _, n in plan)
    with pytest.raises(ValueError, match="passes"):
        ReferenceRequest(8, 8, spp=4, passes=1)


def test_the_whole_description_changes_the_cache_key():
    from skinlab.truth.reference import reference_key

    s = slab_scene()
    req = ReferenceRequest(8, 8, spp=16, passes=2)
    k0 = reference_key(ex.describe(s, 8, 8), req, "3.x")
    assert k0 == reference_key(ex.describe(slab_scene(), 8, 8), req, "3.x")
    s.find("slab").material.update({"subsurface_radius": (1.0, 1.0, 1.0)})
    assert reference_key(ex.describe(s, 8, 8), req, "3.x") != k0
    assert reference_key(ex.describe(slab_scene(), 8, 8), ReferenceRequest(8, 8, spp=32, passes=2), "3.x") != k0
    assert reference_key(ex.describe(slab_scene(), 8, 8), req, "3.y") != k0


def test_frame_is_centred_on_the_scattering_meshes():
    """A far plain occluder does not move the origin off the medium (the ray offset grows with the
    distance from it); with no scattering mesh every mesh counts."""
    s = _box_scene(node_kw={"translation": (1.0, 2.0, 3.0)}, mm_per_unit=10.0)
    plate = Material("black", {"base_color": (0.0, 0.0, 0.0)})
    s.add(MeshNode("plate", box_mesh((2.0, 2.0, 0.1)), plate, translation=(40.0, 0.0, 0.0)))
    d = ex.describe(s, 8, 8)
    assert np.allclose(d.frame_origin, (1.0, 2.0, 3.0))
    box = next(x for x in d.shapes if x.name == "box")
    assert np.allclose(box.positions.max(0), -box.positions.min(0), atol=1e-4)  # the medium is centred
    s.find("box").material = plate
    lo, hi = s.world_bounds()
    assert np.allclose(ex.describe(s, 8, 8).frame_origin, (lo + hi) / 2) and (lo + hi)[0] / 2 == 20.5


def test_environment_map_exports_as_mitsubas_envmap_with_the_same_rotation(tmp_path):
    """The map's own pixels (its sources included), its rotation about +Y and intensity as scale;
    the frame's source lights are not exported again; save/load carries the pixels; the key sees them."""
    from skinlab.scene.envmap import write_map
    from skinlab.truth import description
    from skinlab.truth.reference import reference_key

    px = np.full((16, 32, 3), 0.5, np.float32)
    px[4, 8] = 9000.0
    s = _box_scene()
    for l in list(s.lights()):
        l.visible = False
    s.environment.map = write_map(tmp_path / "sun.exr", px)
    s.environment.rotation_deg = 35.0
    s.environment.intensity = 1.5
    d = ex.describe(s, 8, 8)
    (em,) = d.emitters
    assert em["kind"] == "envmap" and em["rotation_deg"] == 35.0 and em["scale"] == 1.5 and em["map"] == "sun.exr"
    assert np.array_equal(d.environment, px)
    assert any("envmap" in n for n in d.notes)
    path = tmp_path / "d.npz"
    description.save(d, path)
    back = description.load(path)
    assert np.array_equal(back.environment, px) and back.emitters == d.emitters
    req = ReferenceRequest(8, 8, spp=16, passes=2)
    other = ex.describe(s, 8, 8)
    px2 = px.copy()
    px2[4, 9] = 1.0
    other.environment = px2
    assert reference_key(d, req, "3.x") != reference_key(other, req, "3.x")
    # a black map (or intensity 0) is no light: with nothing else the reference refuses the scene
    s.environment.map = write_map(tmp_path / "black.exr", np.zeros((16, 32, 3), np.float32))
    with pytest.raises(ex.ReferenceError, match="no light"):
        ex.describe(s, 8, 8)


def test_envmap_emitter_dict_turns_about_y(tmp_path):
    mi = pytest.importorskip("mitsuba")
    from skinlab.truth.description import mitsuba_emitter
    from skinlab.truth.reference import set_variant

    set_variant("scalar_rgb")
    px = np.ones((8, 16, 3), np.float32)
    e = mitsuba_emitter(mi, {"kind": "envmap", "rotation_deg": 90.0, "scale": 2.0}, px)
    assert e["type"] == "envmap" and e["scale"] == 2.0
    m = np.array(e["to_world"].matrix, np.float64)
    assert np.allclose(m[:3, :3] @ [1.0, 0, 0], [0, 0, -1.0], atol=1e-6)  # as skinlab.scene.envmap.rotation_y
