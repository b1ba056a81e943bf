"""`skinlab demo`: render the default head scene headless (PNG and EXR) and say where it is;
`--gallery` also renders the head with every subsurface model and the bunny as marble, skim milk
and ketchup (Jensen 2001 presets) into OUT/gallery, with a labelled contact sheet."""

from __future__ import annotations

import sys
from pathlib import Path

from skinlab.atomic_write import write_text_atomic
from skinlab.commands.field_options import IMAGE_SIZE, add_command_options
from skinlab.declare import Field
from skinlab.render.settings import RenderSettings, parse_size
from skinlab.resources import scenes_root

ASSETS = scenes_root()
BUNNIES = ("marble", "skimmilk", "ketchup")

DEMO_OPTIONS = (
    Field("out", "string", "out", doc="output folder"),
    IMAGE_SIZE,  # as `skinlab render --size`
    Field(
        "gallery",
        "bool",
        False,
        doc="also render the head with each SSS model and the bunny presets into OUT/gallery "
        "(one PNG each, gallery.md and the labelled contact sheet gallery.png)",
    ),
    Field("no_progress", "bool", False, doc="no progress bar for --gallery"),
)


def register(sub) -> None:
    p = sub.add_parser("demo", help="render the default head scene into OUT (PNG + EXR)")
    add_command_options(p, DEMO_OPTIONS)
    p.set_defaults(func=run)


def run(args) -> int:
    from skinlab.commands.render import render_to_files
    from skinlab.gl.context import describe
    from skinlab.image_output import check_output_path

    w, h = parse_size(args.size)
    out = Path(args.out)
    if args.gallery:
        check_output_path(out / "gallery" / "gallery.png", "--out")
    scene, result, written, ctx = render_to_files(
        None, [out / "head.png", out / "head.exr"], RenderSettings(w, h), timed=True
    )
    print(f"Rendered '{scene.name}' ({scene.source}) at {w}x{h} on {describe(ctx)}")
    print(result.plan.explain())
    print(result.timings.table())
    print("images:")
    for path in written:
        print(f"  {Path(path).resolve()}")
    if args.gallery:
        gallery(out / "gallery", w, h, progress=not args.no_progress)
    return 0


def gallery(folder: Path, w: int, h: int, progress: bool = True) -> list[Path]:
    """Head x every SSS model, bunny x presets; a gallery.md lists them with their frame times and
    gallery.png tiles them (3 columns) with a label under each."""
    from tqdm import tqdm

    from skinlab.gl.context import create_headless_context
    from skinlab.image_output import contact_sheet, write_image
    from skinlab.render.renderer import Renderer
    from skinlab.scene.materials import SSS_MODELS
    from skinlab.scene.scenefile import load_scene

    renderer = Renderer(create_headless_context())
    renderer.reuse = False  # the gallery's frame times are full frames
    jobs = [(f"head-{m}", None, m) for m in SSS_MODELS] + [
        (f"bunny-{b}", ASSETS / f"bunny-{b}.toml", None) for b in BUNNIES
    ]
    rows, written, tiles = [], [], []
    bar = tqdm(jobs, desc="gallery", unit="image", file=sys.stderr, disable=not progress)
    for name, path, model in bar:
        bar.set_postfix_str(name)
        scene = load_scene(path)
        st = RenderSettings(w, h, sss_model=model)
        renderer.render(scene, st, readback=False)  # warm-up: compiles and uploads
        res = renderer.render(scene, st, readback=("ldr",))
        p = write_image(folder / f"{name}.png", res.ldr)
        written.append(p)
        tiles.append((res.ldr, f"{name}  {res.timings.frame_ms:.0f} ms"))
        rows.append(f"| ![{name}]({p.name}) | {name} | {res.timings.frame_ms:.1f} |")
        tqdm.write(f"  {p.resolve()}  ({res.timings.frame_ms:.1f} ms)", file=sys.stdout)
    sheet = write_image(folder / "gallery.png", contact_sheet(tiles, columns=3))
    print(f"  {sheet.resolve()}  (contact sheet)")
    md = [
        "# Skinlab gallery",
        "",
        f"Rendered by `skinlab demo --gallery --size {w}x{h}`; frame times are "
        f"{'CPU-synchronised (software GL)' if renderer.timer.software_gl else 'GPU timer queries'}.",
        "",
        "![contact sheet](gallery.png)",
        "",
        "| image | scene / model | frame ms |",
        "|---|---|---|",
        *rows,
        "",
    ]
    write_text_atomic(folder / "gallery.md", "\n".join(md))
    return written
