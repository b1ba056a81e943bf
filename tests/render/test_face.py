"""The bundled multi-part face (skinlab/assets/scenes/head-eyes.toml): the head, eyeballs with an iris, corneas
of index 1.376 (alpha blend) and lash cards cut out by their texture's alpha (alpha mask), each mesh its
own material and medium, in every technique and in the path-traced truth."""

import numpy as np
import pytest

from skinlab.render.registry import technique_names
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene
from skinlab.truth.export import describe, medium_dict

PARTS = {"LeePerrySmith": "skin", "EyeLeft": "eye", "EyeRight": "eye", "CorneaLeft": "cornea",
         "CorneaRight": "cornea", "Lashes": "lashes"}  # fmt: skip


@pytest.fixture(scope="module")
def face():
    return load_scene("head-eyes")


def test_each_part_keeps_its_own_material_and_medium(face):
    got = {n.name: n.material for n in face.mesh_nodes()}
    assert {k: m.name for k, m in got.items()} == PARTS
    assert got["EyeLeft"] is got["EyeRight"]  # one material, shared
    assert got["CorneaLeft"]["specular"] == pytest.approx(((1.376 - 1) / (1.376 + 1)) ** 2 / 0.08, abs=5e-4)
    assert got["CorneaLeft"]["alpha_mode"] == "blend" and got["Lashes"]["alpha_mode"] == "mask"
    desc = describe(face, 16, 16)
    shapes = {s.name: s for s in desc.shapes}
    assert shapes["LeePerrySmith"].interior == medium_dict(got["LeePerrySmith"].values)
    assert shapes["EyeLeft"].interior == medium_dict(got["EyeLeft"].values) == shapes["EyeRight"].interior
    assert shapes["EyeLeft"].interior != shapes["LeePerrySmith"].interior  # the eye's own medium
    for name in ("CorneaLeft", "Lashes"):
        assert shapes[name].interior is None and shapes[name].bsdf["type"] == "mask"
    assert shapes["CorneaLeft"].bsdf["opacity"] == pytest.approx(0.3)
    lash = shapes["Lashes"].opacity  # the texture's alpha, cut at the material's cutoff
    assert lash is not None and set(np.unique(lash)) == {0.0, 1.0} and 0.05 < lash.mean() < 0.6


@pytest.mark.parametrize("technique", technique_names())
def test_every_technique_renders_the_face(renderer, face, technique):
    kw = {"size": 64} if technique in ("tsd", "exact") else {}
    res = renderer.render(face, RenderSettings.for_technique(technique, 24, 24, shadow_size=256, **kw))
    img = res.hdr
    assert np.isfinite(img).all() and img[..., 3].mean() > 0.9 and img[..., :3].max() > 0.05
    if technique == "tsd":  # the eyes scatter with their own passes, the cornea and lashes do not
        names = res.plan.names()
        assert "tsd_irradiance[EyeLeft]" in names and "tsd_irradiance[EyeRight]" in names
        assert not any("Cornea" in n or "Lashes" in n for n in names if n.startswith("tsd_"))


def test_the_face_is_path_traced(face):
    pytest.importorskip("mitsuba")
    from skinlab.truth.reference import ReferenceRequest, render_reference

    ref = render_reference(face, ReferenceRequest(12, 12, spp=8, passes=2), progress=False, use_cache=False)
    assert ref.image.shape == (12, 12, 4) and np.isfinite(ref.image).all()
    assert ref.image[..., 3].mean() > 0.9 and ref.image[..., :3].mean() > 0.01


def test_a_masked_card_is_cut_out_in_the_truth(tmp_path):
    """A card whose left half is cut away (alpha mask) in front of a red quad: the path tracer sees the
    red through the cut, as the frame does (tests/scene/test_gltf_materials.py)."""
    mi = pytest.importorskip("mitsuba")
    from skinlab.truth.reference import set_variant
    from tests.scene.test_gltf_materials import _card_scene

    scene = _card_scene(tmp_path, "MASK")
    scene.environment.ambient = np.full(3, 0.5)
    desc = describe(scene, 16, 16)
    set_variant("scalar_rgb")
    img = np.asarray(mi.render(mi.load_dict(desc.to_mitsuba(16)), spp=16), np.float64)
    left, right = img[8, 6, :3], img[8, 10, :3]  # behind the cut half, on the kept half
    assert left[0] > 3 * left[2] and right[2] > 3 * right[0]
