"""GLSL environment lighting (skinlab/shaders/lib/environment.glsl, lib/sky_occlusion.glsl) against its
NumPy twins (skinlab/scene/optics/sh.py, split_sum.py, skinlab/render/environment.py env_diffuse), hard
cases included: the poles, the u seam, n.v = 0 and 1, roughness 0 and 1, visibility 0 and 1."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.render.environment import env_diffuse, upload_levels, upload_table
from skinlab.scene.optics import sh, split_sum

F32 = np.float32


def unit(rng, n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def hard_directions(rng):
    d = unit(rng, 300)
    d[:8] = [[0, 1, 0], [0, -1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1], [1e-7, 1, 0], [0, 0.6, -0.8]]
    d[8] = [-1e-6, 0.3, -0.95]  # just left of the u seam (u -> 1)
    d[9] = [1e-6, 0.3, -0.95]  # just right of it (u -> 0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return d.astype(F32).astype(np.float64)


def sh_setup(coeffs):
    return lambda prog: set_array(prog, "u_env_sh", coeffs, 9)


def test_sh_irradiance_matches_numpy(glsl):
    rng = np.random.default_rng(3)
    coeffs = rng.normal(size=(9, 3))
    coeffs[0] = [3.0, 2.0, 1.0]
    n = hard_directions(rng)
    gpu = glsl.evaluate("lib/environment.glsl", "env_sh_irradiance(n)", {"n": n}, 3, setup=sh_setup(coeffs))
    assert_close_fp32(gpu, sh.irradiance(coeffs, n), rtol=1e-4, atol=1e-5, what="env_sh_irradiance")


def test_sh_irradiance_of_a_uniform_sky_is_pi_L():
    # radiance 1 everywhere: only L00 = 4 pi Y00; irradiance pi on every normal
    coeffs = np.zeros((9, 1))
    coeffs[0] = 4 * np.pi * sh.SH_C0
    n = unit(np.random.default_rng(0), 50)
    assert np.allclose(sh.irradiance(coeffs, n), np.pi)


def test_sh_projection_and_irradiance_of_a_linear_sky_are_exact():
    # L(w) = 1 + w.z (band-limited): E(n) = pi + (2 pi / 3) n.z exactly, projected from a fine map
    w, h = 256, 128
    d = split_sum.texel_directions(w, h).reshape(-1, 3)
    omega = split_sum.texel_solid_angles(w, h).ravel()
    coeffs = sh.project(1.0 + d[:, 2:3], d, omega)
    n = unit(np.random.default_rng(1), 40)
    assert np.allclose(sh.irradiance(coeffs, n)[:, 0], np.pi + 2 * np.pi / 3 * n[:, 2], atol=2e-3)
    assert abs(omega.sum() - 4 * np.pi) < 1e-9


def test_sh_rotation_turns_the_light_with_the_map():
    rng = np.random.default_rng(2)
    coeffs = rng.normal(size=(9, 2))
    a = np.radians(37.0)
    r = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    m = sh.rotation(r)
    d = unit(rng, 30)
    # the turned light toward R d is the original toward d
    assert np.allclose(sh.radiance(m @ coeffs, d @ r.T), sh.radiance(coeffs, d), atol=1e-9)
    assert np.allclose(sh.rotation(np.eye(3)), np.eye(9), atol=1e-12)


def test_sky_share_and_occluded_diffuse_match_numpy(glsl):
    """The sky occlusion's record (RGB share seen, rays' share) as lib/sky_occlusion.glsl reads it, the
    hard cases (nothing and everything hidden, out of [0, 1]) included, against env_diffuse."""
    rng = np.random.default_rng(4)
    sky = rng.uniform(-0.2, 1.2, (300, 4))
    sky[0], sky[1], sky[2] = 1.0, 0.0, [1.0, 0.5, 0.0, 0.25]
    sky = sky.astype(F32).astype(np.float64)
    e = rng.uniform(0.5, 2.0, (len(sky), 3)).astype(F32).astype(np.float64)
    inputs = {"sky": sky, "e": e}
    gpu = glsl.evaluate("lib/sky_occlusion.glsl", "e * env_sky_share(sky)", inputs, 3)
    ref = env_diffuse(e, sky)
    assert_close_fp32(gpu, ref, rtol=1e-6, atol=1e-7, what="occluded diffuse")
    assert np.allclose(ref[0], e[0]) and np.allclose(ref[1], 0.0) and np.allclose(ref[2], e[2] * [1, 0.5, 0])
    assert np.allclose(env_diffuse(e), e)
    rays = glsl.evaluate("lib/sky_occlusion.glsl", "env_sky_rays(sky)", inputs, 1)
    assert_close_fp32(rays[:, 0], np.clip(sky[:, 3], 0.0, 1.0), rtol=0, atol=0, what="rays' share")


def test_irradiance_map_reads_as_numpy_does_and_is_the_exact_convolution(glsl, ctx):
    rng = np.random.default_rng(8)
    w, h = 64, 32
    d = split_sum.texel_directions(w, h)
    c = rng.normal(size=(9, 3)) * 0.08
    c[0] = [2.0, 1.5, 1.0]
    img = np.maximum(sh.radiance(c, d), 0.0)
    irr = split_sum.irradiance_map(img, 32, source_width=64)
    # a band-limited, non-negative sky: the map is its SH irradiance (the convolution is exact)
    nd = split_sum.texel_directions(32, 16)
    assert (sh.radiance(c, d) > 0).all()
    assert np.allclose(irr, sh.irradiance(c, nd), rtol=5e-3)
    tex = upload_levels(ctx, [irr])
    try:
        n = hard_directions(rng)

        def setup(prog):
            set_uniforms(prog, {"u_env_to_map": np.eye(3), "u_env_intensity": 1.5})
            bind(prog, "u_env_irradiance", tex)

        gpu = glsl.evaluate("lib/environment.glsl", "env_map_irradiance(n)", {"n": n}, 3, setup=setup)
        u, v = split_sum.equirect_uv(n)
        assert_close_fp32(gpu, 1.5 * split_sum.bilinear(irr, u, v), rtol=4e-3, atol=1e-3, what="env_map_irradiance")
    finally:
        tex.release()


def test_equirect_uv_matches_numpy_at_poles_and_seam(glsl):
    d = hard_directions(np.random.default_rng(5))
    gpu = glsl.evaluate("lib/environment.glsl", "equirect_uv(d)", {"d": d}, 2)
    u, v = split_sum.equirect_uv(d)
    # u wraps: compare on the circle
    du = np.abs(gpu[:, 0] - u)
    du = np.minimum(du, 1 - du)
    # llvmpipe's atan is good to about 1e-5 (a 25th of a texel of a 4096-wide map)
    assert du.max() < 1e-5, du.max()
    assert_close_fp32(gpu[:, 1], v, rtol=1e-5, atol=1e-5, what="equirect v")
    assert gpu[8, 0] > 0.99 and gpu[9, 0] < 0.01  # the two sides of the seam
    # Mitsuba's axes: +Z is the image's centre column, +X a quarter to the right, +Y the top row
    uu, vv = split_sum.equirect_uv(np.array([[0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]]))
    assert np.allclose(uu[:2], [0.5, 0.25]) and np.isclose(vv[2], 0.0)


def test_texel_directions_invert_equirect_uv():
    d = split_sum.texel_directions(16, 8)
    u, v = split_sum.equirect_uv(d)
    assert np.allclose(u, (np.arange(16) + 0.5)[None, :] / 16)
    assert np.allclose(v, (np.arange(8) + 0.5)[:, None] / 8)


def bind(prog, sampler, tex, unit=12):
    """A sampler the included file declares itself, on a unit the evaluator's inputs leave free."""
    tex.use(unit)
    prog[sampler].value = unit


def smooth_levels(rng, width=64, n=4):
    """A mip chain of smooth positive data (neighbouring texels differ by at most a few percent, so
    the GPU's fixed-point filter weights stay within the tolerance)."""
    out = []
    for k in range(n):
        w = width >> k
        d = split_sum.texel_directions(w, w // 2)
        c = rng.normal(size=(9, 3)) * 0.2
        c[0] = [2.0, 1.5, 1.0]
        out.append(np.maximum(sh.radiance(c, d), 0.05).astype(F32))
    return out


def test_env_radiance_reads_levels_as_numpy_does(glsl, ctx):
    rng = np.random.default_rng(6)
    levels = smooth_levels(rng)
    tex = upload_levels(ctx, levels)
    try:
        d = hard_directions(rng)
        rough = rng.uniform(0, 1, len(d))
        rough[:10] = [0, 1, 0.5, 0.2, 0.0, 1.0, 0.33, 0.66, 0.99, 0.01]
        rot = np.radians(25.0)
        r = np.array([[np.cos(rot), 0, np.sin(rot)], [0, 1, 0], [-np.sin(rot), 0, np.cos(rot)]])

        def setup(prog):
            set_uniforms(prog, {"u_env_to_map": r.T, "u_env_intensity": 2.0, "u_env_max_lod": float(len(levels) - 1)})
            bind(prog, "u_env_radiance", tex)

        gpu = glsl.evaluate("lib/environment.glsl", "env_radiance(d, r)", {"d": d, "r": rough}, 3, setup=setup)
        ref = 2.0 * split_sum.sample_levels(levels, d @ r, rough * (len(levels) - 1))
        # the GPU filters with fixed-point weights (llvmpipe: 8 bits): 1/256 of a texel step
        assert_close_fp32(gpu, ref, rtol=4e-3, atol=1e-3, what="env_radiance")
    finally:
        tex.release()


def test_env_brdf_reads_the_table_as_numpy_does(glsl, ctx):
    table = split_sum.brdf_table(16, 64).astype(F32)
    tex = upload_table(ctx, table)
    try:
        nv, r = (a.ravel() for a in np.meshgrid([0.0, 1e-4, 0.1, 0.37, 0.5, 0.9, 1.0], [0.0, 0.05, 0.3, 0.5, 1.0]))
        gpu = glsl.evaluate(
            "lib/environment.glsl", "env_brdf(nv, r)", {"nv": nv, "r": r}, 2, setup=lambda p: bind(p, "u_env_brdf", tex)
        )
        assert_close_fp32(gpu, split_sum.table_lookup(table, nv, r), rtol=4e-3, atol=1e-3, what="env_brdf")
    finally:
        tex.release()


def test_split_sum_table_against_brute_force_integration():
    from skinlab.scene.optics.brdf import ggx_alpha, specular_ggx

    table = split_sum.brdf_table()
    for rough, mu in ((1.0, 1.0), (0.5, 0.5), (0.2, 0.9), (0.0, 1.0)):
        n = 400
        th = (np.arange(n) + 0.5) / n * np.pi / 2
        ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * np.pi
        t, p = np.meshgrid(th, ph, indexing="ij")
        l = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
        v = np.array([np.sqrt(1 - mu * mu), 0, mu])
        h = l + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        dw = np.sin(t) * (np.pi / 2 / n) * (np.pi / n)
        for f0 in (0.04, 1.0):
            f = specular_ggx(l[..., 2], mu, h[..., 2], (l * h).sum(-1), ggx_alpha(rough), np.full(3, f0))[..., 0]
            exact = (f * l[..., 2] * dw).sum()
            a, b = split_sum.table_lookup(table, mu, rough)
            if rough > 0:  # roughness 0 is a delta the grid cannot integrate: A = 1, B = 0 exactly
                assert abs(f0 * a + b - exact) < 0.01 * exact + 2e-3, (rough, mu, f0, f0 * a + b, exact)
    assert np.allclose(split_sum.table_lookup(table, 1.0, 0.0), [1.0, 0.0], atol=1e-6)


def test_specular_occlusion_matches_numpy(glsl):
    nv, vis, r = (
        a.ravel() for a in np.meshgrid([0.0, 0.01, 0.3, 0.7, 1.0, -0.1], [0.0, 0.2, 0.5, 1.0], [0.0, 0.4, 1.0])
    )
    gpu = glsl.evaluate("lib/environment.glsl", "env_specular_occlusion(nv, vis, r)", {"nv": nv, "vis": vis, "r": r})
    ref = split_sum.specular_occlusion(nv, vis, r)
    assert_close_fp32(gpu[:, 0], ref, rtol=1e-4, atol=2e-6, what="specular occlusion")
    assert np.allclose(ref[vis == 1.0], 1.0) and np.allclose(ref[vis == 0.0], 0.0)


def test_prefilter_keeps_the_map_energy_and_levels_blur():
    rng = np.random.default_rng(7)
    img = np.maximum(rng.normal(1.0, 0.5, (64, 128, 3)), 0).astype(F32)
    img[20, 40] = 50.0  # one bright texel
    levels = split_sum.prefilter(img, levels=4, width=64, samples=32)
    mean = []
    for lv in levels:
        om = split_sum.texel_solid_angles(lv.shape[1], lv.shape[0])
        mean.append((lv.mean(-1) * om).sum() / (4 * np.pi))
    om = split_sum.texel_solid_angles(128, 64)
    src = (img.mean(-1) * om).sum() / (4 * np.pi)
    assert np.allclose(mean, src, rtol=0.02), (mean, src)
    assert levels[-1].std() < levels[1].std() < levels[0].std()  # rougher levels are smoother
    assert [lv.shape for lv in levels] == [(32, 64, 3), (16, 32, 3), (8, 16, 3), (4, 8, 3)]


def test_band_ratio_matches_numpy(glsl):
    from skinlab.render.environment import env_band_ratio

    rng = np.random.default_rng(9)
    coeffs = rng.normal(size=(9, 3)) * 0.4
    coeffs[0] = [3.0, 2.0, 1.0]
    coeffs[:, 2] *= 1e-9  # a dark channel: where the SH irradiance vanishes the uniform ratio
    n = hard_directions(rng)
    l0, l1, l2 = (rng.uniform(0.05, 0.3, (len(n), 3)) for _ in range(3))
    uni = rng.uniform(0.02, 0.1, (len(n), 3))
    prelude = "vec3 br(vec3 n, vec3 a, vec3 b, vec3 c, vec3 u) { return env_band_ratio(n, a, b, c, u); }"
    gpu = glsl.evaluate(
        "lib/environment.glsl", "br(n, a, b, c, u)", {"n": n, "a": l0, "b": l1, "c": l2, "u": uni}, 3,
        prelude=prelude, setup=sh_setup(coeffs),
    )  # fmt: skip
    ref = env_band_ratio(coeffs, n, [l0, l1, l2], uni)
    assert_close_fp32(gpu, ref, rtol=2e-3, atol=1e-6, what="env_band_ratio")
    assert (ref <= 4 * uni + 1e-12).all() and (ref >= 0).all()


def test_band_factors_integrate_single_scattering_and_the_entry_kernel_fits():
    """Funk-Hecke: under a band-limited sky L = sum L_lm Y_lm, Jensen's single scattering (isotropic
    phase) toward cosine mu is sum_l lambda_l(mu) sum_m L_lm Y_lm(n); the light entering the multiple
    scattering is sum_k c_k int L t^(k+1) dw (entry_kernel_coefficients): against brute-force
    integration over the hemisphere, at index 1 and 1.3."""
    from skinlab.scene.optics import boundary as bd

    rng = np.random.default_rng(10)
    c = rng.normal(size=(9, 1)) * 0.2
    c[0] = 2.0
    n = np.array([0.0, 0.0, 1.0])
    t = (np.arange(200) + 0.5) / 200 * np.pi / 2
    p = (np.arange(64) + 0.5) / 64 * 2 * np.pi
    tt, pp = np.meshgrid(t, p, indexing="ij")
    w = np.stack([np.sin(tt) * np.cos(pp), np.sin(tt) * np.sin(pp), np.cos(tt)], -1)
    dw = np.sin(tt) * (np.pi / 2 / 200) * (2 * np.pi / 64)
    L = sh.radiance(c, w)[..., 0]
    m = w[..., 2]
    y = sh.sh9_basis(n)
    s = [y[0] * c[0, 0], y[1:4] @ c[1:4, 0], y[4:9] @ c[4:9, 0]]
    for eta in (1.0, 1.3):
        a, mu = 0.7, 0.6
        # the single-scattering kernel of single_ambient_albedo, per unit incident radiance and dw
        e = float(bd.clamp_eta(eta))
        ct = lambda x, e=e: np.sqrt(np.maximum((e - 1) * (e + 1) + x * x, 0)) / e  # noqa: E731
        tr = (lambda x: np.ones_like(x)) if e == 1.0 else (lambda x, e=e: 1 - bd.fresnel_dielectric(x, e))  # noqa: E731
        k = a * tr(np.array(mu)) * tr(m) * m / (4 * np.pi * e * e * (ct(m) + ct(np.array(mu))))
        brute = (L * k * dw).sum()
        bands = sum(bd.single_ambient_band(a, eta, np.array([mu]), b)[0] * s[b] for b in range(3))
        assert bands == pytest.approx(brute, rel=2e-3), (eta, bands, brute)
        coef = bd.entry_kernel_coefficients(np.full(3, a), np.ones(3), eta)
        brute = (L * bd.ms_albedo(a, eta, m) * m * dw).sum()
        fitted = sum(coef[k, 0] * (L * m ** (k + 1) * dw).sum() for k in range(len(coef)))
        assert fitted == pytest.approx(brute, rel=5e-3)
        # a uniform sky's entry is exact: 2 pi sum_k c_k / (k + 2) = pi A_ms_d
        uniform = 2 * np.pi * sum(coef[k, 0] / (k + 2) for k in range(len(coef)))
        assert uniform == pytest.approx(np.pi * bd.hemispherical(lambda x, a=a, eta=eta: bd.ms_albedo(a, eta, x)))


def _lobe_map(width=128):
    """A sky that nine SH bands do not hold: a dim gradient and a bright lobe (a softbox of about 15
    degrees, 40 x the floor), and the texels' directions and solid angles."""
    d = split_sum.texel_directions(width, width // 2)
    axis = np.array([0.5, 0.3, 0.81])
    axis /= np.linalg.norm(axis)
    lobe = 40.0 * np.exp((d @ axis - 1.0) / 0.02)
    img = (0.3 + 0.2 * d[..., 1:2]) * np.array([1.0, 0.9, 0.8]) + lobe[..., None] * np.array([1.0, 1.0, 0.9])
    return img, d.reshape(-1, 3), split_sum.texel_solid_angles(width, width // 2).ravel()


def test_kernel_maps_are_the_exact_convolutions_and_a_uniform_sky_is_closed_form():
    img, d, om = _lobe_map(64)
    k = split_sum.kernel_maps(img, 32, source_width=64)
    assert k.shape == (split_sum.KERNEL_LAYERS, 16, 32, 3)
    n = split_sum.texel_directions(32, 16).reshape(-1, 3)
    t = np.maximum(n @ d.T, 0.0)
    w = split_sum.kernel_weights(t)
    brute = np.einsum("lnt,tc,t->lnc", w, img.reshape(-1, 3), om).reshape(k.shape)
    assert np.allclose(k, brute, rtol=1e-4, atol=1e-6)
    # layer 0 (a grazing view) is the hemisphere's radiance over 4 pi; the t^k layers are cosine powers
    assert np.allclose(w[0], (t > 0) / (4 * np.pi))
    assert np.allclose(w[split_sum.KERNEL_NODES], t**2) and np.allclose(w[-1], t**3)
    flat = split_sum.kernel_maps(np.full((32, 64, 3), 2.0), 32, source_width=64)
    closed = split_sum.uniform_kernel_maps([2.0, 2.0, 2.0])
    assert np.allclose(flat, closed[:, :1, :1], rtol=2e-3)


def test_index_matched_transport_of_a_map_with_a_lobe_is_exact_per_normal():
    """The light a half-space of isotropic skin takes from a map with a softbox-like lobe, per normal,
    against Chandrasekhar's index-matched transport integrated over the map's texels: the single
    scattering toward each view (first order, a/(4 pi) t / (mu + t)) from the kernel maps within 1 %,
    the light entering the multiple scattering within 1 %, where the SH-band ratio applied to the
    exact irradiance (the former way, env_band_ratio) is several percent off on the same normals."""
    from skinlab.render.environment import env_band_ratio, env_entering, env_single
    from skinlab.scene.optics import boundary as bd

    img, d, om = _lobe_map(128)
    kernels = split_sum.kernel_maps(img)
    irr = split_sum.irradiance_map(img)
    coeffs = sh.project(img.reshape(-1, 3), d, om)
    rng = np.random.default_rng(12)
    n = unit(rng, 200)
    t = np.maximum(n @ d.T, 0.0)
    e_exact = np.einsum("nt,tc,t->nc", t, img.reshape(-1, 3), om)
    lit = e_exact[:, 0] > 0.2 * e_exact[:, 0].max()  # normals the lobe lights: where the error shows
    alpha, colour = np.array([0.894, 0.687, 0.494]), np.array([0.463, 0.228, 0.126])
    single = alpha / colour
    lam = bd.single_band_tables(alpha, colour, 1.0)
    for mu in (0.1, 0.5, 0.9):
        exact = single * np.einsum("nt,tc,t->nc", t / (4 * np.pi * (mu + t) + 1e-300) * (t > 0), img.reshape(-1, 3), om)
        got = env_single(kernels, n, np.full(len(n), mu), single)
        err = np.abs(got - exact)[lit].sum() / exact[lit].sum()
        assert err < 0.01, (mu, err)
        bands = [bd.table_lookup(lam[b], np.full(len(n), mu)) for b in range(3)]
        old = e_exact * env_band_ratio(coeffs, n, bands, bands[0] / np.pi)
        assert np.abs(old - exact)[lit].sum() / exact[lit].sum() > 3 * err
    coef = bd.entry_kernel_coefficients(alpha, colour, 1.0)
    gm = np.linspace(0.0, 1.0, 2001)
    for c in range(3):
        ams = np.interp(t, gm, bd.ms_albedo(alpha[c], 1.0, gm))
        exact = np.einsum("nt,t,t->n", ams * t, img.reshape(-1, 3)[:, c], om) / colour[c]
        got = env_entering(kernels, irr, n, coef)[:, c]
        assert np.abs(got - exact)[lit].sum() / exact[lit].sum() < 0.01, c


def test_env_kernel_and_the_matched_single_scattering_read_as_numpy_does(glsl, ctx):
    from skinlab.render.environment import env_single, upload_kernels

    rng = np.random.default_rng(13)
    w = 32
    c = rng.normal(size=(9, 3)) * 0.08
    c[0] = [2.0, 1.5, 1.0]
    kernels = split_sum.kernel_maps(np.maximum(sh.radiance(c, split_sum.texel_directions(64, 32)), 0.0), w, 64)
    tex = upload_kernels(ctx, kernels)
    single = np.array([1.9, 3.0, 3.9])
    try:
        n = hard_directions(rng)
        mu = rng.uniform(0.0, 1.0, len(n))
        mu[:3] = [0.0, 1.0, 0.5]

        def setup(prog):
            set_uniforms(prog, {"u_env_to_map": np.eye(3), "u_env_intensity": 1.5})
            set_uniforms(prog, {"u_sss_eta": 1.0, "u_sss_env_single": tuple(single)})
            bind(prog, "u_env_kernels", tex)

        for layer in (0, 7, split_sum.KERNEL_NODES, split_sum.KERNEL_LAYERS - 1):
            gpu = glsl.evaluate("lib/environment.glsl", f"env_kernel(n, {layer})", {"n": n}, 3, setup=setup)
            ref = 1.5 * split_sum.kernel_lookup(kernels, n, layer)
            assert_close_fp32(gpu, ref, rtol=4e-3, atol=1e-4, what=f"env_kernel layer {layer}")
        gpu = glsl.evaluate("lib/env_single.glsl", "env_single(n, mu)", {"n": n, "mu": mu}, 3, setup=setup)
        assert_close_fp32(gpu, 1.5 * env_single(kernels, n, mu, single), rtol=4e-3, atol=1e-4, what="env_single")
    finally:
        tex.release()
