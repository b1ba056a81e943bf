"""`skinlab demo`: render the default head scene headless (PNG and EXR) and say where it is;
`--gallery` also renders the head with every subsurface model and the bunny as marble, skim milk
and ketchup (Jensen 2001 presets) into OUT/gallery."""

from __future__ import annotations

from pathlib import Path

from app.atomic_write import write_text_atomic
from app.render.settings import RenderSettings, parse_size

ASSETS = Path(__file__).resolve().parents[2] / "assets" / "scenes"
BUNNIES = ("marble", "skimmilk", "ketchup")


def register(sub) -> None:
    p = sub.add_parser("demo", help="render the default head scene into OUT (PNG + EXR)")
    p.add_argument("--out", default="out", help="output folder (default out/)")
    p.add_argument("--size", default="640x640")
    p.add_argument(
        "--gallery",
        action="store_true",
        help="also render the head with each SSS model and the bunny presets into OUT/gallery",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    from app.commands.render import render_to_files
    from app.gl.context import describe

    w, h = parse_size(args.size)
    out = Path(args.out)
    scene, result, written, ctx = render_to_files(None, [out / "head.png", out / "head.exr"], RenderSettings(w, h))
    print(f"Rendered '{scene.name}' ({scene.source}) at {w}x{h} on {describe(ctx)}")
    print(result.plan.explain())
    print("per-pass time (ms, " + result.timings.as_dict()["clock"] + "):")
    for p in result.timings.passes:
        gpu = f"{p.gpu_ms:8.2f}" if p.gpu_ms is not None else "     n/a"
        print(f"  {p.name:<30} cpu {p.cpu_ms:8.2f}   gpu-timer {gpu}")
    print(f"  {'frame':<30} {result.timings.frame_ms:8.2f}")
    print("images:")
    for path in written:
        print(f"  {Path(path).resolve()}")
    if args.gallery:
        gallery(out / "gallery", w, h)
    return 0


def gallery(folder: Path, w: int, h: int) -> list[Path]:
    """Head x every SSS model, bunny x presets; a gallery.md lists them with their frame times."""
    from app.gl.context import create_headless_context
    from app.image_output import write_image
    from app.render.renderer import Renderer
    from scene.materials import SSS_MODELS
    from scene.scenefile import load_scene

    renderer = Renderer(create_headless_context())
    renderer.reuse = False  # the gallery's frame times are full frames
    jobs = [(f"head-{m}", None, m) for m in SSS_MODELS] + [
        (f"bunny-{b}", ASSETS / f"bunny-{b}.toml", None) for b in BUNNIES
    ]
    rows, written = [], []
    for name, path, model in jobs:
        scene = load_scene(path)
        st = RenderSettings(w, h, sss_model=model)
        renderer.render(scene, st, readback=False)  # warm-up: compiles and uploads
        res = renderer.render(scene, st, readback=("ldr",))
        p = write_image(folder / f"{name}.png", res.ldr)
        written.append(p)
        rows.append(f"| ![{name}]({p.name}) | {name} | {res.timings.frame_ms:.1f} |")
        print(f"  {p.resolve()}  ({res.timings.frame_ms:.1f} ms)")
    md = [
        "# Skinlab gallery",
        "",
        f"Rendered by `skinlab demo --gallery --size {w}x{h}`; frame times are "
        f"{'CPU-synchronised (software GL)' if renderer.timer.software_gl else 'GPU timer queries'}.",
        "",
        "| image | scene / model | frame ms |",
        "|---|---|---|",
        *rows,
        "",
    ]
    write_text_atomic(folder / "gallery.md", "\n".join(md))
    return written
