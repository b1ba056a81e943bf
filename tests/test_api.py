"""The documented Python API (skinlab/api.py, README): load a scene or a mesh, render to NumPy."""

import numpy as np
import pytest

from skinlab.api import Skinlab, load
from skinlab.resources import assets_root

ASSETS = assets_root()


@pytest.fixture(scope="module")
def lab():
    with Skinlab() as s:
        yield s


def test_render_head_to_numpy_with_exposure_and_orbit_restored(lab):
    scene = load()
    cam_before = scene.camera.world_matrix.copy()
    f = lab.render(scene, 48, 32, sss_model="none", shadow_size=256)
    assert f.ldr.shape == (32, 48, 4) and f.ldr.dtype == np.uint8
    assert f.hdr.shape == (32, 48, 4) and f.hdr.dtype == np.float32 and np.isfinite(f.hdr).all()
    assert f.depth.shape == (32, 48) and np.isinf(f.depth).any() and np.isfinite(f.depth).any()
    bright = lab.render(scene, 48, 32, sss_model="none", shadow_size=256, exposure=4.0)
    lit = f.hdr[..., 3] > 0
    # exposure scales the display image only: same radiance, brighter PNG pixels
    assert np.allclose(bright.hdr, f.hdr) and bright.ldr[lit, :3].mean() > f.ldr[lit, :3].mean() + 10
    turned = lab.render(scene, 48, 32, sss_model="none", shadow_size=256, camera_orbit=90)
    assert not np.array_equal(turned.depth, f.depth)
    assert scene.environment.exposure == 1.0 and np.allclose(scene.camera.world_matrix, cam_before)
    with pytest.raises(ValueError, match="exposure"):
        lab.render(scene, 8, 8, exposure=0)
    with pytest.raises(ValueError, match="technique"):
        lab.render(scene, 8, 8, technique="magic")
    # the technique's own settings by keyword
    small = lab.render(scene, 24, 24, technique="tsd", size=256, fit_size=False, shadow_size=256)  # no fitting
    assert {p.resolution for p in small.plan.passes if p.name.startswith("tsd_irradiance")} == {(256, 256)}
    with pytest.raises(ValueError, match="render setting taps: not a setting of technique 'tint'"):
        lab.render(scene, 8, 8, technique="tint", taps=9)


def test_a_mesh_file_opens_with_default_camera_lights_and_material(lab, tmp_path):
    obj = tmp_path / "quad.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n")
    scene = load(obj)
    assert scene.name == "quad" and scene.camera is not None
    assert {l.name for l in scene.lights()} == {"key", "fill"}
    (node,) = scene.mesh_nodes()
    assert node.material["subsurface"] == 0.0
    f = lab.render(scene, 40, 40)
    cover = f.hdr[..., 3] > 0
    assert 0.1 < cover.mean() < 0.95  # the default camera frames the quad with a margin
    assert f.hdr[cover, :3].mean() > 0.01  # and the key light lights it


def test_orbit_keeps_distance_to_the_centre_and_moves_to_the_right():
    scene = load(ASSETS / "scenes" / "head.toml")
    lo, hi = scene.world_bounds()
    c = (lo + hi) / 2
    p0 = scene.camera.world_position
    right0 = scene.camera.world_matrix[:3, 0].copy()
    scene.orbit_camera(20)
    p1 = scene.camera.world_position
    assert np.linalg.norm(p1 - c) == pytest.approx(np.linalg.norm(p0 - c))
    assert p1[1] == pytest.approx(p0[1])  # about the vertical axis: the height stays
    assert np.dot(p1 - p0, right0) > 0  # positive degrees: the camera moves to its right
    scene.orbit_camera(-20)
    assert np.allclose(scene.camera.world_position, p0)


def test_the_readme_example_runs(tmp_path, monkeypatch):
    """The Python block of README.md, at a small size, from a directory outside the checkout."""
    import re
    from pathlib import Path

    readme = Path(__file__).resolve().parents[1] / "README.md"
    (code,) = re.findall(r"```python\n(.*?)```", readme.read_text(), re.S)
    assert "640, 480" in code
    monkeypatch.chdir(tmp_path)
    ns: dict = {}
    exec(code.replace("640, 480", "40, 30").replace("print(", "str("), ns)
    frame = ns["frame"]
    assert frame.ldr.shape == (30, 40, 4) and frame.hdr.shape == (30, 40, 4) and frame.depth.shape == (30, 40)
    assert ns["scene"].mesh_nodes()[0].material["roughness"] == 0.3
