"""The texture-space irradiance pass shades the lights without a shadow map in its light loop and
each filled shadow slot's light once, with its translucency (skinlab/shaders/techniques/tsd/irradiance.frag,
u_slot_light): the frame must not depend on the lights' order or on which slot holds a light. With
no ambient light the frame is linear in the lights, so two shadow-casting lights together (one in
slot 0, one in slot 1) render the sum of each alone (in slot 0)."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.render.settings import RenderSettings
from tests.tsd_scenes import backlit_slab_with


def _render(renderer, names, translucency=True):
    s = backlit_slab_with(names)
    st = RenderSettings.for_technique("tsd", 48, 48, shadow_size=512, size=128, translucency=translucency)
    res = renderer.render(s, st, readback=("hdr",))
    assert [p for p in res.plan.passes if p.kind == "tsd_irradiance"], "no texture-space irradiance pass"
    return res.hdr[..., :3].astype(np.float64)


def test_light_order_and_slot_do_not_change_the_frame(renderer):
    a = _render(renderer, ["fill", "back", "key"])  # back in slot 0, key in slot 1
    b = _render(renderer, ["key", "fill", "back"])  # key in slot 0, back in slot 1
    assert a.max() > 0.01
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6 * a.max())


def test_two_shadow_slots_add_up(renderer):
    back = _render(renderer, ["back"])
    both = _render(renderer, ["key", "back"])  # back in slot 1 here
    alone = back + _render(renderer, ["key"])
    assert back.max() > 1e-3  # the light from behind shows through the slab
    np.testing.assert_allclose(both, alone, rtol=1e-5, atol=1e-6 * both.max())


@pytest.mark.parametrize("names", [["fill", "back"], ["key", "back"]])  # back in slot 0, in slot 1
def test_translucency_runs_for_the_slot_of_the_back_light(renderer, names):
    on = _render(renderer, names)
    off = _render(renderer, names, translucency=False)
    assert (on - off).max() > 0.01 * on.max()  # light through the slab (none of it reaches the front otherwise)
    assert (on - off).min() > -1e-6
