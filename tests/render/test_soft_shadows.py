"""Soft shadows of lights with a size (skinlab/shaders/lib/shadow_soft.glsl): the GLSL lookup against
its NumPy twin (skinlab/scene/optics/shadow.py shadow_soft), and the penumbra a straight edge casts in
the frame against the width a disk light of that angular radius casts."""

import math

import moderngl
import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import Material
from skinlab.scene.optics import shadow
from tests.tsd_scenes import pixel_x, slab_scene

MATTE = Material("matte", {"base_color": (0.8, 0.8, 0.8), "specular": 0.0})


def _maps(ctx, rng, h=32, w=32):
    """A distance map of 4 x 4-texel blocks (blockers at random heights, some open) and its depth map
    (depth = (distance + 1) / 2: the light travels +z through world [-1, 1]^3)."""
    blocks = rng.uniform(-1.0, 0.6, (h // 4, w // 4))
    blocks[rng.random(blocks.shape) < 0.3] = 1e30  # no surface
    dist = np.repeat(np.repeat(blocks, 4, 0), 4, 1).astype(np.float32)
    depth = np.where(dist > 1e29, 1.0, (dist + 1.0) / 2.0).astype(np.float32)
    dtex = ctx.depth_texture((w, h), data=depth.tobytes())
    dtex.compare_func = "<="
    dtex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    dtex.repeat_x = dtex.repeat_y = False
    ftex = ctx.texture((w, h), 1, dist.tobytes(), dtype="f4")
    ftex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    ftex.repeat_x = ftex.repeat_y = False
    return depth, dist, dtex, ftex


@pytest.mark.parametrize("area", [False, True])
@pytest.mark.parametrize("local", [False, True])
def test_shadow_soft_matches_numpy_with_nearest_filtering(ctx, glsl, local, area):
    """shadow_soft (and with `area` shadow_soft_area: a receiver's footprint, the texture-space
    texel's, random parallelograms up to a few map texels, some of none) against the NumPy twin."""
    rng = np.random.default_rng(11)
    depth, dist, dtex, ftex = _maps(ctx, rng)
    try:
        m = np.eye(4)
        m[:3, :3] *= 0.5
        m[:3, 3] = 0.5  # world [-1, 1]^3 -> texture [0, 1]^3
        # a directional light along +z (eye w = 0) of angular radius atan(0.05), or a local light
        # whose distances the map holds as they are (its eye far below: distance ~ z + 100)
        soft = np.array([0.05, 0.0, 0.5, 2.0]) if not local else np.array([0.4, 1.0, 0.5 * 100.0, 2.0])
        eye = np.array([0.0, 0.0, 1.0, 0.0]) if not local else np.array([0.0, 0.0, -100.0, 1.0])
        n = 1500
        world = np.stack([rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-0.9, 0.95, n)], 1)
        world[:20, 0] = 1.5  # outside: lit
        nol = rng.uniform(0.1, 1.0, n)
        if local:  # the map's distances are the eye's: shift them by the eye's offset
            world_d = np.linalg.norm(world - eye[:3], axis=1)
            dist_l = np.where(dist > 1e29, dist, dist + 100.0).astype(np.float32)
            ftex.write(dist_l.tobytes())
        world, nol = world.astype(np.float32).astype(np.float64), nol.astype(np.float32).astype(np.float64)
        du, dv = (rng.uniform(-0.15, 0.15, (n, 3)).astype(np.float32).astype(np.float64) for _ in range(2))
        du[:100] = dv[:100] = 0.0  # no footprint: the point's filter

        def setup(prog):
            prog["u_depth"].value = 12
            prog["u_dist"].value = 13
            dtex.use(12)
            ftex.use(13)

        args = "u_depth, u_dist, u_m, u_soft, u_eye, w, nol"
        expr = f"shadow_soft_area({args}, du, dv)" if area else f"shadow_soft({args})"
        gpu = glsl.evaluate(
            "lib/shadow_soft.glsl", expr, {"w": world, "nol": nol, "du": du, "dv": dv},
            uniforms={"u_m": ("mat4", m), "u_soft": ("vec4", soft), "u_eye": ("vec4", eye)},
            prelude="uniform sampler2DShadow u_depth; uniform sampler2D u_dist;", setup=setup,
        )[:, 0]  # fmt: skip
        maps = (depth, dist_l if local else dist, m, soft, eye, world, nol)
        ref = shadow.shadow_soft_area(*maps, du, dv) if area else shadow.shadow_soft(*maps)
        if area:  # a footprint widens the filter: a point's own filter where there is none
            point = shadow.shadow_soft(*maps)
            assert np.array_equal(ref[:100], point[:100]) and (ref != point).mean() > 0.05
        # taps within fp32 rounding of a texel border may pick the neighbour: a few points, a tap each
        diff = np.abs(gpu - ref)
        assert (diff > 1e-6).mean() < 0.05 and diff.max() <= 3 / 16 + 1e-6, (diff > 1e-6).mean()
        assert_close_fp32(gpu[diff < 1e-6], ref[diff < 1e-6], what="shadow_soft")
        assert (ref[:20] == 1).all() and ((ref > 0) & (ref < 1)).mean() > 0.05  # penumbrae exist
        if local:
            assert np.isfinite(world_d).all()
    finally:
        dtex.release()
        ftex.release()


def disk_edge_width(fraction_lo=0.1, fraction_hi=0.9) -> float:
    """The 10-90 % width of a straight edge's shadow under a uniform disk of radius 1: the visible
    fraction at offset x is the disk's segment area beyond x."""
    x = np.linspace(-1, 1, 20001)
    seg = (np.arccos(x) - x * np.sqrt(1 - x * x)) / np.pi  # share of the disk beyond x
    return float(np.interp(fraction_hi, seg[::-1], x[::-1]) - np.interp(fraction_lo, seg[::-1], x[::-1])) * -1


def edge_width(profile, x) -> float:
    p = (profile - profile.min()) / (profile.max() - profile.min())
    order = np.argsort(p)
    return abs(float(np.interp(0.9, p[order], x[order]) - np.interp(0.1, p[order], x[order])))


def test_a_straight_edge_casts_the_penumbra_of_a_disk_light(renderer):
    """slab_scene's occluder edge 1.02 units above the slab, lit along (1, 0, -1): a directional light
    of angular radius theta spreads the edge over 2.04 units per radian of angle along x (the
    ray through the edge meets the slab at x = 1.02 (tan(45 + a) - 1)), i.e. its 10-90 % width is
    2.04 theta times that of a disk's segment profile; without a size the edge is a few texels."""
    s = slab_scene(half=1.0, material=MATTE, occluder=True)
    s.environment.ambient = np.zeros(3)
    for m in s.mesh_nodes():
        if m.name != "slab":
            continue
        m.material = MATTE
    light = s.lights()[0]
    rs = RenderSettings.for_technique("none", 96, 96, shadow_size=2048, bounces=0)
    hard = renderer.render(s, rs).hdr[48, :, 0]
    theta = math.radians(4.0)
    light.angular_radius = theta
    res = renderer.render(s, rs)
    assert "soft shadows (angular radius 4 deg)" in res.plan.explain()
    shadow_pass = next(p for p in res.plan.passes if p.kind == "shadow")
    # the first surface's distance map for the blocker search; the part layers only for translucency
    assert shadow_pass.params.distance and not shadow_pass.params.layers
    assert "exit and next entry" not in shadow_pass.reason
    soft = res.hdr[48, :, 0]
    x = pixel_x(96, 1.0)
    want = 2.04 * theta * disk_edge_width()
    got = edge_width(soft, x)
    assert got == pytest.approx(want, rel=0.25), (got, want)
    assert edge_width(hard, x) < 0.3 * want
    # the shadow and the lit side far from the edge are as before
    assert np.allclose(soft[x < -0.6], hard[x < -0.6], atol=0.02 * hard.max())
    assert np.allclose(soft[x > 0.6], hard[x > 0.6], rtol=0.02)
