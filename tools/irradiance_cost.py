"""A one-off analysis, not a feature: where the texture-space irradiance pass's time goes: the pass on
the head at the default settings, run again with one part of skinlab/shaders/techniques/tsd/irradiance.frag
(or of lib/shadow.glsl) taken out, the variants interleaved round by round so that a change of machine
load hits all alike; the forward pass of the same frame beside it. Each variant is declared where it
lives: a technique option, the scene's materials, or a measurement define the shaders read
(``MEASURE_...``, set through ShaderLibrary.defines in a renderer of its own); none of them is what the
renderer runs.

    .venv/bin/python -m tools.irradiance_cost [--size 640] [--rounds 7] [--scene SCENE] [--tsd-size N]
    .venv/bin/python -m tools.irradiance_cost --coverage [--rounds 9]
    .venv/bin/python -m tools.irradiance_cost --against 9f5625f [--rounds 7]

--against REV[,REV...]: the pass as shipped against the shaders of git revisions (the same Python
code drives them; a revision without techniques/tsd/through_fill.frag gets today's), interleaved: what a
change of the shaders saved.

--coverage: the pass on the slab of reference/slab-edge-skin1 with the slab and its UVs shrunk alike
(the same millimetres per texel) so that they cover less and less of a 512x512 layout (the fraction
covered measured from the pass's coverage),
interleaved: the time follows the covered texels (the pass rasterises the mesh's triangles in UV
space; texels no triangle covers are only cleared).

With translucency, the pass ends with the fill of its light-through record's gutter (across UV seams
and one ring past the other chart borders, skinlab/render/techniques/tsd/passes.py through_fill); that
fill is also timed alone, interleaved, and printed as its part of the base pass.

Variants: base (as shipped), pcf_1tap (lib/shadow.glsl's MEASURE_PCF_1TAP: one shadow compare
instead of the 3x3 PCF), no_translucency (tsd's translucency option off: no light through thin parts,
no record to fill), no_maps (the materials without their normal, colour and occlusion maps),
raster_only (irradiance.frag's MEASURE_RASTER_ONLY: the interpolated inputs written out, the cost of
rasterising the UV layout).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

IRR = "techniques/tsd/irradiance.frag"
MAPS = ("normal_map", "base_color_map", "occlusion_map")
MEASURES = {"pcf_1tap": {"MEASURE_PCF_1TAP": 1}, "raster_only": {"MEASURE_RASTER_ONLY": 1}}
SLAB = "reference/slab-edge-skin1"


def irradiance_pass(res):
    """The frame's texture-space irradiance pass; SystemExit where the plan has none (say why)."""
    for p in res.plan.passes:
        if p.kind == "tsd_irradiance":
            return p
    raise SystemExit("no texture-space irradiance pass in the frame (more texels?):\n" + res.plan.explain())


def covered(renderer, irr) -> float:
    """The fraction of the pass's texels a triangle covers (the coverage of its raw irradiance)."""
    from skinlab.render.techniques.tsd.passes import store

    raw = np.frombuffer(store(renderer).targets(irr.params.node, irr.params.size).raw.read(), np.float32)
    return float((raw.reshape(-1, 4)[:, 3] > 0).mean())


def coverage(rounds: int, sides=(1.0, 0.5, 0.25, 0.1), size: int = 512) -> int:
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.mesh import Mesh
    from skinlab.scene.scenefile import load_scene

    from .cost_variants import finished_ms, load_line

    ctx = create_headless_context()
    runs = {}
    for side in sides:
        scene = load_scene(SLAB)
        for node in scene.mesh_nodes():
            if node.material["subsurface"] > 0:  # the slab and its UV layout shrunk alike (same mm per texel)
                m, k = node.mesh, np.float32(side)
                node.mesh = Mesh(m.name, m.positions * k, m.indices, m.normals, m.uvs * k, source=m.source)
        r = Renderer(ctx)
        r.reuse = False
        st = RenderSettings.for_technique("tsd", 64, 64, size=size, shadow_size=1024)
        res = r.render(scene, st, readback=False)
        irr = irradiance_pass(res)
        runs[side] = (r, r.last_frame, irr, covered(r, irr))
    load0 = os.getloadavg()
    times: dict[float, list[float]] = {k: [] for k in runs}
    for _ in range(rounds):
        for side, (r, frame, irr, _) in runs.items():
            times[side].append(finished_ms(ctx, r.pass_for("tsd_irradiance").run, frame, irr))
    print(f"{describe(ctx)}; tsd_irradiance {size}x{size} texels on the slab of {SLAB}, median of {rounds}")
    print(load_line(load0))
    for side, v in times.items():
        print(f"  UVs x {side:4g}: {runs[side][3]:7.2%} of the layout covered: {statistics.median(v):7.2f} ms")
    for r, *_ in runs.values():
        r.release()
    return 0


def revision_shaders(rev: str, into: Path) -> Path:
    """The shader folder of git revision `rev`, extracted under `into` (skinlab/shaders, or shaders/ of
    revisions from before the package layout); today's record fill where the revision has none."""
    from skinlab.gl.shader_source import SHADER_ROOT

    repo = SHADER_ROOT.parents[1]
    into.mkdir(parents=True)
    for folder in ("skinlab/shaders", "shaders"):
        archive = subprocess.run(["git", "-C", str(repo), "archive", rev, folder], capture_output=True, check=False)
        if archive.returncode == 0:
            break
    else:
        raise SystemExit(f"--against: git archive {rev} failed: {archive.stderr.decode().strip()}")
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive.stdout, check=True)
    root = into / folder
    fill = "techniques/tsd/through_fill.frag"  # (older revisions: the pass ends with today's record fill)
    if not (root / fill).exists() and (SHADER_ROOT / fill).exists():
        (root / fill).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(SHADER_ROOT / fill, root / fill)
    return root


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.irradiance_cost", description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (default 7)")
    ap.add_argument("--scene", default=None, help="scene name or file (default: the head)")
    ap.add_argument("--tsd-size", type=int, default=None, help="texels per side (default: tsd's)")
    ap.add_argument("--coverage", action="store_true", help="the pass's time against the UV area covered")
    ap.add_argument("--against", default=None, help="comma-separated git revisions whose shaders to time instead")
    args = ap.parse_args(argv)
    if args.coverage:
        return coverage(args.rounds, size=args.tsd_size or 512)
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.shader_source import ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    from .cost_variants import finished_ms, load_line, measure_library, without_maps

    ctx = create_headless_context()
    scene = load_scene(args.scene)
    own = {} if args.tsd_size is None else {"size": args.tsd_size}
    st = RenderSettings.for_technique("tsd", args.size, args.size, **own)
    tmp = Path(tempfile.mkdtemp(prefix="skinlab-irradiance-cost-"))
    runs = {}
    try:
        variants = {"base": (ShaderLibrary(), st, scene)}
        if args.against:
            for rev in args.against.split(","):
                variants[rev] = (ShaderLibrary(root=revision_shaders(rev, tmp / rev)), st, scene)
        else:
            variants["pcf_1tap"] = (measure_library(IRR, MEASURES["pcf_1tap"]), st, scene)
            off = RenderSettings.for_technique("tsd", args.size, args.size, translucency=False, **own)
            variants["no_translucency"] = (ShaderLibrary(), off, scene)
            variants["no_maps"] = (ShaderLibrary(), st, without_maps(load_scene(args.scene), MAPS))
            variants["raster_only"] = (measure_library(IRR, MEASURES["raster_only"]), st, scene)
        for name, (library, settings, sc) in variants.items():
            r = Renderer(ctx, library)
            r.reuse = False
            res = r.render(sc, settings, readback=False)
            fwd = next(p for p in res.plan.passes if p.kind == "forward")
            runs[name] = (r, r.last_frame, irradiance_pass(res), fwd)
        from skinlab.render.lights import SHADOW_SLOTS
        from skinlab.render.techniques.tsd.passes import store, through_fill
        from skinlab.render.techniques.tsd.seams import node_border_strips

        base_irr = runs["base"][2]
        fill_times = []
        load0 = os.getloadavg()
        times: dict[str, list[float]] = {k: [] for k in runs}
        fwd_times = []
        for _ in range(args.rounds):
            if base_irr.params.translucency:  # the record's fill alone (the base pass runs it last)
                r = runs["base"][0]
                t = store(r).targets(base_irr.params.node, base_irr.params.size)
                prm = base_irr.params
                slots = min(len(prm.shadow_lights), SHADOW_SLOTS)
                strips = node_border_strips(prm.node.mesh, prm.size)
                fill_times.append(finished_ms(ctx, through_fill, r, t, prm.seams is not None, strips, slots))
            for name, (r, frame, irr, _fwd) in runs.items():
                times[name].append(finished_ms(ctx, r.pass_for("tsd_irradiance").run, frame, irr))
            r, frame, irr, fwd = runs["base"]
            fwd_times.append(finished_ms(ctx, r.pass_for("forward").run, frame, fwd))
        r, frame, irr, _ = runs["base"]
        texels = irr.resolution[0] * irr.resolution[1]
        print(f"{describe(ctx)}; {irr.name} {irr.resolution[0]}x{irr.resolution[1]} texels, frame {args.size}^2")
        share = covered(r, irr)
        print(f"texels covered by a triangle: {share:.1%} (the pass rasterises triangles: only those are shaded)")
        print(load_line(load0))
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
