"""The shadow lookup (skinlab/shaders/lib/shadow.glsl) against its NumPy twin (skinlab/scene/optics/shadow.py),
and its depth bias: sized to the map's texel at the receiver, so that a lit plane stays lit under
the 3x3 PCF at any angle and light does not leak through a shadow at grazing incidence, whatever the
scene's scale."""

import math

import moderngl
import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene import transform as tf
from skinlab.scene.optics import shadow
from skinlab.scene.optics.constants import SHADOW_BIAS_TEXELS, SHADOW_SLOPE_MAX, SHADOW_SLOPE_TEXELS

ORTHO = np.eye(4)
ORTHO[:3, :3] *= 0.5
ORTHO[:3, 3] = 0.5  # world [-1, 1]^3 -> texture [0, 1]^3
# a point light at z = 4 looking down -z, 40 degrees wide, depth 2..6 (clip -> texture space)
CLIP_TO_TEXTURE = np.array([[0.5, 0, 0, 0.5], [0, 0.5, 0, 0.5], [0, 0, 0.5, 0.5], [0, 0, 0, 1.0]])
_VIEW = np.eye(4)
_VIEW[2, 3] = -4.0  # the light at z = 4, looking down -z
PERSPECTIVE = CLIP_TO_TEXTURE @ tf.perspective(math.radians(40), 1.0, 2.0, 6.0) @ _VIEW


def nearest_depth_map(ctx, rng, h: int, w: int, filter: int = moderngl.NEAREST):
    """A random depth map (0.2-0.9) and its depth-compare texture ('<=', NEAREST by default: the twins'
    filtering of single taps; the renderer's maps are LINEAR)."""
    depth = rng.uniform(0.2, 0.9, (h, w)).astype(np.float32)
    tex = ctx.depth_texture((w, h), data=depth.tobytes())
    tex.compare_func = "<="
    tex.filter = (filter, filter)
    tex.repeat_x = tex.repeat_y = False
    return depth, tex


def has_gather(ctx) -> bool:
    """Whether lib/shadow.glsl's shadow_pcf takes its textureGather path (GLSL 4.00 or ARB_gpu_shader5):
    then it is the bilinear 3x3 PCF whatever the texture's filter mode (a gather ignores it)."""
    return ctx.version_code >= 400 or "GL_ARB_gpu_shader5" in ctx.extensions


def world_at(m: np.ndarray, uv: np.ndarray, z: np.ndarray, perspective: bool) -> np.ndarray:
    """World points whose shadow-map texture coordinates under `m` are (uv, z)."""
    ndc = np.stack([uv[:, 0] * 2 - 1, uv[:, 1] * 2 - 1, z * 2 - 1, np.ones(len(uv))], 1)
    world = ndc @ np.linalg.inv(m @ np.linalg.inv(CLIP_TO_TEXTURE)).T if perspective else ndc
    return world[:, :3] / world[:, 3:]


@pytest.mark.parametrize("filter", ["linear", "nearest"])
@pytest.mark.parametrize("matrix", ["orthographic", "perspective"])
def test_shadow_pcf_matches_numpy(ctx, glsl, matrix, filter):
    """The 3x3 PCF against its twin: the bilinear one (four gathers, the weights in fp32) on the
    renderer's LINEAR map, and on a NEAREST one too where the gather path runs (it ignores the filter;
    the fallback's nine taps are then NEAREST taps); points anywhere on the map, its edge texels (clamped
    to the edge) included."""
    rng = np.random.default_rng(7)
    h, w = 16, 24
    depth, tex = nearest_depth_map(ctx, rng, h, w, moderngl.LINEAR if filter == "linear" else moderngl.NEAREST)
    m = ORTHO if matrix == "orthographic" else PERSPECTIVE
    n = 2000
    uv = rng.uniform(0.0, 1.0, (n, 2))
    if filter == "nearest" and not has_gather(ctx):  # NEAREST taps: away from texel borders
        uv = (rng.integers(0, [w, h], (n, 2)) + rng.uniform(0.2, 0.8, (n, 2))) / [w, h]
    z = rng.uniform(0.0, 1.0, n)
    world = world_at(m, uv, z, matrix == "perspective")
    world[:50, 0] = 50.0  # outside the map: lit
    nol = rng.uniform(-0.2, 1.0, n)  # includes grazing and back-facing (the slope clamps)
    world, nol = world.astype(np.float32).astype(np.float64), nol.astype(np.float32).astype(np.float64)
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf(u_map, u_m, world, nol)",
        {"world": world, "nol": nol},
        uniforms={"u_m": ("mat4", m)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    ref = shadow.shadow_pcf(depth, m, world, nol, nearest=filter == "nearest" and not has_gather(ctx))
    p = np.c_[world, np.ones(n)] @ m.T
    zt = p[:, 2] / p[:, 3]
    # a tap whose reference depth lies within fp32 rounding of the stored depth may flip
    bias = shadow.shadow_bias(nol, m, world, (w, h))
    margin = np.abs(depth.reshape(-1)[None, :] - (zt[:, None] - bias[:, None])).min(1) > 1e-5
    assert margin.mean() > 0.95
    assert_close_fp32(gpu[margin], ref[margin], what="shadow_pcf")
    assert (ref[:50] == 1).all() and 0 < ref[50:].mean() < 1
    partial = (ref > 0) & (ref < 1)
    assert partial.mean() > 0.1  # the weights are tested, not only whole footprints (14-26 %)
    # the bias term alone, GPU against NumPy (the texel scale from the matrix's rows)
    gpu_bias = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_bias(u_m, u_m * vec4(world, 1.0), vec2(24.0, 16.0), nol)",
        {"world": world[50:], "nol": nol[50:]},
        uniforms={"u_m": ("mat4", m)},
    )[:, 0]
    assert_close_fp32(gpu_bias, bias[50:], rtol=1e-4, what="shadow_bias")


@pytest.mark.parametrize("matrix", ["orthographic", "perspective"])
def test_shadow_tap_matches_numpy(ctx, glsl, matrix):
    """One bilinear compare tap (single scattering's upstream shadow) against its twin on the renderer's
    LINEAR map: points anywhere, the map's edges and outside it included (llvmpipe's bilinear weights
    are float: within about 1e-6)."""
    rng = np.random.default_rng(11)
    h, w = 16, 24
    depth, tex = nearest_depth_map(ctx, rng, h, w, moderngl.LINEAR)
    m = ORTHO if matrix == "orthographic" else PERSPECTIVE
    n = 2000
    world = world_at(m, rng.uniform(0.0, 1.0, (n, 2)), rng.uniform(0.0, 1.0, n), matrix == "perspective")
    world[:50, 0] = 50.0  # outside the map: lit
    nol = rng.uniform(-0.2, 1.0, n)
    world, nol = world.astype(np.float32).astype(np.float64), nol.astype(np.float32).astype(np.float64)
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_tap(u_map, u_m, world, nol)",
        {"world": world, "nol": nol},
        uniforms={"u_m": ("mat4", m)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    ref = shadow.shadow_tap(depth, m, world, nol)
    p = np.c_[world, np.ones(n)] @ m.T
    bias = shadow.shadow_bias(nol, m, world, (w, h))
    margin = np.abs(depth.reshape(-1)[None, :] - (p[:, 2:3] / p[:, 3:4] - bias[:, None])).min(1) > 1e-5
    assert margin.mean() > 0.95
    assert_close_fp32(gpu[margin], ref[margin], atol=4e-6, what="shadow_tap")
    assert (ref[:50] == 1).all() and ((ref > 0) & (ref < 1)).mean() > 0.1


def test_bias_is_sized_to_the_texel_and_bounded():
    """The bias is a texel plus the slope over the PCF's reach in texels, clamped: scaling the scene
    scales it in world units (a constant in normalised depth did not), a larger map shrinks it, and at
    grazing incidence it stops growing (it was 0.0015 x (1 + 3 tan theta) of the map's depth range:
    at NoL 0.05, 9 % of it)."""
    nol = np.array([1.0, 0.707, 0.2, 0.05, 0.0, -0.5])
    for scale in (1.0, 1000.0):
        m = ORTHO.copy()
        m[:3, :3] /= scale  # world [-scale, scale]^3 -> [0, 1]^3
        world = np.zeros((len(nol), 3))
        for size in (512, 2048):
            texel_world = 2.0 * scale / size
            got = shadow.shadow_bias(nol, m, world, (size, size)) * 2.0 * scale  # texture depth -> world
            tan = np.minimum(np.sqrt(1 - np.clip(nol, 1e-3, 1) ** 2) / np.clip(nol, 1e-3, 1), SHADOW_SLOPE_MAX)
            np.testing.assert_allclose(got, texel_world * (SHADOW_BIAS_TEXELS + SHADOW_SLOPE_TEXELS * tan), rtol=1e-12)
            assert got[0] == pytest.approx(texel_world)  # facing the light: one texel
            assert got[3] == got[4] == got[5] == pytest.approx(texel_world * 16.0)  # grazing: bounded
    # perspective: the texel grows with the distance from the light
    near = shadow.shadow_texel_scale(PERSPECTIVE, [[0.0, 0.0, 1.0]], (256, 256))[0]
    far = shadow.shadow_texel_scale(PERSPECTIVE, [[0.0, 0.0, -1.0]], (256, 256))[0]
    assert far[0] / near[0] == pytest.approx(5.0 / 3.0, rel=1e-9)  # distances 3 and 5 from the light
    assert near[0] == pytest.approx(2 * 3 * math.tan(math.radians(20)) / 256, rel=1e-9)


def _tilted_plane_map(size, slope):
    """Orthographic depth map (texture depth) of the plane z = slope x seen by a light travelling
    along -z through ORTHO (world [-1, 1]^3): each texel holds the plane's depth at its centre."""
    x = (np.arange(size) + 0.5) / size * 2 - 1
    zworld = slope * np.tile(x, (size, 1))
    return (0.5 - 0.5 * zworld).astype(np.float64)  # ORTHO maps z to depth 0.5 z + 0.5; light looks down -z


@pytest.mark.parametrize("degrees", [0.0, 30.0, 60.0, 75.0])
def test_a_lit_plane_stays_lit(degrees):
    """Points on a plane tilted by theta to the light, with its own depth map: all 9 taps lit (no
    acne) up to tan theta = SHADOW_SLOPE_MAX."""
    size, slope = 256, math.tan(math.radians(degrees))
    # the map's depth runs the other way from ORTHO's z (the light travels -z): flip it
    m = ORTHO.copy()
    m[2, 2] = -0.5
    dmap = _tilted_plane_map(size, slope)
    rng = np.random.default_rng(1)
    x = rng.uniform(-0.9, 0.9, 3000)
    y = rng.uniform(-0.9, 0.9, 3000)
    world = np.stack([x, y, slope * x], 1)
    nol = np.full(len(x), math.cos(math.radians(degrees)))
    assert np.all(shadow.shadow_pcf(dmap, m, world, nol) == 1.0)


@pytest.mark.parametrize("degrees", [45.0, 80.0, 87.0])
def test_no_light_through_a_close_occluder_at_grazing_light(degrees):
    """An occluder 24 texels in front of a receiver along the light (a plane at constant depth over
    the half x < 0 of a 1024 map whose depth range is 8 times its width, as a light's box around a
    head seen at close range): receivers behind it are dark at every angle, grazing included. The
    old constant bias, 0.0015 x (1 + 3 tan theta) of the depth range, let light through from 45
    degrees on."""
    size, depth_range = 1024, 16.0
    m = np.eye(4)
    m[0, 0] = m[1, 1] = 0.5  # x, y in [-1, 1] -> [0, 1]
    m[0, 3] = m[1, 3] = 0.5
    m[2, 2], m[2, 3] = -1.0 / depth_range, 0.5  # the light travels -z; z in [-8, 8] -> depth [1, 0]
    texel = 2.0 / size
    gap = 24 * texel  # along the light, world units
    dmap = np.full((size, size), 0.5)  # the receiver's own surface at z = 0 (depth 0.5), lit half
    dmap[:, : size // 2] = 0.5 - gap / depth_range  # the occluder, gap closer to the light, over x < 0
    rng = np.random.default_rng(2)
    world = np.stack([rng.uniform(-0.9, -0.1, 2000), rng.uniform(-0.9, 0.9, 2000), np.zeros(2000)], 1)
    nol = np.full(2000, math.cos(math.radians(degrees)))
    assert np.all(shadow.shadow_pcf(dmap, m, world, nol) == 0.0)
    lit = world * [-1.0, 1.0, 1.0]  # the other half: lit
    assert np.all(shadow.shadow_pcf(dmap, m, lit, nol) == 1.0)
    old_bias = 0.0015 * (1.0 + 3.0 * math.tan(math.radians(min(degrees, 87.13)))) * depth_range  # world units
    assert old_bias > gap  # what let the light through


@pytest.mark.parametrize("matrix", ["orthographic", "perspective"])
def test_shadow_pcf_area_matches_numpy_with_nearest_compare(ctx, glsl, matrix):
    """The footprint's average (a texture-space texel's) against its twin: footprints from half a
    texel (the 3x3 PCF, bilinear where it gathers) to 40 texels (more than SHADOW_AREA_TAPS taps a
    side; NEAREST taps), at any angle to the map's axes, across the light (the depth constant over
    them, so that the compare margin of the plain PCF's test holds for every tap)."""
    rng = np.random.default_rng(11)
    h, w = 32, 48
    depth, tex = nearest_depth_map(ctx, rng, h, w)
    m = ORTHO if matrix == "orthographic" else PERSPECTIVE
    n = 1500
    uv = rng.uniform(0.1, 0.9, (n, 2))
    z = rng.uniform(0.0, 1.0, n)
    world = world_at(m, uv, z, matrix == "perspective")
    texel = shadow.shadow_texel_scale(m, world, (w, h))[0]  # world units per map texel there
    ang = rng.uniform(0, np.pi, n)
    la, lb = (texel * 10 ** rng.uniform(-0.3, 1.6, n) for _ in range(2))
    du = np.stack([np.cos(ang), np.sin(ang), np.zeros(n)], 1) * la[:, None]
    dv = np.stack([-np.sin(ang), np.cos(ang), np.zeros(n)], 1) * lb[:, None]
    nol = rng.uniform(0.1, 1.0, n)
    world, du, dv, nol = (a.astype(np.float32).astype(np.float64) for a in (world, du, dv, nol))
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf_area(u_map, u_m, world, nol, du, dv)",
        {"world": world, "nol": nol, "du": du, "dv": dv},
        uniforms={"u_m": ("mat4", m)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    ref = shadow.shadow_pcf_area(depth, m, world, nol, du, dv, nearest=not has_gather(ctx))
    p = np.c_[world, np.ones(n)] @ m.T
    zt = p[:, 2] / p[:, 3]
    bias = shadow.shadow_bias(nol, m, world, (w, h))
    margin = np.abs(depth.reshape(-1)[None, :] - (zt[:, None] - bias[:, None])).min(1) > 1e-5
    assert margin.mean() > 0.9
    # a tap on a texel border may pick either texel in fp32: a few footprints differ by a tap
    diff = np.abs(gpu[margin] - ref[margin])
    assert np.mean(diff < 1e-5) > 0.97 and diff.max() < 0.05, diff.max()
    wide = np.maximum(la, lb) / texel > 4
    assert wide.sum() > n // 3 and 0 < ref[wide].mean() < 1


def test_shadow_pcf_area_is_the_lit_share_of_the_footprint():
    """A map lit over u > 0.5 (its depth far behind the receivers') and shadowed over u < 0.5, and
    footprints 12 texels wide across the edge at any offset: the visibility is the footprint's lit
    share within a tap's (1/12); one point's 3x3 PCF is 0 or 1 beyond 1.5 texels from the edge."""
    size = 256
    m = ORTHO.copy()
    m[2, 2] = -0.5  # the light travels -z
    dmap = np.ones((size, size))
    dmap[:, : size // 2] = 0.1  # an occluder near the light over u < 0.5
    texel = 2.0 / size  # world units
    offsets = np.linspace(-8, 8, 97)  # the footprint's centre from the edge, texels
    world = np.stack([offsets * texel, np.zeros_like(offsets), np.zeros_like(offsets)], 1)
    du = np.tile([12 * texel, 0.0, 0.0], (len(offsets), 1))
    dv = np.tile([0.0, 2 * texel, 0.0], (len(offsets), 1))
    nol = np.ones(len(offsets))
    got = shadow.shadow_pcf_area(dmap, m, world, nol, du, dv)
    share = np.clip(offsets / 12 + 0.5, 0, 1)
    np.testing.assert_allclose(got, share, atol=1 / 12 + 1e-9)
    assert np.abs(got - share).mean() < 0.03
    point = shadow.shadow_pcf(dmap, m, world, nol)
    assert set(point[np.abs(offsets) > 1.5]) <= {0.0, 1.0}


@pytest.mark.parametrize("degrees", [0.0, 45.0, 70.0])
def test_a_lit_plane_stays_lit_under_a_wide_footprint(ctx, glsl, degrees):
    """A plane tilted to the light with its own depth map, footprints 20 texels across on it: every
    tap's depth on the footprint's plane, so all stay lit (at the centre's depth, the taps up the
    slope would fall behind the surface: acne), GPU and twin."""
    size, slope = 256, math.tan(math.radians(degrees))
    m = ORTHO.copy()
    m[2, 2] = -0.5
    dmap = _tilted_plane_map(size, slope)
    rng = np.random.default_rng(3)
    n = 400
    x, y = rng.uniform(-0.7, 0.7, n), rng.uniform(-0.7, 0.7, n)
    world = np.stack([x, y, slope * x], 1)
    step = 20 * 2.0 / size
    du = np.tile([step, 0.0, slope * step], (n, 1))
    dv = np.tile([0.0, step, 0.0], (n, 1))
    nol = np.full(n, math.cos(math.radians(degrees)))
    assert np.all(shadow.shadow_pcf_area(dmap, m, world, nol, du, dv) == 1.0)
    tex = ctx.depth_texture((size, size), data=dmap.astype(np.float32).tobytes())
    tex.compare_func = "<="
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf_area(u_map, u_m, world, nol, du, dv)",
        {"world": world, "nol": nol, "du": du, "dv": dv},
        uniforms={"u_m": ("mat4", m)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    assert np.all(gpu == 1.0)


def _fitted_maps(ctx, rng):
    """A full map and a fitted one over a window of it (the crop of skinlab/render/shadow_fit.py): their
    depth arrays, textures and texture matrices (orthographic, world [-1, 1]^3 -> the full map)."""
    from skinlab.render.shadow_fit import ShadowWindow

    full, full_tex = nearest_depth_map(ctx, rng, 16, 24)
    fine, fine_tex = nearest_depth_map(ctx, rng, 40, 28)  # w 28, h 40: not square
    win = ShadowWindow(-0.3, -0.5, 0.25, 0.4, 28, 40, 2.0)
    m_full = ORTHO
    m_fine = CLIP_TO_TEXTURE @ win.crop() @ np.linalg.inv(CLIP_TO_TEXTURE) @ ORTHO
    return full, full_tex, fine, fine_tex, m_full, m_fine


def test_shadow_fitted_lookups_match_numpy(ctx, glsl):
    """The fitted map's lookups (lib/shadow.glsl shadow_in_window, shadow_pcf_fitted,
    shadow_pcf_area_fitted) against their twins: points inside the window read the fitted map, points
    outside it or too near its edge for the lookup's reach read the full map."""
    rng = np.random.default_rng(5)
    full, full_tex, fine, fine_tex, m_full, m_fine = _fitted_maps(ctx, rng)
    n = 1500
    world = np.c_[rng.uniform(-0.6, 0.6, (n, 2)), rng.uniform(-1.0, 1.0, n)].astype(np.float32).astype(np.float64)
    nol = rng.uniform(0.1, 1.0, n).astype(np.float32).astype(np.float64)
    reach = 2.5
    inside = shadow.in_window(m_fine, world, (28, 40), reach)
    assert 0.2 < inside.mean() < 0.8
    gpu_in = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_in_window(u_mf, world, vec2(28.0, 40.0), 2.5) ? 1.0 : 0.0",
        {"world": world},
        uniforms={"u_mf": ("mat4", m_fine)},
    )[:, 0]
    # a point within fp32 rounding of the reach may go either way
    p = np.c_[world, np.ones(n)] @ m_fine.T
    c = p[:, :2] / p[:, 3:] * [28, 40]
    edge = np.minimum(np.abs(c - reach), np.abs(c - ([28, 40] - np.array(reach)))).min(1) < 1e-3
    assert np.array_equal(gpu_in[~edge] > 0.5, inside[~edge])
    samplers = {"u_fine": ("sampler2DShadow", fine_tex), "u_full": ("sampler2DShadow", full_tex)}
    uniforms = {"u_mf": ("mat4", m_fine), "u_m": ("mat4", m_full)}
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf_fitted(u_fine, u_mf, u_full, u_m, world, nol)",
        {"world": world, "nol": nol},
        uniforms=uniforms,
        samplers=samplers,
    )[:, 0]
    ref = shadow.shadow_pcf_fitted(fine, m_fine, full, m_full, world, nol, nearest=not has_gather(ctx))
    on_fine = shadow.shadow_pcf(fine, m_fine, world, nol, nearest=not has_gather(ctx))
    on_full = shadow.shadow_pcf(full, m_full, world, nol, nearest=not has_gather(ctx))
    assert np.array_equal(ref, np.where(inside, on_fine, on_full))
    assert np.mean(on_fine[inside] != on_full[inside]) > 0.3  # the two maps do differ there
    ok = ~edge
    diff = np.abs(gpu[ok] - ref[ok])
    assert np.mean(diff < 1e-4) > 0.97, diff.max()
    # the footprint's average: wider footprints need to lie further inside
    du = np.tile([0.04, 0.0, 0.0], (n, 1))
    dv = np.tile([0.0, 0.05, 0.0], (n, 1))
    gpu_a = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_pcf_area_fitted(u_fine, u_mf, u_full, u_m, world, nol, du, dv)",
        {"world": world, "nol": nol, "du": du, "dv": dv},
        uniforms=uniforms,
        samplers=samplers,
    )[:, 0]
    ref_a = shadow.shadow_pcf_area_fitted(fine, m_fine, full, m_full, world, nol, du, dv, nearest=not has_gather(ctx))
    diff_a = np.abs(gpu_a[ok] - ref_a[ok])
    assert np.mean(diff_a < 1e-4) > 0.95, diff_a.max()
    half = 0.5 * (np.abs((du @ m_fine[:3, :3].T)[:, :2]) + np.abs((dv @ m_fine[:3, :3].T)[:, :2])) * [28, 40]
    inside_a = shadow.in_window(m_fine, world, (28, 40), reach + half.max(1))
    assert inside_a.sum() < inside.sum() and (inside_a <= inside).all()


def test_shadow_box_matches_numpy_and_is_the_lit_share(ctx, glsl):
    """A screen sample's lookup in a fitted map (lib/shadow.glsl shadow_box, shadow_box_fitted) against
    its twins, boxes from under a texel (read as one: bilinear) to past SHADOW_BOX_TEXELS (the area
    taps); and on a map lit left of a column edge, the box reads the share of it left of the edge."""
    if not has_gather(ctx):
        pytest.skip("shadow_box needs textureGather (GLSL 4.00 or ARB_gpu_shader5)")
    rng = np.random.default_rng(9)
    full, full_tex, fine, fine_tex, m_full, m_fine = _fitted_maps(ctx, rng)
    n = 1500
    world = np.c_[rng.uniform(-0.3, 0.25, n), rng.uniform(-0.5, 0.4, n), rng.uniform(-1, 1, n)]
    scale = 10 ** rng.uniform(-1.5, -0.3, (n, 2))  # world units: 0.1 to 8 fitted texels
    du = np.c_[scale[:, 0], np.zeros(n), np.zeros(n)]
    dv = np.c_[np.zeros(n), scale[:, 1], np.zeros(n)]
    nol = rng.uniform(0.2, 1.0, n)
    world, du, dv, nol = (a.astype(np.float32).astype(np.float64) for a in (world, du, dv, nol))
    gpu = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_box_fitted(u_fine, u_mf, u_full, u_m, world, nol, du, dv)",
        {"world": world, "nol": nol, "du": du, "dv": dv},
        uniforms={"u_mf": ("mat4", m_fine), "u_m": ("mat4", m_full)},
        samplers={"u_fine": ("sampler2DShadow", fine_tex), "u_full": ("sampler2DShadow", full_tex)},
    )[:, 0]
    ref = shadow.shadow_box_fitted(fine, m_fine, full, m_full, world, nol, du, dv)
    diff = np.abs(gpu - ref)
    assert np.mean(diff < 1e-4) > 0.95 and np.median(diff) < 1e-5, diff.max()
    # a step: texels left of column 10 lit (depth 1), the rest in shadow (depth 0); a receiver at z 0.5
    h, w = 12, 24
    step = np.where(np.arange(w)[None, :] < 10, 1.0, 0.0).repeat(h, 0).astype(np.float32)
    tex = ctx.depth_texture((w, h), data=step.tobytes())
    tex.compare_func = "<="
    tex.repeat_x = tex.repeat_y = False
    k = 200
    x = rng.uniform(7.0, 13.0, k)  # texel units across the edge at 10
    bw = rng.uniform(1.0, 5.0, k)
    uv = np.c_[x / w, np.full(k, 6.0 / h)]
    pts = world_at(ORTHO, uv, np.full(k, 0.5), False)
    wbox = np.c_[bw, np.full(k, 2.0)]
    lit = np.clip((10.0 - (x - bw / 2)) / bw, 0.0, 1.0)
    got = glsl.evaluate(
        "lib/shadow.glsl",
        "shadow_box(u_map, u_m, world, 1.0, wbox)",
        {"world": pts.astype(np.float32).astype(np.float64), "wbox": wbox},
        uniforms={"u_m": ("mat4", ORTHO)},
        samplers={"u_map": ("sampler2DShadow", tex)},
    )[:, 0]
    assert np.allclose(got, lit, atol=2e-4), np.abs(got - lit).max()
    assert np.allclose(shadow.shadow_box(step, ORTHO, pts, np.ones(k), wbox), lit, atol=1e-9)
