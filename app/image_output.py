"""Write images atomically: PNG (8-bit sRGB, for people) or EXR (float linear, for numbers).

Each file is written to a temporary name beside the target and renamed into place
(app/atomic_write.py), so a crash never leaves a half-written image.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from app.atomic_write import atomic_path

FORMATS = {".png": "png", ".exr": "exr"}


def image_format(path: str | Path) -> str:
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise ValueError(f"{path}: unsupported image extension {ext or '(none)'!r}; expected .png or .exr")
    return FORMATS[ext]


def write_image(path: str | Path, pixels: np.ndarray) -> Path:
    """uint8 (H, W, C) -> PNG; float32 (H, W, C) -> half-float EXR. Rows top first."""
    import OpenImageIO as oiio

    path = Path(path)
    fmt = image_format(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    pixels = np.ascontiguousarray(pixels)
    h, w, c = pixels.shape
    if fmt == "png":
        if pixels.dtype != np.uint8:
            raise ValueError(f"{path}: PNG needs 8-bit pixels, got {pixels.dtype}")
        spec = oiio.ImageSpec(w, h, c, "uint8")
    else:
        pixels = pixels.astype(np.float32)
        spec = oiio.ImageSpec(w, h, c, "half")
        spec.attribute("compression", "zip")
    if c == 4:
        spec.channelnames = ("R", "G", "B", "A")
        spec.alpha_channel = 3
    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise OSError(f"{path}: cannot open for writing: {oiio.geterror()}")
        ok = out.write_image(pixels)
        out.close()
        if not ok:
            raise OSError(f"{path}: write failed: {oiio.geterror()}")
    return path


def read_image(path: str | Path) -> np.ndarray:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"{path}: cannot read image: {oiio.geterror()}")
    spec = inp.spec()
    data = inp.read_image(
        0, 0, 0, spec.nchannels, "float" if spec.format.basetype in (oiio.HALF, oiio.FLOAT) else "uint8"
    )
    inp.close()
    return np.asarray(data).reshape(spec.height, spec.width, spec.nchannels)
