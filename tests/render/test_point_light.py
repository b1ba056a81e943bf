import numpy as np
import pytest

from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.resources import assets_root
from skinlab.scene.scenefile import load_scene

BUNNY = assets_root() / "stanford-bunny" / "bunny.ply"


def scene(tmp_path, position, shadow=True):
    p = tmp_path / "b.toml"
    p.write_text(f'''
[scene]
mm_per_unit = 1000.0
[environment]
ambient = 0.0
[[meshes]]
file = "{BUNNY}"
[[lights]]
type = "point"
position = {list(position)}
intensity = 0.05
cast_shadow = {str(shadow).lower()}
''')
    return load_scene(p)


def test_point_light_shadow_and_inverse_square(ctx, tmp_path):
    r = Renderer(ctx)
    st = RenderSettings(96, 96, shadow_size=256)
    near = r.render(scene(tmp_path, [0.0, 0.3, 0.3]), st)
    assert near.plan.names() == ["shadow[light1]", "bounce[1]", "bounce[2]", "forward", "tonemap"]
    assert np.isfinite(near.hdr).all() and near.hdr[..., :3].max() > 0
    unshadowed = r.render(scene(tmp_path, [0.0, 0.3, 0.3], shadow=False), st)
    assert (unshadowed.hdr[..., :3].sum(-1) >= near.hdr[..., :3].sum(-1) - 1e-6).all()
    assert (unshadowed.hdr[..., :3].sum(-1) > near.hdr[..., :3].sum(-1) + 1e-3).any()  # self-shadowing
    # twice as far along the same ray: between a quarter and a half of the light (inverse square;
    # the bunny is not a point, so the ratio is not exactly 1/4)
    far = r.render(scene(tmp_path, [0.0, 0.6, 0.6], shadow=False), st)
    ratio = far.hdr[..., :3].sum() / unshadowed.hdr[..., :3].sum()
    assert 0.15 < ratio < 0.5, ratio


def test_shadowing_point_light_inside_the_scene_is_an_error(ctx, tmp_path):
    with pytest.raises(ValueError, match="light 'light1': a shadow-casting point light must be outside"):
        Renderer(ctx).render(scene(tmp_path, [0.0, 0.1, 0.0]), RenderSettings(32, 32, shadow_size=64))
