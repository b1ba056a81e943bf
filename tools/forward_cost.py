"""Where the plain frame's time goes (the frame `skinlab bench peer` times against pyrender): the head
with sss_model none and no shadow-casting light, rendered with one part of
skinlab/shaders/passes/forward.frag taken out or one texture setting changed, the variants interleaved
round by round so that a change of machine load hits all alike. Whole frames with the colour+depth
read-back, as the peer bench times them. The variants are measurements only (copies of shaders/
under a temporary folder); none of them is what the renderer runs.

    .venv/bin/python -m tools.forward_cost [--size 640] [--rounds 7]

Variants: base (as shipped), aniso1 (the maps filtered without anisotropy), no_maps (no colour or
normal map fetches), no_prepass (RenderSettings.depth_prepass off), raster_only (the interpolated
inputs written out: rasterising, the pre-pass, tone mapping and the read-back), and the
differences of aniso1 from base in the HDR image.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

FWD = "passes/forward.frag"
EDITS = {
    "no_maps": [
        (FWD, "#ifdef HAS_NORMAL_MAP\n    n = perturb", "#if 0\n    n = perturb"),
        (FWD, "#ifdef HAS_BASE_COLOR_MAP\n    base *=", "#if 0\n    base *="),
    ],
    "raster_only": [
        (
            FWD,
            "void main() {",
            "void main() { f_color = vec4(v_world + v_normal + v_tangent.xyz + vec3(v_uv, 0.0), 1.0); return;",
        )
    ],
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (default 7)")
    args = ap.parse_args(argv)
    from skinlab.bench.shader_variants import edited_shader_root
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.shader_source import ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    ctx = create_headless_context()
    scene = load_scene(None)
    for light in scene.lights():
        light.cast_shadow = False  # as the peer bench
    n = args.size
    plain = RenderSettings(n, n, sss_model="none")
    tmp = Path(tempfile.mkdtemp(prefix="skinlab-forward-cost-"))
    runs = {}

    def renderer(name, edits=()):
        r = Renderer(ctx, ShaderLibrary(root=edited_shader_root(tmp / name, name, edits)))
        r.reuse = False
        r.timer.sync = False
        return r

    try:
        runs["base"] = (renderer("base"), plain)
        r = renderer("aniso1")
        r.render(scene, plain, readback=False)
        for t in r.resources.textures.values():
            t.anisotropy = 1.0
        runs["aniso1"] = (r, plain)
        runs["no_maps"] = (renderer("no_maps", EDITS["no_maps"]), plain)
        runs["no_prepass"] = (renderer("no_prepass"), RenderSettings(n, n, sss_model="none", depth_prepass=False))
        runs["raster_only"] = (renderer("raster_only", EDITS["raster_only"]), plain)
        hdr = {k: r.render(scene, st, readback=("hdr",)).hdr for k, (r, st) in runs.items()}
        load0 = os.getloadavg()
        times = {k: [] for k in runs}
        for _ in range(args.rounds):
            for name, (r, st) in runs.items():
                ctx.finish()
                t0 = time.perf_counter()
                r.render(scene, st, readback=("ldr", "depth"))
                times[name].append((time.perf_counter() - t0) * 1e3)
        print(f"{describe(ctx)}; plain frame {n}x{n} (sss_model none, no shadows), median of {args.rounds}")
        print(f"load average {tuple(round(x, 2) for x in load0)} -> {tuple(round(x, 2) for x in os.getloadavg())}")
        base = statistics.median(times["base"])
        for name, v in times.items():
            m = statistics.median(v)
            print(f"  {name:<12} {m:8.1f} ms  ({m / base:5.0%} of base)")
        d = np.abs(hdr["aniso1"][..., :3] - hdr["base"][..., :3])
        print(
            f"aniso1 vs base, HDR: max |difference| {d.max():.4f}, mean {d.mean():.2e} "
            f"(frame max {hdr['base'].max():.3f})"
        )
    finally:
        for r, _ in runs.values():
            r.release()
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
