"""Reuse across frames (skinlab/render/reuse.py): change each input in turn and check that exactly the
passes depending on it run again and that the image equals a from-scratch render."""

import numpy as np
import pytest

from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.scene import transform as tf
from tests.tsd_scenes import skin, slab_scene

SHADOW, STRETCH, IRRADIANCE, DILATE, BLUR = "shadow", "tsd_stretch", "tsd_irradiance", "tsd_dilate", "tsd_blur"
VIEW_INDEPENDENT = {SHADOW, STRETCH, IRRADIANCE, DILATE, BLUR}
LIGHTING = {IRRADIANCE, DILATE, BLUR}  # what a change of light or material re-runs


def settings(**kw):
    tsd = {"size": 64, **{k: v for k, v in kw.items() if k in ("albedo_mix", "size")}}
    base = {k: v for k, v in kw.items() if k not in tsd}
    return RenderSettings(40, 40, **{"shadow_size": 128, **base}, technique=TsdSettings(**tsd))


def ran_kinds(res) -> set[str]:
    """The view-independent pass kinds that ran; a kind runs for all its passes or for none."""
    ran = {}
    for p in res.plan.passes:
        if p.kind in VIEW_INDEPENDENT:
            ran.setdefault(p.kind, set()).add(p.reused_since is None)
    mixed = [k for k, v in ran.items() if len(v) > 1]
    assert not mixed, f"some passes of {mixed} ran, others were reused: {res.plan.explain()}"
    return {k for k, v in ran.items() if True in v}


@pytest.fixture(scope="module")
def fresh(ctx):
    """A second renderer that renders every frame from scratch."""
    r = Renderer(ctx)
    r.reuse = False
    yield r
    r.release()


def move_light(scene):
    sun = scene.find("sun")
    sun.rotation = tf.look_at_rotation(np.zeros(3), np.array([1.0, 0.15, -1.0]) / np.linalg.norm([1.0, 0.15, -1.0]))


def tint_light(scene):
    scene.find("sun").color = np.array([1.0, 0.7, 0.5])


def change_material(scene):
    scene.find("slab").material.update({"base_color": (0.9, 0.7, 0.6)})


def move_slab(scene):
    scene.find("slab").translation = (0.05, -0.03, 0.0)


def change_mesh(scene):
    mesh = scene.find("slab").mesh
    mesh.positions = mesh.positions * np.float32(0.97)
    mesh.version += 1


def change_scale(scene):
    scene.mm_per_unit *= 1.5


def brighten_ambient(scene):
    scene.environment.ambient = np.array([0.05, 0.05, 0.06])


def hide_occluder(scene):
    scene.find("occluder").visible = False


def move_camera(scene):
    cam = scene.camera
    eye = cam.world_position
    cam.look_at(eye + np.array([0.02 * np.linalg.norm(eye), 0.0, 0.0]), (0, 0, 0))


CHANGES = [
    ("nothing", None, {}, set()),
    ("camera", move_camera, {}, set()),
    ("light direction", move_light, {}, {SHADOW} | LIGHTING),
    ("light colour", tint_light, {}, LIGHTING),
    ("material value", change_material, {}, LIGHTING),
    ("transform", move_slab, {}, {SHADOW} | LIGHTING),  # a move changes no length: stretch kept
    ("mesh", change_mesh, {}, VIEW_INDEPENDENT),
    ("scene scale", change_scale, {}, {STRETCH} | LIGHTING),
    ("ambient light", brighten_ambient, {}, LIGHTING),
    ("a mesh hidden", hide_occluder, {}, {SHADOW} | LIGHTING),  # the shadow map loses the occluder
    ("setting albedo_mix", None, {"albedo_mix": 0.3}, LIGHTING),
    ("setting shadow_size", None, {"shadow_size": 256}, {SHADOW} | LIGHTING),
]


@pytest.mark.parametrize("what,change,override,expected", CHANGES, ids=[c[0] for c in CHANGES])
def test_exactly_the_dependent_passes_run_again(renderer, fresh, what, change, override, expected):
    scene = slab_scene(material=skin(), occluder=True)  # a shadow-casting light: translucency on
    first = renderer.render(scene, settings(), readback=False)
    assert ran_kinds(first) == VIEW_INDEPENDENT, first.plan.explain()
    if change is not None:
        change(scene)
    st = settings(**override)
    res = renderer.render(scene, st)
    assert ran_kinds(res) == expected, f"{what}:\n{res.plan.explain()}"
    assert {"forward", "tonemap"} <= set(res.plan.ran())  # view-dependent: every frame
    for p in res.plan.passes:
        if p.reused_since is not None:
            assert p.reused_since == renderer.frame_number - 1
            assert f"reused: inputs unchanged since frame {p.reused_since}" in res.plan.explain()
    ref = fresh.render(scene, st)
    assert ran_kinds(ref) == VIEW_INDEPENDENT
    assert res.hdr[..., 3].max() == 1.0 and res.hdr[..., :3].max() > 0
    if what == "transform":  # the kept stretch map came from the old transform: equal to fp32 rounding
        np.testing.assert_allclose(res.hdr, ref.hdr, rtol=2e-6, atol=1e-7)
    else:
        np.testing.assert_array_equal(res.hdr, ref.hdr)


def test_shared_outputs_never_hand_over_another_pass_result(renderer, fresh):
    """A shadow slot used by another light, level 0 written by the exact convolution: when a pass's
    output texture was overwritten by another pass, the pass runs again."""
    scene = slab_scene(material=skin(), occluder=True)
    tsd, exact = settings(), RenderSettings.for_technique("exact", 40, 40, shadow_size=128, size=64)
    renderer.render(scene, tsd, readback=False)
    renderer.render(scene, exact, readback=False)  # the exact convolution overwrites level 0
    res = renderer.render(scene, tsd)
    # level 0 is blurred again; level 1 still holds the blur of that same level 0 and is kept
    assert res.plan.ran() == ["tsd_blur[slab]0", "forward", "tonemap"], res.plan.explain()
    np.testing.assert_array_equal(res.hdr, fresh.render(scene, tsd).hdr)
    other = slab_scene(material=skin(), occluder=True)  # another scene's sun takes shadow slot 0
    move_light(other)
    renderer.render(other, tsd, readback=False)
    res = renderer.render(scene, tsd)
    assert SHADOW in ran_kinds(res)
    np.testing.assert_array_equal(res.hdr, fresh.render(scene, tsd).hdr)


def test_a_recompiled_shader_runs_every_pass_again(renderer):
    scene = slab_scene(material=skin(), occluder=True)
    renderer.render(scene, settings(), readback=False)
    assert ran_kinds(renderer.render(scene, settings(), readback=False)) == set()
    renderer.programs.reload()  # the viewer's hot reload after a saved shader file
    assert ran_kinds(renderer.render(scene, settings(), readback=False)) == VIEW_INDEPENDENT


def test_without_reuse_every_pass_runs(renderer):
    scene = slab_scene(material=skin(), occluder=True)
    renderer.render(scene, settings(), readback=False)
    renderer.reuse = False
    try:
        res = renderer.render(scene, settings(), readback=False)
    finally:
        renderer.reuse = True
    assert ran_kinds(res) == VIEW_INDEPENDENT and not res.plan.reused()
    assert "reused" not in res.plan.explain()


def test_a_registered_technique_declares_its_view_independent_passes(ctx):
    """The registry route: a technique's planned pass with inputs, and a pass class naming its output
    and publishing it, is reused by the core without the core knowing the technique."""
    from dataclasses import dataclass

    from skinlab.render import registry
    from skinlab.render.frame_plan import PlannedPass
    from skinlab.render.options import TechniqueSettings
    from skinlab.render.reuse import material_state
    from skinlab.render.technique import RenderPass, Technique, TechniquePlan

    runs = []

    class ToyBakePass(RenderPass):
        def __init__(self, renderer):
            super().__init__(renderer)
            self.tex = renderer.ctx.texture((4, 4), 4, dtype="f4")

        def outputs(self, frame, p):
            return (self.tex,)

        def publish(self, frame, p):
            frame.targets["toy_bake"] = self.tex

        def run(self, frame, p):
            runs.append(p.name)
            self.publish(frame, p)

        def release(self):
            self.tex.release()

    @dataclass(frozen=True)
    class ToySettings(TechniqueSettings):
        technique = "toybake"

    class ToyTechnique(Technique):
        name = "toybake"
        settings_type = ToySettings
        passes = {"toy_bake": ToyBakePass}

        def plan(self, ctx):
            node = ctx.meshes[0]
            bake = PlannedPass(
                "toy_bake",
                "toy_bake",
                "toy_bake",
                (4, 4),
                "a view-independent bake",
                None,
                inputs=material_state(node.material),
            )
            return TechniquePlan(before_forward=[bake])

    registry.register(ToyTechnique())
    r = Renderer(ctx)
    try:
        scene = slab_scene()
        st = RenderSettings(16, 16, technique="toybake")
        r.render(scene, st, readback=False)
        move_camera(scene)
        res = r.render(scene, st, readback=False)
        assert runs == ["toy_bake"] and res.plan.reused() == ["toy_bake"] and "toy_bake" in r.last_frame.targets
        change_material(scene)
        r.render(scene, st, readback=False)
        assert runs == ["toy_bake", "toy_bake"]
    finally:
        r.release()
        registry.unregister("toybake")


def test_planning_starts_the_materials_boundary_tables(monkeypatch):
    """plan_frame hands the boundary and slab tables of every visible scattering material to a worker
    (render/boundary.py prefetch_boundaries): they are made without any pass binding them, once, and
    a later bind reads the same (memoised) tables."""
    import time

    from skinlab import cache
    from skinlab.render.boundary import boundary_data, material_boundary
    from skinlab.render.plan import plan_frame

    monkeypatch.setenv("SKINLAB_CACHE_DIR", "off")
    colour = (0.8123, 0.6071, 0.5013)  # a medium no other test made (the tables are keyed by albedo, not radius)
    scene = slab_scene(material=skin(color=colour))
    before = cache.BUILT["boundary._tables"], cache.BUILT["boundary._slab_tables"]
    plan_frame(scene, settings())
    deadline = time.monotonic() + 60.0
    while (cache.BUILT["boundary._tables"], cache.BUILT["boundary._slab_tables"]) == before:
        assert time.monotonic() < deadline, "the plan did not start the boundary tables"
        time.sleep(0.05)
    while cache.computing():  # let the worker finish
        assert time.monotonic() < deadline
        time.sleep(0.05)
    made = cache.BUILT["boundary._tables"], cache.BUILT["boundary._slab_tables"]
    material = scene.mesh_nodes()[0].material
    first = material_boundary(material)
    boundary_data(material)  # what a bind reads: made once already
    assert material_boundary(material) is first
    assert (cache.BUILT["boundary._tables"], cache.BUILT["boundary._slab_tables"]) == made
    assert made[0] > before[0] and made[1] > before[1]
