"""A one-off analysis, not a feature: where the orbiting frame's forward pass spends its time beyond the
plain frame's (issue 27: orbiting <= 1.1x plain). While the camera orbits only the forward pass and tone
mapping run (texture-space diffusion's irradiance and blurs are reused); this times the forward pass alone
of the default frame (reuse on, every other pass run once before), with one part of
skinlab/shaders/passes/forward.frag or of the texture-space hook (techniques/tsd/forward.glsl) taken out at
a time, beside the plain frame's forward pass (sss none, no interreflection), the variants interleaved
round by round so that a change of machine load hits all alike. Process CPU time (every thread's: the
rasteriser's own work), glFinish before and after.

    .venv/bin/python -m tools.orbit_cost [--size 640] [--rounds 9] [--scene SCENE] [--technique NAME]

Variants: base (as shipped), plain (the plain frame's forward pass), no_bounce (the default frame with
no interreflection: the forward pass without its bounce light), and measurement defines the shaders
read (``MEASURE_...``, set through ShaderLibrary.defines in a renderer of its own; none is what the
renderer runs): no_single (MEASURE_NO_SINGLE: no single scattering per light or for ambient light),
no_add_light (MEASURE_NO_ADD_LIGHT: the hook told of no light, with its entry shadow and near gain),
no_sss_radiance (MEASURE_NO_SSS_RADIANCE: the hook's radiance left out: gather, exit, light through),
no_gather (MEASURE_NO_GATHER: the irradiance and its levels not fetched), no_exit (MEASURE_NO_EXIT: the
exit table not read), no_through (MEASURE_NO_THROUGH: the exit factor of light through thin parts
left out), far_single (MEASURE_FAR_SINGLE: single scattering without its near-light factor),
no_ms_rest (MEASURE_NO_MS_REST: the separable boundary's rest not read, whatever u_sss_ms_rest_on),
no_plain_diffuse (MEASURE_NO_PLAIN_DIFFUSE: no Burley diffuse per light, whatever its weight),
slab_const_index (MEASURE_SLAB_CONST_INDEX: the slab exit's tables read at fixed rows: the same
arithmetic without per-fragment indices into uniform arrays), slab_view_only (MEASURE_SLAB_VIEW_ONLY:
of the slab exit only the half that depends on the view: the other's table reads replaced),
slab_no_log (MEASURE_SLAB_NO_LOG: the slab exit's thickness node found without log2 or exp2).

--technique NAME: the forward pass of that technique's frame at its defaults instead of the default frame's
(the measurement defines are the texture-space hook's: with another technique only base, plain, no_bounce
and --against are timed).

--against DIR[,DIR...]: also the forward pass with the shaders of another checkout (DIR/skinlab/shaders,
e.g. ``git archive main skinlab | tar -x -C DIR``; the same Python code drives them), interleaved: what a
change of the shaders saved; its image is compared with this checkout's (max and mean relative
difference of the HDR radiance where it is above 1e-3 of the frame's peak).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import time

FWD = "passes/forward.frag"
MEASURES = {
    "no_single": {"MEASURE_NO_SINGLE": 1},
    "no_add_light": {"MEASURE_NO_ADD_LIGHT": 1},
    "no_sss_radiance": {"MEASURE_NO_SSS_RADIANCE": 1},
    "no_gather": {"MEASURE_NO_GATHER": 1},
    "no_exit": {"MEASURE_NO_EXIT": 1},
    "no_through": {"MEASURE_NO_THROUGH": 1},
    "far_single": {"MEASURE_FAR_SINGLE": 1},
    "no_ms_rest": {"MEASURE_NO_MS_REST": 1},
    "slab_const_index": {"MEASURE_SLAB_CONST_INDEX": 1},
    "slab_view_only": {"MEASURE_SLAB_VIEW_ONLY": 1},
    "slab_no_log": {"MEASURE_SLAB_NO_LOG": 1},
    "no_plain_diffuse": {"MEASURE_NO_PLAIN_DIFFUSE": 1},
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.orbit_cost", description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=9, help="timed rounds (default 9)")
    ap.add_argument("--scene", default=None, help="scene name or file (default: the head)")
    ap.add_argument("--against", default=None, help="comma-separated checkouts whose shaders to time beside")
    ap.add_argument("--only", default=None, help="comma-separated variants to time (default: all)")
    ap.add_argument(
        "--technique", default=None, help="the technique whose frame to time (default: the default frame's)"
    )
    args = ap.parse_args(argv)
    from pathlib import Path

    import numpy as np

    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.shader_source import ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.render.technique import HOOK_INCLUDE
    from skinlab.scene.scenefile import load_scene

    from .cost_variants import load_line, measure_library

    ctx = create_headless_context()
    scene = load_scene(args.scene)
    n = args.size
    full = RenderSettings.for_technique(args.technique, n, n) if args.technique else RenderSettings(n, n)
    tsd = full.technique_name in ("tsd", "exact")
    plain = RenderSettings(n, n, sss_model="none", bounces=0)
    probe = Renderer(ctx)
    probe.render(scene, full, readback=False)
    variants = {  # the tsd hook and its variant defines of the frame's forward programs
        (dict(aliases).get(HOOK_INCLUDE), defines)
        for (_, frag, defines, aliases) in probe.programs.entries
        if frag == FWD and "tsd" in str(dict(aliases).get(HOOK_INCLUDE))
    }
    probe.release()
    if tsd and not variants:
        raise SystemExit("no texture-space forward program in the frame")
    # the group of triangles that reads every slot's light through thin parts, where the mesh is drawn in groups
    hook, hook_defines = min(variants, key=lambda v: int("TSD_THROUGH_READ" in dict(v[1]))) if tsd else (None, ())
    runs = {}

    def add(name, settings, measure=None, library=None):
        if measure:
            library = measure_library(FWD, measure, str(hook), dict(hook_defines))
        r = Renderer(ctx, library) if library is not None else Renderer(ctx)
        r.reuse = True
        for _ in range(2):
            res = r.render(scene, settings, readback=False)
        fwd = next(p for p in res.plan.passes if p.kind == "forward")
        assert r.last_frame is not None  # set by the render
        runs[name] = (r, r.last_frame, fwd)

    wanted = set(args.only.split(",")) if args.only else None
    try:
        no_bounce = dataclasses.replace(full, bounces=0)
        for name, settings in (("base", full), ("plain", plain), ("no_bounce", no_bounce)):
            if wanted is None or name in wanted or name == "base":
                add(name, settings)
        for name, d in MEASURES.items():
            if tsd and (wanted is None or name in wanted):
                add(name, full, d)
        for i, d in enumerate(args.against.split(",") if args.against else ()):
            root = Path(d) / "skinlab" / "shaders"
            if not root.is_dir():
                raise SystemExit(f"--against: no shaders under {root}")
            add(f"against{i}", full, library=ShaderLibrary(root=root))
        load0 = os.getloadavg()
        times: dict[str, list[float]] = {k: [] for k in runs}
        for _ in range(args.rounds):
            for name, (r, frame, fwd) in runs.items():
                ctx.finish()
                c0 = time.process_time()
                r.pass_for("forward").run(frame, fwd)
                ctx.finish()
                times[name].append((time.process_time() - c0) * 1e3)
        print(f"{describe(ctx)}; the forward pass of the orbiting frame, {n}x{n}, process CPU, median of {args.rounds}")
        drawn = f"{len(variants)} texture-space variant(s) drawn"
        print(f"technique {full.technique_name}; hook {hook}, defines {dict(hook_defines)} ({drawn})")
        print(load_line(load0))
        base = statistics.median(times["base"])
        for name, v in times.items():
            m = statistics.median(v)
            print(f"  {name:<16} {m:8.1f} ms  ({m / base:5.0%} of base, {m - base:+7.1f} ms)")
        ours = runs["base"][0].render(scene, full, readback=("hdr",)).hdr[..., :3]
        for i, d in enumerate(args.against.split(",") if args.against else ()):
            theirs = runs[f"against{i}"][0].render(scene, full, readback=("hdr",)).hdr[..., :3]
            lit = np.abs(theirs) > 1e-3 * float(np.abs(theirs).max())
            rel = np.abs(ours - theirs)[lit] / np.abs(theirs)[lit]
            print(
                f"  against{i} = {d}: HDR relative difference max {rel.max():.3g}, mean {rel.mean():.3g}, "
                f"absolute max {np.abs(ours - theirs).max():.3g}"
            )
    finally:
        for r, *_ in runs.values():
            r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
