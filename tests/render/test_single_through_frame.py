"""Single scattering along the light's path through the medium in the frame (RenderSettings.single_through,
lib/sss_single_through.glsl; the term itself: tests/scene/optics/test_single_through.py): a flat part renders
as with the flat term, a convex part gets more light near its terminator and past it, a mesh that does not
scatter and a frame without distance maps are untouched, and the plan says when it runs."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene
from tests.tsd_scenes import backlit_slab_with


def _frame(renderer, scene, technique, size, **opts):
    st = RenderSettings.for_technique(technique, size, size, shadow_size=1024, **opts)
    res = renderer.render(scene, st, readback=("hdr",))
    return res.hdr[..., :3].astype(np.float64), res.plan


@pytest.mark.parametrize("technique", ["tsd", "ssss"])
def test_a_flat_part_renders_as_with_the_flat_term(renderer, technique):
    scene = backlit_slab_with(["key", "back"])  # a thin flat slab lit in front and from behind
    on, plan = _frame(renderer, scene, technique, 48)
    off, _ = _frame(renderer, scene, technique, 48, single_through=False)
    assert "single scattering along the light's path" in next(p for p in plan.passes if p.kind == "forward").reason
    assert on.max() > 0.05
    # the slab's face, a pixel and more inside its rim (at the rim the light entering its sides near a
    # corner skims below the face: a convex part's terminator, with more light)
    inner = _eroded(on.max(-1) > 0.0, 2)
    assert inner.sum() > 300
    np.testing.assert_allclose(on[inner], off[inner], rtol=1e-6, atol=1e-7 * on.max())  # to fp32 rounding
    assert np.all(on >= off - 1e-5 * on.max())


def _eroded(mask, k):
    """`mask` less every pixel within k pixels (8-neighbourhood steps) of its outside."""
    m = mask.copy()
    for _ in range(k):
        p = np.pad(m, 1)
        m = (
            m
            & p[:-2, 1:-1]
            & p[2:, 1:-1]
            & p[1:-1, :-2]
            & p[1:-1, 2:]
            & p[:-2, :-2]
            & p[2:, 2:]
            & p[:-2, 2:]
            & p[2:, :-2]
        )
    return m


def _ball_arcs(size):
    """Per pixel of the ball close-up at `size`: the signed arc (mm) from the terminator (+ lit), nan off it."""
    t = np.tan(np.radians(10.0))
    c = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(c * t, -c * t)
    d = np.stack([x, y, -np.ones_like(x)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.array([0.0, 0.0, 60.0])
    b = d @ o
    disc = b * b - (o @ o - 64.0)
    p = o + d * (-b - np.sqrt(np.maximum(disc, 0)))[..., None]
    light = np.array([1.0, 0.0, -0.6]) / np.linalg.norm([1.0, 0.0, -0.6])
    arc = 8.0 * np.arcsin(np.clip((p / 8.0) @ light, -1, 1))
    return np.where(disc > 0.05, arc, np.nan)


@pytest.mark.parametrize("technique", ["tsd", "ssss"])
def test_a_balls_terminator_gets_more_light_on_both_sides(renderer, technique):
    scene = load_scene(REFERENCE_SCENES / "ball-backlit-skin1.toml")
    on, _ = _frame(renderer, scene, technique, 48)
    off, _ = _frame(renderer, scene, technique, 48, single_through=False)
    arc = _ball_arcs(48)
    lit, past, deep = (arc > 0.2) & (arc < 1.5), (arc < -0.2) & (arc > -1.0), arc < -6.0
    blue = on[..., 2] - off[..., 2]
    assert lit.sum() > 5 and past.sum() > 5 and deep.sum() > 5
    # blue, whose light stays near where it entered: a third more near the terminator, and past it
    assert on[lit, 2].sum() > 1.3 * off[lit, 2].sum()
    assert on[past, 2].sum() > 1.3 * off[past, 2].sum() + 1e-4
    assert blue[deep].max() < 0.02 * on[lit, 2].mean()  # a long chord in front: nothing added far in
    assert np.all(on >= off - 1e-5 * on.max())  # it only adds light (its gain is at least 1)


def test_untouched_without_scattering_or_distance_maps(renderer):
    scene = load_scene(REFERENCE_SCENES / "ball-backlit-skin1.toml")
    a, _ = _frame(renderer, scene, "none", 32)
    b, _ = _frame(renderer, scene, "none", 32, single_through=False)
    np.testing.assert_array_equal(a, b)
    c, plan = _frame(renderer, scene, "ssss", 32, translucency=False)  # no distance maps: the flat term
    d, _ = _frame(renderer, scene, "ssss", 32, translucency=False, single_through=False)
    np.testing.assert_array_equal(c, d)
    assert "single scattering along" not in next(p for p in plan.passes if p.kind == "forward").reason
