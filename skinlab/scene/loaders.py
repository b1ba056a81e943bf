"""Mesh files through trimesh: glTF/GLB (keeping node hierarchy and names, with each primitive's
material and vertex colours: skinlab/scene/gltf_materials.py), OBJ, PLY."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.cache import content_key, stored

from .gltf_materials import FileMaterial
from .mesh import Mesh

SUPPORTED = (".glb", ".gltf", ".obj", ".ply", ".stl", ".off")


@dataclass
class LoadedNode:
    name: str
    parent: str | None  # None: a root of the file
    matrix: np.ndarray  # local 4x4
    mesh: Mesh | None
    material: FileMaterial | None = None  # the file's own material for the mesh (glTF), if any


_CACHE: dict[tuple[str, float], tuple[list[LoadedNode], list[str]]] = {}


def load_mesh_file(path: str | Path, warnings: list[str] | None = None) -> list[LoadedNode]:
    """Nodes of a mesh file, parents before children. Cached per (path, mtime). What the file holds
    that Skinlab does not read (glTF extensions, a second UV set) is appended to `warnings`."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    if path.suffix.lower() not in SUPPORTED:
        raise ValueError(f"{path}: unsupported mesh format {path.suffix!r}; expected one of {', '.join(SUPPORTED)}")
    key = (str(path.resolve()), path.stat().st_mtime)
    if key not in _CACHE:  # on disk too, by the file's content: no trimesh import on the next start
        _CACHE[key] = stored(
            "meshes", content_key(path.suffix.lower(), path.read_bytes()), lambda: _load(path), str(path), code=__name__
        )
    # fresh Mesh objects per call would re-upload; share them (meshes are data, not mutated by the renderer)
    nodes, found = _CACHE[key]
    if warnings is not None:
        warnings.extend(w for w in found if w not in warnings)
    return nodes


def _mesh_from_trimesh(name: str, tm, source: str, colors=None) -> Mesh:
    faces = np.asarray(tm.faces)
    n = len(tm.vertices)
    if faces.size and (faces.min() < 0 or faces.max() >= n):
        bad = int(faces.max()) if faces.max() >= n else int(faces.min())
        raise ValueError(
            f"{source}: mesh {name!r}: a face uses vertex {bad}, but there are only {n} vertices (0..{n - 1})"
        )
    uv = None
    vis = getattr(tm, "visual", None)
    if vis is not None and getattr(vis, "uv", None) is not None and len(vis.uv) == len(tm.vertices):
        uv = np.asarray(vis.uv, np.float32)
    normals = np.asarray(tm.vertex_normals, np.float32)
    return Mesh(
        name=name,
        positions=np.asarray(tm.vertices),
        indices=np.asarray(tm.faces),
        normals=normals,
        uvs=uv,
        source=source,
        colors=colors,
    )


def _load(path: Path) -> tuple[list[LoadedNode], list[str]]:
    import trimesh

    try:
        loaded = trimesh.load(str(path), process=False, maintain_order=True)
    except Exception as exc:  # trimesh raises many kinds
        raise ValueError(f"{path}: cannot read mesh file: {exc}") from None
    if isinstance(loaded, trimesh.Trimesh):
        if len(loaded.faces) == 0:
            raise ValueError(f"{path}: contains no triangles")
        return [LoadedNode(path.stem, None, np.eye(4), _mesh_from_trimesh(path.stem, loaded, str(path)))], []
    if not isinstance(loaded, trimesh.Scene):
        raise ValueError(f"{path}: contains no triangle mesh (got {type(loaded).__name__})")
    gltf = _GltfMaterials(path) if path.suffix.lower() in (".glb", ".gltf") else None
    graph = loaded.graph
    base = graph.base_frame
    out: list[LoadedNode] = []
    meshes: dict[str, tuple[Mesh, FileMaterial | None]] = {}
    # breadth-first from the base frame so parents come first
    frontier = [base]
    seen = {base}
    while frontier:
        nxt = []
        for parent in frontier:
            for child in sorted(graph.transforms.children.get(parent, [])):
                if child in seen:
                    continue
                seen.add(child)
                matrix, geom_name = graph.get(frame_to=child, frame_from=parent)
                mesh, material = None, None
                if geom_name is not None and geom_name in loaded.geometry:
                    g = loaded.geometry[geom_name]
                    if isinstance(g, trimesh.Trimesh) and len(g.faces):
                        if geom_name not in meshes:
                            material, colors = gltf.of(geom_name, g) if gltf is not None else (None, None)
                            meshes[geom_name] = (_mesh_from_trimesh(geom_name, g, str(path), colors), material)
                        mesh, material = meshes[geom_name]
                parent_name = None if parent == base else str(parent)
                out.append(LoadedNode(str(child), parent_name, np.asarray(matrix), mesh, material))
                nxt.append(child)
        frontier = nxt
    if not any(n.mesh for n in out):
        raise ValueError(f"{path}: contains no triangle mesh")
    return out, gltf.warnings() if gltf is not None else []


class _GltfMaterials:
    """Each trimesh geometry's glTF material and vertex colours (skinlab/scene/gltf_materials.py)."""

    def __init__(self, path: Path):
        from .gltf_materials import GltfFile

        self.file = GltfFile(path)
        self.names = self.file.primitive_names()
        self.materials: dict[int, FileMaterial] = {}

    def of(self, geom_name: str, tm) -> tuple[FileMaterial | None, np.ndarray | None]:
        from .gltf_materials import vertex_colours

        f = self.file
        where = self.names.get(geom_name)
        if where is None or f.vertex_count(*where) != len(tm.vertices):
            f.warn(f"{f.path.name}: mesh {geom_name!r}: its glTF primitive was not found; default material")
            return None, None
        prim = f.primitive(*where)
        colors = vertex_colours(tm) if prim.attributes.COLOR_0 is not None else None
        if prim.material is None:
            return None, colors
        if prim.material not in self.materials:
            self.materials[prim.material] = f.material(prim.material)
        return self.materials[prim.material], colors

    def warnings(self) -> list[str]:
        self.file.finish()
        return list(self.file.warnings)
