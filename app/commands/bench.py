"""`skinlab bench peer`: our plain-PBR frame time against pyrender's, same scene, size and EGL."""
from __future__ import annotations

import json
import statistics
import time

from app.render.settings import RenderSettings, parse_size


def register(sub) -> None:
    p = sub.add_parser("bench", help="benchmarks (timings are printed, never asserted)")
    bsub = p.add_subparsers(dest="bench", metavar="BENCH")
    bsub.required = True
    peer = bsub.add_parser("peer", help="Skinlab vs pyrender on the same head, size and EGL context kind")
    peer.add_argument("--size", default="512x512")
    peer.add_argument("--frames", type=int, default=30, help="timed frames per renderer (after warm-up)")
    peer.add_argument("--json", action="store_true")
    peer.set_defaults(func=run_peer_bench)


def peer_bench(size=(512, 512), frames: int = 30) -> dict:
    """Median frame times, both including the colour+depth read-back (pyrender always reads back)."""
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
    settings = RenderSettings(w, h)
    ctx = create_headless_context()
    r = Renderer(ctx)
    r.timer.sync = False  # no glFinish between passes: whole frames are timed here
    r.render(scene, settings)
    ours = []
    for _ in range(frames):
        t0 = time.perf_counter()
        r.render(scene, settings, readback=("ldr", "depth"))  # what pyrender reads back
        ours.append((time.perf_counter() - t0) * 1e3)
    cam = scene.camera
    meshes = [(str(n.mesh.source), n.world_matrix) for n in scene.mesh_nodes()]
    peer = run_peer(meshes, cam.world_matrix, cam.yfov, cam.znear, cam.zfar, size, frames=frames)
    theirs = list(map(float, peer["times"]))
    mo, mt = statistics.median(ours), statistics.median(theirs)
    return {"size": [w, h], "frames": frames, "gl": describe(ctx), "skinlab_ms": mo, "pyrender_ms": mt,
            "ratio_skinlab_over_pyrender": mo / mt}


def run_peer_bench(args) -> int:
    res = peer_bench(parse_size(args.size), args.frames)
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        print(f"{res['gl']}, {res['size'][0]}x{res['size'][1]}, median of {res['frames']} frames "
              f"(colour+depth read back on both):")
        print(f"  skinlab   {res['skinlab_ms']:8.2f} ms/frame")
        print(f"  pyrender  {res['pyrender_ms']:8.2f} ms/frame")
        print(f"  ratio skinlab/pyrender = {res['ratio_skinlab_over_pyrender']:.2f}")
    return 0
