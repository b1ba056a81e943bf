"""`skinlab reference --export-xml DIR` (skinlab/truth/mitsuba_xml.py): a Mitsuba 3 scene file and its meshes
that Mitsuba alone loads and renders like the reference's own description."""

import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")

from skinlab.cli import main  # noqa: E402
from skinlab.truth.export import describe  # noqa: E402
from skinlab.truth.mitsuba_xml import write_mitsuba_xml  # noqa: E402
from skinlab.truth.reference import set_variant  # noqa: E402
from tests.tsd_scenes import skin, slab_scene  # noqa: E402


def test_the_xml_renders_what_the_description_renders(tmp_path):
    set_variant("scalar_rgb")
    scene = slab_scene(material=skin(specular=0.35, roughness=0.4), ambient=0.05)
    desc = describe(scene, 8, 8)
    xml = write_mitsuba_xml(desc, tmp_path / "x", spp=16)
    assert (tmp_path / "x" / "meshes").is_dir() and xml.name == "scene.xml"
    from_xml = np.asarray(mi.render(mi.load_file(str(xml)), spp=16, seed=3), np.float64)
    from_dict = np.asarray(mi.render(mi.load_dict(desc.to_mitsuba(16)), spp=16, seed=3), np.float64)
    assert from_xml.shape == (8, 8, 4) and np.isfinite(from_xml).all()
    assert from_xml[..., :3].mean() > 0.01
    np.testing.assert_allclose(from_xml[..., :3].mean(axis=(0, 1)), from_dict[..., :3].mean(axis=(0, 1)), rtol=0.1)


def test_reference_export_xml_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "head"
    assert main(["reference", "head-skin1", "--export-xml", str(out), "--size", "8x8", "--spp", "4"]) == 0
    assert "wrote" in capsys.readouterr().out
    set_variant("scalar_rgb")
    img = np.asarray(mi.render(mi.load_file(str(out / "scene.xml")), spp=4), np.float64)
    assert img.shape == (8, 8, 4) and np.isfinite(img).all() and img[..., 3].max() > 0


def test_the_xml_carries_environment_maps_spot_and_area_lights(tmp_path):
    """An environment map (its pixels written beside the XML), a spot, a sphere and a rect light: the
    XML renders what the description renders."""
    from skinlab.scene import transform as tf
    from skinlab.scene.envmap import write_map
    from skinlab.scene.graph import LightNode

    set_variant("scalar_rgb")
    scene = slab_scene(material=skin(specular=0.35, roughness=0.4))
    for light in list(scene.lights()):
        light.visible = False
    px = np.full((8, 16, 3), 0.3, np.float32)
    px[2, 4] = 50.0
    scene.environment.map = write_map(tmp_path / "m.exr", px)
    scene.environment.rotation_deg = 40.0
    for kind, kw in (("spot", {"inner_deg": 10.0, "outer_deg": 30.0}), ("sphere", {"radius": 0.2}),
                     ("rect", {"width": 0.5, "height": 0.3})):  # fmt: skip
        light = LightNode(kind, kind, intensity=0.5, **kw)
        light.translation = (0.3, 0.2, 1.5)
        light.rotation = tf.look_at_rotation((0, 0, 0), (0.1, 0.0, -1.0))
        scene.add(light)
    desc = describe(scene, 8, 8)
    assert [e["kind"] for e in desc.emitters] == ["spot", "sphere", "rect", "envmap"]
    xml = write_mitsuba_xml(desc, tmp_path / "x", spp=16)
    assert (tmp_path / "x" / "textures" / "envmap.exr").is_file()
    from_xml = np.asarray(mi.render(mi.load_file(str(xml)), spp=64, seed=3), np.float64)
    from_dict = np.asarray(mi.render(mi.load_dict(desc.to_mitsuba(64)), spp=64, seed=3), np.float64)
    assert from_xml[..., :3].mean() > 0.01
    np.testing.assert_allclose(from_xml[..., :3].mean(axis=(0, 1)), from_dict[..., :3].mean(axis=(0, 1)), rtol=0.1)


LIGHT_KINDS = [
    ("directional", {}),
    ("point", {}),
    ("spot", {"inner_deg": 10.0, "outer_deg": 30.0}),
    ("rect", {"width": 0.5, "height": 0.3}),
    ("sphere", {"radius": 0.2}),
    ("envmap", {}),
]


@pytest.mark.parametrize("kind, shape", LIGHT_KINDS, ids=[k for k, _ in LIGHT_KINDS])
def test_each_light_kind_and_the_environment_round_trip_through_the_xml(tmp_path, kind, shape):
    """One light of each kind alone (and the environment map alone, rotated and scaled): the scene Mitsuba
    loads from the XML has that emitter and renders what the description renders."""
    import xml.etree.ElementTree as ET

    from skinlab.scene import transform as tf
    from skinlab.scene.envmap import write_map
    from skinlab.scene.graph import LightNode

    set_variant("scalar_rgb")
    scene = slab_scene(material=skin(specular=0.35, roughness=0.4))
    for light in list(scene.lights()):
        light.visible = kind == "directional"
    if kind == "envmap":
        px = np.full((8, 16, 3), 0.2, np.float32)
        px[2, 5] = 40.0  # a bright texel: the rotation decides where it lights
        scene.environment.map = write_map(tmp_path / "m.exr", px)
        scene.environment.rotation_deg, scene.environment.intensity = 70.0, 0.8
    elif kind != "directional":
        light = LightNode(kind, kind, intensity=0.5, **shape)
        light.translation = (0.3, 0.2, 1.5)
        light.rotation = tf.look_at_rotation((0, 0, 0), (0.1, 0.0, -1.0))
        scene.add(light)
    desc = describe(scene, 8, 8)
    assert [e["kind"] for e in desc.emitters] == [kind]
    xml = write_mitsuba_xml(desc, tmp_path / "x", spp=16)
    emitters = ET.parse(xml).getroot().iter("emitter")
    want = {"rect": "area", "sphere": "area"}.get(kind, kind)
    assert [e.get("type") for e in emitters] == [want]
    if kind == "envmap":
        text = xml.read_text()
        assert 'name="scale" value="0.8"' in text and "textures/envmap.exr" in text
        assert "show_background" in text and '<boolean name="hide_emitters" value="true"/>' in text  # documented
        assert '<rotate y="1" angle="70.0"/>' in text
    loaded = mi.load_file(str(xml))
    from_xml = np.asarray(mi.render(loaded, spp=64, seed=5), np.float64)[..., :3]
    from_dict = np.asarray(mi.render(mi.load_dict(desc.to_mitsuba(64)), spp=64, seed=5), np.float64)[..., :3]
    assert from_xml.mean() > 1e-3, "the light does not reach the slab"
    np.testing.assert_allclose(from_xml.mean(axis=(0, 1)), from_dict.mean(axis=(0, 1)), rtol=0.05)
