"""Render the head at small size: deterministic, finite, lips on the lips, shadows from the key."""

import numpy as np
import pytest

from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd import TsdSettings
from skinlab.scene import scenefile
from skinlab.scene.scenefile import load_scene
from tests.head_probe import landmarks, project, redness

SIZE = (160, 160)


@pytest.fixture(scope="module")
def renderer(ctx):
    return Renderer(ctx)


@pytest.fixture(scope="module")
def head_frames(renderer):
    s = load_scene()
    settings = RenderSettings(*SIZE, shadow_size=512, technique=TsdSettings(size=256))
    return s, renderer.render(s, settings), renderer.render(s, settings)


def test_head_render_is_deterministic_and_finite(head_frames):
    _, a, b = head_frames
    assert np.isfinite(a.hdr).all()
    assert np.array_equal(a.hdr, b.hdr) and np.array_equal(a.ldr, b.ldr)
    cover = a.hdr[..., 3] > 0
    assert 0.2 < cover.mean() < 0.9  # the head fills a good part of the frame
    assert a.hdr[cover, :3].mean() > 0.05  # lit, not black


def test_lips_are_where_the_lips_are(renderer, head_frames):
    s, a, _ = head_frames
    lm = landmarks(s)
    px = {k: project(s, v, SIZE) for k, v in lm.items()}
    lips, cheek, chin = (redness(a.hdr, px[k]) for k in ("lips", "cheek", "chin"))
    assert lips > 1.25 * cheek and lips > 1.25 * chin, (lips, cheek, chin)
    # negative control: with the asset's UVs left unflipped the colour map lands wrong and the check fails
    wrong = load_scene()
    (head,) = wrong.mesh_nodes()
    head.mesh = scenefile.flip_v(head.mesh)  # flipping twice undoes the scene file's flip_v
    w = renderer.render(wrong, RenderSettings(*SIZE, shadow_size=512, technique=TsdSettings(size=256)))
    assert not redness(w.hdr, px["lips"]) > 1.25 * redness(w.hdr, px["cheek"])


def test_key_light_shadow_darkens_and_plan_skips_unneeded_shadow_passes(renderer, head_frames):
    s, a, _ = head_frames
    names = a.plan.names()
    assert names[0] == "shadow[key]" and names[-2:] == ["forward", "tonemap"]
    assert "tsd_irradiance[LeePerrySmith]" in names  # the skin scatters: texture-space passes
    # plain diffuse (no translucency, which needs the shadow map): a shadow only removes light
    st = RenderSettings(*SIZE, shadow_size=512, sss_model="none")
    a = renderer.render(s, st)
    assert a.plan.names() == ["shadow[key]", "bounce[1]", "bounce[2]", "forward", "tonemap"]
    s.find("key").cast_shadow = False
    b = renderer.render(s, st)
    s.find("key").cast_shadow = True
    assert b.plan.names() == ["bounce[1]", "bounce[2]", "forward", "tonemap"]
    diff = b.hdr[..., :3].sum(-1) - a.hdr[..., :3].sum(-1)
    assert (diff >= -1e-6).all()  # a shadow only removes light
    assert (diff > 0.05).mean() > 0.01  # and it does remove some (nose, neck)


def test_explain_lists_passes_and_reasons(head_frames):
    _, a, _ = head_frames
    text = a.plan.explain()
    assert "shadow[key]" in text and "casts shadows" in text and "shadow[fill]" in text and "skipped" in text


def test_timings_reported_per_pass(head_frames):
    _, a, _ = head_frames
    d = a.timings.as_dict()
    assert set(d["passes"]) == set(a.plan.names())
    assert all(p["cpu_ms"] > 0 for p in d["passes"].values()) and d["frame_ms"] > 0
