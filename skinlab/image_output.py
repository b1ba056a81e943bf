"""Write images atomically: PNG (8-bit sRGB, for people) or EXR (32-bit float linear, for numbers).

EXR is written as full float, not half: half overflows to +Inf above 65504, which a bright light
(intensity 1e6) reaches, and radiance is data that must not be silently changed.

Each file is written to a temporary name beside the target and renamed into place
(skinlab/atomic_write.py), so a crash never leaves a half-written image.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from skinlab.atomic_write import atomic_path, check_writable

FORMATS = {".png": "png", ".exr": "exr"}


def image_format(path: str | Path) -> str:
    ext = Path(path).suffix.lower()
    if ext not in FORMATS:
        raise ValueError(f"{path}: unsupported image extension {ext or '(none)'!r}; expected .png or .exr")
    return FORMATS[ext]


def check_output_path(path: str | Path, option: str = "") -> Path:
    """Fail before any work if ``path`` cannot become an image file: a supported extension, not an
    existing folder, and no regular file where a parent folder must be. ``option`` (e.g. "--out")
    prefixes the message."""
    path = Path(path)
    label = f"{option}: " if option else ""
    try:
        check_writable(path)  # first: a name too long makes even is_dir() raise
    except OSError as exc:
        raise ValueError(f"{label}{path}: {exc.strerror}") from None
    if path.is_dir():
        raise ValueError(f"{label}{path}: is a folder; give a file name such as {path / 'render.png'}")
    try:
        image_format(path)
    except ValueError as exc:
        raise ValueError(f"{label}{exc}") from None
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{label}{path}: {parent} is a file, not a folder")
            if not os.access(parent, os.W_OK):
                raise ValueError(f"{label}{path}: folder {parent} is not writable")
            _probe_folder(parent, path, label)
            break
    return path


def _probe_folder(folder: Path, path: Path, label: str) -> None:
    """A folder that says it is writable but takes no new file (/proc, a read-only mount for root)."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".skinlab-probe.", dir=folder)
    except OSError as exc:
        raise ValueError(f"{label}{path}: cannot create a file in {folder}: {exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(probe)


def write_image(path: str | Path, pixels: np.ndarray) -> Path:
    """uint8 (H, W, C) -> PNG; float (H, W, C) -> 32-bit float EXR. Rows top first."""
    import OpenImageIO as oiio

    path = check_output_path(path)
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
        spec = oiio.ImageSpec(w, h, c, "float")
        spec.attribute("compression", "zip")
    if c == 4:
        spec.channelnames = ("R", "G", "B", "A")
        spec.alpha_channel = 3
    write_pixels(path, pixels, spec)
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


def contact_sheet(tiles: list[tuple[np.ndarray, str]], columns: int = 3, label_px: int = 18) -> np.ndarray:
    """Images (uint8 H x W x C, all the same size) tiled ``columns`` wide on a dark background, each with
    its label in a strip below it; returns opaque uint8 RGBA (the tiles' alpha is dropped)."""
    from PIL import Image, ImageDraw

    h, w = tiles[0][0].shape[:2]
    rows = -(-len(tiles) // columns)
    sheet = Image.new("RGBA", (columns * w, rows * (h + label_px)), (20, 20, 22, 255))
    draw = ImageDraw.Draw(sheet)
    for i, (img, label) in enumerate(tiles):
        if img.shape[:2] != (h, w):
            raise ValueError(f"contact sheet: tile {label!r} is {img.shape[1]}x{img.shape[0]}, expected {w}x{h}")
        x, y = (i % columns) * w, (i // columns) * (h + label_px)
        sheet.paste(Image.fromarray(np.ascontiguousarray(img[..., :3])).convert("RGBA"), (x, y))  # opaque
        draw.text((x + 4, y + h + 3), label, fill=(230, 230, 230, 255))
    return np.asarray(sheet)


def write_pixels(path: Path, pixels: np.ndarray, spec) -> None:
    """`pixels` written with OpenImageIO under `spec` (its format from the file name: PNG, EXR, Radiance
    .hdr), to a temporary name beside `path` and renamed into place; OSError naming `path` on failure."""
    import OpenImageIO as oiio

    with atomic_path(path) as tmp:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise OSError(f"{path}: cannot open for writing: {oiio.geterror().strip()}")
        ok = out.write_image(pixels)
        out.close()
        if not ok:
            raise OSError(f"{path}: write failed: {oiio.geterror().strip()}")
