"""`skinlab view` takes the frame and scene options of `skinlab render` from the same declarations
(skinlab/commands/technique_options.py add_frame_options, skinlab/commands/scene_options.py), parsed and
applied without opening a window: skinlab/commands/view.py view_start builds what ViewerCore starts from."""

import argparse

import pytest

from skinlab.cli import build_parser
from skinlab.commands.view import view_start
from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import preset_values

BUNNY = "skinlab/assets/stanford-bunny/bunny.ply"


def _options(command: str) -> dict[str, argparse.Action]:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {flag: a for a in sub.choices[command]._actions for flag in a.option_strings}


def test_every_frame_and_scene_option_of_render_is_on_view_with_the_same_help():
    render, view = _options("render"), _options("view")
    shared = ["--shadow-size", "--sss", "--technique", "--exposure", "--environment", "--environment-rotation",
              "--environment-intensity", "--background", "--preset", "--set", "--mm-per-unit"]  # fmt: skip
    shared += ["--" + name.replace("_", "-") for name in RenderSettings.options()]
    assert {"--supersample", "--bounces", "--exposure"} <= set(shared)
    for flag in shared:
        assert flag in view, f"skinlab view lacks {flag}"
        r, v = render[flag], view[flag]
        assert (v.help, v.default, v.type, v.choices, v.dest) == (r.help, r.default, r.type, r.choices, r.dest), flag
    # the technique options too: one declaration, both commands
    tech = [f for f in render if f.startswith(("--tsd-", "--ssss-", "--disk-", "--exact-", "--preintegrated-"))]
    assert tech and all(view[f].help == render[f].help for f in tech)
    # what only a headless render can do stays off the viewer
    assert "--out" not in view and "--json" not in view


def _start(*argv, size=(40, 30)):
    args = build_parser().parse_args(["view", *argv])
    return view_start(args, size)


def test_view_options_build_the_settings_and_edits_render_would():
    from skinlab.commands.render import settings_from_args

    argv = ["--bounces", "0", "--supersample", "2", "--sss", "dipole", "--technique", "ssss", "--ssss-taps", "11"]
    start = _start(*argv, "--exposure", "1.5", "--preset", "marble", "--mm-per-unit", "1000", "--set", "roughness=0.3")
    want = settings_from_args(build_parser().parse_args(["render", *argv]), 40, 30)
    assert start["settings"] == want
    assert want.bounces == 0 and want.supersample == 2 and want.technique.taps == 11  # not the defaults
    assert start["edits"].preset == "marble" and start["edits"].mm_per_unit == 1000.0
    # defaults: those of render (RenderSettings' declarations)
    plain = _start()
    assert plain["edits"] is None and plain["settings"] == RenderSettings(40, 30)


@pytest.mark.parametrize(
    "argv, msg",
    [
        (["--bounces", "9"], "--bounces: expected an integer in [0, 8], got 9"),
        (["--supersample", "x"], "--supersample: expected"),
        (["--exposure", "0"], "--exposure: expected a number > 0, got 0.0"),
        (["--preset", "jam"], "--preset: unknown material 'jam'"),
        (["--mm-per-unit", "-1"], "--mm-per-unit: expected a number >= 1e-12, got -1.0"),
        (["--set", "glow=1"], "glow: not a material parameter"),
        (["--environment-intensity", "-1"], "--environment-intensity: expected a number >= 0, got -1.0"),
    ],
)
def test_bad_view_options_fail_before_a_window_opens(argv, msg):
    with pytest.raises(ValueError) as exc:
        _start(*argv)
    assert msg in str(exc.value)


def test_the_core_loads_the_scene_with_the_options_and_keeps_them_on_reload(ctx):
    from skinlab.viewer.core import ViewerCore

    start = _start("--bounces", "1", "--exposure", "2.5", "--preset", "marble", "--mm-per-unit", "1000",
                   "--set", "roughness=0.3", "--environment", "studio", "--environment-rotation", "90")  # fmt: skip
    core = ViewerCore(ctx, BUNNY, watch=False, **start)
    try:
        for scene in (core.scene, core.scene_src._load()):  # the first load and a reload
            m = scene.mesh_nodes()[0].material
            assert all(m[k] == v for k, v in preset_values("marble").items() if k != "roughness")
            assert m["roughness"] == 0.3 and scene.mm_per_unit == 1000.0
            assert scene.environment.exposure == 2.5
            assert scene.environment.map is not None and scene.environment.rotation_deg == 90.0
        assert core.settings.bounces == 1
    finally:
        core.close()
