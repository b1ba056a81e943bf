"""`skinlab render MESH --preset NAME --set KEY=VALUE --mm-per-unit MM` (skinlab/commands/scene_options.py,
skinlab/scene/scene_edits.py) and the same edits from the API (skinlab.api.load)."""

import json

import pytest

from skinlab.api import load
from skinlab.cli import main
from skinlab.scene.materials import preset_values
from skinlab.scene.scene_edits import SceneEditError, make_edits, parse_set, parse_value
from skinlab.scene.scenefile import SceneFileError, load_scene
from tests.commands.test_cli import skinlab

BUNNY = "skinlab/assets/stanford-bunny/bunny.ply"


def test_values_read_as_toml_words_and_comma_lists():
    assert parse_value("0.3") == 0.3 and parse_value("true") is True and parse_value('"x"') == "x"
    assert parse_value("[0.2, 0.8, 0.2]") == [0.2, 0.8, 0.2] == parse_value("0.2,0.8,0.2")
    assert parse_value("dipole") == "dipole"
    assert parse_set("environment.exposure=2") == ("environment.exposure", 2)
    for bad, msg in (
        ("roughness", "expected KEY=VALUE"),
        ("glow=1", "glow: not a material parameter"),
        ("camera.a.b=1", "expected a material parameter, section.key"),
    ):
        with pytest.raises(SceneEditError, match=msg):
            parse_set(bad)
    with pytest.raises(SceneEditError, match=r"--preset: unknown material 'jam'; choose one of .*marble"):
        make_edits("jam", option="--")
    with pytest.raises(SceneEditError, match=r"--mm-per-unit: expected a number >= 1e-12, got -1"):
        make_edits(mm_per_unit=-1, option="--")


def test_a_mesh_file_takes_a_preset_a_set_and_its_scale():
    s = load(BUNNY, preset="marble", mm_per_unit=1000.0, set={"roughness": 0.25, "environment.exposure": 2})
    m = s.mesh_nodes()[0].material
    assert all(m[k] == v for k, v in preset_values("marble").items()) and m["roughness"] == 0.25
    assert s.mm_per_unit == 1000.0 and s.environment.exposure == 2.0
    assert [l.name for l in s.lights()] == ["key", "fill"]  # still the mesh file's default lights


def test_scene_keys_are_validated_like_the_files_own():
    with pytest.raises(SceneFileError, match=r"\[camera\].yfov_deg: expected a number in \(0.0, 179.0\], got 400"):
        load("head", set={"camera.yfov_deg": 400})
    with pytest.raises(SceneFileError, match=r"overrides.roughness: expected a number in \[0, 1\], got 3"):
        load(BUNNY, set={"roughness": 3})
    with pytest.raises(SceneFileError, match=r"the scene has no light named 'sun' \(it has: key, fill\)"):
        load("head", set={"lights.sun.intensity": 2})
    s = load("head", set={"lights.key.intensity": 5.0, "materials.skin.roughness": 0.2, "sss_model": "dipole"})
    assert s.find("key").intensity == 5.0
    assert s.mesh_nodes()[0].material["roughness"] == 0.2 and s.mesh_nodes()[0].material["sss_model"] == "dipole"


def test_render_a_mesh_with_a_preset_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "b.png"
    code = main(["render", BUNNY, "--preset", "ketchup", "--mm-per-unit", "1000", "--set", "roughness=0.3",
                 "--size", "24x24", "--technique", "tint", "--out", str(out), "--json"])  # fmt: skip
    assert code == 0 and out.is_file()
    d = json.loads(capsys.readouterr().out)
    assert any("tint[bunny]" not in s["what"] for s in d["plan"]["skipped"])
    assert not any("subsurface weight is 0" in s["why"] for s in d["plan"]["skipped"])  # it scatters now
    p = skinlab("render", BUNNY, "--set", "roughness=2", "--out", str(tmp_path / "x.png"), "--size", "8x8")
    assert (
        p.returncode == 2 and p.stderr.count("\n") == 1 and "roughness: expected a number in [0, 1], got 2" in p.stderr
    )
    assert not (tmp_path / "x.png").exists()
    p = skinlab("render", BUNNY, "--preset", "jam", "--out", str(tmp_path / "x.png"))
    assert p.returncode == 2 and "--preset: unknown material 'jam'" in p.stderr


def test_tint_says_it_is_a_baseline():
    p = skinlab("render", "--help")
    assert "tint: a baseline to compare the others against, not a look" in " ".join(p.stdout.split())


def test_scene_file_edits_do_not_change_the_file(tmp_path):
    before = load_scene("head").mesh_nodes()[0].material["roughness"]
    load("head", set={"roughness": 0.9})
    assert load_scene("head").mesh_nodes()[0].material["roughness"] == before


def test_export_a_mesh_with_a_preset_as_gltf(tmp_path, capsys):
    out = tmp_path / "bunny.glb"
    assert main(["export", BUNNY, "--preset", "marble", "--mm-per-unit", "1000", "--out", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    m = load(out, mm_per_unit=1000.0).mesh_nodes()[0].material
    want = preset_values("marble")
    assert m["subsurface"] == 1.0 and m["subsurface_color"] == pytest.approx(want["subsurface_color"])
    assert m["subsurface_radius"] == pytest.approx(want["subsurface_radius"], rel=1e-6)
    assert main(["export", BUNNY, "--out", str(tmp_path / "b.obj")]) == 2
    assert "--out: expected a .glb or .gltf path" in capsys.readouterr().err
