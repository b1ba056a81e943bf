"""Skinlab against pyrender on the same head, size and EGL context kind (`skinlab bench peer`)."""

from __future__ import annotations

import math
import statistics
import sys
import time

from tqdm import tqdm

from skinlab.bench.machine_load import load_average
from skinlab.declare import Field
from skinlab.render.settings import RenderSettings

# the benchmark's counts, declared once (checked here; `skinlab bench peer`'s options)
PEER_FIELDS = {
    f.name: f
    for f in (
        Field("frames", "int", 30, (1, math.inf), doc="timed frames per renderer, after 2 warm-up frames"),
        Field(
            "rounds",
            "int",
            3,
            (1, math.inf),
            doc="rounds the frames are split into, each timing Skinlab's settings then pyrender's, so that a "
            "change of machine load hits both alike; the ratio is the median of the rounds'",
        ),
    )
}


def peer_bench(size=(512, 512), frames: int = 30, progress: bool = False, rounds: int = 3) -> dict:
    """Median frame times, both including the colour+depth read-back (pyrender always reads back),
    interleaved: `rounds` rounds, each timing its share of the `frames` of every Skinlab setting and
    then as many of pyrender's (kept alive in a child process), so that a change of machine load
    hits both alike; ``ratio_skinlab_over_pyrender`` is the median of the rounds' ratios.
    ``skinlab_ms`` is the plain-PBR frame (sss_model none and bounces 0, like pyrender's: no subsurface
    scattering, no interreflection);
    ``skinlab_default_ms`` the frame with the default RenderSettings (the head's skin scatters, so
    texture-space diffusion runs); ``skinlab_no_prepass_ms`` the plain frame without the depth
    pre-pass; ``skinlab_passes_ms`` where the plain frame's time goes (glFinish after each pass; "readback":
    reading colour and depth back, as pyrender does)."""
    from skinlab.bench.pyrender_peer import PeerSession
    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.renderer import Renderer
    from skinlab.scene.scenefile import load_scene

    PEER_FIELDS["frames"].check(frames, "--frames")
    PEER_FIELDS["rounds"].check(rounds, "--rounds")
    rounds = min(rounds, frames)
    share = [frames // rounds + (1 if i < frames % rounds else 0) for i in range(rounds)]
    scene = load_scene(None)
    # plain PBR on both sides: no shadow map (pyrender's directional light casts none by default)
    for light in scene.lights():
        light.cast_shadow = False
    w, h = size
    cam = scene.camera
    meshes = [(str(n.mesh.source), n.world_matrix) for n in scene.mesh_nodes()]
    ctx = create_headless_context()
    r = Renderer(ctx)
    r.timer.sync = False  # no glFinish between passes: whole frames are timed here
    r.reuse = False  # full frames (skinlab bench orbit times frames that reuse)
    settings = {
        "plain": RenderSettings(w, h, sss_model="none", bounces=0),
        "no_prepass": RenderSettings(w, h, sss_model="none", bounces=0, depth_prepass=False),
        "default": RenderSettings(w, h),
    }
    # 2 warm-up frames per Skinlab setting, then per round: its frames of each setting and pyrender's
    bar = tqdm(
        total=2 * len(settings) + 4 * frames, desc="bench peer", unit="frame", file=sys.stderr, disable=not progress
    )
    times = {k: [] for k in (*settings, "pyrender")}
    per_round = []
    try:
        for what, st in settings.items():
            bar.set_postfix_str(f"skinlab {what} (warm-up)")
            r.render(scene, st)
            r.render(scene, st)
            bar.update(2)
        bar.set_postfix_str("pyrender (child process starting)")
        with PeerSession(meshes, cam.world_matrix, cam.yfov, cam.znear, cam.zfar, size) as peer:
            for n in share:
                got = {}
                for what, st in settings.items():
                    bar.set_postfix_str(f"skinlab {what}")
                    got[what] = []
                    for _ in range(n):
                        t0 = time.perf_counter()
                        r.render(scene, st, readback=("ldr", "depth"))  # what pyrender reads back
                        got[what].append((time.perf_counter() - t0) * 1e3)
                        bar.update()
                bar.set_postfix_str("pyrender")
                got["pyrender"] = peer.time_frames(n)
                bar.update(n)
                for k, v in got.items():
                    times[k] += v
                per_round.append(statistics.median(got["plain"]) / statistics.median(got["pyrender"]))
        # where the plain frame's time goes: glFinish after each pass, then the read-back alone
        r.timer.sync = True
        per: dict[str, list[float]] = {"readback": []}
        for _ in range(max(3, min(frames, 7))):
            for p in r.render(scene, settings["plain"], readback=False).timings.passes:
                per.setdefault(p.name, []).append(p.cpu_ms)
            t0 = time.perf_counter()
            r.read_targets(r.last_frame, ("ldr", "depth"))
            per["readback"].append((time.perf_counter() - t0) * 1e3)
    finally:
        r.release()
        bar.close()
    med = {k: statistics.median(v) for k, v in times.items()}
    mt = med["pyrender"]
    return {
        "size": [w, h],
        "frames": frames,
        "rounds": rounds,
        "gl": describe(ctx),
        "skinlab_ms": med["plain"],
        "pyrender_ms": mt,
        "ratio_skinlab_over_pyrender": statistics.median(per_round),
        "ratio_per_round": per_round,
        "skinlab_no_prepass_ms": med["no_prepass"],
        "ratio_no_prepass_over_pyrender": med["no_prepass"] / mt,
        "skinlab_passes_ms": {k: statistics.median(v) for k, v in per.items()},
        "loadavg": load_average(),
        "skinlab_default_ms": med["default"],
        "ratio_default_over_pyrender": med["default"] / mt,
    }
