import numpy as np
import pytest

from skinlab.scene import transform as tf
from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Node, Scene
from skinlab.scene.materials import Material
from skinlab.scene.mesh import Mesh


def tri_mesh():
    return Mesh("tri", np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]]))


def test_world_matrix_composes_and_is_cached_until_something_above_changes():
    a, b, c = (
        Node("a", translation=(1, 0, 0)),
        Node("b", rotation=tf.euler_deg_to_quat([0, 0, 90])),
        Node("c", scale=(2, 2, 2)),
    )
    a.add(b)
    b.add(c)
    c.translation = (1, 0, 0)
    p = c.world_matrix @ [0, 0, 0, 1]
    assert np.allclose(p[:3], [1, 1, 0])  # a moves +x, b rotates c's +x offset to +y
    n = c.world_updates
    for _ in range(5):
        _ = c.world_matrix
    assert c.world_updates == n  # cached
    sibling = Node("s")
    a.add(sibling)
    sibling.translation = (5, 5, 5)
    _ = c.world_matrix
    assert c.world_updates == n  # a sibling's change does not touch c
    a.translation = (0, 0, 1)
    assert np.allclose((c.world_matrix @ [0, 0, 0, 1])[:3], [0, 1, 1])
    assert c.world_updates == n + 1


def test_quaternion_round_trip_and_look_at():
    q = tf.euler_deg_to_quat([10, 20, 30])
    assert np.allclose(tf.matrix_to_quat(tf.quat_to_matrix(q)) * np.sign(q[3]), q * np.sign(q[3]))
    r = tf.quat_to_matrix(tf.look_at_rotation([0, 0, 5], [0, 0, 0]))
    assert np.allclose(r @ [0, 0, -1], [0, 0, -1])
    t, rot, s = tf.decompose(tf.compose([1, 2, 3], q, [2, 3, 4]))
    assert np.allclose(t, [1, 2, 3]) and np.allclose(s, [2, 3, 4])


def test_nodes_reject_bad_values_with_their_names():
    with pytest.raises(ValueError, match="light 'k': type must be"):
        LightNode("k", kind="laser")
    with pytest.raises(ValueError, match="camera 'c': yfov"):
        CameraNode("c", yfov=0)
    with pytest.raises(ValueError, match="mm_per_unit"):
        Scene("s", mm_per_unit=0)
    with pytest.raises(ValueError, match="node 'n': rotation"):
        Node("n").rotation = (0, 0, 0, 0)


def test_material_declaration_drives_uniforms_defines_and_validation():
    m = Material("skin", {"roughness": 0.3, "base_color_map": "x.png"})
    u = m.uniforms()
    assert u["u_roughness"] == 0.3 and u["u_subsurface_radius"] == (1.0, 0.2, 0.1)
    assert "u_base_color_map" not in u and m.textures()["u_base_color_map"][1] == "srgb"
    assert m.defines() == {"HAS_BASE_COLOR_MAP": "1"}
    with pytest.raises(ValueError, match=r"material 'skin': roughness: expected a number in \[0, 1\], got 1.5"):
        m.update({"roughness": 1.5})
    with pytest.raises(ValueError, match=r"subsurface_radius: expected 3 numbers in \[0, 1000\], got"):
        m.update({"subsurface_radius": [1, -1, 1]})
    with pytest.raises(ValueError, match="unknown parameter 'roughnes'"):
        m.update({"roughnes": 0.2})
    with pytest.raises(ValueError, match="sss_model: expected one of none, dipole"):
        m.update({"sss_model": "magic"})
    o = m.with_overrides({"roughness": 0.1})
    assert o["roughness"] == 0.1 and m["roughness"] == 0.3


def test_mesh_validation_and_degenerate_normals():
    with pytest.raises(ValueError, match="mesh 'bad'.*out of range"):
        Mesh("bad", np.zeros((3, 3)), np.array([[0, 1, 5]]))
    m = Mesh("flat", np.zeros((3, 3)), np.array([[0, 1, 2]]))  # zero-area triangle
    assert np.isfinite(m.normals).all()
    s = Scene("s")
    s.add(MeshNode("m", tri_mesh(), Material()))
    lo, hi = s.world_bounds()
    assert np.allclose(lo, [0, 0, 0]) and np.allclose(hi, [1, 1, 0])


def test_tangents_follow_uv_u_direction():
    from skinlab.scene.mesh import compute_tangents

    p = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0]], np.float32)
    n = np.tile([0, 0, 1.0], (3, 1))
    uv = np.array([[0, 0], [0, 1], [1, 0]], np.float32)  # u runs along +y here
    t = compute_tangents(p, n, uv, np.array([[0, 1, 2]]))
    assert np.allclose(t[:, :3], [0, 1, 0], atol=1e-6) and set(t[:, 3]) == {-1.0}


def test_param_clamp_keeps_values_in_range_for_widgets():
    from skinlab.scene.materials import PRINCIPLED_PARAMS

    pm = {p.name: p for p in PRINCIPLED_PARAMS}
    assert pm["roughness"].clamp(3.0) == 1.0 and pm["roughness"].clamp(-1) == 0.0
    assert pm["roughness"].clamp(float("nan")) == pm["roughness"].default
    assert pm["subsurface_radius"].clamp((5.0, -1.0, 2000.0)) == (5.0, 0.0, 1000.0)
    assert pm["base_color"].clamp(0.5) == (0.5, 0.5, 0.5)
    assert pm["sss_model"].clamp("pbd") == "pbd"
    with pytest.raises(ValueError, match="sss_model: expected one of"):
        pm["sss_model"].clamp("fog")
    with pytest.raises(ValueError, match="subsurface_radius: expected 3 numbers"):
        pm["subsurface_radius"].clamp((1.0, 2.0))
