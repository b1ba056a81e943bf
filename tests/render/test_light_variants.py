"""Programs that light surfaces compile only the shadow-map slots the frame fills (SHADOW_SLOTS,
skinlab/shaders/lib/lights.glsl; skinlab/render/lights.py light_defines): the image is the same as with both
slots compiled in, and an empty slot's lookups are really gone from the program."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.render.lights import light_defines
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene


def test_light_defines_count_the_filled_slots():
    assert light_defines([], 4) == {"MAX_LIGHTS": 4, "SHADOW_SLOTS": 0}
    assert light_defines(["key"], 3) == {"MAX_LIGHTS": 3, "SHADOW_SLOTS": 1}
    assert light_defines(["a", "b", "c"], 4)["SHADOW_SLOTS"] == 2  # two slots at most


def _frame_programs(renderer, frag: str) -> dict:
    """Compiled programs of `frag`, by their SHADOW_SLOTS define."""
    out = {}
    for (_vs, fs, defines, _inc), entry in renderer.programs.entries.items():
        if fs == frag:
            out[dict(defines).get("SHADOW_SLOTS")] = entry.program
    return out


@pytest.mark.parametrize("shadows", [0, 1])
def test_forward_compiles_only_filled_slots_and_renders_the_same(ctx, monkeypatch, shadows):
    scene = load_scene(None)
    lights = list(scene.lights())
    for i, light in enumerate(lights):
        light.cast_shadow = i < shadows
    st = RenderSettings(48, 48, sss_model="none", shadow_size=256)
    r = Renderer(ctx)
    try:
        img = r.render(scene, st).hdr
        progs = _frame_programs(r, "passes/forward.frag")
        assert set(progs) == {str(shadows)}
        prog = progs[str(shadows)]
        assert ("u_shadow_matrix" in prog) == (shadows > 0)
        assert "u_shadow1" not in prog  # never filled with at most one shadow light
        # the same frame with both slots compiled in (what every frame compiled before)
        import skinlab.render.passes.forward as forward

        monkeypatch.setattr(forward, "light_defines", lambda sl, n, frame=None: {"MAX_LIGHTS": n, "SHADOW_SLOTS": 2})
        full = r.render(scene, st).hdr
        assert "2" in _frame_programs(r, "passes/forward.frag")
    finally:
        r.release()
    lit = img[..., 3] > 0
    assert lit.sum() > 100
    np.testing.assert_array_equal(img, full)
