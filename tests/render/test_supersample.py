"""Antialiasing by supersampling (RenderSettings.supersample): a frame at N = 2 is the frame at twice
the size box-filtered in NumPy (skinlab/render/supersample.py, the twin of the tone-mapping pass's filter),
for the plain shading, texture-space diffusion and the screen-space techniques (whose kernels in
pixels must follow the supersampled size); outline pixels get fractional coverage; bad values are
errors naming the setting. N = 1 stays bit-identical: tests/render/test_technique_images.py."""

import numpy as np
import pytest

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.render.settings import RenderSettings
from skinlab.render.supersample import box_filter, composite_filtered, nearest_depth
from skinlab.scene.optics.color import srgb_encode, tonemap_aces
from skinlab.scene.scenefile import load_scene

SIZE = 24


@pytest.fixture(scope="module")
def head():
    return load_scene(REFERENCE_SCENES / "head-skin1.toml")


def frame(renderer, scene, technique, size, n):
    st = RenderSettings.for_technique(technique, size, size, shadow_size=256, supersample=n)
    return renderer.render(scene, st)


@pytest.mark.parametrize("technique", ["none", "tsd", "ssss", "disk"])
def test_supersampled_frame_is_the_large_frame_box_filtered(renderer, head, technique):
    small = frame(renderer, head, technique, SIZE, 2)
    large = frame(renderer, head, technique, 2 * SIZE, 1)
    assert small.hdr.shape == (SIZE, SIZE, 4) and small.depth.shape == (SIZE, SIZE)
    want = box_filter(large.hdr, 2)
    assert want[..., 3].max() == 1.0 and (want[..., :3] > 0).any()  # the head is in the frame
    np.testing.assert_allclose(small.hdr, want, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(small.depth, nearest_depth(large.depth, 2))
    # tone mapped after filtering: the mean of the samples over the background, then ACES and sRGB
    shown = composite_filtered(large.hdr, 2, RenderSettings().background) * head.environment.exposure
    ldr = np.round(255.0 * srgb_encode(tonemap_aces(shown)))
    assert np.abs(small.ldr[..., :3].astype(float) - ldr).max() <= 1.0
    forward = next(p for p in small.plan.passes if p.name == "forward")
    assert forward.resolution == (2 * SIZE, 2 * SIZE) and "2 x 2 samples" in forward.reason
    screen = [p for p in small.plan.passes if p.kind in ("ssss_blur", "disk_sss")]
    assert all(p.resolution == (2 * SIZE, 2 * SIZE) for p in screen)
    assert len(screen) == (technique in ("ssss", "disk"))


def test_outline_pixels_get_fractional_coverage(renderer, head):
    plain = frame(renderer, head, "none", SIZE, 1)
    aa = frame(renderer, head, "none", SIZE, 4)
    assert set(np.unique(plain.hdr[..., 3])) == {0.0, 1.0}  # without supersampling: all or nothing
    a = aa.hdr[..., 3]
    edge = (a > 0) & (a < 1)
    assert edge.sum() >= SIZE // 2  # the head's outline crosses at least half the rows
    np.testing.assert_allclose(a * 16, np.round(a * 16), atol=1e-5)  # k of the 16 samples
    # each such pixel lies on the outline: between an all-background and an all-object pixel
    pad = np.pad(a, 2, constant_values=0.0)
    for y, x in zip(*np.nonzero(edge)):
        around = pad[y : y + 5, x : x + 5]
        assert around.min() < a[y, x] < around.max()
    # its colour lies between the background's and the object's (luminance, tone-mapped)
    lum = aa.ldr[..., :3].astype(float).mean(-1)
    bg = lum[a == 0].mean()
    assert np.all(lum[edge] != bg) and len(np.unique(lum[edge])) > 1


def test_reuse_keys_on_the_factor(renderer, head):
    renderer.forget_reuse()
    frame(renderer, head, "tsd", SIZE, 1)
    second = frame(renderer, head, "tsd", SIZE, 2)  # view-independent passes are reused...
    assert "shadow[key]" in second.plan.reused()
    assert "forward" in second.plan.ran() and "tonemap" in second.plan.ran()  # ...screen-space ones are not
    renderer.forget_reuse()
    fresh = frame(renderer, head, "tsd", SIZE, 2)
    np.testing.assert_array_equal(second.hdr, fresh.hdr)


def test_supersample_one_is_the_plain_plan(renderer, head):
    res = frame(renderer, head, "none", SIZE, 1)
    assert "hdr_filtered" not in renderer.last_frame.targets
    assert all(p.resolution == (SIZE, SIZE) for p in res.plan.passes if p.kind not in ("shadow", "bounce"))
    assert "supersample" not in res.plan.explain() and "samples per output pixel" not in res.plan.explain()


@pytest.mark.parametrize("bad", [0, 9, 1.5, True, "2", None])
def test_bad_factor_names_the_setting(bad):
    with pytest.raises(ValueError, match=r"render setting supersample: expected an integer in \[1, 8\]"):
        RenderSettings(8, 8, supersample=bad)


def test_supersampled_size_is_bounded():
    with pytest.raises(ValueError, match="supersample.*16384"):
        RenderSettings(4096, 8, supersample=8)
    assert RenderSettings(2048, 8, supersample=8).render_size == (16384, 64)


def test_box_filter_rejects_a_size_not_a_multiple():
    with pytest.raises(ValueError, match="not a multiple of 3"):
        box_filter(np.zeros((4, 6, 4), np.float32), 3)
