"""Material fuzz over the declarations: any values within the ranges declared in
skinlab/scene/materials.py (PRINCIPLED_PARAMS), edges included, plan and render with every registered
technique to finite, non-negative frames. A channel without scattering energy (albedo 0, a radius
of 1e-5 mm) plans as no scattering in that channel; it does not fail the frame.

Renders are tiny (16x16, a 32-texel texture space) and the examples few (the `ci` profile's count
would take minutes here): `SKINLAB_FUZZ_EXAMPLES=200 pytest tests/render/test_material_fuzz.py`
searches longer."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from skinlab.render.registry import get_technique, technique_names
from skinlab.render.settings import RenderSettings
from skinlab.scene.materials import PRINCIPLED_PARAMS, Material
from tests.tsd_scenes import light_from, slab_scene

# the set the 1,000-set probe found: albedo 0 in two channels, a red radius of 1.5e-5 mm
ISSUE_26 = {
    "subsurface": 1.0,
    "subsurface_color": (0.505, 0.0, 0.0),
    "subsurface_radius": (1.5e-05, 1000.0, 157.25),
}


def _number(lo: float, hi: float):
    return st.one_of(st.sampled_from([lo, hi]), st.floats(lo, hi, allow_nan=False, allow_infinity=False))


def _value(p):
    """A value within p's declared range (or one of its choices); edges drawn often."""
    if p.kind == "float":
        return _number(*p.range)
    if p.kind in ("color", "vec3", "vec2"):
        return st.tuples(*[_number(*p.range)] * (2 if p.kind == "vec2" else 3))
    if p.kind == "choice":
        return st.sampled_from(p.choices)
    raise ValueError(f"parameter {p.name}: no strategy for kind {p.kind!r} (add one here)")


FUZZED = [p for p in PRINCIPLED_PARAMS if p.kind != "texture"]  # maps: the bad-input suite covers files
MATERIALS = st.fixed_dictionaries({p.name: _value(p) for p in FUZZED})


def _settings(name: str) -> RenderSettings:
    small = {"size": 32} if "size" in get_technique(name).settings_type.options() else {}
    return RenderSettings.for_technique(name, 16, 16, shadow_size=64, **small)


def _scene(values: dict):
    scene = slab_scene(material=Material("fuzz", values))
    scene.add(light_from((0.4, 0.2, -1.0), intensity=2.0, shadow=True))  # shadow maps and translucency too
    return scene


@pytest.mark.slow
@settings(
    max_examples=int(os.environ.get("SKINLAB_FUZZ_EXAMPLES", 3)),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(values=MATERIALS)
@example(values={**{p.name: p.default for p in FUZZED}, **ISSUE_26})
def test_every_technique_renders_declared_materials_finite_and_non_negative(renderer, values):
    scene = _scene(values)
    for name in technique_names():
        res = renderer.render(scene, _settings(name))
        rgb = res.hdr[..., :3]
        assert np.isfinite(rgb).all(), (name, values)
        assert (rgb >= 0).all(), (name, values, float(rgb.min()))


def test_a_channel_without_energy_plans_as_no_scattering_in_it():
    """The probe's set: its red channel spreads less than 1e-5 mm, green and blue have albedo 0. The
    fit does not fail: green and blue keep the unblurred light; red, whose Burley profile has no energy
    beyond 1e-5 mm, too (a dipole's tail reaches further: sub-picometre Gaussians, which the blur folds
    into the identity as sub-texel)."""
    from skinlab.scene.optics.disk import disk_kernel
    from skinlab.scene.optics.exact_profile import exact_profile_lut
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.optics.profile_fit import profile_fit

    medium = material_medium(Material("m", ISSUE_26).values)
    for model in ("burley", "blender-burley", "dipole", "pbd"):
        fit = profile_fit(model, medium)
        assert np.isfinite(fit.weights).all() and fit.identity[1:].tolist() == [1.0, 1.0], model
        assert not fit.weights[:, 1:].any(), model
        kernel = disk_kernel(model, medium, 8)
        assert np.isfinite(kernel.weights).all() and not kernel.weights[:, 1:].any(), model
        _, R, E = exact_profile_lut(model, medium, n=16)
        assert np.isfinite(R).all() and np.array_equal(E[:, 1:], np.ones((16, 2))), model
    fit = profile_fit("burley", medium)
    assert np.array_equal(fit.identity, np.ones(3)) and not fit.weights.any()
    assert not disk_kernel("burley", medium, 8).weights.any()
    # one scattering channel among them keeps its blur
    mixed = material_medium(Material("m", {**ISSUE_26, "subsurface_color": (0.505, 0.5, 0.0)}).values)
    fit = profile_fit("burley", mixed)
    assert fit.identity.tolist() == [1.0, 0.0, 1.0] and fit.weights[:, 1].sum() == pytest.approx(1.0)
