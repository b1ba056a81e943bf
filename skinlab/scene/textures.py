"""Textures through OpenImageIO: colour maps decoded from sRGB to linear, data maps kept linear.

Arrays are float32 (H, W, C) with row 0 at the *top* of the image as stored in the file; the
renderer flips rows on upload so that v = 0 (OpenGL, as trimesh gives UVs) is the bottom row.
Colour and alpha are read as stored (unassociated: a glTF colour map's alpha is its opacity).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skinlab.native_stderr import silenced

from .optics.color import srgb_decode
from .paths import absolute, existing_file

_CACHE: dict[tuple[str, float, str], np.ndarray] = {}


def _srgb_to_linear(x: np.ndarray, eight_bit: bool) -> np.ndarray:
    """srgb_decode(x) as float32; an 8-bit image has 256 values, decoded once each through a table
    (the same numbers: the table holds srgb_decode of the very floats the file decoded to)."""
    if eight_bit:
        codes = np.rint(x * 255.0).astype(np.uint8)
        values = np.arange(256, dtype=np.float32) / np.float32(255.0)
        if np.array_equal(values[codes], x):
            return srgb_decode(values).astype(np.float32)[codes]
    return srgb_decode(x).astype(np.float32)


def _first_line(message: str) -> str:
    """OIIO's error text, which may repeat what libpng said in several sentences, cut to its first."""
    text = " ".join(message.split())
    for stop in (" PNG read error", " PNG library error"):
        text = text.split(stop)[0]
    return text or "unknown error"


def load_texture(path: str | Path, colorspace: str = "linear") -> np.ndarray:
    if colorspace not in ("srgb", "linear"):
        raise ValueError(f"texture {path}: colorspace must be 'srgb' or 'linear', got {colorspace!r}")
    path = existing_file(path, "texture file")
    key = (str(absolute(path)), path.stat().st_mtime, colorspace)
    if key in _CACHE:
        return _CACHE[key]
    import OpenImageIO as oiio

    # colour and alpha as stored (a glTF colour map's alpha is opacity, not premultiplied into the colour)
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    with silenced():  # libpng and libjpeg print their complaints on stderr: OIIO's error says it once
        inp = oiio.ImageInput.open(str(path), config)
        if inp is None:
            raise ValueError(f"{path}: cannot read texture: {_first_line(oiio.geterror())}")
        try:
            spec = inp.spec()
            data = inp.read_image(0, 0, 0, spec.nchannels, "float")
            # a truncated or corrupt file may still decode partly (grey rows below the damage): refuse it
            if inp.has_error:
                raise ValueError(
                    f"{path}: cannot decode texture (truncated or corrupt?): {_first_line(inp.geterror())}"
                )
        finally:
            inp.close()
    if data is None:
        raise ValueError(f"{path}: cannot decode texture: {_first_line(oiio.geterror())}")
    img = np.asarray(data, np.float32).reshape(spec.height, spec.width, spec.nchannels)
    if colorspace == "srgb":
        rgb = min(3, img.shape[2])
        img = img.copy()
        img[..., :rgb] = _srgb_to_linear(img[..., :rgb], str(spec.format) == "uint8")
    if not np.isfinite(img).all():
        raise ValueError(f"{path}: texture contains NaN or Inf")
    _CACHE[key] = img
    return img


_MEANS: dict[tuple[str, float, str], np.ndarray] = {}


def texture_mean(path: str | Path, colorspace: str = "linear") -> np.ndarray:
    """The mean of a texture's first three channels (linear values; one channel repeated), cached
    by file and modification time: what a colour map contributes to a material's medium."""
    path = Path(path)
    key = (str(absolute(path)), path.stat().st_mtime, colorspace)
    if key not in _MEANS:
        img = load_texture(path, colorspace)
        rgb = img[..., :3] if img.shape[2] >= 3 else np.repeat(img[..., :1], 3, axis=2)
        _MEANS[key] = rgb.reshape(-1, 3).astype(np.float64).mean(axis=0)
    return _MEANS[key]
