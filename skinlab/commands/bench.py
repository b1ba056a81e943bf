"""`skinlab bench peer`: our plain-PBR frame time against pyrender's, same scene, size and EGL
(skinlab/bench/peer.py).
`skinlab bench orbit`: frame time while the camera orbits, with and without reuse across frames, and
the plain frame (skinlab/bench/orbit.py).
`skinlab bench reload`: latency from saving a shader file to the first frame rendered with it
(skinlab/bench/reload.py).
`skinlab bench accuracy`: the accuracy/time ledger of the SSS techniques (skinlab/bench/accuracy.py).
`skinlab bench startup`: how long `skinlab render` takes to answer: fresh, cold and warm starts
(skinlab/bench/startup.py).
This module only parses options and prints; the benchmarks live in skinlab/bench/."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from skinlab.bench.orbit import SCENES as ORBIT_SCENES
from skinlab.bench.orbit import orbit_bench
from skinlab.bench.peer import peer_bench
from skinlab.bench.reload import reload_bench
from skinlab.render.settings import RenderSettings, parse_size

RELOAD_SHADOW_SIZE = 512  # `skinlab bench reload --shadow-size`: its own default, stated in its help


def register(sub) -> None:
    from skinlab.bench.accuracy import SWEEPS  # the sweeps' numbers are the help's defaults

    p = sub.add_parser("bench", help="benchmarks (timings are printed, never asserted)")
    bsub = p.add_subparsers(dest="bench", metavar="BENCH")
    bsub.required = True
    peer = bsub.add_parser("peer", help="Skinlab vs pyrender on the same head, size and EGL context kind")
    peer.add_argument("--size", default="512x512", help="frame size WIDTHxHEIGHT in pixels (default 512x512)")
    peer.add_argument(
        "--frames", type=int, default=30, help="timed frames per renderer, after 2 warm-up frames (default 30)"
    )
    peer.add_argument(
        "--rounds",
        type=int,
        default=3,
        help="rounds the frames are split into, each timing Skinlab's settings then pyrender's, so that a change "
        "of machine load hits both alike; the ratio is the median of the rounds' (default 3)",
    )
    peer.add_argument("--json", action="store_true", help="print the result as JSON")
    peer.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    peer.add_argument(
        "--blender",
        action="store_true",
        help="instead: Blender's EEVEE and Cycles beside Skinlab's default frame on the reference scenes, against "
        "the path-traced truth, in one ledger run (--quick sizes; writes the ledger to --out; see docs/ledger.md)",
    )
    peer.add_argument(
        "--out", default="out/peer-blender", help="with --blender: the ledger's folder (default out/peer-blender)"
    )
    peer.add_argument(
        "--scenes",
        default=None,
        help="with --blender: comma-separated scene names (default: every reference scene)",
    )
    peer.add_argument(
        "--references", action="store_true", help="with --blender: path-trace the references not cached yet"
    )
    peer.add_argument(
        "--cycles-truth",
        action="store_true",
        help="with --blender: Cycles at 1024 spp (random walk and random walk skin) as a second truth against "
        "Mitsuba's, instead of the EEVEE/Cycles frame-time rows (docs/ground-truth.md)",
    )
    peer.set_defaults(func=run_peer_bench)
    orb = bsub.add_parser(
        "orbit",
        help="frame time while the camera orbits the head and the bunny: with reuse across frames (as the viewer), "
        "without, and the plain frame (--sss none), in one run",
    )
    orb.add_argument("--size", default="640x640", help="frame size WIDTHxHEIGHT in pixels (default 640x640)")
    orb.add_argument(
        "--frames",
        type=int,
        default=24,
        help="timed camera steps per scene over one full turn, after 2 warm-up frames (default 24)",
    )
    orb.add_argument(
        "--scenes",
        default=",".join(ORBIT_SCENES),
        help=f"comma-separated scene names, from {', '.join(ORBIT_SCENES)} (default {','.join(ORBIT_SCENES)})",
    )
    orb.add_argument("--json", action="store_true", help="print the result as JSON")
    orb.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    orb.set_defaults(func=run_orbit_bench)
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
    shadow = RenderSettings.fields()["shadow_size"]  # the render setting this benchmark's frames use
    rel.add_argument(
        "--shadow-size",
        type=int,
        default=RELOAD_SHADOW_SIZE,
        help=f"the timed frames' {shadow.doc}: this benchmark's own default, smaller than a render's "
        f"{shadow.default} so that a frame after an edit is quick; {shadow.expected()} "
        f"(default: {RELOAD_SHADOW_SIZE} {shadow.unit})",
    )
    rel.add_argument("--tsd-size", type=int, default=256, help="texture-space diffusion texels per side (default 256)")
    rel.add_argument(
        "--mode",
        choices=("on-demand", "continuous"),
        default="on-demand",
        help="on-demand: the viewer's default loop (idle polls at 60 Hz, a frame only after a "
        "change); continuous: a frame every iteration (as with skinlab view --continuous)",
    )
    rel.add_argument(
        "--timeout", type=float, default=20.0, help="give up on one edit after this many seconds (default 20)"
    )
    rel.add_argument("--json", action="store_true", help="print the result as JSON (every sample)")
    rel.set_defaults(func=run_reload_bench)
    acc = bsub.add_parser(
        "accuracy",
        help="accuracy/time ledger: every SSS technique and setting timed and compared with the "
        "path-traced truth, the exact convolution and the Monte Carlo profile",
    )
    acc.add_argument(
        "--out",
        required=True,
        help="output folder (ledger.csv, ledger.md, ledger.html, ledger.json, pareto.png, cost.png, profiles.png, "
        "error_maps/, flip_maps/, images/, mc_cache/)",
    )
    acc.add_argument("--quick", action="store_true", help="a subset at 160x160 (a few minutes at most on 2 cores)")
    acc.add_argument("--tiny", action="store_true", help=argparse.SUPPRESS)  # tests: 4 settings, head, 64x64
    full, quick = SWEEPS["full"], SWEEPS["quick"]
    from skinlab.bench.sweep import base_setting, reference_technique

    ref = reference_technique()
    ref_size = {n: base_setting(ref, SWEEPS[n]).value("size") if ref else None for n in ("full", "quick")}
    acc.add_argument(
        "--size",
        default=None,
        help=f"WIDTHxHEIGHT (default {full.size[0]}x{full.size[1]}; --quick {quick.size[0]}x{quick.size[1]})",
    )
    acc.add_argument(
        "--scenes",
        default=None,
        help="comma-separated scene names (bundled: `skinlab scenes`; head, "
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
    acc.add_argument(
        "--frames",
        type=int,
        default=None,
        help=f"timed frames per setting (default {full.frames}; --quick {quick.frames})",
    )
    acc.add_argument(
        "--photons",
        type=int,
        default=None,
        help=f"Monte Carlo photons per channel (default {full.photons}; --quick {quick.photons})",
    )
    acc.add_argument(
        "--exact-size",
        type=int,
        default=None,
        help=f"irradiance texels per side of the exact reference (default {ref_size['full']}; "
        f"--quick {ref_size['quick']})",
    )
    acc.add_argument("--no-peer", action="store_true", help="skip the pyrender comparison")
    acc.add_argument(
        "--blender",
        action="store_true",
        help="add Blender's EEVEE and Cycles as peer rows (bpy in a child process: `make test` or `make bench` "
        "installs it into .venv-blender)",
    )
    acc.add_argument("--no-images", action="store_true", help="do not write images/SCENE-SETTING.png")
    acc.add_argument("--no-progress", action="store_true", help="no progress bar")
    acc.set_defaults(func=run_accuracy_bench)
    st = bsub.add_parser(
        "startup",
        help="how long `skinlab render` takes to answer, phase by phase, each in a fresh process: fresh (Skinlab's "
        "and Mesa's shader caches empty), cold (Skinlab's empty, Mesa's kept) and warm (both kept)",
    )
    st.add_argument("scene", nargs="?", default=None, help="a bundled scene name or a scene/mesh file (default head)")
    st.add_argument("--size", default="64x64", help="frame size WIDTHxHEIGHT in pixels (default 64x64)")
    st.add_argument(
        "--rounds", type=int, default=3, help="rounds of fresh, cold and warm starts (default 3); medians are shown"
    )
    st.add_argument("--json", action="store_true", help="print the result as JSON")
    st.set_defaults(func=run_startup_bench)


def run_startup_bench(args) -> int:
    import sys

    from skinlab.bench.startup import report, startup_bench

    res = startup_bench(args.scene, parse_size(args.size), args.rounds, lambda m: print(m, file=sys.stderr))
    print(json.dumps(res, indent=2) if args.json else report(res))
    return 0


def blender_peer_sweep(scenes: str | None):
    """The sweep of `skinlab bench peer --blender`: the quick conditions, Skinlab's default frame with the
    image reference (its quick base setting), no scattering and the tint beside it, every reference scene."""
    from dataclasses import replace

    from skinlab.bench.accuracy import SWEEPS
    from skinlab.bench.blender_peer import default_setting
    from skinlab.bench.sweep import REFERENCE_SCENE_NAMES, Setting, base_setting, reference_technique

    quick = SWEEPS["quick"]
    ref = reference_technique()
    extra = [base_setting(ref, quick)] if ref else []
    extra += [Setting.of("none"), Setting.of("tint"), default_setting()]
    names = tuple(s.strip() for s in scenes.split(",") if s.strip()) if scenes else REFERENCE_SCENE_NAMES
    return replace(quick, name="peer", extra=tuple(x for x in extra if x is not None), every_technique=False,
                   scenes=names)  # fmt: skip


def run_peer_bench(args) -> int:
    if args.blender:
        from skinlab.bench.accuracy import resolve_scene, run_sweep

        sweep = blender_peer_sweep(args.scenes)
        for s in sweep.scenes:
            resolve_scene(s)
        cmd = "skinlab bench peer --blender" + (f" --scenes {args.scenes}" if args.scenes else "")
        cmd += (" --references" if args.references else "") + (" --cycles-truth" if args.cycles_truth else "")
        cmd += f" --out {args.out}"
        from skinlab.bench.blender_peer import PEER_SETTINGS

        blender = PEER_SETTINGS["cycles-truth"] if args.cycles_truth else True
        res = run_sweep(
            sweep,
            Path(args.out),
            peer=False,
            progress=not args.no_progress,
            command=cmd,
            references=args.references,
            blender=blender,
        )
        print("\n".join(blender_summary(res["rows"], res["meta"])))
        for f in res["files"]:
            print(f"  {Path(f).resolve()}")
        return 0 if not (res["meta"].get("blender") or {}).get("error") else 1
    res = peer_bench(parse_size(args.size), args.frames, progress=not args.no_progress, rounds=args.rounds)
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        print(
            f"{res['gl']}, {res['size'][0]}x{res['size'][1]}, median of {res['frames']} frames in "
            f"{res['rounds']} interleaved rounds (colour+depth read back on both):"
        )
        print(f"  skinlab   {res['skinlab_ms']:8.2f} ms/frame (plain PBR: sss_model none)")
        print(f"  pyrender  {res['pyrender_ms']:8.2f} ms/frame")
        rounds = ", ".join(f"{x:.2f}" for x in res["ratio_per_round"])
        print(f"  ratio skinlab/pyrender = {res['ratio_skinlab_over_pyrender']:.2f} (median of the rounds': {rounds})")
        print(
            f"  skinlab without the depth pre-pass {res['skinlab_no_prepass_ms']:8.2f} ms/frame, "
            f"ratio {res['ratio_no_prepass_over_pyrender']:.2f}"
        )
        parts = ", ".join(f"{k} {v:.1f}" for k, v in res["skinlab_passes_ms"].items())
        print(f"  skinlab plain frame per pass (ms, glFinish after each): {parts}")
        print(f"  load average {res['loadavg']}")
        print(
            f"  skinlab with the default settings (texture-space diffusion on the skin) "
            f"{res['skinlab_default_ms']:8.2f} ms/frame, ratio {res['ratio_default_over_pyrender']:.2f}"
        )
    return 0


def blender_summary(rows: list[dict], meta: dict) -> list[str]:
    from skinlab.bench.blender_peer import blender_markdown

    return blender_markdown(rows, meta) or ["the Blender peers were not run"]


def run_orbit_bench(args) -> int:
    scenes = tuple(s.strip() for s in args.scenes.split(",") if s.strip())
    res = orbit_bench(parse_size(args.size), args.frames, scenes, progress=not args.no_progress)
    if args.json:
        print(json.dumps(res, indent=2))
        return 0
    w, h = res["size"]
    print(
        f"{res['gl']}, {w}x{h}, median of {res['frames']} orbit steps after {res['warmup']} warm-up frames "
        f"(wall time + glFinish, no read-back); load average {res['loadavg_start']} -> {res['loadavg_end']} "
        f"on {res['cpu_count']} cores"
    )
    for r in res["scenes"]:
        print(f"  {r['scene']}:")
        print(f"    orbit (texture-space diffusion, reuse) {r['orbit_ms']:8.2f} ms")
        print(f"    full  (texture-space diffusion)        {r['full_ms']:8.2f} ms")
        print(f"    plain (--sss none)                     {r['plain_ms']:8.2f} ms")
        print(f"    plain with reuse (shadow map kept)     {r['plain_orbit_ms']:8.2f} ms")
        print(
            f"    orbit_over_plain {r['orbit_over_plain']:.2f}   full_over_plain {r['full_over_plain']:.2f}   "
            f"orbit_over_plain_orbit {r['orbit_over_plain_orbit']:.2f}"
        )
        print(
            f"    process CPU time: orbit {r['orbit_cpu_ms']:.1f}, full {r['full_cpu_ms']:.1f}, plain "
            f"{r['plain_cpu_ms']:.1f} ms: orbit_over_plain {r['orbit_over_plain_cpu']:.2f}   "
            f"full_over_plain {r['full_over_plain_cpu']:.2f}"
        )
        for m in ("full", "plain"):
            parts = ", ".join(f"{n} {v:.1f}" for n, v in r["passes_cpu_ms"][m].items())
            print(f"    {m} frame per pass (process CPU ms): {parts}")
        print(f"    passes run while orbiting: {', '.join(r['passes_run_while_orbiting'])}")
    return 0


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

    from skinlab.bench.accuracy import SWEEPS

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
        over["reference_values"] = (("size", args.exact_size),)  # the image reference's base setting
    if args.scenes is not None:
        names = tuple(s.strip() for s in args.scenes.split(",") if s.strip())
        if not names:
            raise ValueError("--scenes: expected a comma-separated list such as head,bunny")
        over["scenes"] = names
    return replace(sweep, **over)


def truth_console_lines(res: dict) -> list[str]:
    """What the console says about the truth: each scene measured without it, and what the ranks are then against."""
    truth = res["meta"].get("truth") or {}
    out = [
        f"  {scene}: not measured against the path-traced truth: {why}"
        for scene, why in (truth.get("missing") or {}).items()
    ]
    if truth and res["error_axis"] != "truth_rel_l1_block":
        out.append("  the ranks and recommendations are against the exact convolution, not the truth (see ledger.md)")
    return out


def run_accuracy_bench(args) -> int:
    from skinlab.bench.accuracy import resolve_scene, run_sweep

    sweep = accuracy_sweep_from_args(args)
    for s in sweep.scenes:
        resolve_scene(s)  # bad names fail before any rendering
    flags = [
        ("--quick", args.quick),
        ("--tiny", args.tiny),
        ("--no-peer", args.no_peer),
        ("--references", args.references),
        ("--blender", args.blender),
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
        blender=args.blender,
    )
    rows = res["rows"]
    for line in truth_console_lines(res):
        print(line)
    n_ok = sum(r["status"] == "ok" for r in rows)
    print(f"{res['meta']['gl']}: {len(rows)} settings ({n_ok} ok) in {res['meta']['total_s']:.1f} s")
    for r in rows:
        if r["status"] != "ok":
            print(f"  {r['scene']}: {r['setting']}: {r['status']}: {r['error']}")
    for f in res["files"]:
        print(f"  {Path(f).resolve()}")
    return 0
