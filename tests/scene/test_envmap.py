"""Environment maps (skinlab/scene/envmap.py): reading and refusing maps, the bright sources taken out
as lights (energy kept, nothing left to flicker), SH and levels, the cache, the map in the world."""

import math

import numpy as np
import pytest

from skinlab.scene import envmap
from skinlab.scene.graph import Scene
from skinlab.scene.optics import sh, split_sum


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))
    envmap.clear_cache()


def sky(w=64, h=32, seed=0):
    rng = np.random.default_rng(seed)
    return (0.5 + 0.2 * rng.random((h, w, 3))).astype(np.float32)


def power(img):
    om = split_sum.texel_solid_angles(img.shape[1], img.shape[0])
    return (img.astype(np.float64) * om[..., None]).sum((0, 1))


@pytest.mark.parametrize(
    "shape, fill, words",
    [
        ((16, 16, 3), 1.0, ["twice as wide"]),
        ((1, 1, 3), 1.0, ["1x1", "twice as wide"]),
        ((2, 4, 3), 1.0, ["at least 8x4", "ambient"]),
        ((16, 32, 3), np.nan, ["NaN or Inf", "column 0, row 0"]),
        ((16, 32, 3), np.inf, ["NaN or Inf"]),
    ],
)
def test_bad_maps_are_refused_with_one_line_naming_the_file(tmp_path, shape, fill, words):
    px = np.ones(shape, np.float32)
    if not np.isfinite(fill):
        px[0, 0, 1] = fill
    path = envmap.write_map(tmp_path / "bad.exr", px)
    with pytest.raises(envmap.EnvironmentMapError) as e:
        envmap.load_pixels(path)
    msg = str(e.value)
    assert "bad.exr" in msg and "\n" not in msg
    for w in words:
        if w == "1x1" and shape != (1, 1, 3):
            continue
        assert w in msg or w == "twice as wide" and shape == (1, 1, 3) and "1x1" in msg, msg


def test_missing_and_unknown_files(tmp_path):
    with pytest.raises(envmap.EnvironmentMapError, match="not found.*bundled maps by name: .*studio"):
        envmap.resolve_map(tmp_path / "nope.exr")
    (tmp_path / "m.png").write_bytes(b"x")
    with pytest.raises(envmap.EnvironmentMapError, match=r"\.exr or \.hdr"):
        envmap.resolve_map(tmp_path / "m.png")
    assert envmap.resolve_map("studio") == envmap.bundled_maps()["studio"]
    assert {"studio", "city", "courtyard", "interior"} <= set(envmap.bundled_maps())


def test_negative_texels_read_as_zero_and_are_counted(tmp_path):
    px = sky()
    px[3, 4] = -1.0
    img, negative = envmap.load_pixels(envmap.write_map(tmp_path / "neg.exr", px))
    assert negative == 1 and img.min() >= 0.0 and img[3, 4].max() == 0.0


def test_a_sun_becomes_a_source_and_the_energy_is_kept():
    img = sky()
    j, i = 9, 40
    img[j, i] = 30000.0  # "a sun texel at 30,000"
    sources, rest = envmap.extract_sources(img)
    assert len(sources) == 1
    src = sources[0]
    d = split_sum.texel_directions(64, 32)[j, i]
    assert np.degrees(np.arccos(np.clip(src.direction @ d, -1, 1))) < 0.01
    # nothing lost or counted twice: the rest's power plus the source's irradiance is the map's power
    assert np.allclose(power(rest) + src.irradiance, power(img), rtol=1e-9)
    # what is left is no brighter than the threshold: no texel to flicker in a prefilter
    mean = (power(img) @ envmap.LUMA) / (4 * math.pi)
    assert (rest.astype(np.float64) @ envmap.LUMA).max() <= envmap.SOURCE_THRESHOLD * mean * (1 + 1e-6)
    assert src.angular_radius < math.radians(5) and src.texels == 1


def test_sources_wrap_across_the_seam_and_at_most_two_are_kept():
    img = sky()
    img[10, 0] = img[10, 63] = 5000.0  # one source across u = 0
    img[20, 30] = 8000.0
    img[5, 50] = 3000.0
    sources, _ = envmap.extract_sources(img)
    assert len(sources) == 2
    # the brightest first: the seam's two texels are one source, toward -Z (u = 0); then the 8000 one;
    # the third is left in the map
    assert sources[0].texels == 2 and abs(sources[0].direction[0]) < 1e-9 and sources[0].direction[2] < -0.8
    assert sources[1].texels == 1
    d = split_sum.texel_directions(64, 32)[20, 30]
    assert np.allclose(sources[1].direction, d)
    assert (sources[0].irradiance @ envmap.LUMA) > (sources[1].irradiance @ envmap.LUMA)


def test_a_soft_sky_has_no_sources():
    sources, rest = envmap.extract_sources(sky())
    assert sources == [] and np.array_equal(rest, sky())


def test_uniform_and_black_maps(tmp_path):
    u = envmap.prepare(envmap.write_map(tmp_path / "u.exr", np.full((16, 32, 3), 0.25, np.float32)))
    assert u.uniform and not u.black and len(u.levels) == 1
    n = np.array([[0, 1.0, 0], [0.6, 0, 0.8]])
    assert np.allclose(sh.irradiance(u.sh, n), math.pi * 0.25)
    b = envmap.prepare(envmap.write_map(tmp_path / "b.exr", np.zeros((16, 32, 3), np.float32)))
    assert b.black and b.sources == []


def test_preparation_is_cached_on_disk_by_content(tmp_path):
    path = envmap.write_map(tmp_path / "m.exr", sky())
    first = envmap.prepare(path)
    assert first.cached == "" and first.seconds > 0.05
    files = list((tmp_path / "cache" / "environment").glob("*.npz"))
    assert len(files) == 1 and not list((tmp_path / "cache" / "environment").glob(".*"))
    envmap.clear_cache()
    again = envmap.prepare(path)
    assert again.cached == "disk" and again.key == first.key
    assert np.array_equal(again.sh, first.sh) and all(np.array_equal(a, b) for a, b in zip(again.levels, first.levels))
    assert envmap.prepare(path).cached == "memory"
    # other content, other key
    other = sky(seed=1)
    envmap.write_map(path, other)
    assert envmap.map_key(path) != first.key


def test_the_map_turns_about_y_in_the_world():
    img = sky()
    img[8, 16] = 9000.0  # toward +X of the map, above the horizon
    d_map = split_sum.texel_directions(64, 32)[8, 16]
    r = envmap.rotation_y(90.0)
    assert np.allclose(r @ [1.0, 0, 0], [0, 0, -1.0])  # counter-clockwise seen from above: +X -> -Z
    assert np.allclose(r @ [0, 0, 1.0], [1.0, 0, 0])
    coeffs = sh.project(img.reshape(-1, 3), split_sum.texel_directions(64, 32).reshape(-1, 3),
                        split_sum.texel_solid_angles(64, 32).ravel())  # fmt: skip
    prepared = envmap.PreparedMap("k", "m", 64, 32, coeffs, [img])
    world = envmap.world_sh(prepared, 90.0, 2.0)
    n = np.array([[0.3, 0.5, 0.81], [1.0, 0, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    assert np.allclose(sh.irradiance(world, n @ r.T), 2.0 * sh.irradiance(coeffs, n), rtol=1e-9)
    # the texel toward +X of the map lies toward -Z in the world at 90 degrees
    assert np.allclose(r @ d_map, [d_map[2], d_map[1], -d_map[0]]) and d_map[0] > 0.7


def test_environment_lights_follow_rotation_and_intensity(tmp_path):
    img = sky()
    img[8, 16] = 9000.0
    s = Scene("s")
    s.environment.map = envmap.write_map(tmp_path / "sun.exr", img)
    s.environment.intensity = 3.0
    (a,) = envmap.environment_lights(s)
    d0 = -a.direction  # toward the source
    e0 = a.radiance.copy()
    s.environment.rotation_deg = 90.0
    (b,) = envmap.environment_lights(s)
    assert b is a and b.cast_shadow  # the same light object (reuse keys on its uid)
    assert np.allclose(-b.direction, envmap.rotation_y(90.0) @ d0)
    assert np.allclose(b.radiance, e0) and b.angular_radius > 0
    s.environment.intensity = 1.5
    assert np.allclose(envmap.environment_lights(s)[0].radiance, e0 / 2)
    s.environment.map = None
    assert envmap.environment_lights(s) == []


def test_bad_settings_name_the_key():
    with pytest.raises(envmap.EnvironmentMapError, match=r"\[environment\]\.intensity: expected a finite number >= 0"):
        envmap.check_settings("[environment]", 0.0, -1.0)
    with pytest.raises(envmap.EnvironmentMapError, match=r"rotation_deg"):
        envmap.check_settings("[environment]", float("nan"), 1.0)
