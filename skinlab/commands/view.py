"""`skinlab view [SCENE]`: the desktop viewer (pyglet window, Dear ImGui panel, pass inspector,
hot reload of shaders, scene and presets). See docs/viewer.md."""

from __future__ import annotations

import logging
import math
import sys

from skinlab.commands.field_options import add_command_options, check_command_options
from skinlab.commands.scene_options import (
    add_scene_edit_options,
    add_scene_look_options,
    scene_edits_from_args,
    scene_look_from_args,
)
from skinlab.commands.technique_options import add_frame_options, render_settings_from_args
from skinlab.declare import Field
from skinlab.render.settings import parse_size

# the viewer's own options (the frame's and the scene's come from their declarations elsewhere)
VIEW_OPTIONS = (
    Field("size", "string", "960x720", doc="window size WIDTHxHEIGHT"),
    Field("watch", "bool", True, doc="reload shaders, the scene file and presets when they change"),
    Field(
        "settle",
        "float",
        0.05,
        (0.0, 10.0),
        unit="seconds",
        doc="how long a changed file must stay unchanged before it is reloaded",
    ),
    Field("shader_dir", "string", shown="the project's shaders/", doc="shader folder"),
    Field("screenshot_dir", "string", "out/screenshots", doc="where S (PNG) and shift+S (EXR) save screenshots"),
    Field("frames", "int", None, (1, math.inf), doc="render this many frames, then exit (for tests and scripts)"),
    Field("screenshot", "string", doc="with --frames: save the last frame here (.png or .exr) before exiting"),
    Field("continuous", "bool", False, doc="render every loop iteration, not only on changes"),
    Field("no_ui", "bool", False, doc="start with the panel and overlay hidden (H toggles)"),
)


def register(sub) -> None:
    p = sub.add_parser(
        "view", help="open the desktop viewer (orbit camera, parameter panel, pass inspector, hot reload)"
    )
    p.add_argument(
        "scene",
        nargs="?",
        help="scene file (TOML) or a mesh file (.glb .gltf .obj .ply .stl .off: default camera, two lights and "
        "a plain grey material); default: the Lee Perry-Smith head",
    )
    add_command_options(p, VIEW_OPTIONS[:1])  # --size
    # the frame and the scene as `skinlab render` takes them, from the same declarations: --shadow-size,
    # --supersample, --bounces, ..., --sss, --technique (T cycles) and its settings; --exposure, the
    # environment map, --camera-orbit; --preset, --set KEY=VALUE, --mm-per-unit (applied again on every
    # scene reload)
    add_frame_options(p)
    add_scene_look_options(p)
    add_scene_edit_options(p)
    add_command_options(p, VIEW_OPTIONS[1:])
    p.set_defaults(func=run)


def view_start(args, size: tuple[int, int]) -> dict:
    """What the viewer starts from, checked (errors name the option): ``settings`` (RenderSettings of
    the window's size), ``edits`` (SceneEdits) and ``prepare`` (--exposure, --environment ... on each
    loaded scene): ViewerCore's and ViewerWindow's keywords of those names."""
    return {
        "settings": render_settings_from_args(args, *size),
        "edits": scene_edits_from_args(args),
        "prepare": scene_look_from_args(args),
    }


def run(args) -> int:
    from skinlab.image_output import image_format

    size = parse_size(args.size)
    check_command_options(args, VIEW_OPTIONS)  # --frames >= 1, --settle in [0, 10] seconds
    if args.screenshot:
        if args.frames is None:
            raise ValueError("--screenshot: needs --frames N (interactive screenshots: press S)")
        image_format(args.screenshot)  # fail before opening a window
    start = view_start(args, size)  # errors name the option, before a window opens
    if not logging.getLogger().handlers:
        logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="skinlab view: %(message)s")
    logging.getLogger("OpenGL").setLevel(logging.WARNING)  # PyOpenGL's "no OpenGL_accelerate" notice

    from skinlab.viewer.window import ViewerWindow

    win = ViewerWindow(
        args.scene,
        size,
        watch=args.watch,
        screenshot_dir=args.screenshot_dir,
        shader_root=args.shader_dir,
        settle_s=args.settle,
        continuous=args.continuous,
        show_ui=not args.no_ui,
        **start,
    )
    return win.run(frames=args.frames, screenshot=args.screenshot)
