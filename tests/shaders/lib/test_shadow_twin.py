import moderngl
import numpy as np

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import shadow


def test_shadow_pcf_matches_numpy_with_nearest_compare(ctx, glsl):
    rng = np.random.default_rng(7)
    h, w = 16, 24
    depth = rng.uniform(0.2, 0.9, (h, w)).astype(np.float32)
    tex = ctx.depth_texture((w, h), data=depth.tobytes())
    tex.compare_func = "<="
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    m = np.eye(4)
    m[:3, :3] *= 0.5
    m[:3, 3] = 0.5  # world [-1, 1]^3 -> texture [0, 1]^3
    n = 2000
    # texel centres jittered away from texel borders, so NEAREST picks the same texel on both sides
    uv = (rng.integers(0, [w, h], (n, 2)) + rng.uniform(0.2, 0.8, (n, 2))) / [w, h]
    z = rng.uniform(0.0, 1.0, n)
    world = np.stack([uv[:, 0] * 2 - 1, uv[:, 1] * 2 - 1, z * 2 - 1], 1)
    world[:50, 0] = 1.5  # outside the map: lit
    nol = rng.uniform(-0.2, 1.0, n)  # includes grazing and back-facing (bias clamps)
    world, nol = world.astype(np.float32).astype(np.float64), nol.astype(np.float32).astype(np.float64)
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf(u_map, u_m, world, nol)",
        {"world": world, "nol": nol},
        uniforms={"u_m": ("mat4", m)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    ref = shadow.shadow_pcf(depth, m, world, nol)
    # a tap whose reference depth lies within fp32 rounding of the stored depth may flip
    margin = np.abs(depth.reshape(-1)[None, :] - (z[:, None] - shadow.shadow_bias(nol)[:, None])).min(1) > 1e-5
    assert margin.mean() > 0.95
    assert_close_fp32(gpu[margin], ref[margin], what="shadow_pcf")
    assert (ref[:50] == 1).all() and 0 < ref[50:].mean() < 1
