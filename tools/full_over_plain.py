"""A one-off measurement, not a feature: the full default frame against the plain one, by process CPU time
and wall time: the head and the skim-milk bunny, three renderers (`full`: the default settings, every
pass every frame; `plain`: sss none, no interreflection; `orbit`: the default settings with reuse, the
camera still), frames alternating, glFinish after every pass, medians (of frames and of each pass's
process CPU time). What `skinlab bench orbit` reports as full_over_plain(_cpu), for any revision:
``--code DIR`` imports skinlab from DIR first (a ``git archive REV | tar -x -C DIR`` of an older
revision), so the same measurement times the code before a change.

    .venv/bin/python -m tools.full_over_plain [--frames 7] [--size 640] [--scenes head,bunny-skimmilk] [--code DIR]

Prints one JSON object: per scene the medians (cpu_ms, wall_ms) and the ratios, the load average."""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from contextlib import contextmanager
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.full_over_plain", description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=7)
    ap.add_argument("--size", type=int, default=640)
    ap.add_argument("--scenes", default="head,bunny-skimmilk", help="comma-separated bundled scenes")
    ap.add_argument("--code", default=None, help="a folder holding the skinlab package to time")
    args = ap.parse_args(argv)
    if args.code:  # time another checkout's package (its folder first on the path), else this one's
        sys.path.insert(0, str(Path(args.code).resolve()))
    import skinlab
    import skinlab.render.timing as timing
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene

    passes: dict = {}  # (mode, pass) -> process CPU ms of each run, recorded around the timer's own measure
    measure = timing.PassTimer.measure

    @contextmanager
    def measure_cpu(self, name):
        c0 = time.process_time()
        with measure(self, name):
            yield
        passes.setdefault((self.mode, name), []).append((time.process_time() - c0) * 1e3)

    timing.PassTimer.measure = measure_cpu  # type: ignore[method-assign]  # instrumented (restored below: a caller in the same process keeps its own)
    try:
        ctx = create_headless_context()
        out = {"code": str(Path(skinlab.__file__).parent), "size": args.size, "load_start": os.getloadavg()}
        n = args.size
        for name in args.scenes.split(","):
            scene = load_scene(name)
            modes = {
                "full": RenderSettings(n, n),
                "plain": RenderSettings(n, n, sss_model="none", bounces=0),
                "orbit": RenderSettings(n, n),
            }
            rs = {}
            for m, st in modes.items():
                r = rs[m] = Renderer(ctx)
                r.reuse = m == "orbit"
                r.timer.mode = m  # type: ignore[attr-defined]  # a tag measure_cpu reads; glFinish after every pass (the default): each pass's CPU time is its own
                for _ in range(2):
                    r.render(scene, st, readback=False)
            cpu: dict[str, list[float]] = {m: [] for m in modes}
            wall: dict[str, list[float]] = {m: [] for m in modes}
            passes.clear()
            for _ in range(args.frames):
                for m, st in modes.items():
                    c0, t0 = time.process_time(), time.perf_counter()
                    rs[m].render(scene, st, readback=False)
                    ctx.finish()
                    cpu[m].append((time.process_time() - c0) * 1e3)
                    wall[m].append((time.perf_counter() - t0) * 1e3)
            c = {m: statistics.median(v) for m, v in cpu.items()}
            w = {m: statistics.median(v) for m, v in wall.items()}
            out[name] = {
                "cpu_ms": c,
                "wall_ms": w,
                "full_over_plain_cpu": c["full"] / c["plain"],
                "full_over_plain_wall": w["full"] / w["plain"],
                "orbit_over_plain_cpu": c["orbit"] / c["plain"],
                "passes_cpu_ms": {
                    m: {p: round(statistics.median(v), 2) for (mm, p), v in passes.items() if mm == m} for m in modes
                },
            }
            for r in rs.values():
                r.release()
    finally:
        timing.PassTimer.measure = measure  # type: ignore[method-assign]
    out["load_end"] = os.getloadavg()
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
