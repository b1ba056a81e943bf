"""The forward pass shades the lights without a shadow map in its light loop and each filled shadow slot's
light once, the slot a compile-time constant (skinlab/shaders/passes/forward.frag shade_light,
u_slot_light), as do the hooks that gather their own light (techniques/preintegrated/forward.glsl
pis_light) and the light through thin parts of the screen-space hooks (lib/sss_translucency.glsl
sss_translucent_toward). So the frame must not depend on the lights' order or on which slot holds a
light, and with no ambient light it is linear in the lights: two shadow-casting lights together (slots 0
and 1) render the sum of each alone (in slot 0). The texture-space irradiance's own loop:
tests/render/techniques/test_tsd_irradiance_lights.py."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.render.lights import set_light_uniforms
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import LightNode
from tests.tsd_scenes import backlit_slab_with

# techniques whose forward pass shades the lights (none: the plain frame), with the light through the
# slab where they have it; the lights: tests/tsd_scenes.py SLAB_LIGHTS
TECHNIQUES = {"none": {}, "ssss": {"translucency": True}, "preintegrated": {"translucency": True}}


def _render(renderer, technique, names, **opts):
    s = backlit_slab_with(names)
    own = {**TECHNIQUES[technique], **opts}
    st = RenderSettings.for_technique(technique, 48, 48, shadow_size=512, bounces=0, **own)
    res = renderer.render(s, st, readback=("hdr",))
    return res.hdr[..., :3].astype(np.float64)


@pytest.mark.parametrize("technique", list(TECHNIQUES))
def test_light_order_and_slot_do_not_change_the_frame(renderer, technique):
    a = _render(renderer, technique, ["fill", "back", "key"])  # back in slot 0 (light 1), key in slot 1 (light 2)
    b = _render(renderer, technique, ["key", "fill", "back"])  # key in slot 0 (light 0), back in slot 1 (light 2)
    assert a.max() > 0.01
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6 * a.max())


@pytest.mark.parametrize("technique", list(TECHNIQUES))
def test_two_shadow_slots_add_up(renderer, technique):
    key = _render(renderer, technique, ["key"])
    both = _render(renderer, technique, ["back", "key"])  # key in slot 1 here
    alone = key + _render(renderer, technique, ["back"])
    assert key.max() > 0.01
    np.testing.assert_allclose(both, alone, rtol=1e-5, atol=1e-6 * both.max())


@pytest.mark.parametrize("technique", ["ssss", "preintegrated"])
def test_light_through_comes_from_the_back_lights_slot(renderer, technique):
    for names in (["fill", "back"], ["key", "back"]):  # back in slot 0, in slot 1
        on = _render(renderer, technique, names)
        off = _render(renderer, technique, names, translucency=False)
        assert (on - off).max() > 0.01 * on.max()  # light through the slab (none of it reaches the front otherwise)
        assert (on - off).min() > -1e-6


class _Prog(dict):
    """A program's uniforms as set_light_uniforms sees them: names to writable slots."""

    def __contains__(self, name):
        return name in ("u_slot_light",)

    def __getitem__(self, name):
        return self.setdefault(name, _Uniform())


class _Uniform:
    array_length = 2

    def write(self, data):
        self.data = np.frombuffer(data, np.int32)


class _Frame:
    class scene:
        mm_per_unit = 1.0

    shadow_matrices: dict = {}
    shadow_fine_matrices: dict = {}


def test_slot_lights_name_each_slots_light_and_refuse_a_stranger():
    lights = [LightNode(n, "directional") for n in ("fill", "key", "rim")]
    prog = _Prog()
    set_light_uniforms(prog, _Frame(), lights, [lights[2], lights[1]], 4)
    assert prog["u_slot_light"].data.tolist() == [2, 1]
    set_light_uniforms(prog, _Frame(), lights, [lights[1]], 4)
    assert prog["u_slot_light"].data.tolist() == [1, -1]  # an empty slot
    with pytest.raises(ValueError, match="shadow light 'other' is not among the 3 lights"):
        set_light_uniforms(prog, _Frame(), lights, [LightNode("other", "directional")], 4)
