"""skinlab/scene/gltf_json.py: a glTF's JSON and GLB binary chunk read with the standard library give what
pygltflib reads from the same file; a damaged file is refused with a reason."""

from __future__ import annotations

import struct

import pygltflib
import pytest

from skinlab.resources import assets_root
from skinlab.scene.gltf_json import read_gltf

HEAD = assets_root() / "lee-perry-smith" / "LeePerrySmith.glb"


def test_the_heads_glb_reads_as_pygltflib_reads_it():
    doc, blob = read_gltf(HEAD)
    ref = pygltflib.GLTF2().load(str(HEAD))
    assert blob == ref.binary_blob()
    assert [m.name for m in doc.meshes] == [m.name for m in ref.meshes]
    for mesh, rmesh in zip(doc.meshes, ref.meshes):
        for prim, rprim in zip(mesh.primitives, rmesh.primitives):
            assert prim.attributes.POSITION == rprim.attributes.POSITION
            assert prim.attributes.TEXCOORD_0 == rprim.attributes.TEXCOORD_0
            assert prim.material == rprim.material and (prim.mode or 4) == rprim.mode
    assert [a.count for a in doc.accessors] == [a.count for a in ref.accessors]
    assert [(v.byteOffset or 0, v.byteLength) for v in doc.bufferViews] == [
        (v.byteOffset or 0, v.byteLength) for v in ref.bufferViews
    ]
    assert doc.no_such_property is None  # absent: None, the reader states the default


def test_extensions_and_extras_stay_dicts_and_absent_arrays_are_empty(tmp_path):
    path = tmp_path / "m.gltf"
    path.write_text(
        '{"asset": {"version": "2.0"}, "materials": [{"name": "a", "extensions": {"KHR_x": {"k": 1}},'
        ' "extras": {"skinlab": {"sss_model": "pbd"}}, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]}'
    )
    doc, blob = read_gltf(path)
    m = doc.materials[0]
    assert blob is None and doc.meshes == [] and doc.textures == []
    assert m.extensions == {"KHR_x": {"k": 1}} and m.extras["skinlab"]["sss_model"] == "pbd"
    assert m.pbrMetallicRoughness.baseColorTexture.index == 0 and m.pbrMetallicRoughness.metallicFactor is None


def _glb(json_bytes: bytes, version: int = 2, extra: int = 0) -> bytes:
    json_bytes += b" " * (-len(json_bytes) % 4)
    body = struct.pack("<II", len(json_bytes), 0x4E4F534A) + json_bytes
    return b"glTF" + struct.pack("<II", version, 12 + len(body) + extra) + body


@pytest.mark.parametrize(
    "data, why",
    [
        (_glb(b'{"asset": {}}', version=1), "GLB version 1"),
        (_glb(b'{"asset": {}}', extra=40), "truncated"),
        (_glb(b"{not json"), "not glTF JSON"),
        (b"glTF\x02\x00", "truncated GLB header"),
        (b"[1, 2]", "not an object"),
        (b"\xff\xfe garbage", "not glTF JSON"),
    ],
)
def test_a_damaged_file_says_why(tmp_path, data, why):
    path = tmp_path / "bad.glb"
    path.write_bytes(data)
    with pytest.raises(ValueError, match=why):
        read_gltf(path)
