"""`skinlab bench orbit`: what a frame costs while a person orbits the camera (the viewer's most
common action), with reuse across frames, without it, and the plain frame, in one run.

Per scene (the head, the bunny and the head under the studio HDR map by default), the camera circles
the scene's centre at its own
distance and height; after warm-up frames, every step of the path renders three frames, one per
renderer, interleaved so that a change of machine load hits all three alike:

- ``orbit``: the default settings (texture-space diffusion) with reuse on, as the viewer renders: the
  shadow maps and texture-space passes keep their results, forward shading and tone mapping run;
- ``full``: the same frame with reuse off (every pass runs every frame);
- ``plain``: the plain frame (``--sss none --bounces 0``: no subsurface scattering, no interreflection), reuse off;
- ``plain_orbit``: the plain frame with reuse on (its shadow map is kept).

Frame time is wall time of ``render(readback=False)`` followed by ``glFinish`` (the viewer reads
nothing back). The medians and the ratios ``orbit_over_plain`` and ``full_over_plain`` are reported
with the load average, since the machine may be shared. Beside them, the same from the process's CPU
time over each frame (``*_cpu_ms``, ``*_over_plain_cpu``: every thread's, so on software GL the
rasteriser's own work), which a machine loaded by other jobs inflates far less than the wall time;
and per pass, one frame of each of ``full`` and ``plain`` with glFinish after every pass (wall and CPU).
"""

from __future__ import annotations

import math
import os
import statistics
import time

import numpy as np

from skinlab.bench.machine_load import load_average
from skinlab.declare import Field
from skinlab.render.settings import RenderSettings
from skinlab.resources import scenes_root

ASSETS = scenes_root()
SCENES = {"head": None, "bunny": ASSETS / "bunny-skimmilk.toml", "head-studio": ASSETS / "head-studio.toml"}
# timed steps over one turn (checked here; `skinlab bench orbit --frames`)
ORBIT_FRAMES = Field(
    "frames", "int", 24, (1, math.inf), doc="timed camera steps per scene over one full turn, after 2 warm-up frames"
)
MODES = ("orbit", "full", "plain", "plain_orbit")
WARMUP = 2


def orbit_path(camera, centre: np.ndarray, steps: int):
    """Camera poses (eye, target) circling `centre` about the world's up axis, one full turn."""
    offset = camera.world_position - centre
    for i in range(steps):
        a = 2.0 * math.pi * i / max(steps, 1)
        c, s = math.cos(a), math.sin(a)
        rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
        yield centre + rot @ offset, centre


def orbit_scene(name: str, path, size, frames: int, ctx, progress=None) -> dict:
    from skinlab.render.renderer import Renderer
    from skinlab.scene.scenefile import load_scene

    scene = load_scene(path)
    w, h = size
    renderers = {m: Renderer(ctx) for m in MODES}
    settings = {
        "orbit": RenderSettings(w, h),
        "full": RenderSettings(w, h),
        "plain": RenderSettings(w, h, sss_model="none", bounces=0),
        "plain_orbit": RenderSettings(w, h, sss_model="none", bounces=0),
    }
    for m, r in renderers.items():
        r.timer.sync = False  # whole frames are timed
        r.reuse = m in ("orbit", "plain_orbit")
    lo, hi = scene.world_bounds()
    cam = scene.camera
    times: dict[str, list[float]] = {m: [] for m in MODES}
    cpu: dict[str, list[float]] = {m: [] for m in MODES}
    ran: dict[str, set] = {m: set() for m in MODES}
    try:
        start_eye = cam.world_position
        for _ in range(WARMUP):  # compiles, uploads, the kept results of the first pose
            for m in MODES:
                renderers[m].render(scene, settings[m], readback=False)
        for eye, target in orbit_path(cam, (lo + hi) / 2, frames):
            cam.look_at(eye, target)
            for m in MODES:
                c0, t0 = time.process_time(), time.perf_counter()
                res = renderers[m].render(scene, settings[m], readback=False)
                ctx.finish()
                times[m].append((time.perf_counter() - t0) * 1e3)
                cpu[m].append((time.process_time() - c0) * 1e3)
                ran[m].update(res.plan.ran())
            if progress is not None:
                progress.update(1)
        cam.look_at(start_eye, (lo + hi) / 2)
        # one frame per mode with glFinish after each pass: where the time goes
        breakdown, breakdown_cpu = {}, {}
        for m in ("full", "plain"):
            r = renderers[m]
            r.timer.sync = True
            res = r.render(scene, settings[m], readback=False)
            breakdown[m] = {p.name: round(p.cpu_ms, 2) for p in res.timings.passes}
            breakdown_cpu[m] = {p.name: round(p.process_ms, 2) for p in res.timings.passes}
    finally:
        for r in renderers.values():
            r.release()
    med = {m: statistics.median(v) for m, v in times.items()}
    med_cpu = {m: statistics.median(v) for m, v in cpu.items()}
    return {
        "scene": name,
        "frames": frames,
        **{f"{m}_ms": med[m] for m in MODES},
        "orbit_over_plain": med["orbit"] / med["plain"],
        "full_over_plain": med["full"] / med["plain"],
        "orbit_over_plain_orbit": med["orbit"] / med["plain_orbit"],
        **{f"{m}_cpu_ms": med_cpu[m] for m in MODES},
        "orbit_over_plain_cpu": med_cpu["orbit"] / med_cpu["plain"],
        "full_over_plain_cpu": med_cpu["full"] / med_cpu["plain"],
        "passes_run_while_orbiting": sorted(ran["orbit"], key=lambda n: (n != "forward", n)),
        "passes_ms": breakdown,
        "passes_cpu_ms": breakdown_cpu,
    }


def orbit_bench(
    size=(640, 640), frames: int = 24, scenes=("head", "bunny", "head-studio"), progress: bool = True
) -> dict:
    from tqdm import tqdm

    from skinlab.gl.context import create_headless_context, describe

    ORBIT_FRAMES.check(frames, "--frames")
    unknown = [s for s in scenes if s not in SCENES]
    if unknown:
        raise ValueError(f"--scenes: expected names from {', '.join(SCENES)}, got {unknown[0]!r}")
    ctx = create_headless_context()
    load_start = load_average()
    t0 = time.perf_counter()
    rows = []
    with tqdm(total=frames * len(scenes), desc="orbit", unit="step", disable=not progress) as bar:
        for s in scenes:
            bar.set_postfix_str(s)
            rows.append(orbit_scene(s, SCENES[s], size, frames, ctx, bar))
    return {
        "size": list(size),
        "frames": frames,
        "warmup": WARMUP,
        "gl": describe(ctx),
        "cpu_count": os.cpu_count(),
        "loadavg_start": load_start,
        "loadavg_end": load_average(),
        "total_s": round(time.perf_counter() - t0, 1),
        "scenes": rows,
    }
