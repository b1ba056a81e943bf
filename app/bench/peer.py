"""Skinlab against pyrender on the same head, size and EGL context kind (`skinlab bench peer`)."""

from __future__ import annotations

import os
import statistics
import sys
import time

from tqdm import tqdm

from app.render.settings import RenderSettings


def _loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def peer_bench(size=(512, 512), frames: int = 30, progress: bool = False) -> dict:
    """Median frame times, both including the colour+depth read-back (pyrender always reads back).
    ``skinlab_ms`` is the plain-PBR frame (sss_model none, like pyrender's: no subsurface scattering);
    ``skinlab_default_ms`` the frame with the default RenderSettings (the head's skin scatters, so
    texture-space diffusion runs); ``skinlab_no_prepass_ms`` the plain frame without the depth
    pre-pass; ``skinlab_passes_ms`` where the plain frame's time goes (glFinish after each pass; "readback":
    reading colour and depth back, as pyrender does)."""
    from app.bench.pyrender_peer import run_peer
    from app.gl.context import create_headless_context, describe
    from app.render.renderer import Renderer
    from scene.scenefile import load_scene

    if frames < 1:
        raise ValueError(f"--frames: expected >= 1, got {frames}")
    scene = load_scene(None)
    # plain PBR on both sides: no shadow map (pyrender's directional light casts none by default)
    for light in scene.lights():
        light.cast_shadow = False
    w, h = size
    ctx = create_headless_context()
    r = Renderer(ctx)
    r.timer.sync = False  # no glFinish between passes: whole frames are timed here
    r.reuse = False  # full frames (skinlab bench orbit times frames that reuse)

    # frames (with 2 warm-ups) of three Skinlab settings, then pyrender's in one subprocess (one step)
    bar = tqdm(total=3 * (frames + 2) + 1, desc="bench peer", unit="frame", file=sys.stderr, disable=not progress)

    def timed(settings, what):
        bar.set_postfix_str(what)
        r.render(scene, settings)
        r.render(scene, settings)
        bar.update(2)
        out = []
        for _ in range(frames):
            t0 = time.perf_counter()
            r.render(scene, settings, readback=("ldr", "depth"))  # what pyrender reads back
            out.append((time.perf_counter() - t0) * 1e3)
            bar.update()
        return out

    try:
        plain = RenderSettings(w, h, sss_model="none")
        ours = timed(plain, "skinlab plain PBR")
        ours_no_prepass = timed(RenderSettings(w, h, sss_model="none", depth_prepass=False), "skinlab no pre-pass")
        ours_default = timed(RenderSettings(w, h), "skinlab default")
        # where the plain frame's time goes: glFinish after each pass, then the read-back alone
        r.timer.sync = True
        per: dict[str, list[float]] = {"readback": []}
        for _ in range(max(3, min(frames, 7))):
            for p in r.render(scene, plain, readback=False).timings.passes:
                per.setdefault(p.name, []).append(p.cpu_ms)
            t0 = time.perf_counter()
            r.read_targets(r.last_frame, ("ldr", "depth"))
            per["readback"].append((time.perf_counter() - t0) * 1e3)
    finally:
        r.release()
    bar.set_postfix_str("pyrender (subprocess)")
    cam = scene.camera
    meshes = [(str(n.mesh.source), n.world_matrix) for n in scene.mesh_nodes()]
    peer = run_peer(meshes, cam.world_matrix, cam.yfov, cam.znear, cam.zfar, size, frames=frames)
    bar.update()
    bar.close()
    theirs = list(map(float, peer["times"]))
    mo, mt = statistics.median(ours), statistics.median(theirs)
    md = statistics.median(ours_default)
    mn = statistics.median(ours_no_prepass)
    return {
        "size": [w, h],
        "frames": frames,
        "gl": describe(ctx),
        "skinlab_ms": mo,
        "pyrender_ms": mt,
        "ratio_skinlab_over_pyrender": mo / mt,
        "skinlab_no_prepass_ms": mn,
        "ratio_no_prepass_over_pyrender": mn / mt,
        "skinlab_passes_ms": {k: statistics.median(v) for k, v in per.items()},
        "loadavg": _loadavg(),
        "skinlab_default_ms": md,
        "ratio_default_over_pyrender": md / mt,
    }
