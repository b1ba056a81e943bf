"""Small GLB files built with pygltflib for the glTF material tests: quads (two triangles) with UVs,
normals, optional vertex colours, one material each, textures embedded as PNG."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pygltflib
from PIL import Image


def png_bytes(pixels: np.ndarray) -> bytes:
    """(H, W, C) uint8 as PNG bytes (C = 1, 3 or 4)."""
    a = np.asarray(pixels, np.uint8)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[..., 0]
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG")
    return buf.getvalue()


def checker(n: int = 8, cells: int = 2, a=(255, 255, 255), b=(0, 0, 0)) -> np.ndarray:
    y, x = np.mgrid[0:n, 0:n] * cells // n
    mask = ((x + y) % 2 == 0)[..., None]
    return np.where(mask, np.array(a, np.uint8), np.array(b, np.uint8)).astype(np.uint8)


class GlbBuilder:
    """Accumulates buffers, accessors, images and meshes; ``save(path)`` writes one GLB."""

    def __init__(self):
        self.g = pygltflib.GLTF2(scene=0, scenes=[pygltflib.Scene(nodes=[])])
        self.blob = bytearray()
        self.extensions_used: set[str] = set()

    def _view(self, data: bytes, target=None) -> int:
        while len(self.blob) % 4:
            self.blob += b"\0"
        self.g.bufferViews.append(
            pygltflib.BufferView(buffer=0, byteOffset=len(self.blob), byteLength=len(data), target=target)
        )
        self.blob += data
        return len(self.g.bufferViews) - 1

    def _accessor(self, a: np.ndarray, kind: str, target=None, component=pygltflib.FLOAT, normalized=None) -> int:
        view = self._view(a.tobytes(), target)
        acc = pygltflib.Accessor(
            bufferView=view, componentType=component, count=len(a), type=kind, normalized=normalized
        )
        if kind == "VEC3" and component == pygltflib.FLOAT and target == pygltflib.ARRAY_BUFFER:
            acc.min, acc.max = a.min(0).tolist(), a.max(0).tolist()
        self.g.accessors.append(acc)
        return len(self.g.accessors) - 1

    def image(self, pixels: np.ndarray) -> int:
        """An embedded PNG texture; returns the texture index."""
        view = self._view(png_bytes(pixels))
        self.g.images.append(pygltflib.Image(bufferView=view, mimeType="image/png"))
        self.g.textures.append(pygltflib.Texture(source=len(self.g.images) - 1))
        return len(self.g.textures) - 1

    def material(self, **kw) -> int:
        """A pygltflib.Material from keywords (pbr=dict for pbrMetallicRoughness, extensions=dict)."""
        pbr = kw.pop("pbr", None)
        ext = kw.pop("extensions", None)
        m = pygltflib.Material(**kw)
        if pbr is not None:
            m.pbrMetallicRoughness = pygltflib.PbrMetallicRoughness(**pbr)
        if ext:
            m.extensions = ext
            self.extensions_used.update(ext)
        self.g.materials.append(m)
        return len(self.g.materials) - 1

    def quad(
        self,
        name: str,
        material: int | None,
        centre=(0.0, 0.0, 0.0),
        size: float = 2.0,
        colors: np.ndarray | None = None,
        uv_top_left: bool = True,
    ) -> int:
        """A quad facing +Z, UVs in glTF's convention (v = 0 at the image's top); a node of its own."""
        h = size / 2
        c = np.asarray(centre, np.float32)
        pos = (np.array([[-h, -h, 0], [h, -h, 0], [h, h, 0], [-h, h, 0]], np.float32) + c).astype(np.float32)
        nrm = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
        uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
        if not uv_top_left:
            uv[:, 1] = 1 - uv[:, 1]
        idx = np.array([0, 1, 2, 0, 2, 3], np.uint32)
        attrs = pygltflib.Attributes(
            POSITION=self._accessor(pos, "VEC3", pygltflib.ARRAY_BUFFER),
            NORMAL=self._accessor(nrm, "VEC3", pygltflib.ARRAY_BUFFER),
            TEXCOORD_0=self._accessor(uv, "VEC2", pygltflib.ARRAY_BUFFER),
        )
        if colors is not None:
            attrs.COLOR_0 = self._accessor(np.asarray(colors, np.float32), "VEC4", pygltflib.ARRAY_BUFFER)
        prim = pygltflib.Primitive(
            attributes=attrs,
            indices=self._accessor(idx, "SCALAR", pygltflib.ELEMENT_ARRAY_BUFFER, pygltflib.UNSIGNED_INT),
            material=material,
        )
        self.g.meshes.append(pygltflib.Mesh(name=name, primitives=[prim]))
        self.g.nodes.append(pygltflib.Node(name=name, mesh=len(self.g.meshes) - 1))
        self.g.scenes[0].nodes.append(len(self.g.nodes) - 1)
        return len(self.g.nodes) - 1

    def save(self, path: Path) -> Path:
        self.g.buffers = [pygltflib.Buffer(byteLength=len(self.blob))]
        self.g.extensionsUsed = sorted(self.extensions_used)
        self.g.set_binary_blob(bytes(self.blob))
        self.g.save_binary(str(path))
        return Path(path)
