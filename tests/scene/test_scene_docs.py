"""docs/scenes.md is generated from the declarations: it must be up to date and cover every key."""

from skinlab.scene.materials import PRINCIPLED_PARAMS
from skinlab.scene.scene_docs import DOC_PATH, main, scenes_markdown
from skinlab.scene.scene_keys import SCENE_FILE_KEYS


def test_docs_scenes_md_is_up_to_date():
    assert DOC_PATH.read_text(encoding="utf-8") == scenes_markdown(), "run: python -m skinlab.scene.scene_docs"
    assert main(["--check"]) == 0


def test_every_key_and_parameter_is_documented_with_its_meaning():
    text = scenes_markdown()
    for section, keys in SCENE_FILE_KEYS.items():
        assert f"## `{section}`" in text
        for k in keys:
            assert f"| `{k.name}` |" in text and k.doc
    for p in PRINCIPLED_PARAMS:
        assert f"| `{p.name}` |" in text and p.doc, p.name
    # one meaning for the subsurface pair, the same as the code's (skinlab/scene/optics/material_medium.py)
    radius = next(p for p in PRINCIPLED_PARAMS if p.name == "subsurface_radius")
    colour = next(p for p in PRINCIPLED_PARAMS if p.name == "subsurface_color")
    assert "R = 4 pi l" in radius.doc and radius.unit == "mm"
    assert "surface albedo" in colour.doc
    assert "Subsurface Radius" in text and "blender-burley" in text


def test_a_declared_key_change_makes_the_docs_stale(monkeypatch):
    from skinlab.scene import scene_keys

    changed = dict(SCENE_FILE_KEYS)
    changed["[scene]"] = changed["[scene]"][:1]
    monkeypatch.setattr("skinlab.scene.scene_docs.SCENE_FILE_KEYS", changed)
    assert scenes_markdown() != DOC_PATH.read_text(encoding="utf-8")
    assert scene_keys.SCENE_FILE_KEYS["[scene]"][1].name == "mm_per_unit"
