"""Translucency in the forward pass for the techniques without a texture-space pass (screen-space
SSS, disk, pre-integrated skin; skinlab/render/translucency.py, skinlab/shaders/lib/sss_translucency.glsl):
a back-lit sheet transmits what texture-space diffusion and the NumPy slab transmission say; a
front-lit scene does not change; it is planned only where a scattering material and a
shadow-casting light are."""

import numpy as np
import pytest

from skinlab.render.boundary import material_boundary
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import Material
from skinlab.scene.optics import translucency as tr
from skinlab.scene.optics.material_medium import material_medium
from tests.tsd_scenes import quad_mesh, skin, slab_scene

SCREEN = ("ssss", "disk", "preintegrated")
MM_PER_UNIT = 20.0  # slab_scene's scale


def sheet(thickness_mm, light_dir=(0, 0, 1), shadow=True):
    """slab_scene's 40 x 40 mm skin square (z = 0, facing the camera at +z) with a second, plain
    square thickness_mm behind it facing away: a sheet of that thickness whose far face the light
    (travelling along light_dir; default straight from behind) falls on. Thickness 0: the skin square
    alone, a sheet of no thickness (the light's first surface is the visible face itself)."""
    s = slab_scene(material=skin(radius=(8.0, 4.0, 2.0)), light_dir=light_dir)
    s.lights()[0].cast_shadow = shadow
    if thickness_mm > 0:
        back = quad_mesh("back", -1, 1, 1, -1, z=-thickness_mm / MM_PER_UNIT)  # facing -z
        s.add(MeshNode("back", back, Material("back", {"specular": 0.0})))
    return s


def settings(technique, **kw):
    return RenderSettings.for_technique(technique, 48, 48, shadow_size=1024, **kw)


def expected_radiance(thickness_mm):
    """NumPy: the light through the sheet at normal incidence (irradiance 1, subsurface 1) leaving toward
    a viewer straight in front: through(1, d) x exit_T(1; 1, d) / pi x the subsurface albedo, the exit
    factor of light that came through (skinlab/scene/optics/slab.py slab_exit; the colour rule,
    docs/scenes.md)."""
    mat = skin(radius=(8.0, 4.0, 2.0))
    tabs, medium = material_boundary(mat), material_medium(mat.values)
    colour = np.asarray(mat["subsurface_color"])
    through = tr.through([1.0], [thickness_mm], tabs, medium, colour)[0]
    return colour * through * tr.translucent_exit(1.0, 1.0, thickness_mm, tabs, medium, colour)[0] / np.pi


@pytest.mark.parametrize("technique", SCREEN)
def test_back_lit_sheet_transmits_what_tsd_and_numpy_say(renderer, technique):
    """Through 0.5 mm and 3 mm of skin lit from behind: black without translucency; with it the
    centre pixel is the NumPy slab transmission (the exact slab transmittance and the exit factor of
    light that came through) and texture-space diffusion's pixel within 1e-4 relative. The tolerance:
    measured agreement is 4e-7 (fp32); the camera's 2-degree field moves the exit factor by 1.5e-5
    across the view; the blur of a uniform region returns it (weights sum to 1)."""
    for d_mm in (0.5, 3.0):
        off = renderer.render(sheet(d_mm), settings(technique, translucency=False))
        assert off.hdr[24, 24, :3].max() == 0.0  # the far side is all the light there is
        assert ("translucency", "disabled in the settings") in off.plan.skipped
        res = renderer.render(sheet(d_mm), settings(technique))
        c = res.hdr[24, 24, :3].astype(np.float64)
        ref = expected_radiance(d_mm)
        np.testing.assert_allclose(c, ref, rtol=1e-4)
        if d_mm >= 3.0:
            assert c[0] > 5 * c[2]  # red goes furthest
        tsd = renderer.render(sheet(d_mm), settings("tsd")).hdr[24, 24, :3].astype(np.float64)
        np.testing.assert_allclose(c, tsd, rtol=1e-4)
    thin = renderer.render(sheet(0.5), settings(technique)).hdr[24, 24, :3]
    # blue, absorbed most, passes more through 0.5 mm than through 3 mm (red, whose mean free path is
    # longer than 0.5 mm, is scattered less there: its diffuse transmittance peaks past 1 mm)
    assert thin[2] > 10 * c[2]


@pytest.mark.parametrize("technique", ("ssss", "disk"))
def test_translucency_is_in_the_light_the_screen_pass_spreads(renderer, technique):
    """The screen-space techniques add it to the subsurface target their pass filters (which beat
    adding it after the filter against the path-traced back-lit slab: docs/tsd.md)."""
    renderer.render(sheet(0.5), settings(technique))
    target = renderer.last_frame.targets[f"{technique}_diffuse"]
    w, h = target.size
    img = np.frombuffer(target.read(), np.float32).reshape(h, w, 4)
    np.testing.assert_allclose(img[24, 24, :3], expected_radiance(0.5), rtol=1e-4)
    assert img[24, 24, 3] >= 1.0  # a scattering pixel: the pass filters it


@pytest.mark.parametrize("technique", SCREEN)
def test_front_lit_scene_is_unchanged(renderer, technique):
    """Lit from the front (the light cannot reach the sheet's visible face from behind): the frame
    with translucency equals the frame without it (within 1e-6), though its shadow pass writes
    distance maps and its forward pass computes the term."""
    scene = sheet(0.5, light_dir=(0.3, 0.2, -1.0))
    on = renderer.render(scene, settings(technique))
    assert "distance map for translucency" in on.plan.explain()
    off = renderer.render(scene, settings(technique, translucency=False)).hdr[..., :3].copy()
    assert off[24, 24].min() > 0.05
    np.testing.assert_allclose(on.hdr[..., :3], off, rtol=0, atol=1e-6)


@pytest.mark.parametrize("technique", (*SCREEN, "tsd"))
def test_hard_cases_stay_finite(renderer, technique):
    """Zero thickness (a skin square alone, lit from behind) and light grazing the far face (1 degree):
    finite, non-negative, and far darker than 0.5 mm at normal incidence (nothing collides in no
    thickness; the far face catches sin 1 degree of the light)."""
    brightest = expected_radiance(0.5)
    for scene in (sheet(0.0), sheet(0.5, light_dir=(1.0, 0.0, np.tan(np.radians(1.0))))):
        img = renderer.render(scene, settings(technique)).hdr[..., :3]
        assert np.all(np.isfinite(img)) and img.min() >= 0.0
        assert np.all(img[8:40, 8:40] <= 0.05 * brightest)


@pytest.mark.parametrize("technique", SCREEN)
def test_planned_only_where_needed(renderer, technique):
    """In the frame plan (--explain): the forward pass's reason and the shadow pass's distance map;
    skipped with its reason without a shadow-casting light; not at all where nothing scatters."""
    res = renderer.render(sheet(0.5), settings(technique))
    text = res.plan.explain()
    forward = next(p for p in res.plan.passes if p.kind == "forward")
    assert "translucency through thin parts" in forward.reason
    shadow = next(p for p in res.plan.passes if p.kind == "shadow")
    assert shadow.params.distance and shadow.params.layers and "distance map for translucency" in text
    assert "exit and next entry at 512x512" in shadow.reason  # half the shadow map's texels per side
    res = renderer.render(sheet(0.5, shadow=False), settings(technique))
    assert ("translucency", "no shadow-casting light") in res.plan.skipped
    assert res.hdr[24, 24, :3].max() == 0.0
    plain = sheet(0.5)
    plain.find("slab").material = Material("plain", {"base_color": (0.5, 0.5, 0.5), "specular": 0.0})
    res = renderer.render(plain, settings(technique))
    shadow = next(p for p in res.plan.passes if p.kind == "shadow")
    assert not shadow.params.distance
    assert "translucency" not in res.plan.explain()


def test_reference_back_lit_slab_matches_tsd_and_numpy(renderer):
    """The path-traced reference scene slab-thin-backlit-skin1 (a closed 60 x 60 x 3 mm box of skin1
    lit from behind at 30 degrees, the camera off-axis): the middle 4 x 4 pixels of every technique
    equal e back through(back, 3 mm) exit_T(NoV; back, 3 mm) / pi x base colour (the exit factor of light
    that came through, not the reflected light's exit(NoV)), NoV at the slab's middle, within
    1e-3 relative (measured 3e-4: the block's pixels see the face at NoV within 0.003 of the middle's),
    and texture-space diffusion's block within 1e-3."""
    from skinlab.bench.truth_ledger import REFERENCE_SCENES
    from skinlab.scene.scenefile import load_scene

    scene = load_scene(REFERENCE_SCENES / "slab-thin-backlit-skin1.toml")
    mat, light = scene.mesh_nodes()[0].material, scene.lights()[0]
    tabs, medium = material_boundary(mat), material_medium(mat.values)
    v = np.asarray(scene.camera.world_matrix[:3, 3]) - np.array([0.0, 0.0, 1.5])
    nov = v[2] / np.linalg.norm(v)
    back = float(light.direction[2])  # the visible face's normal is +z; the light travels toward it
    ref = (
        np.asarray(mat["base_color"])
        * light.radiance
        * back
        * tr.through([back], [3.0], tabs, medium, mat["subsurface_color"])[0]
        * tr.translucent_exit(nov, back, 3.0, tabs, medium, mat["subsurface_color"])[0]
        / np.pi
    )
    blocks = {}
    for t in ("tsd", *SCREEN):
        img = renderer.render(scene, RenderSettings.for_technique(t, 96, 96, shadow_size=1024)).hdr[..., :3]
        blocks[t] = img[46:50, 46:50].reshape(-1, 3).astype(np.float64).mean(0)
        np.testing.assert_allclose(blocks[t], ref, rtol=1e-3, err_msg=t)
    for t in SCREEN:
        np.testing.assert_allclose(blocks[t], blocks["tsd"], rtol=1e-3, err_msg=t)


def sheets_apart(gap_mm, thickness_mm=3.0):
    """Two sheets of thickness_mm, gap_mm of air between them, lit straight from behind: the
    visible skin square (z = 0) and the three faces behind it (the front sheet's far face, the back
    sheet's two), each facing where its sheet's outside is."""
    s = sheet(thickness_mm)
    for name, z_mm, facing in (("back_near", thickness_mm + gap_mm, 1), ("back_far", 2 * thickness_mm + gap_mm, -1)):
        z = -z_mm / MM_PER_UNIT
        q = quad_mesh(name, -1, 1, -1, 1, z=z) if facing > 0 else quad_mesh(name, -1, 1, 1, -1, z=z)
        s.add(MeshNode(name, q, Material(name, {"specular": 0.0})))
    return s


@pytest.mark.parametrize("technique", (*SCREEN, "tsd"))
def test_light_through_two_sheets_apart_crosses_their_matter_not_the_air(renderer, technique):
    """Two 3 mm sheets 10 mm apart: the light reaching the visible face crossed 6 mm of matter
    (index-matched parallel sheets transmit as one of their summed thickness), not 16 mm as if the
    air between were tissue; one sheet 16 mm thick transmits as before (16 mm)."""
    apart = renderer.render(sheets_apart(10.0), settings(technique)).hdr[24, 24, :3].astype(np.float64)
    np.testing.assert_allclose(apart, expected_radiance(6.0), rtol=1e-3)
    assert np.all(apart > 3 * expected_radiance(16.0))
    thick = renderer.render(sheet(16.0), settings(technique)).hdr[24, 24, :3].astype(np.float64)
    np.testing.assert_allclose(thick, expected_radiance(16.0), rtol=1e-3)
