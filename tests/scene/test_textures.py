"""Texture decoding: 8-bit files kept as codes, decoded through a table to the numbers a float read
of the file gives; the map's mean from a histogram of the codes; bad files refused in one line."""

from __future__ import annotations

import numpy as np
import pytest

from skinlab.scene import textures
from skinlab.scene.optics.color import srgb_decode


def _write(path, pixels, fmt="uint8"):
    import OpenImageIO as oiio

    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, fmt)
    spec.attribute("oiio:UnassociatedAlpha", 1)  # the codes as given: alpha is not premultiplied
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec)
    assert out.write_image(pixels)
    out.close()
    return path


def _float_read(path):
    """The file as OpenImageIO's float conversion gives it (what load_texture decoded before)."""
    import OpenImageIO as oiio

    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(str(path), config)
    spec = inp.spec()
    data = inp.read_image(0, 0, 0, spec.nchannels, "float")
    inp.close()
    return np.asarray(data, np.float32).reshape(spec.height, spec.width, spec.nchannels)


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_an_8_bit_map_decodes_to_the_numbers_a_float_read_gives(tmp_path, channels):
    rng = np.random.default_rng(channels)
    codes = rng.integers(0, 256, (5, 7, channels), dtype=np.uint8)
    codes[0, 0] = 0
    codes[0, 1] = 255
    path = _write(tmp_path / f"m{channels}.png", codes)

    stored = textures.read_texture(path)
    assert stored.eight_bit and stored.pixels.dtype == np.uint8
    np.testing.assert_array_equal(stored.pixels, codes)

    floats = _float_read(path)
    np.testing.assert_array_equal(textures.load_texture(path, "linear"), floats)
    srgb = textures.load_texture(path, "srgb")
    colour = 3 if channels >= 3 else 1  # grey + alpha: the alpha is not colour
    np.testing.assert_array_equal(srgb[..., :colour], srgb_decode(floats[..., :colour]).astype(np.float32))
    np.testing.assert_array_equal(srgb[..., colour:], floats[..., colour:])
    assert srgb.min() == 0.0 and srgb.max() == 1.0

    # the mean from the histogram of codes is the mean of the decoded map
    for space, img in (("srgb", srgb), ("linear", floats)):
        rgb = img[..., :3] if channels >= 3 else np.repeat(img[..., :1], 3, axis=2)
        want = rgb.reshape(-1, 3).astype(np.float64).mean(axis=0)
        np.testing.assert_allclose(textures.texture_mean(path, space), want, rtol=1e-12)


def test_a_float_map_stays_float_and_nan_is_refused(tmp_path):
    values = np.linspace(0.0, 4.0, 2 * 3 * 3, dtype=np.float32).reshape(2, 3, 3)
    path = _write(tmp_path / "m.exr", values, "float")
    stored = textures.read_texture(path)
    assert not stored.eight_bit and stored.pixels.dtype == np.float32
    np.testing.assert_array_equal(textures.load_texture(path, "linear"), values)
    np.testing.assert_allclose(textures.load_texture(path, "srgb"), srgb_decode(values), rtol=1e-6)

    values[1, 1, 1] = np.nan
    bad = _write(tmp_path / "nan.exr", values, "float")
    with pytest.raises(ValueError, match=r"nan\.exr: texture contains NaN or Inf"):
        textures.read_texture(bad)


def test_bad_texture_files_and_colorspaces_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.png"):
        textures.read_texture(tmp_path / "missing.png")
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not a png at all")
    with pytest.raises(ValueError, match=r"junk\.png: cannot read texture"):
        textures.read_texture(junk)
    good = _write(tmp_path / "g.png", np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(ValueError, match="colorspace must be 'srgb' or 'linear'"):
        textures.load_texture(good, "rec709")
