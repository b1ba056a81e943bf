"""`skinlab render [SCENE] --out PATH --size WxH [--technique NAME] [--json] [--explain] [--reuse]`: the
technique options come from the registered techniques (app/commands/technique_options.py)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from app.commands.technique_options import add_technique_options, technique_from_args
from app.render.settings import RenderSettings, parse_size
from scene.materials import SSS_MODELS


def register(sub) -> None:
    p = sub.add_parser("render", help="render a scene headless to PNG or EXR")
    p.add_argument("scene", nargs="?", help="scene file (TOML); default: the Lee Perry-Smith head")
    p.add_argument("--out", default="out/render.png", help="output image: .png (tone mapped) or .exr (linear)")
    p.add_argument("--size", default="640x640", help="WIDTHxHEIGHT (default 640x640)")
    p.add_argument("--shadow-size", type=int, default=2048, help="shadow map resolution")
    p.add_argument(
        "--sss",
        choices=SSS_MODELS,
        default=None,
        help="subsurface model for every material (default: each material's own sss_model)",
    )
    add_technique_options(p)
    p.add_argument("--json", action="store_true", help="print timings and output paths as JSON")
    p.add_argument("--explain", action="store_true", help="print the frame plan (passes and why each runs)")
    p.add_argument(
        "--reuse",
        action="store_true",
        help="the timed frame reuses the warm-up frame's results whose inputs did not change (shadow maps, "
        "texture-space irradiance and blurs: what the viewer does while only the camera moves); --explain "
        "lists them as 'reused: inputs unchanged since frame 1'. Default: every pass runs",
    )
    p.set_defaults(func=run)


def render_to_files(scene_path, outputs: list[Path], settings: RenderSettings, reuse: bool = False):
    """Render once and write each output (PNG from the tone-mapped image, EXR linear). A warm-up
    frame comes first; with `reuse` the written frame reuses its view-independent results."""
    from app.gl.context import create_headless_context
    from app.image_output import image_format, write_image
    from app.render.renderer import Renderer
    from scene.scenefile import load_scene

    for o in outputs:
        image_format(o)  # fail before rendering
    scene = load_scene(scene_path)
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    renderer.render(scene, settings, readback=False)  # warm-up: compiles and uploads are not frame time
    if not reuse:
        renderer.forget_reuse()  # the timed frame runs every pass
    result = renderer.render(scene, settings)
    written = []
    for o in outputs:
        pixels = result.ldr if image_format(o) == "png" else result.hdr
        written.append(str(write_image(o, pixels)))
    return scene, result, written, ctx


def settings_from_args(args, w: int, h: int) -> RenderSettings:
    return RenderSettings(w, h, shadow_size=args.shadow_size, sss_model=args.sss, technique=technique_from_args(args))


def run(args) -> int:
    w, h = parse_size(args.size)
    settings = settings_from_args(args, w, h)
    scene, result, written, ctx = render_to_files(args.scene, [Path(args.out)], settings, args.reuse)
    for warning in result.plan.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    if args.explain:
        print(result.plan.explain(), file=sys.stderr if args.json else sys.stdout)
    if args.json:
        from app.gl.context import describe

        print(
            json.dumps(
                {
                    "scene": str(scene.source),
                    "outputs": written,
                    "size": [w, h],
                    "gl": describe(ctx),
                    "timings": result.timings.as_dict(),
                    "plan": result.plan.as_dict(),
                },
                indent=2,
            )
        )
    else:
        for path in written:
            print(f"wrote {path}")
        for p in result.timings.passes:
            print(f"  {p.name:<18} {p.cpu_ms:8.2f} ms")
        for name in result.plan.reused():
            print(f"  {name:<18}    reused")
    return 0
