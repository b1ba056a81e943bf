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
import dataclasses
import json
import math
from pathlib import Path

from skinlab.bench.orbit import SCENES as ORBIT_SCENES
from skinlab.bench.orbit import orbit_bench
from skinlab.bench.peer import peer_bench
from skinlab.bench.reload import reload_bench
from skinlab.commands.field_options import IMAGE_SIZE, add_command_options, check_command_options, own_default
from skinlab.declare import Field
from skinlab.render.settings import RenderSettings, parse_size

JSON = Field("json", "bool", False, doc="print the result as JSON")
NO_PROGRESS = Field("no_progress", "bool", False, doc="no progress bar on stderr")


def _own_size(default: str) -> Field:
    return own_default(IMAGE_SIZE, default, f"this benchmark's own default (a render's is {IMAGE_SIZE.default})")


def peer_options() -> tuple[Field, ...]:
    from skinlab.bench.peer import PEER_FIELDS

    return (
        _own_size("512x512"),
        PEER_FIELDS["frames"],
        PEER_FIELDS["rounds"],
        JSON,
        NO_PROGRESS,
        Field(
            "blender",
            "bool",
            False,
            doc="instead: Blender's EEVEE and Cycles beside Skinlab's default frame on the reference scenes, "
            "against the path-traced truth, in one ledger run (--quick sizes; writes the ledger to --out; see "
            "docs/ledger.md)",
        ),
        Field("out", "string", "out/peer-blender", doc="with --blender: the ledger's folder"),
        Field("scenes", "string", doc="with --blender: comma-separated scene names", shown="every reference scene"),
        Field("references", "bool", False, doc="with --blender: path-trace the references not cached yet"),
        Field(
            "cycles_truth",
            "bool",
            False,
            doc="with --blender: Cycles at 1024 spp (random walk and random walk skin) as a second truth against "
            "Mitsuba's, instead of the EEVEE/Cycles frame-time rows (docs/ground-truth.md)",
        ),
    )


def orbit_options() -> tuple[Field, ...]:
    from skinlab.bench.orbit import ORBIT_FRAMES

    scenes = Field(
        "scenes",
        "string",
        ",".join(ORBIT_SCENES),
        doc=f"comma-separated scene names, from {', '.join(ORBIT_SCENES)}",
    )
    return (IMAGE_SIZE, ORBIT_FRAMES, scenes, JSON, NO_PROGRESS)


def reload_options() -> tuple[Field, ...]:
    """The benchmark's own parameters (skinlab/bench/reload.py) and the two render settings its frames
    use, from their declarations, with this benchmark's own (smaller) defaults, said in their help."""
    from skinlab.bench.reload import RELOAD_FIELDS, RELOAD_SHADOW_SIZE, RELOAD_TSD_SIZE
    from skinlab.render.registry import get_technique

    shadow = RenderSettings.fields()["shadow_size"]
    tsd = dataclasses.replace(get_technique("tsd").settings_type.options()["size"], name="tsd_size")
    quick = "so that a frame after an edit is quick"
    return (
        _own_size("128x128"),
        RELOAD_FIELDS["repeats"],
        RELOAD_FIELDS["file"],
        RELOAD_FIELDS["settle"],
        own_default(
            shadow,
            RELOAD_SHADOW_SIZE,
            f"this benchmark's own default, smaller than a render's {shadow.default} {quick}",
        ),  # fmt: skip
        own_default(
            tsd,
            RELOAD_TSD_SIZE,
            f"texture-space diffusion's; this benchmark's own default, smaller than a render's {tsd.default} {quick}",
        ),  # fmt: skip
        RELOAD_FIELDS["mode"],
        RELOAD_FIELDS["timeout"],
        Field("json", "bool", False, doc="print the result as JSON (every sample)"),
    )


def accuracy_options() -> tuple[Field, ...]:
    """The ledger's options; the defaults the sweeps hold (skinlab/bench/accuracy.py SWEEPS) are stated
    in their help."""
    from skinlab.bench.accuracy import SWEEPS
    from skinlab.bench.sweep import base_setting, reference_technique
    from skinlab.render.registry import get_technique
    from skinlab.scene.optics.montecarlo import WALK_FIELDS

    full, quick = SWEEPS["full"], SWEEPS["quick"]
    ref = reference_technique()
    ref_size = {n: base_setting(ref, SWEEPS[n]).value("size") if ref else None for n in ("full", "quick")}
    both = lambda a, b: f"{a}; --quick {b}"  # noqa: E731
    sizes = (full.size, quick.size)
    exact = get_technique(ref).settings_type.options()["size"] if ref else Field("size", "int", None, (16, 8192))
    exact = dataclasses.replace(exact, name="exact_size")
    return (
        Field(
            "out",
            "string",
            doc="output folder (ledger.csv, ledger.md, ledger.html, ledger.json, pareto.png, cost.png, profiles.png, "
            "error_maps/, flip_maps/, images/, mc_cache/)",
        ),
        Field("quick", "bool", False, doc="a subset at 160x160 (a few minutes at most on 2 cores)"),
        own_default(IMAGE_SIZE, None, "each sweep's own default", shown=both(*(f"{w}x{h}" for w, h in sizes))),
        Field(
            "scenes",
            "string",
            doc="comma-separated scene names (bundled: `skinlab scenes`; head, bunny) or .toml paths",
            shown="every reference scene; --quick head-skin1-matched, bunny-skimmilk, slab-edge-skin1",
        ),
        Field(
            "references",
            "bool",
            False,
            doc="path-trace the scenes' references that are not cached yet (skinlab reference; minutes per scene "
            "on 2 cores: full 192x192 at 1024 spp, --quick 96x96 at 256 spp, or a scene's own [measure] truth_size, "
            "truth_spp and truth_rr_depth); without it a scene whose reference "
            "is not cached is measured without the truth",
        ),
        Field(
            "frames", "int", None, (1, math.inf), doc="timed frames per setting", shown=both(full.frames, quick.frames)
        ),  # fmt: skip
        dataclasses.replace(
            WALK_FIELDS["photons"],
            default=None,
            doc="Monte Carlo photons per channel",
            shown=both(full.photons, quick.photons),
        ),  # fmt: skip
        own_default(exact, None, "of the exact reference", shown=both(ref_size["full"], ref_size["quick"])),
        Field("no_peer", "bool", False, doc="skip the pyrender comparison"),
        Field(
            "blender",
            "bool",
            False,
            doc="add Blender's EEVEE and Cycles as peer rows (bpy in a child process: `make test` or `make bench` "
            "installs it into .venv-blender)",
        ),
        Field("no_images", "bool", False, doc="do not write images/SCENE-SETTING.png"),
        Field("no_progress", "bool", False, doc="no progress bar"),
    )


def startup_options() -> tuple[Field, ...]:
    from skinlab.bench.startup import STARTUP_ROUNDS

    return (_own_size("64x64"), STARTUP_ROUNDS, JSON)


def register(sub) -> None:
    p = sub.add_parser("bench", help="benchmarks (timings are printed, never asserted)")
    bsub = p.add_subparsers(dest="bench", metavar="BENCH")
    bsub.required = True
    peer = bsub.add_parser("peer", help="Skinlab vs pyrender on the same head, size and EGL context kind")
    add_command_options(peer, peer_options())
    peer.set_defaults(func=run_peer_bench)
    orb = bsub.add_parser(
        "orbit",
        help="frame time while the camera orbits the head and the bunny: with reuse across frames (as the viewer), "
        "without, and the plain frame (--sss none), in one run",
    )
    add_command_options(orb, orbit_options())
    orb.set_defaults(func=run_orbit_bench)
    rel = bsub.add_parser(
        "reload",
        help="shader hot reload: time from saving a file to the first frame rendered with the new program (headless)",
    )
    add_command_options(rel, reload_options())
    rel.set_defaults(func=run_reload_bench)
    acc = bsub.add_parser(
        "accuracy",
        help="accuracy/time ledger: every SSS technique and setting timed and compared with the "
        "path-traced truth, the exact convolution and the Monte Carlo profile",
    )
    add_command_options(acc, accuracy_options(), required=("out",))
    acc.add_argument("--tiny", action="store_true", help=argparse.SUPPRESS)  # tests: 4 settings, head, 64x64
    acc.set_defaults(func=run_accuracy_bench)
    st = bsub.add_parser(
        "startup",
        help="how long `skinlab render` takes to answer, phase by phase, each in a fresh process: fresh (Skinlab's "
        "and Mesa's shader caches empty), cold (Skinlab's empty, Mesa's kept) and warm (both kept)",
    )
    st.add_argument("scene", nargs="?", default=None, help="a bundled scene name or a scene/mesh file (default head)")
    add_command_options(st, startup_options())
    st.set_defaults(func=run_startup_bench)


def run_startup_bench(args) -> int:
    import sys

    from skinlab.bench.startup import report, startup_bench

    check_command_options(args, startup_options())
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
    check_command_options(args, peer_options())
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
    check_command_options(args, orbit_options())
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
    check_command_options(args, reload_options())
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
    check_command_options(args, accuracy_options())
    if args.frames is not None:
        over["frames"] = args.frames
    if args.photons is not None:
        over["photons"] = args.photons
    if args.exact_size is not None:
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
