"""Per-technique frame times with and without reuse, and each pass's GPU time (timer queries), on
whatever GL the machine has: the figures for a real GPU in README.md ("Measured") came from this on a
lent H100 (see docs/interreflection.md for how to carry the project there).

    python tools/frame_times.py [--size 1920x1080] [--frames 15] [--warmup-s 10] [--out times.json]

For each scene (the head, the skim-milk bunny) and setting: the median wall time of `frames` frames of
`Renderer.render(readback=False)` + glFinish, with every pass run (reuse off) and as an orbiting viewer
renders (reuse on: the camera does not move, so only camera-dependent passes run), and the median GPU
time per pass. The first ``warmup_s`` seconds render texture-space diffusion frames so that a GPU's
clocks are up before anything is timed."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

SETTINGS = (
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


def main(argv: list[str]) -> int:
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings, parse_size
    from skinlab.scene.interreflection import build_transfer, clear_cache
    from skinlab.scene.scenefile import load_scene

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", default="1920x1080")
    p.add_argument("--frames", type=int, default=15)
    p.add_argument("--warmup-s", type=float, default=10.0)
    p.add_argument("--out", default="")
    args = p.parse_args(argv)
    w, h = parse_size(args.size)
    ctx = create_headless_context()
    r = Renderer(ctx)
    out = {"gl": describe(ctx), "size": [w, h], "loadavg": list(os.getloadavg()), "results": []}
    print(out["gl"], flush=True)
    for name in ("head", "bunny-skimmilk"):
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
        for tech, extra in SETTINGS:
            for reuse in (False, True):
                r.reuse = reuse
                st = RenderSettings.for_technique(tech, w, h, **extra)
                n = max(3, args.frames // 5) if tech == "exact" else args.frames
                for _ in range(2):
                    r.render(s, st, readback=False)
                times, passes = [], {}
                for _ in range(n):
                    t1 = time.perf_counter()
                    res = r.render(s, st, readback=False)
                    ctx.finish()
                    times.append((time.perf_counter() - t1) * 1e3)
                    for k, v in res.timings.as_dict()["passes"].items():
                        if v.get("gpu_ms") is not None:
                            passes.setdefault(k, []).append(v["gpu_ms"])
                row = {
                    "scene": Path(name).stem,
                    "technique": tech,
                    "settings": extra,
                    "reuse": reuse,
                    "frame_ms": float(np.median(times)),
                    "passes_gpu_ms": {k: float(np.median(v)) for k, v in passes.items()},
                    "interreflection_ray_cast_s": cast_s,
                }
                out["results"].append(row)
                gpu = sum(row["passes_gpu_ms"].values())
                print(
                    f"{row['scene']:15s} {tech:13s} {json.dumps(extra):16s} {'reuse' if reuse else 'full':5s} "
                    f"{row['frame_ms']:8.2f} ms  GPU {gpu:7.2f} ms",
                    flush=True,
                )
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
