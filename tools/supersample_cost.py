"""A one-off measurement, not a feature: what antialiasing by supersampling costs
(RenderSettings.supersample): the plain (no scattering) head frame at 640x640 with N = 1, 2, 4,
interleaved rounds, every pass run each frame (reuse off); median frame time and the forward,
tone-mapping and shadow passes, with the load average.

    python -m tools.supersample_cost [--rounds 5] [--frames 3] [--size 640] [--scene SCENE]

Used for the timing table of docs/measured.md."""

from __future__ import annotations

import argparse
import os
import statistics
import sys

from skinlab.gl.context import create_headless_context
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene

FACTORS = (1, 2, 4)
PASSES = ("forward", "tonemap", "shadow[key]")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.supersample_cost", description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    ap.add_argument("--frames", type=int, default=3, help="frames per setting and round (default 3)")
    ap.add_argument("--size", type=int, default=640, help="frame width and height (default 640)")
    ap.add_argument("--scene", default=None, help="scene name or file (default: the head)")
    args = ap.parse_args(argv)
    rounds, per_round = args.rounds, args.frames
    r = Renderer(create_headless_context())
    r.reuse = False
    scene = load_scene(args.scene)
    sts = {n: RenderSettings.for_technique("none", args.size, args.size, supersample=n) for n in FACTORS}
    for st in sts.values():
        r.render(scene, st, readback=False)  # compiles and uploads are not frame time
    load0 = os.getloadavg()[0]
    ms: dict[int, dict[str, list[float]]] = {n: {k: [] for k in ("frame", *PASSES)} for n in sts}
    for _ in range(rounds):
        for n, st in sts.items():
            for _ in range(per_round):
                d = r.render(scene, st, readback=False).timings.as_dict()
                ms[n]["frame"].append(d["frame_ms"])
                for k in PASSES:
                    ms[n][k].append(d["passes"][k]["cpu_ms"])
    load1 = os.getloadavg()[0]
    base = statistics.median(ms[1]["frame"])
    for n in sts:
        m = {k: statistics.median(v) for k, v in ms[n].items()}
        print(
            f"N={n}: frame {m['frame']:.1f} ms (x{m['frame'] / base:.2f} of N=1): forward {m['forward']:.1f}, "
            f"tonemap {m['tonemap']:.1f}, shadow {m['shadow[key]']:.1f}; {len(ms[n]['frame'])} frames"
        )
    print(f"load average {load0:.2f} -> {load1:.2f} (1 min); {rounds} interleaved rounds of {per_round} frames")
    r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
