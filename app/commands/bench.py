"""`skinlab bench peer`: our plain-PBR frame time against pyrender's, same scene, size and EGL.
`skinlab bench reload`: latency from saving a shader file to the first frame rendered with it.
`skinlab bench accuracy`: the accuracy/time ledger of the SSS techniques (app/bench/accuracy.py)."""

from __future__ import annotations

import argparse
import json
import re
import statistics
import time
from pathlib import Path

from app.render.settings import RenderSettings, parse_size


def register(sub) -> None:
    p = sub.add_parser("bench", help="benchmarks (timings are printed, never asserted)")
    bsub = p.add_subparsers(dest="bench", metavar="BENCH")
    bsub.required = True
    peer = bsub.add_parser("peer", help="Skinlab vs pyrender on the same head, size and EGL context kind")
    peer.add_argument("--size", default="512x512")
    peer.add_argument("--frames", type=int, default=30, help="timed frames per renderer (after warm-up)")
    peer.add_argument("--json", action="store_true")
    peer.set_defaults(func=run_peer_bench)
    rel = bsub.add_parser(
        "reload",
        help="shader hot reload: time from saving a file to the first frame rendered with the new program (headless)",
    )
    rel.add_argument("--size", default="128x128", help="frame size (default 128x128)")
    rel.add_argument("--repeats", type=int, default=10, help="edits to time (default 10)")
    rel.add_argument(
        "--file",
        default="passes/tonemap.frag",
        help="shader file to edit, relative to shaders/ (default passes/tonemap.frag)",
    )
    rel.add_argument(
        "--settle",
        type=float,
        default=0.05,
        help="ShaderWatcher settle time in seconds (default 0.05, as skinlab view)",
    )
    rel.add_argument("--shadow-size", type=int, default=512)
    rel.add_argument("--tsd-size", type=int, default=256)
    rel.add_argument(
        "--mode",
        choices=("on-demand", "continuous"),
        default="on-demand",
        help="on-demand: the viewer's default loop (idle polls at 60 Hz, a frame only after a "
        "change); continuous: a frame every iteration (as with skinlab view --continuous)",
    )
    rel.add_argument("--timeout", type=float, default=20.0, help="give up on one edit after this many seconds")
    rel.add_argument("--json", action="store_true")
    rel.set_defaults(func=run_reload_bench)
    acc = bsub.add_parser(
        "accuracy",
        help="accuracy/time ledger: every SSS technique and setting timed and compared with the "
        "path-traced truth, the exact convolution and the Monte Carlo profile",
    )
    acc.add_argument(
        "--out",
        required=True,
        help="output folder (ledger.csv, ledger.md, ledger.json, pareto.png, cost.png, images/, mc_cache/)",
    )
    acc.add_argument("--quick", action="store_true", help="a subset at 160x160 (a few minutes at most on 2 cores)")
    acc.add_argument("--tiny", action="store_true", help=argparse.SUPPRESS)  # tests: 4 settings, head, 64x64
    acc.add_argument("--size", default=None, help="WIDTHxHEIGHT (default 640x640; --quick 160x160)")
    acc.add_argument(
        "--scenes",
        default=None,
        help="comma-separated scene names (assets/scenes/reference/NAME.toml, assets/scenes/NAME.toml; head, "
        "bunny) or .toml paths (default: every reference scene; --quick head-skin1-matched, bunny-skimmilk, "
        "slab-edge-skin1)",
    )
    acc.add_argument(
        "--references",
        action="store_true",
        help="path-trace the scenes' references that are not cached yet (skinlab reference; minutes per scene "
        "on 2 cores: full 192x192 at 1024 spp, --quick 96x96 at 256 spp); without it a scene whose reference "
        "is not cached is measured without the truth",
    )
    acc.add_argument("--frames", type=int, default=None, help="timed frames per setting (default 10; --quick 5)")
    acc.add_argument(
        "--photons", type=int, default=None, help="Monte Carlo photons per channel (default 200000; --quick 20000)"
    )
    acc.add_argument(
        "--exact-size",
        type=int,
        default=None,
        help="irradiance texels per side of the exact reference (default 1024; --quick 256)",
    )
    acc.add_argument("--no-peer", action="store_true", help="skip the pyrender comparison")
    acc.add_argument("--no-images", action="store_true", help="do not write images/SCENE-SETTING.png")
    acc.add_argument("--no-progress", action="store_true", help="no progress bar")
    acc.set_defaults(func=run_accuracy_bench)


def peer_bench(size=(512, 512), frames: int = 30) -> dict:
    """Median frame times, both including the colour+depth read-back (pyrender always reads back).
    ``skinlab_ms`` is the plain-PBR frame (sss_model none, like pyrender's: no subsurface scattering);
    ``skinlab_default_ms`` the frame with the default RenderSettings (the head's skin scatters, so
    texture-space diffusion runs)."""
    from app.bench.pyrender_peer import run_peer
    from app.gl.context import create_headless_context, describe
    from app.render.renderer import Renderer
    from scene.scenefile import load_scene

    if frames < 1:
        raise ValueError(f"--frames: expected >= 1, got {frames}")
    scene = load_scene(None)
    # plain PBR on both sides: no shadow map (pyrender's directional light casts none by default)
    for light in scene.lights():
        light.cast_shadow = False
    w, h = size
    ctx = create_headless_context()
    r = Renderer(ctx)
    r.timer.sync = False  # no glFinish between passes: whole frames are timed here

    def timed(settings):
        r.render(scene, settings)
        r.render(scene, settings)
        out = []
        for _ in range(frames):
            t0 = time.perf_counter()
            r.render(scene, settings, readback=("ldr", "depth"))  # what pyrender reads back
            out.append((time.perf_counter() - t0) * 1e3)
        return out

    try:
        ours = timed(RenderSettings(w, h, sss_model="none"))
        ours_default = timed(RenderSettings(w, h))
    finally:
        r.release()
    cam = scene.camera
    meshes = [(str(n.mesh.source), n.world_matrix) for n in scene.mesh_nodes()]
    peer = run_peer(meshes, cam.world_matrix, cam.yfov, cam.znear, cam.zfar, size, frames=frames)
    theirs = list(map(float, peer["times"]))
    mo, mt = statistics.median(ours), statistics.median(theirs)
    md = statistics.median(ours_default)
    return {
        "size": [w, h],
        "frames": frames,
        "gl": describe(ctx),
        "skinlab_ms": mo,
        "pyrender_ms": mt,
        "ratio_skinlab_over_pyrender": mo / mt,
        "skinlab_default_ms": md,
        "ratio_default_over_pyrender": md / mt,
    }


def run_peer_bench(args) -> int:
    res = peer_bench(parse_size(args.size), args.frames)
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        print(
            f"{res['gl']}, {res['size'][0]}x{res['size'][1]}, median of {res['frames']} frames "
            f"(colour+depth read back on both):"
        )
        print(f"  skinlab   {res['skinlab_ms']:8.2f} ms/frame (plain PBR: sss_model none)")
        print(f"  pyrender  {res['pyrender_ms']:8.2f} ms/frame")
        print(f"  ratio skinlab/pyrender = {res['ratio_skinlab_over_pyrender']:.2f}")
        print(
            f"  skinlab with the default settings (texture-space diffusion on the skin) "
            f"{res['skinlab_default_ms']:8.2f} ms/frame, ratio {res['ratio_default_over_pyrender']:.2f}"
        )
    return 0


# -- shader hot-reload latency -------------------------------------------------------------------------

_MAIN = re.compile(r"\bvoid\s+main\s*\(\s*(void)?\s*\)")
_OUT = re.compile(r"^\s*(?:layout\s*\([^)]*\)\s*)?out\s+vec4\s+(\w+)\s*;", re.M)


def bench_edit(text: str, i: int) -> tuple[str, bool]:
    """The i-th edit of a shader file and whether it must change the image.

    A fragment stage with one ``out vec4`` gets its ``main`` wrapped so the output is scaled by
    0.5 or 0.75 (alternating: every edit changes the image); any other file gets a comment
    appended, which recompiles the programs that include it without changing pixels."""
    outs = _OUT.findall(text)
    if len(outs) == 1 and len(_MAIN.findall(text)) == 1:
        factor = 0.5 if i % 2 == 0 else 0.75
        body = _MAIN.sub("void skinlab_bench_main()", text, count=1)
        return (
            body + f"\n// skinlab bench reload edit {i}\nvoid main() {{\n    skinlab_bench_main();\n"
            f"    {outs[0]}.rgb *= {factor};\n}}\n"
        ), True
    return text + f"\n// skinlab bench reload edit {i}\n", False


def _stats(values: list[float]) -> dict:
    return {
        "median": statistics.median(values),
        "max": max(values),
        "min": min(values),
        "samples": [round(v, 3) for v in values],
    }


def reload_bench(
    size=(128, 128),
    repeats: int = 10,
    file: str = "passes/tonemap.frag",
    settle_s: float = 0.05,
    shadow_size: int = 512,
    tsd_size: int = 256,
    timeout_s: float = 20.0,
    mode: str = "on-demand",
) -> dict:
    """Copy shaders/ to a temporary folder, render the head continuously with a Renderer on it
    while a ShaderWatcher watches the copy, write an edited ``file`` ``repeats`` times and time
    each write until the end of the first frame (tone-mapped pixels read back) whose programs
    were recompiled from it; where the edit changes the image, that frame's pixels must differ
    from the previous frame's. This is the viewer's loop without a window: ``on-demand`` polls
    at 60 Hz while idle and renders once a reload was applied (the viewer's default);
    ``continuous`` renders a frame every iteration, so a save usually waits for the frame in
    flight before it is even polled."""
    import shutil
    import tempfile

    import numpy as np

    from app.gl.context import create_headless_context, describe
    from app.gl.hot_reload import ShaderWatcher
    from app.gl.shader_source import SHADER_ROOT, ShaderError, ShaderLibrary
    from app.render.renderer import Renderer
    from scene.scenefile import load_scene

    if repeats < 1:
        raise ValueError(f"--repeats: expected >= 1, got {repeats}")
    if mode not in ("on-demand", "continuous"):
        raise ValueError(f"--mode: expected on-demand or continuous, got {mode!r}")
    if not 0.0 <= settle_s <= 10.0:
        raise ValueError(f"--settle: expected seconds in [0, 10], got {settle_s}")
    w, h = size
    settings = RenderSettings(w, h, shadow_size=shadow_size, tsd_size=tsd_size)
    ctx = create_headless_context()
    scene = load_scene(None)
    with tempfile.TemporaryDirectory(prefix="skinlab-reload-") as tmp:
        root = Path(tmp) / "shaders"
        shutil.copytree(SHADER_ROOT, root)
        target = (root / file).resolve()
        if root.resolve() not in target.parents or not target.is_file():
            raise ValueError(f"--file: no shader file {file!r} under {SHADER_ROOT}")
        renderer = Renderer(ctx, ShaderLibrary(root=root))
        watcher = ShaderWatcher(renderer.programs, root, settle_s=settle_s)
        try:
            prev = renderer.render(scene, settings, readback=("ldr",)).ldr  # compile everything once
            keys = renderer.programs.dependents({target})
            if not keys:
                raise ValueError(f"--file: no program of the head's frame includes {file}")
            original = target.read_text(encoding="utf-8")
            latency, reload_ms, compile_ms, frame_ms, frames_waited = [], [], [], [], []
            image_check = bench_edit(original, 0)[1]
            for i in range(repeats):
                # let late events of the previous write settle, so each edit starts from quiet
                t_quiet = time.perf_counter()
                while time.perf_counter() - t_quiet < max(3 * settle_s, 0.1):
                    if watcher.poll() is not None:
                        prev = renderer.render(scene, settings, readback=("ldr",)).ldr
                    time.sleep(0.005)
                gens = {k: renderer.programs.entries[k].generation for k in keys}
                text, _ = bench_edit(original, i)
                t0 = time.perf_counter()
                target.write_text(text, encoding="utf-8")
                t_reload, t_compile, n = None, None, 0
                while True:
                    tp = time.perf_counter()
                    errors = watcher.poll()
                    if errors is not None:
                        if errors:
                            raise ShaderError(f"bench edit {i} of {file} did not compile: {errors[0]}")
                        t_reload = time.perf_counter()
                        t_compile = t_reload - tp
                    elif mode == "on-demand":
                        if time.perf_counter() - t0 > timeout_s:
                            raise RuntimeError(f"no reload of {file} within {timeout_s} s of writing it")
                        time.sleep(1 / 60)
                        continue
                    tf0 = time.perf_counter()
                    res = renderer.render(scene, settings, readback=("ldr",))
                    t_end = time.perf_counter()
                    n += 1
                    if all(renderer.programs.entries[k].generation > g for k, g in gens.items()):
                        break
                    if t_end - t0 > timeout_s:
                        raise RuntimeError(f"no reload of {file} within {timeout_s} s of writing it")
                if image_check and np.array_equal(res.ldr, prev):
                    raise RuntimeError(f"edit {i} of {file} was recompiled but the frame did not change")
                prev = res.ldr
                latency.append((t_end - t0) * 1e3)
                reload_ms.append((t_reload - t0) * 1e3 if t_reload is not None else float("nan"))
                compile_ms.append(t_compile * 1e3 if t_compile is not None else float("nan"))
                frame_ms.append((t_end - tf0) * 1e3)
                frames_waited.append(n)
        finally:
            watcher.stop()
            renderer.release()
    return {
        "gl": describe(ctx),
        "mode": mode,
        "size": [w, h],
        "file": file,
        "programs": len(keys),
        "repeats": repeats,
        "settle_s": settle_s,
        "check": "image changed" if image_check else "program recompiled",
        "latency_ms": _stats(latency),
        "reload_applied_ms": _stats(reload_ms),
        "recompile_ms": _stats(compile_ms),
        "first_frame_ms": _stats(frame_ms),
        "frames_until_new": frames_waited,
    }


def run_reload_bench(args) -> int:
    res = reload_bench(
        parse_size(args.size),
        args.repeats,
        args.file,
        args.settle,
        args.shadow_size,
        args.tsd_size,
        args.timeout,
        args.mode,
    )
    if args.json:
        print(json.dumps(res, indent=2))
        return 0
    lat, rel, fr = res["latency_ms"], res["reload_applied_ms"], res["first_frame_ms"]
    comp = res["recompile_ms"]
    print(
        f"{res['gl']}, {res['mode']} frames, {res['size'][0]}x{res['size'][1]}, "
        f"{res['repeats']} edits of shaders/{res['file']} "
        f"({res['programs']} program(s) depend on it; settle {res['settle_s']} s; check: {res['check']})"
    )
    print(f"  save -> first new frame   median {lat['median']:8.1f} ms   max {lat['max']:8.1f} ms")
    print(f"  save -> reload applied    median {rel['median']:8.1f} ms   max {rel['max']:8.1f} ms")
    print(f"    of which recompiling    median {comp['median']:8.1f} ms   max {comp['max']:8.1f} ms")
    print(f"  the first new frame       median {fr['median']:8.1f} ms   max {fr['max']:8.1f} ms")
    return 0


# -- accuracy/time ledger ----------------------------------------------------------------------------------


def accuracy_sweep_from_args(args):
    """The Sweep chosen by --quick/--tiny with the explicit overrides applied."""
    from dataclasses import replace

    from app.bench.accuracy import SWEEPS

    if args.quick and args.tiny:
        raise ValueError("--quick and --tiny: choose one")
    sweep = SWEEPS["tiny" if args.tiny else "quick" if args.quick else "full"]
    over = {}
    if args.size:
        over["size"] = parse_size(args.size)
    if args.frames is not None:
        if args.frames < 1:
            raise ValueError(f"--frames: expected >= 1, got {args.frames}")
        over["frames"] = args.frames
    if args.photons is not None:
        if args.photons < 2:
            raise ValueError(f"--photons: expected >= 2, got {args.photons}")
        over["photons"] = args.photons
    if args.exact_size is not None:
        if not 16 <= args.exact_size <= 8192:
            raise ValueError(f"--exact-size: expected texels per side in [16, 8192], got {args.exact_size}")
        over["exact_size"] = args.exact_size
    if args.scenes is not None:
        names = tuple(s.strip() for s in args.scenes.split(",") if s.strip())
        if not names:
            raise ValueError("--scenes: expected a comma-separated list such as head,bunny")
        over["scenes"] = names
    return replace(sweep, **over)


def run_accuracy_bench(args) -> int:
    from app.bench.accuracy import resolve_scene, run_sweep

    sweep = accuracy_sweep_from_args(args)
    for s in sweep.scenes:
        resolve_scene(s)  # bad names fail before any rendering
    flags = [
        ("--quick", args.quick),
        ("--tiny", args.tiny),
        ("--no-peer", args.no_peer),
        ("--references", args.references),
    ]
    opts = [
        ("--size", args.size),
        ("--scenes", args.scenes),
        ("--frames", args.frames),
        ("--photons", args.photons),
        ("--exact-size", args.exact_size),
    ]
    command = " ".join(
        [
            "skinlab bench accuracy",
            *(f for f, on in flags if on),
            *(f"{k} {v}" for k, v in opts if v is not None),
            f"--out {args.out}",
        ]
    )
    res = run_sweep(
        sweep,
        Path(args.out),
        peer=not args.no_peer,
        progress=not args.no_progress,
        images=not args.no_images,
        command=command,
        references=args.references,
    )
    rows = res["rows"]
    n_ok = sum(r["status"] == "ok" for r in rows)
    print(f"{res['meta']['gl']}: {len(rows)} settings ({n_ok} ok) in {res['meta']['total_s']:.1f} s")
    for r in rows:
        if r["status"] != "ok":
            print(f"  {r['scene']}: {r['setting']}: {r['status']}: {r['error']}")
    for f in res["files"]:
        print(f"  {Path(f).resolve()}")
    return 0
