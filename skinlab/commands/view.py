"""`skinlab view [SCENE]`: the desktop viewer (pyglet window, Dear ImGui panel, pass inspector,
hot reload of shaders, scene and presets). See docs/viewer.md."""

from __future__ import annotations

import logging
import sys

from skinlab.commands.scene_options import (
    add_scene_edit_options,
    add_scene_look_options,
    scene_edits_from_args,
    scene_look_from_args,
)
from skinlab.commands.technique_options import add_frame_options, render_settings_from_args
from skinlab.render.settings import parse_size


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
    p.add_argument("--size", default="960x720", help="window size WIDTHxHEIGHT (default 960x720)")
    # the frame and the scene as `skinlab render` takes them, from the same declarations: --shadow-size,
    # --supersample, --bounces, ..., --sss, --technique (T cycles) and its settings; --exposure and the
    # environment map; --preset, --set KEY=VALUE, --mm-per-unit (applied again on every scene reload)
    add_frame_options(p)
    add_scene_look_options(p)
    add_scene_edit_options(p)
    w = p.add_mutually_exclusive_group()
    w.add_argument(
        "--watch",
        dest="watch",
        action="store_true",
        default=True,
        help="reload shaders, the scene file and presets when they change (default)",
    )
    w.add_argument("--no-watch", dest="watch", action="store_false", help="do not watch files")
    p.add_argument(
        "--settle",
        type=float,
        default=0.05,
        help="seconds a changed file must stay unchanged before it is reloaded (default 0.05)",
    )
    p.add_argument("--shader-dir", help="shader folder (default: the project's shaders/)")
    p.add_argument(
        "--screenshot-dir",
        default="out/screenshots",
        help="where S (PNG) and shift+S (EXR) save screenshots (default out/screenshots)",
    )
    p.add_argument("--frames", type=int, help="render this many frames, then exit (for tests and scripts)")
    p.add_argument("--screenshot", help="with --frames: save the last frame here (.png or .exr) before exiting")
    p.add_argument("--continuous", action="store_true", help="render every loop iteration, not only on changes")
    p.add_argument("--no-ui", action="store_true", help="start with the panel and overlay hidden (H toggles)")
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
    if args.frames is not None and args.frames < 1:
        raise ValueError(f"--frames: expected an integer >= 1, got {args.frames}")
    if args.screenshot:
        if args.frames is None:
            raise ValueError("--screenshot: needs --frames N (interactive screenshots: press S)")
        image_format(args.screenshot)  # fail before opening a window
    if not (0.0 <= args.settle <= 10.0):
        raise ValueError(f"--settle: expected seconds in [0, 10], got {args.settle}")
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
