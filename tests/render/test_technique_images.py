"""Every registered technique renders the same images as before the technique registry existed.

tests/data/technique_images.npz holds small HDR frames rendered by the code before the techniques
moved into packages (skinlab/render/techniques/); each technique must reproduce them to fp32 rounding.
After a deliberate change of a technique's images, regenerate them with

    python -m tests.render.test_technique_images

and say why in the commit message.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from skinlab.render.registry import get_technique
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import MeshNode
from skinlab.scene.materials import Material
from tests.tsd_scenes import quad_mesh, skin, slab_scene

DATA = Path(__file__).resolve().parents[1] / "data" / "technique_images.npz"
TECHNIQUES = ("none", "tint", "tsd", "exact", "ssss")
SIZE = 48


def mixed_slab():
    """The shadow-edge slab (burley skin, translucency through the shadow), a little ambient light and
    a plain, non-scattering square over one corner: a scattering and a non-scattering material in view."""
    s = slab_scene(occluder=True, material=skin("burley"), ambient=0.05)
    plain = Material("plain", {"base_color": (0.2, 0.5, 0.9), "roughness": 0.3})
    s.add(MeshNode("plain", quad_mesh("plain", 0.4, 1.2, 0.4, 1.2, z=0.05), plain))
    return s


def head():
    from skinlab.scene.scenefile import load_scene

    return load_scene()


# per scene: shadow map and texture-space diffusion sizes (the head needs 256 texels for its blur levels)
SCENES = {
    "mixed_slab": (mixed_slab, dict(shadow_size=512, tsd_size=64)),
    "head": (head, dict(shadow_size=256, tsd_size=256)),
}


def settings_for(technique: str, scene: str) -> RenderSettings:
    sizes = SCENES[scene][1]
    own = get_technique(technique).settings_type.options()
    extra = {"size": sizes["tsd_size"]} if "size" in own else {}  # texture-space techniques' texels
    return RenderSettings.for_technique(technique, SIZE, SIZE, shadow_size=sizes["shadow_size"], **extra)


def render_all(renderer) -> dict[str, np.ndarray]:
    out = {}
    for scene_name, (make, _) in SCENES.items():
        scene = make()
        for t in TECHNIQUES:
            out[f"{scene_name}/{t}"] = renderer.render(scene, settings_for(t, scene_name), readback=("hdr",)).hdr
    return out


@pytest.fixture(scope="module")
def frames(renderer):
    return render_all(renderer)


@pytest.mark.parametrize("scene", list(SCENES))
@pytest.mark.parametrize("technique", TECHNIQUES)
def test_technique_renders_its_stored_image(frames, scene, technique):
    ref = np.load(DATA)[f"{scene}/{technique}"]
    img = frames[f"{scene}/{technique}"]
    assert img.shape == ref.shape and np.isfinite(img).all()
    assert ref[..., :3].max() > 0.01  # the stored image is lit, not an empty frame
    # fp32 rounding: a few units in the last place of each value
    tol = 4 * np.finfo(np.float32).eps * np.maximum(np.abs(ref), 1e-3)
    bad = np.abs(img - ref) > tol
    assert not bad.any(), (int(bad.sum()), float(np.abs(img - ref).max()))


def test_techniques_differ_from_each_other():
    """The stored images are distinct: a technique silently drawn as another would fail above."""
    data = np.load(DATA)
    for scene in SCENES:
        imgs = {t: data[f"{scene}/{t}"] for t in TECHNIQUES}
        for i, a in enumerate(TECHNIQUES):
            for b in TECHNIQUES[i + 1 :]:
                assert np.abs(imgs[a] - imgs[b]).max() > 1e-3, (scene, a, b)


if __name__ == "__main__":  # regenerate the stored images
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer

    images = render_all(Renderer(create_headless_context()))
    DATA.parent.mkdir(parents=True, exist_ok=True)
    tmp = DATA.with_suffix(".tmp.npz")
    np.savez_compressed(tmp, **images)
    tmp.replace(DATA)
    print(f"wrote {DATA} ({len(images)} images)", file=sys.stderr)
