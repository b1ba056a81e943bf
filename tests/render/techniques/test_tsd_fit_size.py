"""Texture-space diffusion sized from each mesh's area and its size on screen (TsdSettings.fit_size):
many small meshes cost about what their pixels cost (each used to get the full 512x512 chain), the
image stays the same, and the render summary says when sub-texel Gaussians leave light unblurred."""

from __future__ import annotations

import io
import re

import numpy as np

from skinlab.render.plan import plan_frame
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd.plan import FITTED_MIN, TsdIrradianceParams
from skinlab.scene.graph import MeshNode
from tests.tsd_scenes import quad_mesh, skin, slab_scene


def tiles(n: int, size_units: float = 2.0):
    """n x n small squares of skin tiling the slab scene's view (2 x 2 units)."""
    scene = slab_scene(mesh=quad_mesh("slab", -0.01, 0.01, -0.01, 0.01))  # a speck: the scene's camera and light
    step = size_units / n
    for i in range(n):
        for j in range(n):
            x, y = -1 + i * step, -1 + j * step
            scene.add(MeshNode(f"tile{i}_{j}", quad_mesh(f"tile{i}_{j}", x, x + 0.9 * step, y, y + 0.9 * step), skin()))
    return scene


def sizes(plan) -> dict[str, int]:
    return {p.params.node.name: p.resolution[0] for p in plan.passes if isinstance(p.params, TsdIrradianceParams)}


def test_small_meshes_get_small_texture_spaces():
    scene = tiles(6)
    fitted = sizes(plan_frame(scene, RenderSettings.for_technique("tsd", 96, 96, bounces=0)))
    full = sizes(plan_frame(scene, RenderSettings.for_technique("tsd", 96, 96, fit_size=False, bounces=0)))
    assert len(fitted) == len(full) == 37 and set(full.values()) == {512}
    tiles_fitted = {k: v for k, v in fitted.items() if k.startswith("tile")}
    # each tile spans ~14 pixels: 2 texels a pixel -> 28, a power of two -> 32 (the least a mesh gets)
    assert set(tiles_fitted.values()) == {FITTED_MIN}
    texels = sum(v * v for v in tiles_fitted.values())
    assert texels <= 4 * 96 * 96  # 4 texels a pixel of the image at most (here exactly), not 36 x 512^2
    # a bigger image: more texels, never more than the size setting
    big = sizes(plan_frame(scene, RenderSettings.for_technique("tsd", 640, 640, size=128, bounces=0)))
    assert set(v for k, v in big.items() if k.startswith("tile")) == {128}


def test_fitted_texture_space_renders_the_same_image(renderer):
    scene = tiles(2)
    fitted = renderer.render(scene, RenderSettings.for_technique("tsd", 32, 32, shadow_size=64, size=256))
    full = renderer.render(scene, RenderSettings.for_technique("tsd", 32, 32, shadow_size=64, size=256, fit_size=False))
    assert max(sizes(fitted.plan).values()) < 256 and set(sizes(full.plan).values()) == {256}
    a, b = fitted.hdr[..., :3].astype(np.float64), full.hdr[..., :3].astype(np.float64)
    assert np.abs(a - b).sum() / np.abs(b).sum() < 0.02  # relative L1 of the whole frame
    assert "texels a side, from the mesh's" in fitted.plan.explain()


def test_render_summary_notes_unblurred_subtexel_gaussians(tmp_path, capsys):
    """The head at 512 texels: most of its six Gaussians are narrower than a texel. The summary says which
    light is left unblurred and the texels per side that would blur what this image's pixels show."""
    from skinlab.scene.scenefile import load_scene

    head = load_scene("head")
    plan = plan_frame(head, RenderSettings.for_technique("tsd", 640, 640, size=512, bounces=0))
    (note,) = plan.notes
    assert re.search(r"\b[4-6] of 6 Gaussians", note) and "green and blue" in note, note
    assert "--tsd-size 1024" in note, note
    (small,) = plan_frame(head, RenderSettings.for_technique("tsd", 256, 256, size=512, bounces=0)).notes
    assert "narrower than half a pixel here too" in small and "--tsd-size" not in small
    assert not plan_frame(
        head, RenderSettings.for_technique("tsd", 256, 256, size=8192, fit_size=False, bounces=0)
    ).notes


def test_long_frames_show_progress(renderer, monkeypatch):
    import skinlab.commands.render as render_command

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    err = Terminal()
    monkeypatch.setattr(render_command.sys, "stderr", err)
    monkeypatch.setattr(render_command, "PROGRESS_AFTER_S", 0.0)
    res = render_command.render_with_progress(renderer, tiles(1), RenderSettings(16, 16, shadow_size=64), "frame")
    assert res.hdr is not None and "frame:" in err.getvalue() and "passes" in err.getvalue()
