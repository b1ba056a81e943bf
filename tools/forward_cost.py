"""A one-off analysis, not a feature: where the plain frame's time goes (the frame `skinlab bench peer`
times against pyrender): the head with sss_model none and no shadow-casting light, rendered with one
part of skinlab/shaders/passes/forward.frag taken out or one texture setting changed, the variants
interleaved round by round so that a change of machine load hits all alike. Whole frames with the
colour+depth read-back, as the peer bench times them. Each variant is declared where it lives: a
render setting, the scene's materials, or a measurement define the shader reads (``MEASURE_...``,
set through ShaderLibrary.defines in a renderer of its own); none of them is what the renderer runs.

    .venv/bin/python -m tools.forward_cost [--size 640] [--rounds 7] [--scene SCENE] [--translucency TECHNIQUE]

With ``--translucency TECHNIQUE`` (a technique whose forward hook adds the light through thin parts:
ssss, disk, preintegrated) it times that technique's forward pass alone instead (the head as shipped,
its shadows and distance maps drawn once), with the translucency off (the technique's own setting)
and with one part of lib/sss_translucency.glsl taken out: no_thickness (MEASURE_NO_THICKNESS: no
distance-map or part-layer lookup, 3 mm everywhere), no_slab_through (MEASURE_NO_SLAB_THROUGH: the
slab transmittance's table not read), no_slab_exit (MEASURE_NO_SLAB_EXIT: the exit factor of light
that came through not read) and all three.

Variants: base (as shipped), aniso1 (the maps filtered without anisotropy), no_maps (the materials
without their colour, normal and occlusion maps), no_prepass (RenderSettings.depth_prepass off),
raster_only (forward.frag's MEASURE_RASTER_ONLY: the interpolated inputs written out: rasterising,
the pre-pass, tone mapping and the read-back), and the differences of aniso1 from base in the HDR
image.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

FWD = "passes/forward.frag"
MAPS = ("base_color_map", "normal_map")
TRANSLUCENCY_PARTS = {
    "no_thickness": {"MEASURE_NO_THICKNESS": 1},
    "no_slab_through": {"MEASURE_NO_SLAB_THROUGH": 1},
    "no_slab_exit": {"MEASURE_NO_SLAB_EXIT": 1},
}


def translucency_cost(technique: str, size: int, rounds: int, scene_name: str | None) -> int:
    """The forward pass of `technique` alone, with its translucency and without parts of it (the module's doc)."""
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.options import technique_settings
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.render.technique import HOOK_INCLUDE
    from skinlab.render.translucency import DEFINE
    from skinlab.scene.scenefile import load_scene

    from .cost_variants import finished_ms, load_line, measure_library, print_medians

    if "translucency" not in technique_settings(technique).options():
        raise SystemExit(f"--translucency: {technique!r} has no translucency setting")
    parts = dict(TRANSLUCENCY_PARTS)
    parts["all_three"] = {k: v for d in TRANSLUCENCY_PARTS.values() for k, v in d.items()}
    ctx = create_headless_context()
    scene = load_scene(scene_name)
    on = RenderSettings.for_technique(technique, size, size)
    off = RenderSettings.for_technique(technique, size, size, translucency=False)
    variants: dict[str, tuple[dict | None, RenderSettings]] = {"base": (None, on), "off": (None, off)}
    variants.update({k: (d, on) for k, d in parts.items()})
    runs = {}
    try:
        probe = Renderer(ctx)
        probe.render(scene, on, readback=False)
        hooks = {  # the hook of each forward program compiled with the translucency
            dict(aliases).get(HOOK_INCLUDE)
            for (_, frag, defines, aliases) in probe.programs.entries
            if frag == FWD and DEFINE in dict(defines)
        }
        probe.release()
        if len(hooks) != 1 or None in hooks:
            raise SystemExit(
                f"--translucency: {technique}'s forward pass adds no light through thin parts here "
                "(a technique whose forward hook does: ssss, disk, preintegrated; a scene with a shadow-casting light)"
            )
        hook = str(hooks.pop())
        for name, (defines, st) in variants.items():
            lib = measure_library(FWD, defines, hook, {DEFINE: 1}) if defines else None
            r = Renderer(ctx, lib) if lib is not None else Renderer(ctx)
            r.reuse = False
            res = r.render(scene, st, readback=False)
            fwd = next(p for p in res.plan.passes if p.kind == "forward")
            runs[name] = (r, r.last_frame, fwd)
        load0 = os.getloadavg()
        times: dict[str, list[float]] = {k: [] for k in runs}
        for _ in range(rounds):
            for name, (r, frame, fwd) in runs.items():
                times[name].append(finished_ms(ctx, r.pass_for("forward").run, frame, fwd))
        print(f"{describe(ctx)}; the forward pass of {technique} alone, {size}x{size}, median of {rounds}")
        print(load_line(load0))
        print_medians(times, 16)
    finally:
        for r, *_ in runs.values():
            r.release()
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.forward_cost", description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (default 7)")
    ap.add_argument("--scene", default=None, help="scene name or file (default: the head)")
    ap.add_argument(
        "--translucency",
        default=None,
        metavar="TECHNIQUE",
        help="time TECHNIQUE's forward pass and the parts of its translucency",
    )
    args = ap.parse_args(argv)
    if args.translucency:
        return translucency_cost(args.translucency, args.size, args.rounds, args.scene)
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.shader_source import ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    from .cost_variants import load_line, measure_library, print_medians, without_maps

    def scene_without_shadows(maps=True):
        scene = load_scene(args.scene)
        for light in scene.lights():
            light.cast_shadow = False  # as the peer bench
        return scene if maps else without_maps(scene, MAPS)

    ctx = create_headless_context()
    scene = scene_without_shadows()
    n = args.size
    plain = RenderSettings(n, n, sss_model="none")
    runs = {}

    def renderer(measure: dict | None = None) -> Renderer:
        r = Renderer(ctx, measure_library(FWD, measure) if measure else ShaderLibrary())
        r.reuse = False
        r.timer.sync = False
        return r

    try:
        runs["base"] = (renderer(), plain, scene)
        r = renderer()
        r.render(scene, plain, readback=False)
        for t in r.resources.textures.values():
            t.anisotropy = 1.0
        runs["aniso1"] = (r, plain, scene)
        runs["no_maps"] = (renderer(), plain, scene_without_shadows(maps=False))
        runs["no_prepass"] = (renderer(), RenderSettings(n, n, sss_model="none", depth_prepass=False), scene)
        runs["raster_only"] = (renderer({"MEASURE_RASTER_ONLY": 1}), plain, scene)
        hdr = {k: r.render(sc, st, readback=("hdr",)).hdr for k, (r, st, sc) in runs.items()}
        load0 = os.getloadavg()
        times: dict[str, list[float]] = {k: [] for k in runs}
        for _ in range(args.rounds):
            for name, (r, st, sc) in runs.items():
                ctx.finish()
                t0 = time.perf_counter()
                r.render(sc, st, readback=("ldr", "depth"))
                times[name].append((time.perf_counter() - t0) * 1e3)
        print(f"{describe(ctx)}; plain frame {n}x{n} (sss_model none, no shadows), median of {args.rounds}")
        print(load_line(load0))
        print_medians(times, 12)
        d = np.abs(hdr["aniso1"][..., :3] - hdr["base"][..., :3])
        print(
            f"aniso1 vs base, HDR: max |difference| {d.max():.4f}, mean {d.mean():.2e} "
            f"(frame max {hdr['base'].max():.3f})"
        )
    finally:
        for r, *_ in runs.values():
            r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
