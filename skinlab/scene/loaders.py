"""Mesh files through trimesh: glTF/GLB (keeping node hierarchy and names, with each primitive's
material and vertex colours: skinlab/scene/gltf_materials.py), OBJ, PLY."""

from __future__ import annotations

import re
import warnings as py_warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.cache import content_key, stored

from .gltf_materials import FileMaterial
from .mesh import Mesh
from .paths import absolute, existing_file

SUPPORTED = (".glb", ".gltf", ".obj", ".ply", ".stl", ".off")


@dataclass
class LoadedNode:
    name: str
    parent: str | None  # None: a root of the file
    matrix: np.ndarray  # local 4x4
    mesh: Mesh | None
    material: FileMaterial | None = None  # the file's own material for the mesh (glTF), if any


_CACHE: dict[tuple[str, float], tuple[list[LoadedNode], list[str]]] = {}

# a node's transform may scale by no more than this, nor by less than its inverse: beyond it float32
# positions and normal matrices overflow or vanish (NaN pixels, a singular matrix)
MAX_SCALE = 1e12


def load_mesh_file(path: str | Path, warnings: list[str] | None = None) -> list[LoadedNode]:
    """Nodes of a mesh file, parents before children. Cached per (path, mtime). What the file holds
    that Skinlab does not read (glTF extensions, a second UV set) is appended to `warnings`."""
    path = existing_file(path, "mesh file")
    if path.suffix.lower() not in SUPPORTED:
        raise ValueError(f"{path}: unsupported mesh format {path.suffix!r}; expected one of {', '.join(SUPPORTED)}")
    key = (str(absolute(path)), path.stat().st_mtime)
    # on disk too, by the file's content: no trimesh import on the next start; in memory and on disk, a load
    # whose extracted textures were deleted since is made again
    if key not in _CACHE or not _files_present(_CACHE[key]):
        _CACHE[key] = stored(
            "meshes",
            content_key(path.suffix.lower(), path.read_bytes()),
            lambda: _load(path),
            str(path),
            code=__name__,
            valid=_files_present,  # textures taken out of the file live apart, under $SKINLAB_CACHE_DIR/gltf
        )
    # fresh Mesh objects per call would re-upload; share them (meshes are data, not mutated by the renderer)
    nodes, found = _CACHE[key]
    if warnings is not None:
        warnings.extend(w for w in found if w not in warnings)
    return nodes


def _files_present(loaded: tuple[list[LoadedNode], list[str]]) -> bool:
    """Whether every file a cached load refers to still exists: the textures its materials name
    (written under $SKINLAB_CACHE_DIR/gltf, which may be deleted apart from the cached meshes)."""
    nodes, _found = loaded
    for n in nodes:
        if n.material is not None:
            for k, v in n.material.values.items():
                if k.endswith("_map") and isinstance(v, str | Path) and not Path(v).is_file():
                    return False
    return True


def clear_cache() -> None:
    """Forget the mesh files loaded in this process (the disk cache stays): the next load is a new
    process's."""
    _CACHE.clear()


_OBJ_FACE = re.compile(rb"^[ \t]*f[ \t]+([^\r\n#]*)", re.M)


def check_obj_indices(path: Path, data: bytes) -> None:
    """OBJ indices start at 1 (negative ones count back from the end); 0 is no vertex, though a
    reader may silently take it as the last one. Raises ValueError naming the line."""
    for m in _OBJ_FACE.finditer(data):
        for corner in m.group(1).split():
            if any(part in (b"0", b"-0", b"+0") for part in corner.split(b"/")):
                line = data.count(b"\n", 0, m.start()) + 1
                raise ValueError(
                    f"{path}: line {line}: face corner {corner.decode(errors='replace')!r} uses index 0 "
                    "(OBJ indices start at 1)"
                )


def _check_node_matrix(path: Path, name: str, matrix: np.ndarray) -> None:
    if not np.isfinite(matrix).all():
        raise ValueError(
            f"{path}: node {name!r}: its transform (translation, rotation, scale or matrix) has NaN or Inf"
        )


def _scale_range(matrix: np.ndarray) -> tuple[float, float]:
    s = np.linalg.svd(np.asarray(matrix, np.float64)[:3, :3], compute_uv=False)
    return float(s.min()), float(s.max())


def transform_problem(matrix: np.ndarray) -> str | None:
    """What is wrong with a 4x4 transform for rendering ("is singular (...)", "scales by 1e+30",
    "moves it by ..."), or None: scale factors in [1/MAX_SCALE, MAX_SCALE], translation up to MAX_SCALE."""
    m = np.asarray(matrix, np.float64)
    if not np.isfinite(m).all():
        return "has NaN or Inf"
    lo, hi = _scale_range(m)
    far = float(np.abs(m[:3, 3]).max())
    if lo < 1.0 / MAX_SCALE:
        return f"is singular (scales by {lo:.3g}: a zero scale?)"
    if hi > MAX_SCALE:
        return f"scales by {hi:.3g}"
    if far > MAX_SCALE:
        return f"moves it by {far:.3g}"
    return None


TRANSFORM_RANGE = f"expected scale factors in [{1 / MAX_SCALE:g}, {MAX_SCALE:g}] and translations up to {MAX_SCALE:g}"


def check_node_scales(path: Path, nodes: list[LoadedNode]) -> None:
    """Every mesh node's world transform (through its parents in the file) passes
    :func:`transform_problem`; otherwise ValueError naming the node whose own transform is at fault
    (a zero scale, a singular matrix, a scale of 1e30)."""
    world: dict[str, np.ndarray] = {}
    parent_of = {ln.name: ln.parent for ln in nodes}
    local = {ln.name: ln.matrix for ln in nodes}
    for ln in nodes:  # parents come first
        world[ln.name] = ln.matrix if ln.parent is None else world[ln.parent] @ ln.matrix
        if ln.mesh is None or transform_problem(world[ln.name]) is None:
            continue
        chain = [ln.name]
        while (up := parent_of[chain[-1]]) is not None:
            chain.append(up)
        culprit = next((n for n in reversed(chain) if transform_problem(local[n])), None)
        what = transform_problem(world[ln.name] if culprit is None else local[culprit])
        raise ValueError(
            f"{path}: node {culprit or ln.name!r}: its {'world ' if culprit is None else ''}transform {what}; "
            + TRANSFORM_RANGE
            + (f" (it holds mesh node {ln.name!r})" if culprit not in (None, ln.name) else "")
        )


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
    normals = np.asarray(tm.vertex_normals)  # float64: zero, NaN or huge ones are replaced by Mesh, named
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
    """The file's nodes and what loading it found to say (the glTF's unread parts, normals Mesh
    recomputed: both cached with the nodes, so a warm start says them again)."""
    import trimesh

    if path.suffix.lower() == ".obj":
        check_obj_indices(path, path.read_bytes())
    try:
        with py_warnings.catch_warnings(), np.errstate(all="ignore"):  # Inf coordinates: we say so, in one line
            py_warnings.simplefilter("ignore")
            loaded = trimesh.load(str(path), process=False, maintain_order=True)
    except Exception as exc:  # trimesh raises many kinds
        raise ValueError(f"{path}: cannot read mesh file: {exc}") from None
    with py_warnings.catch_warnings(), np.errstate(all="ignore"):
        py_warnings.simplefilter("ignore")
        nodes, found = _nodes(path, loaded, trimesh)
    notes = [n for m in {id(ln.mesh): ln.mesh for ln in nodes if ln.mesh is not None}.values() for n in m.notes]
    return nodes, [*found, *(n for n in notes if n not in found)]


def _nodes(path: Path, loaded, trimesh) -> tuple[list[LoadedNode], list[str]]:
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
                matrix, found = graph.get(frame_to=child, frame_from=parent)
                geom_name = None if found is None else str(found)
                _check_node_matrix(path, str(child), np.asarray(matrix))
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
    check_node_scales(path, out)
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
