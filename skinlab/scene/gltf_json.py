"""A glTF file's JSON and binary chunk, read with the standard library (the glTF 2.0 specification,
section 4.4 "GLB file format specification": a 12-byte header, then a JSON chunk and an optional BIN
chunk, each 8-byte aligned).

:class:`GltfJson` reads the JSON as attributes, the way skinlab/scene/gltf_materials.py walks it: a
property the file leaves out is None (the reader states each default itself), an object is a
:class:`GltfJson`, an array a list of them, and ``extensions`` and ``extras`` stay plain dicts.
pygltflib does the same and more (it builds dataclasses for every object: 0.3 s to import and 0.15 s
to read the head's file); Skinlab only reads, so this is all a load needs.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

GLB_MAGIC = b"glTF"
CHUNK_JSON, CHUNK_BIN = 0x4E4F534A, 0x004E4942
_RAW = ("extensions", "extras")  # left as the file's dicts
_ARRAYS = ("accessors", "buffers", "bufferViews", "images", "materials", "meshes", "nodes", "textures")


class GltfJson:
    """One glTF JSON object, its properties as attributes (None when absent)."""

    __slots__ = ("_d",)

    def __init__(self, d: dict):
        self._d = d

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return _wrap(self._d.get(name), raw=name in _RAW)

    def __repr__(self) -> str:
        return f"GltfJson({self._d!r})"


def _wrap(value: Any, raw: bool = False) -> Any:
    if raw:
        return value
    if isinstance(value, dict):
        return GltfJson(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


def read_gltf(path: Path) -> tuple[GltfJson, bytes | None]:
    """(the file's JSON, its GLB binary chunk or None). ValueError naming the file when it is not a
    glTF: a GLB with a wrong magic, version, length or chunk layout, or JSON that does not parse to
    an object."""
    data = Path(path).read_bytes()
    blob = None
    if data[:4] == GLB_MAGIC:
        if len(data) < 20:
            raise ValueError("truncated GLB header")
        version, length = struct.unpack_from("<II", data, 4)
        if version != 2:
            raise ValueError(f"GLB version {version}, expected 2")
        if length > len(data):
            raise ValueError(f"GLB says {length} bytes, the file has {len(data)} (truncated?)")
        chunks: dict[int, bytes] = {}
        at = 12
        while at + 8 <= length:
            size, kind = struct.unpack_from("<II", data, at)
            if at + 8 + size > length:
                raise ValueError("a GLB chunk runs past the end of the file (truncated?)")
            chunks.setdefault(kind, data[at + 8 : at + 8 + size])
            at += 8 + size
        if CHUNK_JSON not in chunks:
            raise ValueError("GLB without a JSON chunk")
        text, blob = chunks[CHUNK_JSON], chunks.get(CHUNK_BIN)
    else:
        text = data
    try:
        doc = json.loads(text.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"not glTF JSON ({exc})") from None
    if not isinstance(doc, dict):
        raise ValueError("glTF JSON is not an object")
    for key in _ARRAYS:  # an array the file leaves out is empty (an index into it fails as out of range)
        if doc.get(key) is None:
            doc[key] = []
    return GltfJson(doc), blob
