"""A one-off measurement, not a feature: per-technique frame times with and without reuse, and each pass's
GPU time (timer queries), on whatever GL the machine has, for the fragment and the compute path of every
pass that has both (RenderSettings.compute, skinlab/render/compute.py): the figures for a real GPU in
README.md ("Measured") came from this on a lent H100 (see docs/interreflection.md for how to carry the
project there).

    python -m tools.frame_times [--size 1920x1080] [--frames 15] [--warmup-s 10] [--compute off,on]
                                [--scenes head,bunny-skimmilk] [--techniques tsd,ssss] [--out times.json]

For each scene (the head, the skim-milk bunny), setting and compute mode (`off`: fragment shaders,
`on`: compute shaders wherever the context has them, `auto`: the planner's choice): the median wall
time of `frames` frames of `Renderer.render(readback=False)` + glFinish, with every pass run (reuse
off) and as an orbiting viewer renders (reuse on: the camera does not move, so only camera-dependent
passes run), the median GPU time per pass (timer queries) and, with glFinish after every pass, each
pass's process CPU time (what the passes cost on software GL, where timer queries see nothing). At
the end, per pass, fragment against compute side by side. The first ``warmup_s`` seconds render
texture-space diffusion frames so that a GPU's clocks are up before anything is timed."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

SETTINGS: tuple[tuple[str, dict], ...] = (
    ("none", {"bounces": 0}),
    ("none", {}),
    ("tsd", {"bounces": 0}),
    ("tsd", {}),
    ("tsd", {"size": 1024}),
    ("ssss", {}),
    ("disk", {}),
    ("preintegrated", {}),
    ("exact", {}),
)


def main(argv: list[str] | None = None) -> int:
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings, parse_size
    from skinlab.scene.interreflection import build_transfer, clear_cache
    from skinlab.scene.scenefile import load_scene

    p = argparse.ArgumentParser(prog="python -m tools.frame_times", description=__doc__.split("\n\n")[0])
    p.add_argument("--size", default="1920x1080")
    p.add_argument("--frames", type=int, default=15)
    p.add_argument("--warmup-s", type=float, default=10.0)
    p.add_argument("--compute", default="off,on", help="comma-separated RenderSettings.compute modes (off, on, auto)")
    p.add_argument("--scenes", default="head,bunny-skimmilk", help="comma-separated bundled scenes")
    p.add_argument("--techniques", default="", help="comma-separated techniques (default: every setting below)")
    p.add_argument("--out", default="")
    args = p.parse_args(argv)
    modes = [m.strip() for m in args.compute.split(",") if m.strip()]
    bad = [m for m in modes if m not in ("off", "on", "auto")]
    if bad or not modes:
        p.error(f"--compute: expected modes from off, on, auto, got {args.compute!r}")
    wanted = {t.strip() for t in args.techniques.split(",") if t.strip()}
    settings = [s for s in SETTINGS if not wanted or s[0] in wanted]
    w, h = parse_size(args.size)
    ctx = create_headless_context()
    r = Renderer(ctx)
    results: list[dict] = []
    out: dict[str, object] = {"gl": describe(ctx), "size": [w, h], "loadavg": list(os.getloadavg()), "results": results}
    print(out["gl"], flush=True)
    for name in [x.strip() for x in args.scenes.split(",") if x.strip()]:
        s = load_scene(name)
        clear_cache()
        t0 = time.perf_counter()
        build_transfer(s.mesh_nodes(), RenderSettings().bounce_rays)
        cast_s = time.perf_counter() - t0
        r.reuse = False
        warm = RenderSettings.for_technique("tsd", w, h)
        end = time.perf_counter() + args.warmup_s
        while time.perf_counter() < end:
            r.render(s, warm, readback=False)
        for tech, extra in settings:
            for mode in modes:
                for reuse in (False, True):
                    results.append(time_setting(ctx, r, s, name, tech, extra, mode, reuse, w, h, args.frames))
                    results[-1]["interreflection_ray_cast_s"] = cast_s
    out["fragment_vs_compute"] = compare_paths(results)
    if args.out:
        from skinlab.atomic_write import write_text_atomic

        write_text_atomic(Path(args.out), json.dumps(out, indent=1))
    return 0


def time_setting(ctx, r, s, name, tech, extra, mode, reuse, w, h, frames) -> dict:
    """One setting's frames: the median frame time, GPU time per pass; then one frame with glFinish
    after every pass for each pass's process CPU time."""
    from skinlab.render.settings import RenderSettings

    r.reuse = reuse
    st = RenderSettings.for_technique(tech, w, h, compute=mode, **extra)
    n = max(3, frames // 5) if tech == "exact" else frames
    r.timer.sync = False  # whole frames are timed; the GPU timer queries time the passes
    for _ in range(2):
        r.render(s, st, readback=False)
    times: list[float] = []
    passes: dict[str, list[float]] = {}
    for _ in range(n):
        t1 = time.perf_counter()
        res = r.render(s, st, readback=False)
        ctx.finish()
        times.append((time.perf_counter() - t1) * 1e3)
        for k, v in res.timings.as_dict()["passes"].items():
            if v.get("gpu_ms") is not None:
                passes.setdefault(k, []).append(v["gpu_ms"])
    r.timer.sync = True
    synced = r.render(s, st, readback=False)
    row = {
        "scene": Path(name).stem,
        "technique": tech,
        "settings": extra,
        "compute": mode,
        "reuse": reuse,
        "frame_ms": float(np.median(times)),
        "passes_gpu_ms": {k: float(np.median(v)) for k, v in passes.items()},
        "passes_cpu_ms": {p.name: p.process_ms for p in synced.timings.passes},
        "paths": {p.name: ("compute" if "; compute shader" in p.reason else "fragment") for p in synced.plan.passes},
    }
    gpu = sum(row["passes_gpu_ms"].values())
    print(
        f"{row['scene']:15s} {tech:13s} {json.dumps(extra):16s} compute {mode:4s} {'reuse' if reuse else 'full':5s} "
        f"{row['frame_ms']:8.2f} ms  GPU {gpu:7.2f} ms",
        flush=True,
    )
    return row


def compare_paths(rows: list[dict]) -> list[dict]:
    """Per (scene, technique, settings, pass) that ran as a fragment pass with compute off and as a compute
    pass with compute on (frames without reuse): both GPU times (None on software GL) and process CPU times."""
    key = lambda r: (r["scene"], r["technique"], json.dumps(r["settings"]))  # noqa: E731
    full = [r for r in rows if not r["reuse"]]
    off = {key(r): r for r in full if r["compute"] == "off"}
    out = []
    for r in full:
        base = off.get(key(r)) if r["compute"] == "on" else None
        if base is None:
            continue
        for name, path in r["paths"].items():
            if path != "compute" or name not in base["passes_cpu_ms"]:
                continue
            out.append(
                {
                    "scene": r["scene"],
                    "technique": r["technique"],
                    "settings": r["settings"],
                    "pass": name,
                    "fragment_gpu_ms": base["passes_gpu_ms"].get(name),
                    "compute_gpu_ms": r["passes_gpu_ms"].get(name),
                    "fragment_cpu_ms": base["passes_cpu_ms"][name],
                    "compute_cpu_ms": r["passes_cpu_ms"].get(name),
                }
            )
    if out:
        print("per pass, fragment against compute (GPU ms; process CPU ms):")
        fmt = lambda v: f"{v:8.3f}" if v is not None else "     n/a"  # noqa: E731
        for c in out:
            print(
                f"  {c['scene']:15s} {c['technique']:8s} {c['pass']:30s} GPU {fmt(c['fragment_gpu_ms'])} -> "
                f"{fmt(c['compute_gpu_ms'])}   CPU {fmt(c['fragment_cpu_ms'])} -> {fmt(c['compute_cpu_ms'])}"
            )
    return out


if __name__ == "__main__":
    sys.exit(main())
