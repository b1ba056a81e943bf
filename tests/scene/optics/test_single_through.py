"""Single scattering along the light's path through the medium (skinlab/scene/optics/single_through.py) and
its GLSL twin (lib/sss_single_through.glsl): exact on a plane, near the brute-force integral below a ball's
terminator where the flat term is far off, and not applied where it must not be."""

import numpy as np
import pytest

from skinlab.gl.glsl_eval import assert_close_fp32
from skinlab.scene.optics import single_through as st
from skinlab.scene.optics.single_scattering import single_scatter_brdf
from tests.translucency_maps import distance_texture, layer_textures, lookup_setup, no_exit
from tests.tsd_scenes import skin

SIGMA = np.array([1 / 1.2953, 1 / 0.9524, 1 / 0.6711])  # skin1's extinction per mm (isotropic, reduced)
EYE = np.array([0.0, 0.0, -1.0, 0.0])  # a directional light travelling -z: l = (0, 0, 1)
L = np.array([0.0, 0.0, 1.0])
R = 8.0  # the ball's radius (mm = scene units)
SIZE = 512
HALF = 10.0  # the map spans [-HALF, HALF] in x and y


def _matrix():
    m = np.eye(4)
    m[0, 0] = m[1, 1] = 0.5 / HALF
    m[0, 3] = m[1, 3] = 0.5
    return m


def _texel_centres():
    c = (np.arange(SIZE) + 0.5) / SIZE * 2 * HALF - HALF
    return np.meshgrid(c, c)  # x along columns, y along rows (row 0 at v = 0)


def _ball_map():
    """The distance map of a ball of radius R at the origin under the light: -z of its top, none outside."""
    x, y = _texel_centres()
    q = R * R - x * x - y * y
    return np.where(q > 0, -np.sqrt(np.maximum(q, 0)), 1e30)


def _plane_map(a, b):
    """The distance map of the plane z = a x + b y (its lit side up)."""
    x, y = _texel_centres()
    return -(a * x + b * y)


def _ball_path(p, to, s):
    """The exact path inside the ball along the light (+z) from p + to s (mm)."""
    x = p + to * s
    q = R * R - x[..., 0] ** 2 - x[..., 1] ** 2
    return np.maximum(np.sqrt(np.maximum(q, 0)) - x[..., 2], 0.0)


def _brute_integral(p, to, chord):
    """int_0^chord sigma e^{-sigma (s + d(s))} ds along the view ray inside the ball (midpoint rule)."""
    out = []
    for pi, ti, ci in zip(p, to, chord):
        s = (np.arange(4000) + 0.5) / 4000 * ci
        d = _ball_path(pi[None, :], ti[None, :], s[:, None])
        out.append((SIGMA[None, :] * np.exp(-SIGMA[None, :] * (s + d)[:, None])).sum(0) * ci / 4000)
    return np.array(out)


def _ball_points(angles_deg):
    """Points on the ball at these angles from the terminator (+: the lit side) in the x-z plane, their
    normals, and a viewer along +x+z (toward the camera of the reference scene's kind)."""
    a = np.radians(np.asarray(angles_deg, np.float64))
    n = np.stack([np.cos(a), np.zeros_like(a), np.sin(a)], 1)
    v = np.tile(np.array([0.6, 0.0, 0.8]), (len(a), 1))
    return R * n, n, v


ALPHA = np.array([0.9585, 0.8381, 0.6779])  # skin1's single-scattering albedo (isotropic)

# the GLSL twin's two outputs as one vec4 each: gain (rgb) or f (rgb), and ng.l > 0 in a
GLSL_TERMS = """vec4 through_terms(vec3 p, vec3 nrm, vec3 view, vec3 sig, bool shadow) {
    vec3 gain, f;
    SingleView sv = single_scatter_view(nrm, view, max(u_sss_eta, 1.0));
    sss_single_through(0, p, nrm, vec3(0.0, 0.0, 1.0), sv, sig, gain, f);
    return vec4(shadow ? f : gain, 0.0);
}
vec4 through_gain(vec3 p, vec3 nrm, vec3 view, vec3 sig) { return through_terms(p, nrm, view, sig, false); }
vec4 through_shadow(vec3 p, vec3 nrm, vec3 view, vec3 sig) { return through_terms(p, nrm, view, sig, true); }"""


def _gain(dist, m, world, n, v, eye=EYE, layers=None, gap=0.0, shrink=0.005):
    return st.single_through(dist, layers, m, eye, world, n, L, v, SIGMA, ALPHA, 1.0, 0.0, shrink, 1.0, gap)[0]


def _shadow(dist, m, world, n, v, layers=None, gap=0.0, alpha=ALPHA, eta=1.0):
    return st.single_through(dist, layers, m, EYE, world, n, L, v, SIGMA, alpha, eta, 0.0, 0.005, 1.0, gap)[1]


def _gpu(glsl, what, world, n, v, setup):
    return glsl.evaluate(
        "lib/sss_single_through.glsl",
        f"{what}(pos, nrm, view, sig)",
        {"pos": world, "nrm": n, "view": v, "sig": np.tile(SIGMA, (len(n), 1))},
        4,
        prelude=GLSL_TERMS,
        setup=setup,
    )[:, :3]


def test_integral_is_exact_for_a_linear_path_and_finite_at_the_edges():
    s = np.array([[0.0, 0.2, 0.7, 2.5]])
    for slope in (0.0, 0.1, 1.0, 10.0, 1e3):
        for start in (0.0, 0.5):
            got = st.through_integral(SIGMA, s, start + slope * s)
            np.testing.assert_allclose(got[0], np.exp(-SIGMA * start) / (1 + slope), rtol=1e-12)
    # a path that shrinks as fast as the ray goes (a segment's rate 0), one that shrinks faster, a huge one
    for d in ([1.0, 0.8, 0.3, 0.0], [2.0, 0.5, 0.2, 0.1], [1e6, 1e6, 1e6, 1e6], [0.0, 0.0, 0.0, 0.0]):
        got = st.through_integral(SIGMA, s, np.array([d]))
        assert np.all(np.isfinite(got)) and np.all(got >= 0)
    assert np.all(st.through_integral(SIGMA, s, np.array([[1e6] * 4])) == 0)
    np.testing.assert_allclose(st.through_integral(SIGMA, s, np.zeros((1, 4)))[0], 1.0, rtol=1e-12)


def test_the_integrals_glsl_twin_is_finite_however_steep_the_path(glsl):
    """A path that falls 80 mm in the first segment (a far chord at the point, none below: the head's
    rims) overflowed the segment's exponential; the twin and NumPy agree and stay finite."""
    s = np.tile([0.0, 0.15, 0.6, 2.0], (6, 1))
    d = np.array(
        [
            [80.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.3, 1.2, 4.0],
            [5.0, 4.85, 4.4, 3.0],
            [0.0, 1e-6, 2e-6, 1e-5],
            [1e4, 1e4, 0.0, 1e4],
        ]
    )
    sig = np.tile(SIGMA, (6, 1))
    sig[1] = (1e-8, 1.0, 1e3)  # a channel that hardly scatters (its light goes on), one that stops at once
    ref = st.through_integral(sig, s, d)
    assert np.all(np.isfinite(ref)) and np.all(ref >= 0)
    np.testing.assert_allclose(ref[1, 0], 1.0, rtol=1e-6)  # d = 0: the exponential's whole weight, at any rate
    prelude = """vec4 integral(vec4 s4, vec4 d4, vec3 sig) {
        float s[4] = float[4](s4.x, s4.y, s4.z, s4.w);
        float d[4] = float[4](d4.x, d4.y, d4.z, d4.w);
        return vec4(sss_single_through_integral(sig, s, d), 0.0);
    }"""
    gpu = glsl.evaluate(
        "lib/sss_single_through.glsl",
        "integral(s4, d4, sig)",
        {"s4": s, "d4": d, "sig": sig},
        4,
        prelude=prelude,
    )[:, :3]
    assert np.all(np.isfinite(gpu))
    assert_close_fp32(gpu, ref, atol=1e-5, what="sss_single_through_integral")


def test_on_a_plane_the_gain_is_one_at_every_incidence(ctx, glsl):
    a, b = 0.3, -0.2  # a tilted plane
    dist = _plane_map(a, b)
    ng = np.array([-a, -b, 1.0]) / np.linalg.norm([-a, -b, 1.0])
    # points on the plane, the light's cosine there fixed by the tilt; viewers from steep to grazing
    xy = np.array([[0.5, 1.0], [-2.0, 3.0], [4.0, -1.0], [0.0, 0.0]])
    world = np.column_stack([xy, a * xy[:, 0] + b * xy[:, 1]])
    t = np.cross(ng, [1.0, 0, 0])
    t /= np.linalg.norm(t)
    v = np.array([ng, 0.3 * ng + t, 0.05 * ng + t, 0.7 * ng - t])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    m, n = _matrix(), np.tile(ng, (4, 1))
    np.testing.assert_allclose(_gain(dist, m, world, n, v, shrink=0.01), 1.0, atol=1e-9)
    tex, none = distance_texture(ctx, dist), no_exit(ctx)
    setup = lookup_setup([tex, tex], [m, m], [EYE, EYE], 0.01, 1.0, skin(), exits=(none, none))
    gpu = _gpu(glsl, "through_gain", world, n, v, setup)
    assert_close_fp32(gpu, np.ones((4, 3)), atol=2e-4, what="sss_single_through's gain on a plane")


def test_below_a_balls_terminator_it_follows_the_brute_force_integral(ctx, glsl):
    dist, m = _ball_map(), _matrix()
    world, n, v = _ball_points([2.0, 5.0, 10.0, 20.0, 40.0])  # the lit side, near the terminator and beyond
    gain = _gain(dist, m, world, n, v)
    co, cto, to, _ = st.view(n, v, 1.0)
    chord = -2 * np.sum(world * to, -1)  # the view ray's path inside the ball
    cg = n @ L
    exact = _brute_integral(world, to, chord) * ((cg + cto) / cg)[:, None]
    # within 30 % of the exact integral, where the flat term (gain 1) is off by up to several times
    assert np.all(np.abs(gain / exact - 1) < 0.3), gain / exact
    assert exact[0].min() > 2.0
    assert np.all(np.diff(gain[:, 2]) < 0)  # blue's gain falls away from the terminator
    tex, none = distance_texture(ctx, dist), no_exit(ctx)
    setup = lookup_setup([tex, tex], [m, m], [EYE, EYE], 0.005, 1.0, skin(), exits=(none, none))
    assert_close_fp32(
        _gpu(glsl, "through_gain", world, n, v, setup), gain, atol=1e-3 * gain.max(), what="the gain on a ball"
    )


def test_past_a_balls_terminator_the_light_is_the_brute_force_integrals(ctx, glsl):
    dist, m = _ball_map(), _matrix()
    world, n, v = _ball_points([-8.0, -12.0, -18.0, -35.0])  # the shadow side (beyond a texel of the rim)
    f = _shadow(dist, m, world, n, v)
    co, cto, to, _ = st.view(n, v, 1.0)
    chord = -2 * np.sum(world * to, -1)
    # the exact term at the matched index: alpha p E times the integral along the view ray inside the ball
    exact = ALPHA * (1 / (4 * np.pi)) * _brute_integral(world, to, chord)
    assert np.all(f[:3] > 0) and np.all(np.diff(f[:3, 0]) < 0)  # it fades into the shadow
    np.testing.assert_allclose(f[:3], exact[:3], rtol=0.3)
    assert f[3].max() < 0.05 * f[0].max()  # a long chord in front (and a grazing view): little left
    assert np.all(_gain(dist, m, world, n, v) == 1.0)  # the lit side's factor does not apply here
    from skinlab.render.boundary import material_boundary, single_scattering_factor

    tabs = material_boundary(skin())
    ref = _shadow(dist, m, world, n, v, alpha=single_scattering_factor(skin(), tabs), eta=tabs.eta)
    tex, none = distance_texture(ctx, dist), no_exit(ctx)
    setup = lookup_setup([tex, tex], [m, m], [EYE, EYE], 0.005, 1.0, skin(), exits=(none, none))
    gpu = _gpu(glsl, "through_shadow", world, n, v, setup)
    assert_close_fp32(gpu, ref, atol=1e-3 * ref.max(), what="sss_single_through's light past the terminator")


def test_not_applied_to_a_sheet_a_sharp_edge_another_part_or_a_point_light(ctx, glsl):
    dist, m = _ball_map(), _matrix()
    # a sheet: the bottom face of a flat part lit from above (its entry face opposed to its own)
    flat = np.zeros((SIZE, SIZE))
    sheet = _shadow(flat, m, np.array([[0.5, 0.5, -2.0]]), np.array([[0.0, 0.0, -1.0]]), np.array([[0.0, 0.6, -0.8]]))
    assert np.all(sheet == 0)
    # a box's side face below its lit top: the entry face at 90 degrees to the point's own (a sharp edge)
    side = _shadow(flat, m, np.array([[0.5, 0.5, -1.0]]), np.array([[1.0, 0.0, 0.0]]), np.array([[0.8, 0.0, 0.6]]))
    assert np.all(side == 0)
    # another part in front: the part layers put the first part's exit above the points
    world, n, v = _ball_points([5.0, -12.0])
    layers = np.zeros((SIZE // 2, SIZE // 2, 3))
    layers[..., 0], layers[..., 1], layers[..., 2] = -30.0, 1.0, -20.0
    np.testing.assert_array_equal(_gain(dist, m, world, n, v, layers=layers, gap=0.1), 1.0)
    np.testing.assert_array_equal(_shadow(dist, m, world, n, v, layers=layers, gap=0.1), 0.0)
    assert _shadow(dist, m, world, n, v)[1].max() > 0  # (without the other part: light)
    # a point light: the flat term
    point = np.array([0.0, 0.0, 50.0, 1.0])
    np.testing.assert_array_equal(_gain(dist, m, world, n, v, eye=point), 1.0)
    # the GLSL twin of the layered case
    tex = distance_texture(ctx, dist)
    ex, en = layer_textures(ctx, layers)
    setup = lookup_setup([tex, tex], [m, m], [EYE, EYE], 0.005, 1.0, skin(), exits=((ex, en), (ex, en)), part_gap=0.1)
    np.testing.assert_array_equal(_gpu(glsl, "through_gain", world, n, v, setup), 1.0)
    np.testing.assert_array_equal(_gpu(glsl, "through_shadow", world, n, v, setup), 0.0)


@pytest.mark.parametrize("eta", [1.0, 1.4])
def test_the_shadow_terms_amplitude_is_the_flat_terms_at_the_same_entry(eta):
    """Where the path inside is the flat one, the shadow side's term equals the flat BRDF-like term times the
    entry cosine (single_scatter_brdf x c): the same amplitude, refraction and Fresnel factors."""
    c, v = 0.4, np.array([0.3, 0.0, 0.954])
    n = np.array([0.0, 0.0, 1.0])
    l = np.array([np.sqrt(1 - c * c), 0.0, c])
    alpha = np.array([0.9, 0.8, 0.7])
    flat = single_scatter_brdf(n, l, v / np.linalg.norm(v), alpha, eta, 0.0) * c
    co, cto, to, t_out = st.view(n, v / np.linalg.norm(v), eta)
    from skinlab.scene.optics.fresnel import fresnel_from_cosines, hg_phase
    from skinlab.scene.optics.single_scattering import refract_cos

    ct = refract_cos(c, eta)
    ti = -l / eta + (c / eta - ct) * n
    amp = (1 - fresnel_from_cosines(c, ct, 1.0, eta)) * t_out[0] * hg_phase(-ti @ to[0], 0.0) / eta**2 * (c / ct)
    s = np.array([[0.0, 0.2, 0.7, 2.5]])
    ours = alpha * amp * st.through_integral(SIGMA, s, s * cto[0] / ct)[0]
    np.testing.assert_allclose(ours, flat, rtol=1e-9)


def test_an_infinite_extinction_leaves_the_light_at_the_point(ctx, glsl):
    """A subsurface radius of 0 (or a denormal) makes the extinction infinite: the term stays finite (it was a
    NaN in blue, inf x 0 at the point: the material fuzz test's find), and none of that channel's light
    reaches past the terminator."""
    dist, m = _ball_map(), _matrix()
    world, n, v = _ball_points([5.0, -12.0])
    sig = np.array([SIGMA[0], SIGMA[1], np.inf])
    gain, f = st.single_through(dist, None, m, EYE, world, n, L, v, sig, ALPHA, 1.0, 0.0, 0.005, 1.0)
    assert np.all(np.isfinite(gain)) and np.all(np.isfinite(f))
    assert gain.min() >= 1.0 and f.min() >= 0.0 and f[1, 2] < 1e-6 * f[1, 0]  # past the terminator: none of it
    tex, none = distance_texture(ctx, dist), no_exit(ctx)
    setup = lookup_setup([tex, tex], [m, m], [EYE, EYE], 0.005, 1.0, skin(), exits=(none, none))
    inputs = {"pos": world, "nrm": n, "view": v, "sig": np.tile([SIGMA[0], SIGMA[1], 3.4e38], (2, 1))}
    for what in ("through_gain", "through_shadow"):
        gpu = glsl.evaluate(
            "lib/sss_single_through.glsl",
            f"{what}(pos, nrm, view, sig * vec3(1.0, 1.0, 10.0))",
            inputs,
            4,
            prelude=GLSL_TERMS,
            setup=setup,
        )
        assert np.all(np.isfinite(gpu)), what
