"""`skinlab render [SCENE|MESH] --out PATH --size WxH [--supersample N] [--technique NAME] [--preset NAME]
[--set KEY=VALUE] [--mm-per-unit MM] [--json] [--explain] [--time] [--reuse]`: the technique options come from the
registered techniques and --supersample from RenderSettings' declaration (skinlab/commands/technique_options.py);
--preset/--set/--mm-per-unit edit the scene before it is built (skinlab/commands/scene_options.py)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from skinlab.commands.field_options import IMAGE_SIZE, add_command_options
from skinlab.commands.scene_options import (
    add_scene_edit_options,
    add_scene_look_options,
    scene_edits_from_args,
    scene_look_from_args,
)
from skinlab.commands.technique_options import add_frame_options, render_settings_from_args
from skinlab.declare import Field
from skinlab.render.settings import RenderSettings, parse_size

# the command's own options (the frame's and the scene's come from their declarations elsewhere)
RENDER_OPTIONS = (
    Field(
        "out",
        "string",
        "out/render.png",
        doc="output image: .png (tone mapped, 8-bit sRGB) or .exr (linear radiance, 32-bit float, with alpha)",
    ),
    IMAGE_SIZE,
    Field("json", "bool", False, doc="print outputs, timings and the frame plan as JSON"),
    Field("explain", "bool", False, doc="print the frame plan (passes and why each runs)"),
    Field(
        "time",
        "bool",
        False,
        doc="render a warm-up frame first and write and time the second, so that the per-pass times leave "
        "out shader compiles and texture uploads. Default: one frame, its times include them",
    ),
    Field(
        "reuse",
        "bool",
        False,
        doc="implies --time; the timed frame reuses the warm-up frame's results whose inputs did not change "
        "(shadow maps, texture-space irradiance and blurs: what the viewer does while only the camera moves); "
        "--explain lists them as 'reused: inputs unchanged since frame 1'. Default: every pass runs",
    ),
)


def register(sub) -> None:
    p = sub.add_parser("render", help="render a scene headless to PNG or EXR")
    p.add_argument(
        "scene",
        nargs="?",
        help="scene file (TOML) or a mesh file (.glb .gltf .obj .ply .stl .off: default camera, two lights "
        "and a plain grey material); default: the Lee Perry-Smith head",
    )
    add_command_options(p, RENDER_OPTIONS[:2])  # --out, --size
    add_scene_look_options(p)  # --exposure, --environment MAP and its rotation, intensity, --background, --camera-orbit
    add_frame_options(p)  # --shadow-size, --supersample, --bounces, ..., --sss, --technique and its options
    add_scene_edit_options(p)  # --preset, --set KEY=VALUE, --mm-per-unit
    add_command_options(p, RENDER_OPTIONS[2:])  # --json, --explain, --time, --reuse
    p.set_defaults(func=run)


def render_to_files(
    scene_path,
    outputs: list[Path],
    settings: RenderSettings,
    prepare=None,
    reuse: bool = False,
    edits=None,
    timed: bool = False,
):
    """Render and write each output (PNG from the tone-mapped image, EXR linear).
    ``prepare(scene)`` may adjust the loaded scene (camera, exposure) before rendering; ``edits``
    (SceneEdits: --preset, --set, --mm-per-unit) change it before it is built. One frame, unless
    ``timed`` (or ``reuse``): then a warm-up frame comes first and the second is written and timed;
    with ``reuse`` it reuses the warm-up's view-independent results."""
    from skinlab.gl.context import create_headless_context
    from skinlab.image_output import check_output_path, image_format, write_image
    from skinlab.render.renderer import Renderer
    from skinlab.scene.scenefile import load_scene

    for o in outputs:
        check_output_path(o, "--out")  # fail before rendering
    scene = load_scene(scene_path, edits)
    if prepare is not None:
        prepare(scene)
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    if timed or reuse:
        # warm-up: compiles and uploads are not frame time
        render_with_progress(renderer, scene, settings, "warm-up frame", readback=False)
        if not reuse:
            renderer.forget_reuse()  # the timed frame runs every pass
    result = render_with_progress(renderer, scene, settings, "timed frame" if timed or reuse else "frame")
    written = []
    for o in outputs:
        pixels = result.ldr if image_format(o) == "png" else result.hdr
        written.append(str(write_image(o, pixels)))
    return scene, result, written, ctx


PROGRESS_AFTER_S = 2.0
# what the reported times are of (the table's last line, and render --json's "timed_frame")
FRAME_FIRST = "the first frame: shader compiles and texture uploads included; --time for a warmed-up frame"
FRAME_TIMED = "the second frame, after a warm-up frame"


def render_with_progress(renderer, scene, settings, what: str, readback=True):
    """Renderer.render, with a progress bar on a terminal's stderr once a frame has taken
    PROGRESS_AFTER_S (a scene of many scattering meshes runs hundreds of passes); the frame's timings
    count the passes only, not the bar."""
    from tqdm import tqdm

    steps = renderer.frame_steps(scene, settings, readback)
    shown = sys.stderr.isatty()
    bar = tqdm(desc=what, unit=" passes", delay=PROGRESS_AFTER_S, leave=False, file=sys.stderr, disable=not shown)
    with bar:
        while True:
            try:
                name = next(steps)
            except StopIteration as done:
                return done.value
            bar.set_postfix_str(name, refresh=False)
            bar.update()


def settings_from_args(args, w: int, h: int) -> RenderSettings:
    return render_settings_from_args(args, w, h)


def run(args) -> int:
    w, h = parse_size(args.size)
    settings = settings_from_args(args, w, h)
    edits = scene_edits_from_args(args)
    look = scene_look_from_args(args)  # --exposure, --environment ..., --camera-orbit
    timed = args.time or args.reuse
    scene, result, written, ctx = render_to_files(
        args.scene, [Path(args.out)], settings, look, args.reuse, edits, timed=timed
    )
    for warning in result.plan.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    if args.explain:  # the warnings were printed above, once
        print(result.plan.explain(warnings=False), file=sys.stderr if args.json else sys.stdout)
    if args.json:
        from skinlab.gl.context import describe

        print(
            json.dumps(
                {
                    "scene": str(scene.source),
                    "outputs": written,
                    "size": [w, h],
                    "gl": describe(ctx),
                    "timings": result.timings.as_dict(),
                    "timed_frame": FRAME_TIMED if timed else FRAME_FIRST,
                    "plan": result.plan.as_dict(),
                    "warnings": result.plan.warnings,
                    "notes": result.plan.notes,
                },
                indent=2,
            )
        )
    else:
        for path in written:
            print(f"wrote {path}")
        for note in result.plan.notes:  # what a setting costs this image, and what would change it
            print(f"note: {note}")
        print(result.timings.table())
        print(f"  ({FRAME_TIMED if timed else FRAME_FIRST})")
        for name in result.plan.reused():
            print(f"  {name}: reused, inputs unchanged since the warm-up frame")
    return 0
