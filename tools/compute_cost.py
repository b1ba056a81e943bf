"""Each pass's fragment path against its compute path (RenderSettings.compute, skinlab/render/compute.py)
on whatever GL the machine has: two renderers, compute off and on, frames alternating so that a change
of machine load hits both alike, every pass run (no reuse) with glFinish after each; per pass the
median process CPU time (every thread's: on software GL the rasteriser's own work, which a loaded
machine inflates less than wall time) and, on a GPU, the median timer-query time.

    .venv/bin/python -m tools.compute_cost [--scene head] [--technique tsd] [--size 640] [--rounds 5]
                                           [--tsd-size N]

Prints one line per pass: fragment, compute, compute / fragment. Passes without a compute variant run
the same code in both frames: their ratio shows the noise of the run."""

from __future__ import annotations

import argparse
import os
import statistics
import sys


def main(argv=None) -> int:
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", default="head")
    ap.add_argument("--technique", default="tsd")
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--tsd-size", type=int, default=None, help="texels of a texture-space technique")
    args = ap.parse_args(argv)
    ctx = create_headless_context()
    scene = load_scene(args.scene)
    extra = {"size": args.tsd_size} if args.tsd_size else {}
    modes = {
        c: RenderSettings.for_technique(args.technique, args.size, args.size, compute=c, **extra) for c in ("off", "on")
    }
    renderers = {}
    for c, st in modes.items():
        r = renderers[c] = Renderer(ctx)
        r.reuse = False
        r.render(scene, st, readback=False)  # compiles, uploads
    cpu = {c: {} for c in modes}
    gpu = {c: {} for c in modes}
    paths = {}
    load0 = os.getloadavg()
    for _ in range(args.rounds):
        for c, st in modes.items():
            res = renderers[c].render(scene, st, readback=False)
            for p in res.timings.passes:
                cpu[c].setdefault(p.name, []).append(p.process_ms)
                if p.gpu_ms is not None and not res.timings.software_gl:
                    gpu[c].setdefault(p.name, []).append(p.gpu_ms)
            if c == "on":
                paths = {p.name: "; compute shader" in p.reason for p in res.plan.passes}
    print(f"{describe(ctx)}; {args.scene}, {args.technique} {extra or ''} at {args.size}^2, median of {args.rounds}")
    print(f"load average {tuple(round(x, 2) for x in load0)} -> {tuple(round(x, 2) for x in os.getloadavg())}")
    print("process CPU ms per pass (GPU ms where timer queries see the work): fragment, compute, compute / fragment")
    for name, v in cpu["off"].items():
        a, b = statistics.median(v), statistics.median(cpu["on"][name])
        g = ""
        if gpu["off"].get(name) and gpu["on"].get(name):
            ga, gb = statistics.median(gpu["off"][name]), statistics.median(gpu["on"][name])
            g = f"   GPU {ga:8.3f} {gb:8.3f} {gb / ga:5.2f}"
        mark = "compute" if paths.get(name) else "same code"
        print(f"  {name:32s} {a:8.1f} {b:8.1f} {b / a:5.2f}  ({mark}){g}")
    for r in renderers.values():
        r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
