"""`skinlab demo`: render the default head scene headless (PNG and EXR) and say where it is."""
from __future__ import annotations

from pathlib import Path

from app.render.settings import RenderSettings, parse_size


def register(sub) -> None:
    p = sub.add_parser("demo", help="render the default head scene into OUT (PNG + EXR)")
    p.add_argument("--out", default="out", help="output folder (default out/)")
    p.add_argument("--size", default="640x640")
    p.set_defaults(func=run)


def run(args) -> int:
    from app.commands.render import render_to_files
    from app.gl.context import describe

    w, h = parse_size(args.size)
    out = Path(args.out)
    scene, result, written, ctx = render_to_files(None, [out / "head.png", out / "head.exr"],
                                                  RenderSettings(w, h))
    print(f"Rendered '{scene.name}' ({scene.source}) at {w}x{h} on {describe(ctx)}")
    print(result.plan.explain())
    print("per-pass time (ms, " + result.timings.as_dict()["clock"] + "):")
    for p in result.timings.passes:
        gpu = f"{p.gpu_ms:8.2f}" if p.gpu_ms is not None else "     n/a"
        print(f"  {p.name:<18} cpu {p.cpu_ms:8.2f}   gpu-timer {gpu}")
    print(f"  {'frame':<18} {result.timings.frame_ms:8.2f}")
    print("images:")
    for path in written:
        print(f"  {Path(path).resolve()}")
    return 0
