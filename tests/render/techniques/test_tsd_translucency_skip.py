"""Texture-space translucency is left out for a mesh that light cannot cross: no part of it is
thinner than the thickness past which its material lets through less than REACH_EPS (1e-4) of the
light a surface facing the light receives (skinlab/render/techniques/tsd/plan.py can_shine_through,
skinlab/scene/optics/translucency_reach.py, skinlab/scene/mesh_thickness.py). The skip must really happen (the plan
says so, the irradiance pass runs without the variant, no distance map is drawn) and change the
image by less than the stated tolerance: 1e-4 of the frame's brightest value."""

from __future__ import annotations

import numpy as np
import pytest

import skinlab.render.techniques.tsd.plan as tsd_plan
from skinlab.render.settings import RenderSettings
from skinlab.resources import assets_root
from skinlab.scene import transform as tf
from skinlab.scene.graph import LightNode
from skinlab.scene.mesh import Mesh
from skinlab.scene.mesh_thickness import is_closed, thinner_than
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.slab import slab_table, slab_through
from skinlab.scene.optics.translucency_reach import REACH_EPS, translucency_reach_mm, transmission_bound
from skinlab.scene.scenefile import load_scene

REF = assets_root() / "scenes" / "reference"
TOL = 1e-4  # of the frame's brightest value


def _frame(renderer, scene, size=128, **kw):
    st = RenderSettings.for_technique("tsd", 64, 64, shadow_size=512, size=size, **kw)
    return renderer.render(scene, st, readback=("hdr",))


def _irradiance(res):
    return [p for p in res.plan.passes if p.kind == "tsd_irradiance"]


def _thick_backlit():
    """The back-lit slab scene (skin1; camera on the unlit side) with the 40 mm slab in place of the
    3 mm one, and a front light as bright as the back one (both cast shadows)."""
    scene = load_scene(REF / "slab-thin-backlit-skin1.toml")
    scene.mesh_nodes()[0].mesh = load_scene(REF / "slab-edge-skin1.toml").find("slab-160x160x40").mesh
    front = LightNode("front", "directional", intensity=3.0, cast_shadow=True)
    front.rotation = tf.look_at_rotation(np.zeros(3), np.array([-0.5, 0.0, -0.866]))
    scene.add(front)
    return scene


def test_a_40mm_slab_of_skin_skips_translucency_within_tolerance(renderer, monkeypatch):
    scene = _thick_backlit()
    res = _frame(renderer, scene)
    (irr,) = _irradiance(res)
    assert irr.params.translucency is False
    assert any(what.startswith("translucency[") for what, _ in res.plan.skipped)
    shadow = [p for p in res.plan.passes if p.kind == "shadow"]
    assert len(shadow) == 2 and not any(p.params.distance for p in shadow)  # no distance maps drawn
    monkeypatch.setattr(tsd_plan, "can_shine_through", lambda *a: True)  # the frame without the skip
    full = _frame(renderer, scene)
    assert _irradiance(full)[0].params.translucency is True
    a, b = res.hdr[..., :3].astype(np.float64), full.hdr[..., :3].astype(np.float64)
    assert b.max() > 0.05
    assert (b - a).max() > 0.0  # the back light does come through the 40 mm, a little
    assert np.abs(a - b).max() <= TOL * b.max(), np.abs(a - b).max() / b.max()


def test_the_shadow_edge_slab_plans_no_distance_map(renderer):
    res = _frame(renderer, load_scene(REF / "slab-edge-skin1.toml"))
    assert _irradiance(res)[0].params.translucency is False
    assert any(what == "translucency[slab-160x160x40]" for what, _ in res.plan.skipped)
    assert not any(p.params.distance for p in res.plan.passes if p.kind == "shadow")


def test_a_3mm_slab_keeps_its_translucency(renderer):
    res = _frame(renderer, load_scene(REF / "slab-thin-backlit-skin1.toml"))
    (irr,) = _irradiance(res)
    assert irr.params.translucency is True
    assert not any(what.startswith("translucency[") for what, _ in res.plan.skipped)
    assert any(p.params.distance for p in res.plan.passes if p.kind == "shadow")


def test_the_head_keeps_its_translucency(renderer):
    res = _frame(renderer, load_scene(None), size=256)  # ears and nostrils
    assert _irradiance(res)[0].params.translucency is True


def test_a_scaled_down_slab_becomes_thin_enough(renderer):
    scene = load_scene(REF / "slab-edge-skin1.toml")
    node = next(n for n in scene.mesh_nodes() if n.name == "slab-160x160x40")
    node.scale = (1.0, 1.0, 0.1)  # 4 mm thick: the smallest singular value of the transform counts
    assert _irradiance(_frame(renderer, scene))[0].params.translucency is True


def _skin1():
    m = load_scene(REF / "slab-edge-skin1.toml").find("slab-160x160x40").material
    return material_medium(m.values), m["subsurface_color"]


def test_reach_bounds_the_transmission():
    med, colour = _skin1()
    reach = translucency_reach_mm(med.alpha_arr, med.mfp_arr, med.eta, colour)
    assert 3.0 < reach < 40.0  # skin1 shines through 3 mm, not through 40 mm
    past = reach * np.geomspace(1.0, 100.0, 60)
    r = transmission_bound(past, med.alpha_arr, med.mfp_arr, med.eta, colour)
    assert (r < REACH_EPS).all()
    before = transmission_bound([reach / 1.05], med.alpha_arr, med.mfp_arr, med.eta, colour)
    assert before.max() >= REACH_EPS  # the grid's previous point is still above: reach is not loose by more


@pytest.mark.parametrize("eta", [1.0, 1.4])
def test_the_bound_holds_at_every_incidence(eta):
    """back T(back, d) / E(1) <= transmission_bound(d) for every cosine, not only the table's nodes."""
    med, colour = _skin1()
    table = slab_table(med.alpha_arr, colour)
    front = material_boundary_front(med, colour, eta)
    d = np.geomspace(1e-3, 60.0, 30)
    bound = transmission_bound(d, med.alpha_arr, med.mfp_arr, eta, colour)
    for back in np.linspace(0.0, 1.0, 37):
        got = np.array([back * slab_through(back, x, table, med.mfp_arr, med.alpha_arr, eta) for x in d]) / front
        assert (got <= bound * (1 + 1e-9) + 1e-300).all(), back


def material_boundary_front(med, colour, eta):
    from skinlab.scene.optics.boundary import boundary_tables

    return boundary_tables(med.alpha_arr, colour, eta).entry[-1]


@pytest.mark.parametrize(
    "alpha, expect",
    [((1.0, 1.0, 1.0), "far"), ((0.0, 0.0, 0.0), "zero"), ((1e-6, 0.5, 0.999999), "finite")],
)
def test_reach_hard_cases_stay_defined(alpha, expect):
    reach = translucency_reach_mm(np.array(alpha), np.array([1.0, 1.0, 1.0]), 1.4, (0.8, 0.6, 0.5))
    r = transmission_bound(np.geomspace(1e-3, 1e4, 50), np.array(alpha), np.ones(3), 1.4, (0.8, 0.6, 0.5))
    assert np.isfinite(r).all()
    # without absorption the diffusion falls only as 1/d: it shines through anything of human size
    assert {"far": 1e4 < reach < np.inf, "zero": reach == 0.0, "finite": 0 < reach < 1e4}[expect]


def _box(w: float, h: float, t: float) -> Mesh:
    """A closed w x h x t box, flat-shaded (each face its own four vertices)."""
    faces = []
    c = np.array([w, h, t]) / 2
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = [a for a in range(3) if a != axis]
            quad = []
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = np.zeros(3)
                p[axis], p[u], p[v] = sign * c[axis], su * c[u], sv * c[v]
                quad.append(p)
            n = np.zeros(3)
            n[axis] = sign
            faces.append((quad, n))
    pos, nrm, idx = [], [], []
    for quad, n in faces:
        b = len(pos)
        pos += quad
        nrm += [n] * 4
        tri = [(b, b + 1, b + 2), (b, b + 2, b + 3)]
        # wind counter-clockwise seen from outside
        e = np.cross(quad[1] - quad[0], quad[2] - quad[0])
        idx += tri if np.dot(e, n) > 0 else [(a, c_, b_) for a, b_, c_ in tri]
    return Mesh("box", np.array(pos), np.array(idx), normals=np.array(nrm))


def test_thinnest_part_of_boxes_and_open_sheets():
    box = _box(60.0, 60.0, 3.0)
    assert thinner_than(box, 3.01) and not thinner_than(box, 2.99)
    thick = _box(160.0, 160.0, 40.0)
    assert thinner_than(thick, 40.5) and not thinner_than(thick, 39.5)
    sheet = Mesh("sheet", np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]]), np.array([[0, 1, 2], [0, 2, 3]]))
    # answers stay right in any order of limits (what one search finds is kept for the next)
    fresh = _box(60.0, 60.0, 3.0)
    assert [thinner_than(fresh, x) for x in (100.0, 2.0, 2.9, 3.1, 1.0, 2.999, 3.001)] == [
        True,
        False,
        False,
        True,
        False,
        False,
        True,
    ]
    # an open sheet bounds nothing (the light may have entered another mesh in front of it)
    assert not is_closed(sheet) and thinner_than(sheet, 1e-6)
    assert is_closed(box) and is_closed(thick)
