"""Textures through OpenImageIO: colour maps decoded from sRGB to linear, data maps kept linear.

:func:`read_texture` gives the pixels as stored: an 8-bit file's codes as uint8 (the renderer uploads
them as they are, into an sRGB texture for a colour map, so the GPU decodes and filters in linear
light as every real-time engine does), anything else as float32. :func:`load_texture` gives float32
linear values (H, W, C) for the code that computes with them (the truth's export, glTF, a map's mean).
Row 0 is at the *top* of the image as stored in the file; the renderer flips rows on upload so that
v = 0 (OpenGL, as trimesh gives UVs) is the bottom row. Colour and alpha are read as stored
(unassociated: a glTF colour map's alpha is its opacity).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.native_stderr import silenced

from .optics.color import srgb_decode
from .paths import absolute, existing_file


@dataclass(frozen=True)
class StoredTexture:
    """A texture's pixels as the file stores them: (H, W, C) uint8 codes when ``eight_bit``, else
    float32 values (finite: a map with NaN or Inf is refused when read)."""

    pixels: np.ndarray
    eight_bit: bool


_STORED: dict[tuple[str, float], StoredTexture] = {}
_CACHE: dict[tuple[str, float, str], np.ndarray] = {}
# the 256 codes of an 8-bit channel as float32, k * (1/255) as OpenImageIO converts them (so a map
# decodes to the very numbers a float read of the file gives), and their sRGB decode
_CODE_VALUES = np.arange(256, dtype=np.float32) * np.float32(1.0 / 255.0)
_SRGB_CODES = srgb_decode(_CODE_VALUES).astype(np.float32)


def _check_colorspace(path, colorspace: str) -> None:
    if colorspace not in ("srgb", "linear"):
        raise ValueError(f"texture {path}: colorspace must be 'srgb' or 'linear', got {colorspace!r}")


def _first_line(message: str) -> str:
    """OIIO's error text, which may repeat what libpng said in several sentences, cut to its first."""
    text = " ".join(message.split())
    for stop in (" PNG read error", " PNG library error"):
        text = text.split(stop)[0]
    return text or "unknown error"


def read_texture(path: str | Path) -> StoredTexture:
    """The texture's pixels as stored (see :class:`StoredTexture`), decoded once per file and
    modification time. A file that is missing, unreadable, truncated or holds NaN/Inf is refused
    with a one-line error naming it."""
    path = existing_file(path, "texture file")
    key = (str(absolute(path)), path.stat().st_mtime)
    if key in _STORED:
        return _STORED[key]
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
            eight_bit = str(spec.format) == "uint8"
            data = inp.read_image(0, 0, 0, spec.nchannels, "uint8" if eight_bit else "float")
            # a truncated or corrupt file may still decode partly (grey rows below the damage): refuse it
            if inp.has_error:
                raise ValueError(
                    f"{path}: cannot decode texture (truncated or corrupt?): {_first_line(inp.geterror())}"
                )
        finally:
            inp.close()
    if data is None:
        raise ValueError(f"{path}: cannot decode texture: {_first_line(oiio.geterror())}")
    img = np.asarray(data, np.uint8 if eight_bit else np.float32).reshape(spec.height, spec.width, spec.nchannels)
    if not eight_bit and not np.isfinite(img).all():
        raise ValueError(f"{path}: texture contains NaN or Inf")
    stored = _STORED[key] = StoredTexture(img, eight_bit)
    return stored


def load_texture(path: str | Path, colorspace: str = "linear") -> np.ndarray:
    """The texture as float32 linear values (H, W, C): a colour map (``srgb``) decoded from sRGB in
    its first three channels, alpha and data maps (``linear``) as stored; an 8-bit code k is
    k * (1/255) in float32 before decoding."""
    _check_colorspace(path, colorspace)
    stored = read_texture(path)
    key = (str(absolute(Path(path))), Path(path).stat().st_mtime, colorspace)
    if key in _CACHE:
        return _CACHE[key]
    px = stored.pixels
    img = _CODE_VALUES[px] if stored.eight_bit else px.copy()
    if colorspace == "srgb":
        rgb = 3 if img.shape[2] >= 3 else 1  # grey + alpha: the grey is colour, the alpha is not
        if stored.eight_bit:
            img[..., :rgb] = _SRGB_CODES[px[..., :rgb]]
        else:
            img[..., :rgb] = srgb_decode(img[..., :rgb]).astype(np.float32)
    _CACHE[key] = img
    return img


_MEANS: dict[tuple[str, float, str], np.ndarray] = {}


def texture_mean(path: str | Path, colorspace: str = "linear") -> np.ndarray:
    """The mean of a texture's first three channels (linear values; one channel repeated), cached
    by file and modification time: what a colour map contributes to a material's medium."""
    path = Path(path)
    key = (str(absolute(path)), path.stat().st_mtime, colorspace)
    if key not in _MEANS:
        _check_colorspace(path, colorspace)
        stored = read_texture(path)
        channels = [0, 1, 2] if stored.pixels.shape[2] >= 3 else [0, 0, 0]
        if stored.eight_bit:  # a histogram of the codes: no decoded copy of the map
            values = _SRGB_CODES if colorspace == "srgb" else _CODE_VALUES
            counts = [np.bincount(stored.pixels[..., c].ravel(), minlength=256) for c in channels]
            n = stored.pixels.shape[0] * stored.pixels.shape[1]
            _MEANS[key] = np.array([float(values.astype(np.float64) @ k) / n for k in counts])
        else:
            img = load_texture(path, colorspace)
            _MEANS[key] = img[..., channels].reshape(-1, 3).astype(np.float64).mean(axis=0)
    return _MEANS[key]
