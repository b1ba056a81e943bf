"""Where the texture-space irradiance pass's time goes: the pass on the head at the default settings,
run again with one part of skinlab/shaders/techniques/tsd/irradiance.frag (or of lib/shadow.glsl) taken out,
the variants interleaved round by round so that a change of machine load hits all alike; the
forward pass of the same frame beside it. The variants are measurements only (copies of shaders/
under a temporary folder); none of them is what the renderer runs.

    .venv/bin/python -m tools.irradiance_cost [--size 640] [--rounds 7] [--scene PATH]
    .venv/bin/python -m tools.irradiance_cost --coverage [--rounds 9]
    .venv/bin/python -m tools.irradiance_cost --against 9f5625f [--rounds 7]

--against REV[,REV...]: the pass as shipped against the shaders/ of git revisions (the same Python
code drives them; a revision without techniques/tsd/through_fill.frag gets today's), interleaved: what a
change of the shaders saved.

--coverage: the pass on a square whose UVs cover 100 %, 25 %, 6.25 % and 1 % of a 512x512 layout
(tests/tsd_scenes.py slab_scene), interleaved: the time follows the covered texels (the pass
rasterises the mesh's triangles in UV space; texels no triangle covers are only cleared).

With translucency, the pass ends with the fill of its light-through record's gutter (across UV seams
and one ring past the other chart borders, skinlab/render/techniques/tsd/passes.py through_fill); that
fill is also timed alone, interleaved, and printed as its part of the base pass.

Variants: base (as shipped), pcf_1tap (one shadow
compare instead of the 3x3 PCF), no_translucency, no_maps (no normal, colour or occlusion map
fetches), raster_only (the interpolated inputs written out: the cost of rasterising the UV layout).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

IRR = "techniques/tsd/irradiance.frag"
VARIANTS = {
    "base": [],
    "pcf_1tap": [
        (
            "lib/shadow.glsl",
            "for (int y = -1; y <= 1; ++y)\n        for (int x = -1; x <= 1; ++x)\n"
            "            sum += texture(map, vec3(c.xy + vec2(x, y) * texel, c.z - bias));\n    return sum / 9.0;",
            "return texture(map, vec3(c.xy, c.z - bias));",
        )
    ],
    "no_translucency": [(IRR, "#ifdef TSD_TRANSLUCENCY\n    float back", "#if 0\n    float back")],
    "no_maps": [
        (IRR, "#ifdef HAS_NORMAL_MAP\n    n = perturb", "#if 0\n    n = perturb"),
        (IRR, "#ifdef HAS_BASE_COLOR_MAP\n    base *=", "#if 0\n    base *="),
        (IRR, "#ifdef HAS_OCCLUSION_MAP\n    occlusion =", "#if 0\n    occlusion ="),
    ],
    "raster_only": [
        (
            IRR,
            "void main() {",
            "void main() { f_irradiance = vec4(v_world + v_normal + v_tangent.xyz + vec3(v_uv, 0.0), 1.0); return;",
        )
    ],
}


def coverage(rounds: int) -> int:
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from tests.tsd_scenes import quad_mesh, skin, slab_scene

    ctx = create_headless_context()
    runs = {}
    for side in (1.0, 0.5, 0.25, 0.1):
        mesh = quad_mesh("slab", -1, 1, -1, 1, uv=((0, 0), (side, side)))
        scene = slab_scene(mesh=mesh, material=skin(), occluder=True)
        r = Renderer(ctx)
        r.reuse = False
        res = r.render(scene, RenderSettings.for_technique("tsd", 64, 64, size=512, shadow_size=1024), readback=False)
        runs[side] = (r, r.last_frame, next(p for p in res.plan.passes if p.kind == "tsd_irradiance"))
    load0 = os.getloadavg()
    times = {k: [] for k in runs}
    for _ in range(rounds):
        for side, (r, frame, irr) in runs.items():
            ctx.finish()
            t0 = time.perf_counter()
            r.pass_for("tsd_irradiance").run(frame, irr)
            ctx.finish()
            times[side].append((time.perf_counter() - t0) * 1e3)
    print(f"{describe(ctx)}; tsd_irradiance 512x512 texels on a square, median of {rounds}")
    print(f"load average {tuple(round(x, 2) for x in load0)} -> {tuple(round(x, 2) for x in os.getloadavg())}")
    for side, v in times.items():
        print(f"  UV area {side * side:7.2%} of the layout: {statistics.median(v):7.2f} ms")
    for r, *_ in runs.values():
        r.release()
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (default 7)")
    ap.add_argument("--scene", default=None, help="scene file (default: the head)")
    ap.add_argument("--coverage", action="store_true", help="the pass's time against the UV area covered")
    ap.add_argument("--against", default=None, help="comma-separated git revisions whose shaders/ to time instead")
    args = ap.parse_args(argv)
    if args.coverage:
        return coverage(args.rounds)
    from skinlab.bench.shader_variants import edited_shader_root
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.shader_source import SHADER_ROOT, ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    ctx = create_headless_context()
    scene = load_scene(args.scene)
    st = RenderSettings(args.size, args.size)
    tmp = Path(tempfile.mkdtemp(prefix="skinlab-irradiance-cost-"))
    runs = {}
    try:
        variants = VARIANTS
        if args.against:
            variants = {"base": []} | {rev: None for rev in args.against.split(",")}
        for name, edits in variants.items():
            root = tmp / name
            if edits is None:  # a revision's shaders
                root.mkdir()
                repo = SHADER_ROOT.parent
                archive = subprocess.run(
                    ["git", "-C", str(repo), "archive", name, "shaders"], capture_output=True, check=False
                )
                if archive.returncode != 0:
                    raise SystemExit(f"--against: git archive {name} failed: {archive.stderr.decode().strip()}")
                subprocess.run(["tar", "-x", "-C", str(root)], input=archive.stdout, check=True)
                root, edits = root / "shaders", []
                fill = "techniques/tsd/through_fill.frag"  # (older revisions: the pass ends with today's record fill)
                if not (root / fill).exists() and (SHADER_ROOT / fill).exists():
                    shutil.copy(SHADER_ROOT / fill, root / fill)
            else:
                edited_shader_root(root, name, edits)
            r = Renderer(ctx, ShaderLibrary(root=root))
            r.reuse = False
            res = r.render(scene, st, readback=False)
            irr = next(p for p in res.plan.passes if p.kind == "tsd_irradiance")
            fwd = next(p for p in res.plan.passes if p.kind == "forward")
            runs[name] = (r, r.last_frame, irr, fwd)
        from skinlab.render.lights import SHADOW_SLOTS
        from skinlab.render.techniques.tsd.passes import store, through_fill
        from skinlab.render.techniques.tsd.seams import node_border_strips

        base_irr = runs["base"][2]
        fill_times = []
        load0 = os.getloadavg()
        times = {k: [] for k in runs}
        fwd_times = []
        for _ in range(args.rounds):
            if base_irr.params.translucency:  # the record's fill alone (the base pass runs it last)
                r = runs["base"][0]
                t = store(r).targets(base_irr.params.node, base_irr.params.size)
                ctx.finish()
                t0 = time.perf_counter()
                prm = base_irr.params
                slots = min(len(prm.shadow_lights), SHADOW_SLOTS)
                through_fill(r, t, prm.seams is not None, node_border_strips(prm.node.mesh, prm.size), slots)
                ctx.finish()
                fill_times.append((time.perf_counter() - t0) * 1e3)
            for name, (r, frame, irr, _fwd) in runs.items():
                ctx.finish()
                t0 = time.perf_counter()
                r.pass_for("tsd_irradiance").run(frame, irr)
                ctx.finish()
                times[name].append((time.perf_counter() - t0) * 1e3)
            r, frame, irr, fwd = runs["base"]
            ctx.finish()
            t0 = time.perf_counter()
            r.pass_for("forward").run(frame, fwd)
            ctx.finish()
            fwd_times.append((time.perf_counter() - t0) * 1e3)
        texels = irr.resolution[0] * irr.resolution[1]
        r, frame, irr, _ = runs["base"]
        raw = np.frombuffer(frame.targets[f"tsd_irradiance_raw[{irr.params.node.name}]"].read(), np.float32)
        covered = float((raw.reshape(-1, 4)[:, 3] > 0).mean())
        print(f"{describe(ctx)}; {irr.name} {irr.resolution[0]}x{irr.resolution[1]} texels, frame {args.size}^2")
        print(f"texels covered by a triangle: {covered:.1%} (the pass rasterises triangles: only those are shaded)")
        print(f"load average {tuple(round(x, 2) for x in load0)} -> {tuple(round(x, 2) for x in os.getloadavg())}")
        base = statistics.median(times["base"])
        for name, v in times.items():
            m = statistics.median(v)
            print(f"  {name:<16} {m:8.1f} ms  ({m / base:5.0%} of base; {m * 1e6 / texels:6.0f} ns per texel)")
        if fill_times:
            m = statistics.median(fill_times)
            print(f"  of which the light-through record's fill {m:5.1f} ms  ({m / base:5.1%} of base)")
        f = statistics.median(fwd_times)
        print(f"  forward pass     {f:8.1f} ms  ({f * 1e6 / args.size**2:6.0f} ns per pixel)")
    finally:
        for r, *_ in runs.values():
            r.release()
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
