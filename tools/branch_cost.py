"""A one-off measurement, not a feature: whether the software rasteriser (llvmpipe) pays for a branch no
fragment takes. A fullscreen pass over a float texture of one value runs a branch of 64 texel fetches
where the fetched value exceeds 0.5: the texture all 0 (not taken anywhere), all 1 (taken everywhere)
and in stripes of `--stripe` texels (each SIMD group agrees or disagrees, by the stripes' width).
Medians of wall time with glFinish, interleaved rounds. docs/tsd.md ("Third round") quotes it.
With ``--straight`` the branch holds the same work written out, without a loop (64 fetches and
sines one after the other): what a branch of straight-line arithmetic costs where no fragment takes
it (docs/tsd.md, "Fifth round": llvmpipe runs it masked; the loop's own test of its lanes is what
stops the looped branch after one masked turn).

    .venv/bin/python -m tools.branch_cost [--size 1024] [--rounds 5] [--stripe 1] [--straight]"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

FRAGMENT = """#version 330
uniform sampler2D t;
out vec4 o;
void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    float v = texelFetch(t, q, 0).r;
    vec4 acc = vec4(0.0);
    if (v > 0.5) {
        for (int i = 0; i < 64; ++i)
            acc += texelFetch(t, (q + ivec2(i, 3 * i)) % textureSize(t, 0), 0) * sin(float(i) + acc.x);
    }
    o = acc + v;
}"""
# the branch's body written out: no loop whose test of its lanes could end it
STRAIGHT = FRAGMENT.replace(
    """        for (int i = 0; i < 64; ++i)
            acc += texelFetch(t, (q + ivec2(i, 3 * i)) % textureSize(t, 0), 0) * sin(float(i) + acc.x);""",
    "".join(
        f"        acc += texelFetch(t, (q + ivec2({i}, {3 * i})) % textureSize(t, 0), 0) * sin({i}.0 + acc.x);\n"
        for i in range(64)
    ),
)
VERTEX = "#version 330\nin vec2 p;\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); }"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.branch_cost", description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--stripe", type=int, default=1, help="texels per stripe of the mixed case")
    ap.add_argument("--straight", action="store_true", help="the branch's work written out, without a loop")
    args = ap.parse_args(argv)
    from skinlab.gl.context import create_headless_context

    ctx = create_headless_context()
    n = args.size
    prog = ctx.program(vertex_shader=VERTEX, fragment_shader=STRAIGHT if args.straight else FRAGMENT)
    vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "2f", "p")])
    fbo = ctx.framebuffer([ctx.texture((n, n), 4, dtype="f4")])
    stripes = ((np.arange(n) // max(args.stripe, 1)) % 2).astype("f4")
    cases = {
        "not taken": np.zeros((n, n), "f4"),
        "taken": np.ones((n, n), "f4"),
        f"stripes of {args.stripe}": np.tile(stripes, (n, 1)),
    }
    textures = {k: ctx.texture((n, n), 1, v.tobytes(), dtype="f4") for k, v in cases.items()}
    times: dict[str, list[float]] = {k: [] for k in cases}
    fbo.use()
    for _ in range(args.rounds):
        for k, tex in textures.items():
            tex.use(0)
            ctx.finish()
            t0 = time.perf_counter()
            vao.render()
            ctx.finish()
            times[k].append((time.perf_counter() - t0) * 1e3)
    print(ctx.info["GL_RENDERER"], f"{n}x{n}", "(straight-line branch)" if args.straight else "(looped branch)")
    for k, v in times.items():
        print(f"  {k:16s} {statistics.median(v):8.1f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
