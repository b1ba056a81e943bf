"""Oblique entry (skinlab/shaders/lib/sss_oblique.glsl vs skinlab/scene/optics/oblique.py): the diffusion of light
arriving at an angle is centred sin(theta_t) z0 along the surface from where it entered (Wang &
Jacques 1995), and the shadow lookup point built from it; the entry's spread (three lookups weighted per
channel, single scattering's pair). Twins within 1e-4, hard cases finite."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics.constants import ENTRY_RAMP_N1, ENTRY_RAMP_N2, ENTRY_RAMP_N3, LUMA_B, LUMA_G, LUMA_R
from skinlab.scene.optics.oblique import (
    LUMA,
    entry_diffusion_k,
    entry_offset,
    entry_pair_weights,
    entry_point,
    entry_ramp_means,
    entry_ramp_nodes,
    entry_ramp_points,
    entry_ramp_weights,
    near_entry,
    near_entry_gain,
    single_entry_k,
    single_pair_rate,
)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _cases(n=600, seed=5):
    rng = np.random.default_rng(seed)
    ng = _unit(rng.normal(size=(n, 3)))
    l = _unit(rng.normal(size=(n, 3)))
    z0 = rng.uniform(0.0, 3.0, (n, 3))
    eta = rng.uniform(0.7, 1.6, n)
    mpu = np.full(n, 1.0)
    mpu[n // 2 :] = 1000.0  # a scene in metres
    # hard cases: normal incidence, exactly grazing, light from below, no scattering, eta 1 and < 1
    l[:10] = ng[:10]
    l[10:20] = _unit(np.cross(ng[10:20], rng.normal(size=(10, 3))))
    l[20:30] = -ng[20:30]
    z0[30:40] = 0.0
    eta[40:50] = 1.0
    eta[50:60] = 0.5
    return ng, l, z0, eta, mpu


def test_entry_offset_twin(glsl):
    ng, l, z0, eta, mpu = _cases()
    gpu = glsl.evaluate(
        "lib/sss_oblique.glsl",
        "sss_entry_offset(ng, l, z0, eta, mpu)",
        {"ng": ng, "l": l, "z0": z0, "eta": eta, "mpu": mpu},
        out_components=3,
    )
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)  # the inputs the GPU sees
    ref = entry_offset(f32(ng), f32(l), f32(z0), f32(eta), mpu)
    assert np.isfinite(ref).all() and np.abs(ref[:10]).max() < 1e-6 and (ref[30:40] == 0).all()
    # in millimetres: the same absolute accuracy whatever the scene's unit
    assert_close_fp32(gpu * mpu[:, None], ref * mpu[:, None], rtol=1e-4, atol=1e-5, what="sss_entry_offset")


def test_entry_point_twin(glsl):
    ng, l, z0, eta, _ = _cases(seed=6)
    world = np.random.default_rng(7).uniform(-5, 5, ng.shape)
    gpu = glsl.evaluate(
        "lib/sss_oblique.glsl",
        "sss_entry_point(w, ng, l, z0, eta, 1.0)",
        {"w": world, "ng": ng, "l": l, "z0": z0, "eta": eta},
        out_components=3,
    )
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
    ref = entry_point(f32(world), f32(ng), f32(l), f32(z0), f32(eta), 1.0)
    assert_close_fp32(gpu, ref, rtol=1e-4, atol=2e-5, what="sss_entry_point")


def test_offset_is_wang_and_jacques_shift():
    """sin(theta_t) z0 against the light's travel along the surface, z0 weighted by luminance."""
    ng = np.array([[0.0, 0.0, 1.0]])
    z0 = np.array([1.3, 0.95, 0.67])  # skin1's 1 / mu_t' (mm)
    lum = z0 @ [LUMA_R, LUMA_G, LUMA_B]
    assert np.allclose(LUMA, [0.2126, 0.7152, 0.0722]) and LUMA.sum() == pytest.approx(1.0)
    for deg in (0.0, 30.0, 45.0, 80.0, 90.0):
        t = np.radians(deg)
        l = np.array([[0.0, -np.sin(t), np.cos(t)]])  # light from -y: it travels toward +y
        for eta in (1.0, 1.4):
            off = entry_offset(ng, l, z0, eta, 1.0)[0]
            sin_t = np.sin(t) / eta
            assert off == pytest.approx([0.0, -sin_t * lum, 0.0], abs=1e-12)  # toward the light, in the plane
    # a scene in metres: the same millimetres, in scene units
    l = _unit(np.array([[0.0, -1.0, 1.0]]))
    assert entry_offset(ng, l, z0, 1.0, 1000.0) == pytest.approx(entry_offset(ng, l, z0, 1.0, 1.0) / 1000.0)
    # total internal reflection side (eta < 1): sin(theta_t) is clamped at 1, |offset| <= z0
    grazing = np.array([[0.0, -1.0, 0.0]])
    assert np.linalg.norm(entry_offset(ng, grazing, z0, 0.5, 1.0)) == pytest.approx(lum)
    # the lookup point moves toward the light by the offset's length: for a directional light the
    # point's place across the shadow map is that of the offset alone
    p = entry_point(np.zeros((1, 3)), ng, l, z0, 1.0, 1.0)[0]
    off = entry_offset(ng, l, z0, 1.0, 1.0)[0]
    across = lambda x: x - l[0] * (x @ l[0])
    assert across(p) == pytest.approx(across(off)) and (p - off) @ l[0] == pytest.approx(np.linalg.norm(off))


def _near_cases(n=600, seed=8):
    """Points d_mm from a light at a finite distance: any direction and distance (0.05-200 mm), with the
    hard cases: the light straight above, in the tangent plane, below it, at the point, z0 = 0."""
    rng = np.random.default_rng(seed)
    ng = _unit(rng.normal(size=(n, 3)))
    d = _unit(rng.normal(size=(n, 3))) * rng.uniform(0.05, 200.0, (n, 1))
    z0 = rng.uniform(0.0, 3.0, (n, 3))
    eta = rng.uniform(0.8, 1.6, n)
    d[:10] = ng[:10] * rng.uniform(0.1, 5.0, (10, 1))
    d[10:20] = _unit(np.cross(ng[10:20], rng.normal(size=(10, 3)))) * 2.0
    d[20:30] = -np.abs(d[20:30] @ ng[20:30].T).diagonal()[:, None] * ng[20:30]
    d[30:35] = 0.0
    z0[35:45] = 0.0
    return d, ng, z0, eta


NEAR_OUTS = """
vec3 near_g(vec3 d, vec3 ng, vec3 z0, float eta) { vec3 mu; return sss_near_entry(d, ng, z0, eta, mu); }
vec3 near_mu(vec3 d, vec3 ng, vec3 z0, float eta) { vec3 mu; sss_near_entry(d, ng, z0, eta, mu); return mu; }
"""


def test_near_entry_twin(glsl):
    d, ng, z0, eta = _near_cases()
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
    g_ref, mu_ref = near_entry(f32(d), f32(ng), f32(z0), f32(eta))
    assert np.isfinite(g_ref).all() and np.isfinite(mu_ref).all()
    assert (g_ref[10:35] == 1.0).all()  # in or below the plane, at the point: unchanged
    assert g_ref[35:45] == pytest.approx(np.ones((10, 3)), rel=1e-6)  # no scattering: no shift
    for expr, ref in (("near_g(d, ng, z0, eta)", g_ref), ("near_mu(d, ng, z0, eta)", mu_ref)):
        gpu = glsl.evaluate(
            "lib/sss_oblique.glsl",
            expr,
            {"d": d, "ng": ng, "z0": z0, "eta": eta},
            out_components=3,
            prelude=NEAR_OUTS,
        )
        assert_close_fp32(gpu, ref, rtol=2e-4, atol=2e-5, what=expr)


def test_near_entry_gain_twin(glsl):
    from skinlab.gl.uniforms import set_array, set_uniforms
    from skinlab.scene.optics import boundary as b

    d, ng, z0, _ = _near_cases(seed=9)
    for eta in (1.0, 1.3):
        t = b.boundary_tables((0.894, 0.687, 0.494), (0.46, 0.23, 0.126), eta)

        def setup(prog, t=t, eta=eta):
            set_array(prog, "u_sss_entry", t.entry, b.ANGULAR_NODES)
            set_uniforms(prog, {"u_sss_eta": eta})

        gpu = glsl.evaluate(
            "lib/sss_near_light.glsl", "sss_near_entry_gain(d, ng, z0)", {"d": d, "ng": ng, "z0": z0}, 3, setup=setup
        )
        f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
        ref = near_entry_gain(f32(d), f32(ng), f32(z0), eta, t.entry)
        assert np.isfinite(ref).all()
        assert_close_fp32(gpu, ref, rtol=3e-4, atol=3e-5, what="sss_near_entry_gain")


def test_near_entry_keeps_the_flux_and_moves_it_away():
    """Under a point light h above a plane the diffusion's irradiance E(s) mu_s / J integrates to the
    flux that entered (the Jacobian of the shift), and its mean distance from the light's foot grows
    by about the Wang & Jacques shift k sin(theta) (here its flux-weighted mean)."""
    h, k = 2.0, np.array([1.3, 0.95, 0.67])
    rho = np.concatenate([np.linspace(0.0, 20.0, 40001)[1:], np.geomspace(20.0, 2e5, 20000)[1:]])
    d = np.stack([rho, np.zeros_like(rho), np.full_like(rho, h)], -1)
    ng = np.tile([0.0, 0.0, 1.0], (len(rho), 1))
    g, mu_s = near_entry(d, ng, k, 1.0)
    e_mu = h / (rho**2 + h * h) ** 1.5  # E mu of a unit-intensity point light
    ring = np.gradient(rho) * 2 * np.pi * rho
    flux = np.sum(e_mu * ring)  # 2 pi (1 - h / d_max): the whole plane's
    assert flux == pytest.approx(2 * np.pi, rel=1e-3)
    moved = (e_mu[:, None] * g * ring[:, None]).sum(0)
    assert moved == pytest.approx(np.full(3, flux), rel=2e-3)
    # each point's entry lies nearer the foot, at the cosine the map says
    rs = np.sqrt(np.maximum(h * h / mu_s**2 - h * h, 0.0))
    assert (rs <= rho[:, None] + 1e-9).all()
    on = rho < 1e3  # past that the cosine is under NEAR_MIN_COS's reach of float precision in this check
    want = np.broadcast_to(rho[on, None], rs[on].shape)
    assert rs[on] + k * rs[on] / np.sqrt(rs[on] ** 2 + h * h) == pytest.approx(want, rel=1e-6, abs=1e-6)
    # the light moves away from the foot: within 20 mm its mean distance grows, red (longest z0) most
    near = rho < 20.0
    w0 = e_mu[near] * ring[near]
    mean0 = np.sum(w0 * rho[near]) / w0.sum()
    w1 = (e_mu * g.T).T[near] * ring[near, None]
    mean1 = (w1 * rho[near, None]).sum(0) / w1.sum(0)
    assert (mean1 > mean0).all() and mean1[0] > mean1[1] > mean1[2]
    # a light far away (directional-like within a small patch): no change
    far = near_entry(np.array([[0.3, 0.0, 1e6]]), ng[:1], k, 1.0)[0]
    assert far == pytest.approx(np.ones((1, 3)), abs=1e-5)


RAMP_OUTS = """
vec3 ramp_mix(vec3 m, vec3 v) { return sss_ramp_mix(m, v.x, v.y, v.z); }
vec3 single_pair(float k, vec3 rate, vec3 v) { return sss_single_pair(k, rate, v.x, v.y); }
vec3 ramp_means_at(vec3 w, vec3 ng, vec3 l, vec3 z0, vec3 decay, float eta) {
    vec3 p1, p2, p3;
    return sss_ramp_setup(w, ng, l, z0, decay, eta, 1.0, p1, p2, p3);
}
vec3 ramp_point_at(vec3 w, vec3 ng, vec3 l, vec3 z0, vec3 decay, float eta, float k) {
    vec3 p[3];
    sss_ramp_setup(w, ng, l, z0, decay, eta, 1.0, p[0], p[1], p[2]);
    return k < 0.5 ? p[0] : (k < 1.5 ? p[1] : p[2]);
}
vec3 means_single(vec3 z0, float mu_l, float mu_v, float eta) {
    return sss_ramp_means(z0, vec3(sss_single_k(mu_l, mu_v, eta)));
}
vec3 means_diffusion(vec3 z0, vec3 decay, float mu_l, float eta) {
    return sss_ramp_means(z0, sss_diffusion_k(decay, mu_l, eta));
}
"""


def _ramp_cases(n=400, seed=11):
    rng = np.random.default_rng(seed)
    z0 = rng.uniform(0.0, 3.0, (n, 3))
    z0[:10] = 0.0  # no scattering
    z0[10:20, 1:] = 0.0  # red alone
    alpha = rng.uniform(0.0, 1.0, (n, 3))
    alpha[20:30] = 1.0  # no absorption: the diffusion's k is 1
    mu_l, mu_v = rng.uniform(0.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    mu_l[30:40], mu_v[40:50] = 0.0, 0.0  # grazing light, grazing view
    eta = rng.uniform(0.8, 1.6, n)
    v = rng.uniform(0.0, 1.0, (n, 3))
    return z0, alpha, mu_l, mu_v, eta, v


def test_entry_ramp_twins(glsl):
    z0, alpha, mu_l, mu_v, eta, v = _ramp_cases()
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)
    decay = np.sqrt(3.0 * (1.0 - f32(alpha)))
    m_d = entry_ramp_means(f32(z0), entry_diffusion_k(f32(alpha), f32(mu_l), f32(eta)))
    m_s = entry_ramp_means(f32(z0), single_entry_k(f32(mu_l), f32(mu_v), f32(eta)))
    assert np.isfinite(m_d).all() and np.isfinite(m_s).all() and (m_d >= 0).all() and (m_d[:10] <= 1.0).all()
    ins = {"z0": z0, "decay": decay, "mu_l": mu_l, "mu_v": mu_v, "eta": eta, "m": m_d, "v": v}
    for expr, ref in (
        ("means_diffusion(z0, decay, mu_l, eta)", m_d),
        ("means_single(z0, mu_l, mu_v, eta)", m_s),
        ("sss_ramp_nodes(m)", entry_ramp_nodes(f32(m_d))),
        ("ramp_mix(m, v)", np.einsum("ncs,ns->nc", entry_ramp_weights(f32(m_d)), f32(v))),
    ):
        gpu = glsl.evaluate("lib/sss_oblique.glsl", expr, ins, out_components=3, prelude=RAMP_OUTS)
        assert_close_fp32(gpu, ref, rtol=2e-4, atol=2e-5, what=expr)
    # single scattering's pair from the material's rate (the frame's one exp2) is the pair of its means
    k = single_entry_k(f32(mu_l), f32(mu_v), f32(eta))
    rate = np.array([single_pair_rate(z) for z in f32(z0)])
    want = np.einsum("ncs,ns->nc", entry_pair_weights(entry_ramp_means(f32(z0), k)), f32(v)[:, :2])
    scat = (f32(z0) > 0).all(axis=1)  # a channel without scattering: the rate's cap, all at the point
    ins = {"k": k, "rate": rate, "v": v}
    for expr, ref in (("single_pair(k, rate, v)", want),):
        gpu = glsl.evaluate("lib/sss_oblique.glsl", expr, ins, out_components=3, prelude=RAMP_OUTS)
        assert_close_fp32(gpu[scat], ref[scat], rtol=2e-4, atol=2e-5, what=expr)
        assert np.isfinite(gpu).all()


def test_entry_ramp_spreads_each_channel_as_an_exponential():
    """The three lookups stand for an exponential distance of mean m: their weights sum to 1, are a third
    each for a channel at the luminance mean, and the lookups' mean for each channel is its own m within
    25 % over a 4x range of m (the coarse three-point rule); single scattering's pair keeps its mean
    within a factor (its nodes are 0 and the whole offset). The diffusion's k is 1 without absorption and
    grows with it and with the light's cosine; single scattering's is 2 at normal incidence and view."""
    m = np.array([[1.3, 1.0, 0.7], [0.5, 0.5, 0.5], [2.0, 1.0, 0.5]])
    w = entry_ramp_weights(m)
    assert w.sum(-1) == pytest.approx(np.ones((3, 3)))
    assert w[1] == pytest.approx(np.full((3, 3), 1.0 / 3.0))
    nodes = entry_ramp_nodes(m)
    mean = np.einsum("ncs,ns->nc", w, nodes)
    assert mean == pytest.approx(m, rel=0.25)
    assert np.einsum("s,s->", np.full(3, 1.0 / 3.0), [ENTRY_RAMP_N1, ENTRY_RAMP_N2, ENTRY_RAMP_N3]) == pytest.approx(
        1.0
    )
    assert entry_ramp_weights(np.array([[1e-12, 1.0, 1.0]]))[0, 0] == pytest.approx([1.0, 0.0, 0.0])
    pw = entry_pair_weights(np.array([0.25, 1.0, 4.0]))
    assert pw.sum(-1) == pytest.approx(np.ones(3)) and np.all(np.diff(pw[:, 1]) > 0)  # longer: more from b
    assert entry_diffusion_k(np.array([1.0, 1.0, 1.0]), 0.7, 1.0) == pytest.approx(np.ones(3))
    k = entry_diffusion_k(np.array([0.9, 0.7, 0.5]), np.array([0.2, 0.9]), 1.0)
    assert np.all(np.diff(k, axis=-1) > 0) and np.all(k[1] > k[0])
    assert single_entry_k(1.0, 1.0, 1.4) == pytest.approx(2.0) and single_entry_k(0.3, 0.0, 1.0) == pytest.approx(7.0)
    assert entry_ramp_means(np.zeros(3)) == pytest.approx(np.ones(3))  # no scattering: finite, unused


def test_entry_ramp_setup_twin(glsl):
    """sss_ramp_setup (the diffusion's three lookup points and its means) against entry_ramp_points, the
    entry offset's hard cases included (normal incidence: every point at the surface point, grazing,
    light from below, no scattering, eta 1 and < 1)."""
    ng, l, z0, eta, _ = _cases(seed=12)
    rng = np.random.default_rng(13)
    world = rng.uniform(-5, 5, ng.shape)
    alpha = rng.uniform(0.0, 1.0, ng.shape)
    f32 = lambda x: np.asarray(x, np.float32).astype(np.float64)  # noqa: E731
    m, pts = entry_ramp_points(f32(world), f32(ng), f32(l), f32(z0), f32(alpha), f32(eta), 1.0)
    assert np.isfinite(m).all() and np.isfinite(pts).all()
    assert pts[:10] == pytest.approx(np.repeat(f32(world)[:10, None, :], 3, 1), abs=1e-6)  # normal incidence
    decay = np.sqrt(3.0 * (1.0 - f32(alpha)))
    ins = {"w": world, "ng": ng, "l": l, "z0": z0, "decay": decay, "eta": eta}
    gpu = glsl.evaluate(
        "lib/sss_oblique.glsl", "ramp_means_at(w, ng, l, z0, decay, eta)", ins, out_components=3, prelude=RAMP_OUTS
    )
    assert_close_fp32(gpu, m, rtol=2e-4, atol=2e-5, what="sss_ramp_setup means")
    for k in range(3):
        gpu = glsl.evaluate(
            "lib/sss_oblique.glsl",
            "ramp_point_at(w, ng, l, z0, decay, eta, kk)",
            {**ins, "kk": np.full(len(ng), float(k))},
            out_components=3,
            prelude=RAMP_OUTS,
        )
        assert_close_fp32(gpu, pts[:, k], rtol=1e-4, atol=3e-5, what=f"sss_ramp_setup point {k}")
