"""OpenPBR Surface's subsurface names (skinlab/scene/openpbr.py), similarity theory
(skinlab/scene/optics/similarity.py) and the anisotropy g reaching the medium: the truth's phase and
coefficients, the realtime single-scattering term."""

import math

import numpy as np
import pytest

from skinlab.render.boundary import material_boundary, single_scattering_factor
from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import Material
from skinlab.scene.optics import similarity as sim
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.media import invert_surface_albedo
from skinlab.scene.scenefile import SceneFileError, load_scene
from skinlab.truth.export import medium_dict
from tests.tsd_scenes import skin, slab_scene


def write_scene(tmp_path, material_toml: str, mm: float = 10.0):
    (tmp_path / "s.toml").write_text(
        f'[scene]\nmm_per_unit = {mm}\n{material_toml}\n[[meshes]]\nfile = "{tmp_path / "q.obj"}"\nmaterial = "m"\n'
    )
    (tmp_path / "q.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")
    return tmp_path / "s.toml"


def test_similarity_round_trips_and_edges():
    a = np.array([0.0, 0.2, 0.5, 0.9, 0.999, 1.0])
    for g in (-0.9, -0.3, 0.0, 0.5, 0.95):
        back = sim.reduced_albedo(sim.real_albedo(a, g), g)
        assert back == pytest.approx(a, abs=1e-12)
        assert sim.real_mfp(sim.reduced_mfp(2.0, sim.real_albedo(a, g), g), a, g) == pytest.approx(np.full(6, 2.0))
    assert sim.real_albedo(a, 0.0) == pytest.approx(a)
    assert sim.real_albedo(0.5, 0.8)[()] > 0.5  # forward scattering: more real scattering for the same diffusion
    c = np.linspace(0.0, 1.0, 21)
    assert sim.van_de_hulst_colour(sim.van_de_hulst_albedo(c)) == pytest.approx(c, abs=2e-5)


def test_van_de_hulst_and_skinlabs_inversion_agree_at_index_1():
    # the figure docs/references.md#openpbr and docs/scenes.md state
    worst = max(
        float(np.max(np.abs(invert_surface_albedo(np.full(3, c), 1.0) - sim.van_de_hulst_albedo(c))))
        for c in np.linspace(0.1, 0.95, 18)
    )
    assert 0.01 < worst < 0.045


def test_subsurface_weight_is_an_exact_alias(tmp_path):
    s = load_scene(write_scene(tmp_path, "[materials.m]\nsubsurface_weight = 0.7\n"))
    assert s.mesh_nodes()[0].material["subsurface"] == 0.7
    assert Material("x").update({"subsurface_weight": 0.3})["subsurface"] == 0.3
    with pytest.raises(SceneFileError, match=r"give subsurface or its alias subsurface_weight, not both"):
        load_scene(write_scene(tmp_path, "[materials.m]\nsubsurface_weight = 0.7\nsubsurface = 0.2\n"))


def test_openpbr_table_converts_to_the_same_medium(tmp_path):
    mm = 10.0
    path = write_scene(
        tmp_path,
        "[materials.m]\nspecular = 0.3\n[materials.m.openpbr]\nsubsurface_weight = 1.0\n"
        "subsurface_color = [0.8, 0.5, 0.3]\nsubsurface_radius = 0.05\nsubsurface_radius_scale = [1.0, 0.5, 0.25]\n"
        "subsurface_scatter_anisotropy = 0.6\n",
        mm,
    )
    m = load_scene(path).mesh_nodes()[0].material
    assert m["subsurface"] == 1.0 and m["subsurface_color"] == (0.8, 0.5, 0.3)
    assert m["subsurface_scatter_anisotropy"] == 0.6
    medium = material_medium(m.values)
    # the reduced medium's real mean free path is OpenPBR's radius x scale x mm per unit
    real = sim.real_mfp(medium.mfp_arr, medium.alpha_arr, 0.6)
    assert real == pytest.approx(0.05 * np.array([1.0, 0.5, 0.25]) * mm, rel=1e-9)
    # g = 0: the radius is 4 pi x the mean free path
    path = write_scene(tmp_path, "[materials.m.openpbr]\nsubsurface_radius = 0.1\nsubsurface_radius_scale = 1\n", mm)
    m = load_scene(path).mesh_nodes()[0].material
    assert m["subsurface_radius"] == pytest.approx((4 * math.pi * 1.0,) * 3)
    # the truth gets back OpenPBR's extinction and g
    d = medium_dict({**m.values, "subsurface_scatter_anisotropy": 0.0}, 1.0)
    assert d["phase"] == {"type": "isotropic"} and d["scale"] == pytest.approx(1.0)


def test_openpbr_names_in_the_wrong_place_are_clear_errors(tmp_path):
    with pytest.raises(SceneFileError, match=r"subsurface_radius_scale: OpenPBR's radius pair .* openpbr table"):
        load_scene(write_scene(tmp_path, "[materials.m]\nsubsurface_radius_scale = [1, 0.5, 0.25]\n"))
    with pytest.raises(SceneFileError, match=r"\[materials.m\].openpbr: unknown OpenPBR key\(s\) base_color"):
        load_scene(write_scene(tmp_path, "[materials.m.openpbr]\nbase_color = 1\n"))
    with pytest.raises(SceneFileError, match=r"openpbr.subsurface_radius: expected a length >= 0"):
        load_scene(write_scene(tmp_path, "[materials.m.openpbr]\nsubsurface_radius = -1\n"))
    with pytest.raises(
        SceneFileError, match=r"subsurface_scatter_anisotropy: expected a number in \[-0.95, 0.95\], got 1.0"
    ):
        load_scene(write_scene(tmp_path, "[materials.m.openpbr]\nsubsurface_scatter_anisotropy = 1.0\n"))


def test_anisotropy_reaches_the_truth_medium():
    iso = skin().values
    fwd = {**iso, "subsurface_scatter_anisotropy": 0.8}
    a, b = medium_dict(iso), medium_dict(fwd)
    assert a["phase"] == {"type": "isotropic"}
    assert b["phase"] == {"type": "hg", "g": 0.8}
    m = material_medium(iso)
    # the same reduced medium: sigma_s (1 - g) + sigma_a is the isotropic one's sigma_t'
    sa = np.asarray(a["sigma_t"]["value"]) * a["scale"]
    sb = np.asarray(b["sigma_t"]["value"]) * b["scale"]
    alb = np.asarray(b["albedo"]["value"])
    assert sb * (1 - alb) + sb * alb * (1 - 0.8) == pytest.approx(sa, rel=1e-9)
    assert np.asarray(a["albedo"]["value"]) == pytest.approx(m.alpha_arr)


def test_anisotropy_reaches_the_frames_single_scattering(renderer):
    iso = skin()
    fwd = skin(subsurface_scatter_anisotropy=0.8)
    t = material_boundary(iso)
    assert np.all(single_scattering_factor(fwd, material_boundary(fwd)) > single_scattering_factor(iso, t))
    frames = []
    for mat in (iso, fwd):
        scene = slab_scene(material=mat, light_dir=(0.3, 0.0, -1.0))
        frames.append(renderer.render(scene, RenderSettings.for_technique("tint", 16, 16, shadow_size=128)).hdr)
    # forward scattering sends less single-scattered light back toward a camera opposite the light
    assert not np.allclose(frames[0], frames[1], rtol=1e-3)
