"""Every setting is declared once (skinlab/declare.py Field): each option of every command,
each viewer widget and each scene-file key comes from a declaration, its default stated there alone."""

import argparse
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from skinlab.cli import build_parser
from skinlab.commands.compare import COMPARE_OPTIONS
from skinlab.commands.demo import DEMO_OPTIONS
from skinlab.commands.export import EXPORT_OPTIONS
from skinlab.commands.render import RENDER_OPTIONS, settings_from_args
from skinlab.commands.scene_options import CAMERA_ORBIT, SET_OPTION
from skinlab.commands.scenes import SCENES_OPTIONS
from skinlab.commands.view import VIEW_OPTIONS
from skinlab.declare import Field
from skinlab.render.registry import techniques
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import CameraNode, LightNode
from skinlab.scene.materials import PRINCIPLED_PARAMS, Material
from skinlab.scene.scene_keys import SCENE_FILE_KEYS, scene_key
from skinlab.scene.scenefile import SceneFileError, load_scene
from skinlab.viewer.panel import (
    LIGHT_ANGULAR_RADIUS,
    WIDGETS,
    light_widgets,
    material_widgets,
    render_widgets,
    technique_widgets,
)

ROOT = Path(__file__).resolve().parents[1]
BUNNY = ROOT / "skinlab/assets/stanford-bunny/bunny.ply"


def declarations() -> list[Field]:
    from skinlab.commands.bench import accuracy_options, orbit_options, peer_options, reload_options, startup_options
    from skinlab.commands.mc import mc_options
    from skinlab.commands.profile import PROFILE_OPTIONS, SOURCE_OPTIONS
    from skinlab.commands.reference import reference_options

    out = [*PRINCIPLED_PARAMS, *RenderSettings.fields().values(), *RENDER_OPTIONS, *VIEW_OPTIONS]
    out += [*EXPORT_OPTIONS, *SCENES_OPTIONS, *DEMO_OPTIONS, *COMPARE_OPTIONS]
    out += [*(f for fields in mc_options() for f in fields), *SOURCE_OPTIONS, *PROFILE_OPTIONS, *reference_options()]
    out += [*peer_options(), *orbit_options(), *reload_options(), *accuracy_options(), *startup_options()]
    out += [CAMERA_ORBIT, SET_OPTION, LIGHT_ANGULAR_RADIUS]
    out += [f for t in techniques() for f in t.settings_type.options().values()]
    return out + [f for keys in SCENE_FILE_KEYS.values() for f in keys]


def subcommands(parser=None, prefix=()):
    """(path, parser) of every command of the CLI, subcommands included (("bench", "reload"), ...)."""
    parser = parser or build_parser()
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sub in a.choices.items():
                yield (*prefix, name), sub
                yield from subcommands(sub, (*prefix, name))


def command_options(command: str) -> dict[str, argparse.Action]:
    sub = dict(subcommands())[tuple(command.split())]
    return {flag: a for a in sub._actions for flag in a.option_strings}


COMMANDS = [" ".join(path) for path, sub in subcommands() if not any(
    isinstance(a, argparse._SubParsersAction) for a in sub._actions)]  # fmt: skip
# options that are no declaration's, and why
NOT_DECLARED = {
    "--help": "argparse's own (-h)",
    "--technique": "the registry's techniques with their descriptions (skinlab/commands/technique_options.py)",
    "--albedo": "mc and profile: a refused spelling, hidden (two albedos, two names: --single-albedo, "
    "--surface-albedo)",
    "--tiny": "bench accuracy: hidden, for tests (4 settings, the head, 64x64)",
}


def test_the_commands_checked_are_every_command_of_the_cli():
    assert {"render", "view", "export", "scenes", "demo", "compare", "mc", "profile", "reference"} <= set(COMMANDS)
    assert {f"bench {b}" for b in ("peer", "orbit", "reload", "accuracy", "startup")} <= set(COMMANDS)
    assert "bench" not in COMMANDS  # a group: its subcommands have the options


@pytest.mark.parametrize("command", COMMANDS)
def test_every_option_of_a_command_comes_from_a_declaration(command):
    """Every option of every command (all of build_parser()'s subparsers) takes its help from a
    declaration, but those NOT_DECLARED lists."""
    docs = [f.doc.replace("%", "%%") for f in declarations() if f.doc]
    options = command_options(command)
    assert len(options) > (40 if command in ("render", "view") else 2)  # the parser is real
    for flag, action in options.items():
        if flag in NOT_DECLARED or flag == "-h":
            assert flag != "--albedo" or action.help == argparse.SUPPRESS, flag
            continue
        assert any(doc in action.help for doc in docs), f"{command} {flag}: help from no declaration"


def own_options() -> dict[str, list[Field]]:
    """Each command's own declared options (render's and view's frame settings are None until given:
    test_render_settings_are_options_of_both_commands_with_their_declared_help)."""
    from skinlab.commands import bench
    from skinlab.commands.mc import mc_options
    from skinlab.commands.profile import PROFILE_OPTIONS, SOURCE_OPTIONS
    from skinlab.commands.reference import reference_options

    out = {"render": RENDER_OPTIONS, "view": VIEW_OPTIONS, "export": EXPORT_OPTIONS, "scenes": SCENES_OPTIONS}
    out |= {"demo": DEMO_OPTIONS, "compare": COMPARE_OPTIONS, "mc": [f for fs in mc_options() for f in fs]}
    out |= {"profile": [*SOURCE_OPTIONS, *PROFILE_OPTIONS], "reference": reference_options()}
    for name in ("peer", "orbit", "reload", "accuracy", "startup"):
        out[f"bench {name}"] = getattr(bench, f"{name}_options")()
    return {k: list(v) for k, v in out.items()}


@pytest.mark.parametrize("command", COMMANDS)
def test_a_command_s_own_options_have_their_declared_spelling_default_and_help(command):
    from skinlab.commands.field_options import option_flags

    fields = own_options()[command]  # every command has its own declared options
    options = command_options(command)
    for f in fields:
        a = options[option_flags(f)[0]]
        assert a.dest == f.name and a.default == f.default and f.doc.replace("%", "%%") in a.help, (command, f.name)
        if f.kind == "choice":
            assert tuple(a.choices) == f.choices


def test_a_shared_setting_taken_with_another_default_says_so():
    """--size, --shadow-size, --tsd-size, --exact-size ...: an option made from a render or technique setting
    (or the image size) has that declaration's default, None (the declaration's holds), or says in its help
    that its default is its own."""
    from skinlab.commands.field_options import IMAGE_SIZE

    shared = [IMAGE_SIZE, *RenderSettings.fields().values()]
    shared += [replace(f, name=f"{t.name}_{n}") for t in techniques() for n, f in t.settings_type.options().items()]
    seen = 0
    for command in COMMANDS:
        for flag, a in command_options(command).items():
            for f in shared:
                if not f.doc or f.doc.replace("%", "%%") not in (a.help or ""):
                    continue
                if a.default not in (None, f.default):
                    assert "own default" in a.help, (command, flag)
                    seen += 1
    assert seen >= 6  # reference --size, bench peer/reload/startup --size, reload --shadow-size and --tsd-size


def test_an_option_value_outside_its_declaration_is_one_line_naming_it(capsys):
    """The one error shape, `--NAME: expected <what>, got <value>`, for the commands declared last."""
    from skinlab.cli import main

    for argv, line in (
        (["mc", "--single-albedo", "0.5", "--max-steps", "0"], "--max-steps: expected an integer >= 1, got 0"),
        (["mc", "--single-albedo", "0.5", "--g", "1"], "--g: expected a number in (-1, 1), got 1.0"),
        (["profile", "burley", "--mc-photons", "1"], "--mc-photons: expected an integer in [2, 10000000000], got 1"),
        (["reference", "--seed", "-1"], "--seed: expected an integer in [0, 4294967295], got -1"),
        (["reference", "--rr-depth", "0"], "--rr-depth: expected an integer in [1, 1048576], got 0"),
        (["bench", "reload", "--settle", "11"], "--settle: expected a number in [0, 10], got 11.0"),
        (["bench", "accuracy", "--out", "x", "--exact-size", "8"], "--exact-size: expected an integer in [16, 8192]"),
        (["bench", "startup", "--rounds", "0"], "--rounds: expected an integer >= 1, got 0"),
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert line in err and len(err.strip().splitlines()) == 1, (argv, err)
    # the request checks through the same declaration as the option
    from skinlab.truth.reference import ReferenceRequest

    with pytest.raises(ValueError, match=r"^reference rr_depth: expected an integer in \[1, 1048576\], got 0$"):
        ReferenceRequest(8, 8, rr_depth=0)


def test_render_settings_are_options_of_both_commands_with_their_declared_help():
    render, view = command_options("render"), command_options("view")
    for name, f in RenderSettings.fields().items():
        flag = "--" + name.replace("_", "-")
        if not f.cli:  # width, height (--size), background, ...: no option of theirs
            # (--background is the [environment] show_background key's, another meaning)
            assert all(flag not in o or f.doc not in o[flag].help for o in (render, view)), flag
            continue
        for options in (render, view):
            a = options[flag]
            assert a.help == f.help() and a.default is None, flag  # None: the declaration's default holds
            assert all(options[extra] is a for extra in f.flags)  # --sss: the same option as --sss-model
    assert {"--shadow-size", "--sss", "--bounces", "--supersample", "--exposure", "--camera-orbit"} <= set(view)


def test_shadow_size_has_one_default_stated_in_its_declaration():
    decl = RenderSettings.fields()["shadow_size"]
    assert decl.default == RenderSettings().shadow_size == 2048 and decl.unit == "texels"
    st = settings_from_args(build_parser().parse_args(["render"]), 8, 8)
    assert (
        st.shadow_size == decl.default and "(default: 2048 texels)" in command_options("render")["--shadow-size"].help
    )
    # no module but the declaration writes a shadow-size default: a line naming a shadow size with 2048
    for path in (ROOT / "skinlab").rglob("*.py"):
        if path.name == "settings.py" and path.parent.name == "render":
            continue
        for line in path.read_text(encoding="utf-8").splitlines():
            assert not re.search(r"shadow.?size\W.*\b2048\b", line), (path, line)
    # `skinlab bench reload --shadow-size` is a distinct option (its own default), and its help says so
    bench = build_parser()._actions
    sub = next(a for a in bench if isinstance(a, argparse._SubParsersAction)).choices["bench"]
    reload_cmd = next(a for a in sub._actions if isinstance(a, argparse._SubParsersAction)).choices["reload"]
    a = next(a for a in reload_cmd._actions if "--shadow-size" in a.option_strings)
    assert a.default == 512 and "this benchmark's own default" in a.help and "render's 2048" in a.help
    assert decl.doc in a.help


def test_every_viewer_widget_comes_from_a_declaration():
    st = RenderSettings()
    assert [w.param for w in render_widgets(st)] == list(RenderSettings.panel_options())
    for w in render_widgets(st):
        assert w.doc == RenderSettings.fields()[w.param].help()
    for t in techniques():
        s = t.settings_type()
        ws = technique_widgets(s)
        assert [w.param for w in ws] == list(s.options())
        assert all(w.doc == s.options()[w.param].help() for w in ws)
    ws = material_widgets(Material("m"))
    assert [w.param for w in ws] == [p.name for p in PRINCIPLED_PARAMS]
    assert all(w.doc == p.help() for w, p in zip(ws, PRINCIPLED_PARAMS, strict=True))
    kinds = ("directional", "point", "spot", "rect", "sphere")
    for kind in kinds:
        for w in light_widgets(LightNode("l", kind)):
            decl = LIGHT_ANGULAR_RADIUS if w.param == LIGHT_ANGULAR_RADIUS.name else scene_key("[[lights]]", w.param)
            assert decl.doc in w.doc and w.widget.startswith(WIDGETS[decl.kind]), (kind, w.param)


def test_every_declared_default_is_a_valid_value_of_its_declaration():
    checked = 0
    for f in declarations():
        if f.default is None or f.kind in ("table", "tables", "vec4", "scale", "texture"):
            continue
        value = f.check(f.default)
        assert np.allclose(value, f.default) if f.kind in ("float", "color", "vec3", "vec2") else value == f.default
        checked += 1
    assert checked > 60


def test_scene_keys_are_read_with_their_declared_defaults(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(
        f'[[meshes]]\nfile = "{BUNNY}"\n[camera]\nposition = [0, 0, 5]\n'
        '[[lights]]\ntype = "spot"\nposition = [0, 0, 3]\n[[lights]]\ntype = "rect"\nposition = [0, 1, 3]\n'
        '[[lights]]\ntype = "sphere"\nposition = [1, 0, 3]\n',
        encoding="utf-8",
    )
    scene = load_scene(path)
    key = lambda section, name: scene_key(section, name).default  # noqa: E731
    cam = scene.camera
    assert (cam.znear, cam.zfar) == (key("[camera]", "znear"), key("[camera]", "zfar"))
    assert np.isclose(np.degrees(cam.yfov), key("[camera]", "yfov_deg"))
    assert scene.environment.exposure == key("[environment]", "exposure")
    assert np.allclose(scene.environment.ambient, key("[environment]", "ambient"))
    spot, rect, sphere = scene.lights()
    assert (spot.inner_deg, spot.outer_deg) == (key("[[lights]]", "inner_deg"), key("[[lights]]", "outer_deg"))
    assert (rect.width, rect.height, sphere.radius) == tuple(
        key("[[lights]]", n) for n in ("width", "height", "radius")
    )
    assert spot.intensity == key("[[lights]]", "intensity") and spot.cast_shadow is key("[[lights]]", "cast_shadow")
    assert np.allclose(spot.color, key("[[lights]]", "color")) and spot.name == "light1"
    # the API's own defaults (LightNode, Environment, MeasureSpec: what parse_measure builds) are the scene file's
    from skinlab.scene.graph import Environment
    from skinlab.scene.measure import MeasureSpec

    api = LightNode("x", "spot")
    assert (api.inner_deg, api.outer_deg, api.intensity) == (spot.inner_deg, spot.outer_deg, spot.intensity)
    api_cam = CameraNode()
    assert (api_cam.znear, api_cam.zfar, api_cam.yfov) == (cam.znear, cam.zfar, cam.yfov)
    framed = load_scene(BUNNY).camera  # a mesh file's camera frames it with the declared field of view
    assert np.isclose(np.degrees(framed.yfov), key("[camera]", "yfov_deg"))
    env = Environment()
    for f in SCENE_FILE_KEYS["[environment]"]:
        if f.default is not None:
            assert np.allclose(getattr(env, f.name), f.default), f.name
    spec = MeasureSpec()
    assert all(getattr(spec, f.name) == f.default for f in SCENE_FILE_KEYS["[measure]"])


def test_unknown_scene_keys_are_refused_naming_every_declared_one(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(f'[[meshes]]\nfile = "{BUNNY}"\n[camera]\nfov = 30\n', encoding="utf-8")
    with pytest.raises(SceneFileError) as exc:
        load_scene(path)
    msg = str(exc.value)
    assert "[camera]: unknown key(s) fov; expected some of" in msg
    assert all(k.name in msg for k in SCENE_FILE_KEYS["[camera]"])


def test_a_bad_value_is_one_line_naming_it_and_what_was_expected():
    f = RenderSettings.fields()["bounces"]
    with pytest.raises(ValueError, match=r"^render setting bounces: expected an integer in \[0, 8\], got 9$"):
        RenderSettings(bounces=9)
    with pytest.raises(ValueError, match=r"^material 'm': roughness: expected a number in \[0, 1\], got 2$"):
        Material("m", {"roughness": 2})
    assert f.clamp(9.6) == 8 and f.clamp(float("nan")) == f.default
    with pytest.raises(ValueError, match=r"^exposure: expected a number > 0, got 0$"):
        scene_key("[environment]", "exposure").check(0)
