"""The second shadow map fitted to what the camera sees (skinlab/render/shadow_fit.py): its window holds
every visible point and maps onto the whole map, it is planned only for close-ups (a camera that sees
the whole scene keeps the one map, and its frame is unchanged), its texels are finer by what the plan
says, a shadow edge in it falls where the geometry puts it, and the frame re-fits it only when the
camera moves."""

import math

import numpy as np
import pytest

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.render.passes.shadow import CLIP_TO_TEXTURE, light_view_proj
from skinlab.render.settings import RenderSettings
from skinlab.render.shadow_fit import FIT_MIN_GAIN, FIT_SAMPLE_TEXELS, ShadowWindow, fit_window, sees_everything
from skinlab.scene import transform as tf
from skinlab.scene.scenefile import load_scene


@pytest.mark.parametrize("w", [1.0, 0.25])
def test_the_crop_maps_the_window_onto_the_map(w):
    """Clip points whose x / w, y / w lie in the window land in [-1, 1] after the crop and the division,
    for w = 1 (orthographic) and w != 1 (perspective); depth and w are untouched."""
    win = ShadowWindow(-0.3, 0.1, 0.5, 0.4, 64, 32, 4.0)
    rng = np.random.default_rng(2)
    ndc = np.c_[rng.uniform(win.x0, win.x1, 200), rng.uniform(win.y0, win.y1, 200), rng.uniform(-1, 1, 200)]
    clip = np.c_[ndc * w, np.full(200, w)]
    out = clip @ win.crop().T
    xy = out[:, :2] / out[:, 3:]
    assert (np.abs(xy) <= 1 + 1e-12).all()
    assert np.allclose(out[:, 2:], clip[:, 2:])
    corners = np.array([[win.x0, win.y0, 0, 1], [win.x1, win.y1, 0, 1]]) * [w, w, 1, w]
    c = corners @ win.crop().T
    assert np.allclose(c[:, :2] / c[:, 3:], [[-1, -1], [1, 1]])


def test_fit_window_holds_the_points_at_the_full_maps_texel_count():
    """A window over a small patch: every point inside it, shaped as the patch (texels square), about as
    many texels as the full map, and the gain its texels have over the full map's; a patch as wide
    as the map gives no fitted map."""
    rng = np.random.default_rng(3)
    pts = np.c_[rng.uniform(0.1, 0.3, 500), rng.uniform(-0.5, -0.45, 500), rng.uniform(-1, 1, 500)]
    win = fit_window(np.eye(4), pts, 1024, 16384)
    assert win is not None
    assert win.x0 < 0.1 and win.x1 > 0.3 and win.y0 < -0.5 and win.y1 > -0.45
    # the texel rounded up to a power of sqrt 2: between half the full map's count and all of it
    assert 0.49 * 1024**2 < win.nx * win.ny < 1.01 * 1024**2
    tx, ty = (win.x1 - win.x0) / win.nx, (win.y1 - win.y0) / win.ny
    assert abs(tx / ty - 1) < 0.05  # square texels
    assert win.gain == pytest.approx(min(win.nx / (win.x1 - win.x0), win.ny / (win.y1 - win.y0)) / 512)
    assert win.gain > 10
    # a screen sample wider than FIT_SAMPLE_TEXELS of those texels: the texel grows to that share of it
    coarse = fit_window(np.eye(4), pts, 1024, 16384, footprint=0.0005 * FIT_SAMPLE_TEXELS)
    assert coarse is not None and 0.0005 <= (coarse.x1 - coarse.x0) / coarse.nx < 0.0005 * 1.42
    assert coarse.nx < win.nx and coarse.gain < win.gain
    assert fit_window(np.eye(4), pts, 1024, 16384, footprint=0.01 * FIT_SAMPLE_TEXELS) is None  # too little gain
    wide = np.c_[rng.uniform(-0.9, 0.9, 500), rng.uniform(-0.9, 0.9, 500), np.zeros(500)]
    assert fit_window(np.eye(4), wide, 1024, 16384) is None
    assert fit_window(np.eye(4), np.zeros((0, 3)), 1024, 16384) is None
    # a thin line of points still gets an area, and the longest side is capped
    line = np.c_[np.linspace(-0.9, 0.9, 50), np.full(50, 0.2), np.zeros(50)]
    thin = fit_window(np.eye(4), line, 1024, 4096)
    assert thin is not None and thin.nx <= 4096 and thin.y1 > thin.y0


def test_a_camera_that_sees_the_scene_keeps_one_map(renderer):
    """The bundled head's default view sees the whole head: no fitted map, so its frame is the one-map
    frame bit for bit; a close-up plans one, saying how much finer its texels are."""
    head = load_scene()
    rs = RenderSettings.for_technique("none", 48, 48, shadow_size=256)
    on = renderer.render(head, rs)
    assert not [p for p in on.plan.passes if p.kind == "shadow_fit"]
    off = renderer.render(head, RenderSettings.for_technique("none", 48, 48, shadow_size=256, shadow_fit=False))
    assert np.array_equal(on.hdr, off.hdr)
    nose = load_scene(REFERENCE_SCENES / "nose-shadow-skin1.toml")
    plan = renderer.plan(nose, RenderSettings.for_technique("none", 48, 48, shadow_size=256))
    (shadow,) = [p for p in plan.passes if p.kind == "shadow_fit"]
    assert shadow.params.fine is not None and shadow.params.fine.gain >= FIT_MIN_GAIN
    assert f"{shadow.params.fine.gain:.1f}x finer texels" in shadow.reason
    (irradiance,) = [p for p in plan.passes if p.kind == "tsd_irradiance"] or [None]
    assert irradiance is None  # plain diffuse: no texture-space pass to read it
    tsd = renderer.plan(nose, RenderSettings.for_technique("tsd", 48, 48, shadow_size=256))
    (irradiance,) = [p for p in tsd.passes if p.kind == "tsd_irradiance"]
    assert shadow.name in irradiance.after
    assert all(shadow.name not in p.after for p in tsd.passes if p.kind == "bounce")


def test_the_slit_edge_in_the_fitted_map_falls_where_the_plates_put_it(renderer):
    """slit-marble's 2 mm slit (plates' inner edges at x = +-1 mm, light along them): in the fitted map the
    lit texels across the slab run from x = -1 to +1 to within a fitted texel, which is finer than the
    full map's by the planned gain."""
    scene = load_scene(REFERENCE_SCENES / "slit-marble.toml")
    rs = RenderSettings.for_technique("none", 256, 16, supersample=4)  # the close-up tables' (at 1 x 1 a
    res = renderer.render(scene, rs, readback=("hdr",))  # pixel is wider than the full map's texels: no fit)
    (shadow,) = [p for p in res.plan.passes if p.kind == "shadow_fit"]
    win = shadow.params.fine
    assert win is not None and win.gain >= 4
    fine = renderer.passes["shadow_fit"].fine[0].depth  # type: ignore[attr-defined]
    assert fine.size == (win.nx, win.ny)
    depth = np.frombuffer(fine.read(), np.float32).reshape(win.ny, win.nx)
    lo, hi = scene.world_bounds()
    m = CLIP_TO_TEXTURE @ win.crop() @ light_view_proj(scene.lights()[0], lo, hi)
    p = np.array([0.0, 0.0, 0.0, 1.0]) @ m.T  # the slab's top face at the slit's centre
    row = int(p[1] / p[3] * win.ny)
    slab = p[2] / p[3]
    lit = np.abs(depth[row] - slab) < 1e-3  # the texels that see the slab, not a plate
    cols = np.nonzero(lit)[0]
    texel_mm = 1.0 / (m[0, 0] * win.nx)  # world mm per fitted texel across the slit
    x0, x1 = ((cols[0], cols[-1] + 1) - m[0, 3] * win.nx) * texel_mm
    assert abs(x0 + 1.0) <= 1.01 * texel_mm and abs(x1 - 1.0) <= 1.01 * texel_mm, (x0, x1, texel_mm)
    full_texel_mm = 1.0 / (CLIP_TO_TEXTURE @ light_view_proj(scene.lights()[0], lo, hi))[0, 0] / 2048
    assert full_texel_mm / texel_mm == pytest.approx(win.gain, rel=0.05)


def test_the_fitted_map_follows_the_camera_and_is_reused_while_it_holds_still(renderer):
    """The same close-up twice: the fitted map reused; the camera moved a little: the same (snapped)
    window, reused; moved further: re-fitted, and the full map and the interreflection kept; moved
    back out to see the whole scene: the fitted map dropped, as shadow_fit = false renders."""
    scene = load_scene(REFERENCE_SCENES / "slit-skin1.toml")
    rs = RenderSettings.for_technique("none", 64, 8, shadow_size=512)

    def shadow(res, kind="shadow_fit"):
        (p,) = [p for p in res.plan.passes if p.kind == kind]
        return p

    a = shadow(renderer.render(scene, rs))
    b = shadow(renderer.render(scene, rs))
    assert a.params.fine is not None and b.reused_since is not None
    start = scene.camera.translation.copy()
    scene.camera.translation = start + np.array([0.01, 0.0, 0.0])
    nudged = renderer.render(scene, rs)
    assert shadow(nudged).params.fine == a.params.fine and shadow(nudged).reused_since is not None
    scene.camera.translation = start + np.array([6.0, 0.0, 0.0])
    moved = renderer.render(scene, rs)
    c = shadow(moved)
    assert c.reused_since is None and c.params.fine is not None and c.params.fine != a.params.fine
    assert shadow(moved, "shadow").reused_since is not None
    eye = np.array([0.0, 0.0, 4000.0])
    scene.camera.translation = eye
    scene.camera.rotation = tf.look_at_rotation(eye, np.zeros(3))
    scene.camera.yfov = math.radians(30)
    lo, hi = scene.world_bounds()
    assert sees_everything(scene.camera, 8.0, lo, hi)
    far = renderer.render(scene, rs)
    assert not [p for p in far.plan.passes if p.kind == "shadow_fit"]
    plain = renderer.render(scene, RenderSettings.for_technique("none", 64, 8, shadow_size=512, shadow_fit=False))
    assert np.array_equal(far.hdr, plain.hdr)
