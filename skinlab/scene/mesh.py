"""Triangle meshes: positions, normals, UVs, tangents; tangent generation and UV atlases."""

from __future__ import annotations

import itertools
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from skinlab.cache import cache_dir, content_key, disk_enabled, stored

_UIDS = itertools.count(1)


@dataclass
class Mesh:
    name: str
    positions: np.ndarray  # (N, 3) float32
    indices: np.ndarray  # (M, 3) uint32
    normals: np.ndarray = None  # type: ignore[assignment]  # (N, 3) float32; None: made from the faces
    uvs: np.ndarray | None = None  # (N, 2) float32, OpenGL convention (v up)
    tangents: np.ndarray | None = None  # (N, 4) float32, w = handedness
    source: str = ""
    version: int = 0  # bump when geometry changes (GPU buffers and stretch maps key on it)
    notes: tuple[str, ...] = ()  # what was repaired on the way in (normals recomputed): the loader warns of it
    _bounds: tuple | None = field(default=None, repr=False, metadata={"transient": True})
    # unique for the process (unlike id(), never reused after the mesh is freed): GPU caches key on it
    uid: int = field(default_factory=lambda: next(_UIDS), repr=False, compare=False, metadata={"transient": True})
    colors: np.ndarray | None = field(default=None, repr=False)  # (N, 4) float32 linear RGBA (glTF COLOR_0)

    def __post_init__(self) -> None:
        where = f"mesh {self.name!r}" + (f" ({self.source})" if self.source else "")
        self.positions = _float32_positions(where, self.positions)
        self.indices = np.ascontiguousarray(self.indices, np.uint32).reshape(-1, 3)
        if self.positions.ndim != 2 or self.positions.shape[1] != 3:
            raise ValueError(f"{where}: positions must be (N, 3), got {self.positions.shape}")
        if len(self.indices) == 0:
            raise ValueError(f"{where}: has no triangles")
        if self.indices.max() >= len(self.positions):
            raise ValueError(
                f"{where}: triangle index {self.indices.max()} out of range ({len(self.positions)} vertices)"
            )
        if not np.isfinite(self.positions).all():
            raise ValueError(f"{where}: positions contain NaN or Inf")
        if self.normals is None:
            self.normals = vertex_normals(self.positions, self.indices)
        else:
            self.normals, note = _valid_normals(where, self.normals, self.positions, self.indices)
            if note:
                self.notes = (*self.notes, note)
        self.normals = np.ascontiguousarray(self.normals, np.float32)
        if self.uvs is not None:
            self.uvs = np.ascontiguousarray(self.uvs, np.float32)
        if self.tangents is not None:
            self.tangents = np.ascontiguousarray(self.tangents, np.float32)
        if self.colors is not None:
            c = np.asarray(self.colors, np.float32)
            if c.ndim != 2 or c.shape[0] != len(self.positions) or c.shape[1] not in (3, 4):
                raise ValueError(f"{where}: vertex colours must be (N, 3) or (N, 4) for N vertices, got {c.shape}")
            if c.shape[1] == 3:
                c = np.concatenate([c, np.ones((len(c), 1), np.float32)], axis=1)
            if not np.isfinite(c).all():
                raise ValueError(f"{where}: vertex colours contain NaN or Inf")
            self.colors = np.ascontiguousarray(np.clip(c, 0.0, None))

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        if self._bounds is None:
            self._bounds = (self.positions.min(0).astype(np.float64), self.positions.max(0).astype(np.float64))
        return self._bounds

    def bound_corners(self) -> np.ndarray:
        lo, hi = self.bounds
        return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])

    def ensure_tangents(self) -> np.ndarray:
        if self.tangents is None:
            if self.uvs is None:
                raise ValueError(f"mesh {self.name!r}: tangents need UVs")
            self.tangents = compute_tangents(self.positions, self.normals, self.uvs, self.indices)
        return self.tangents

    def uv_array(self, what: str) -> np.ndarray:
        """The UVs, or ValueError naming the mesh and that `what` needs them."""
        if self.uvs is None:
            raise ValueError(
                f"mesh {self.name!r} ({self.source or 'no file'}) has no UV coordinates, and {what} needs them"
            )
        return self.uvs

    def ensure_uvs(self, reason: str = "a technique needs UVs", generate: bool = True) -> None:
        """Generate a UV atlas with xatlas if the mesh has none (or raise naming the mesh)."""
        if self.uvs is not None:
            return
        if not generate:
            raise ValueError(f"mesh {self.name!r} ({self.source or 'no file'}) has no UV coordinates, and {reason}")
        generate_atlas(self)


def _float32_positions(where: str, positions) -> np.ndarray:
    """Positions as float32, refusing NaN, Inf and coordinates beyond float32 range (1e39 would
    become Inf) with the vertex named, before the cast (no numpy overflow warning on stderr)."""
    p = np.asarray(positions)
    if p.dtype != np.float32 and p.size:
        p64 = np.asarray(p, np.float64)
        bad = ~np.isfinite(p64) | (np.abs(p64) > np.finfo(np.float32).max)
        if bad.any():
            v = int(np.argwhere(bad)[0][0])
            raise ValueError(
                f"{where}: vertex {v} is at {p64[v].tolist()}: positions must be finite and within float32 range"
            )
    return np.ascontiguousarray(p, np.float32)


def _valid_normals(where: str, normals, positions: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, str]:
    """The given vertex normals with those that are zero, NaN, Inf or of the wrong count replaced by
    the triangles' area-weighted normals, and a note saying how many were replaced ("" if none)."""
    n = np.asarray(normals, np.float64)
    if n.shape != positions.shape:
        return vertex_normals(positions, indices), (
            f"{where}: {n.shape[0] if n.ndim else 0} normals for {len(positions)} vertices; "
            "recomputed from the triangles"
        )
    with np.errstate(all="ignore"):
        length = np.linalg.norm(n, axis=1)
    bad = ~np.isfinite(length) | (length < 1e-6)
    if not bad.any():
        return n, ""
    n = n.copy()
    used = np.zeros(len(n), bool)
    used[indices.reshape(-1)] = True
    n[bad & ~used] = 0.0  # a vertex no triangle uses is never drawn: a zero normal (no rays), without a word
    bad &= used
    if not bad.any():
        return n, ""
    n[bad] = vertex_normals(positions, indices)[bad]
    return n, (
        f"{where}: {int(bad.sum())} of {len(n)} vertex normals were zero, NaN or Inf; recomputed from the triangles"
    )


_ATLASED: dict[int, Mesh] = {}


def with_atlas(mesh: Mesh) -> Mesh:
    """``mesh`` if it has UVs, else a copy of it with an xatlas atlas (one per source mesh and
    process). The source is left alone: meshes from skinlab.scene.loaders are shared through its cache."""
    if mesh.uvs is not None:
        return mesh
    if mesh.uid not in _ATLASED:
        copy = Mesh(mesh.name, mesh.positions, mesh.indices, mesh.normals, None, None, mesh.source, colors=mesh.colors)
        generate_atlas(copy)
        _ATLASED[mesh.uid] = copy
    return _ATLASED[mesh.uid]


def vertex_normals(positions: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals; degenerate vertices get +Z rather than NaN."""
    p = positions.astype(np.float64)
    f = indices.astype(np.int64)
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    n = np.zeros_like(p)
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    out = np.where(ln > 0, n / np.where(ln > 0, ln, 1), [0.0, 0.0, 1.0])
    return out.astype(np.float32)


def compute_tangents(positions, normals, uvs, indices) -> np.ndarray:
    """Per-vertex tangents (xyz) and handedness (w) from UV derivatives (Lengyel 2001), with
    Gram-Schmidt against the normal; triangles with degenerate UVs contribute nothing and
    vertices left without a tangent get any unit vector perpendicular to the normal."""
    p = positions.astype(np.float64)
    uv = uvs.astype(np.float64)
    n = normals.astype(np.float64)
    f = indices.astype(np.int64)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    d1, d2 = uv[f[:, 1]] - uv[f[:, 0]], uv[f[:, 2]] - uv[f[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    ok = np.abs(det) > 1e-20
    r = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)[:, None]
    sdir = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    tdir = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    t = np.zeros_like(p)
    b = np.zeros_like(p)
    for k in range(3):
        np.add.at(t, f[:, k], sdir)
        np.add.at(b, f[:, k], tdir)
    t = t - n * np.sum(n * t, axis=1, keepdims=True)
    ln = np.linalg.norm(t, axis=1, keepdims=True)
    # fallback: any perpendicular
    alt = np.cross(n, np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
    alt /= np.maximum(np.linalg.norm(alt, axis=1, keepdims=True), 1e-30)
    t = np.where(ln > 1e-12, t / np.where(ln > 1e-12, ln, 1), alt)
    w = np.where(np.sum(np.cross(n, t) * b, axis=1) < 0.0, -1.0, 1.0)
    return np.concatenate([t, w[:, None]], axis=1).astype(np.float32)


ATLAS_CACHE_VERSION = 2  # bump when the way atlases are made changes


_KEYS: dict[tuple[int, int], str] = {}  # (mesh uid, version) -> mesh_key


def mesh_key(mesh: Mesh) -> str:
    """Content hash of a mesh's arrays (positions, triangles, normals, UVs), computed once per mesh
    version: what per-mesh data cached on disk (skinlab/cache.py: rays, seams, thickness) is keyed by."""
    key = (mesh.uid, mesh.version)
    k = _KEYS.get(key)
    if k is None:
        k = _KEYS[key] = content_key(
            *(np.zeros(0) if a is None else a for a in (mesh.positions, mesh.indices, mesh.normals, mesh.uvs))
        )
        if len(_KEYS) > 512:
            _KEYS.pop(next(iter(_KEYS)))
    return k


def atlas_key(positions: np.ndarray, indices: np.ndarray) -> str:
    """Content hash of a mesh's geometry (the atlas depends on nothing else), with the xatlas version."""
    import xatlas

    return content_key(
        f"atlas-v{ATLAS_CACHE_VERSION}-xatlas-{getattr(xatlas, '__version__', '?')}",
        np.ascontiguousarray(positions, np.float32),
        np.ascontiguousarray(indices, np.uint32),
    )


def generate_atlas(mesh: Mesh, cache: bool = True) -> None:
    """Give ``mesh`` a UV atlas with xatlas (vertices are split along chart seams). Atlases are
    cached by mesh content under the cache directory (skinlab/cache.py; xatlas takes seconds on a
    70k-triangle scan); ``cache=False`` or SKINLAB_CACHE_DIR=off always recomputes."""
    where = f"mesh {mesh.name!r}" + (f" ({Path(mesh.source).name})" if mesh.source else "")

    def parametrize():
        import xatlas

        print(
            f"skinlab: generating a UV atlas for {where}, {len(mesh.indices)} triangles, with xatlas"
            + (f"; cached in {cache_dir() / 'atlas'} for next time" if cache and disk_enabled() else ""),
            file=sys.stderr,
            flush=True,
        )
        return tuple(xatlas.parametrize(mesh.positions, mesh.indices))

    if cache:
        vmapping, idx, uvs = stored(
            "atlas", atlas_key(mesh.positions, mesh.indices), parametrize, f"the atlas of {where}"
        )
    else:
        vmapping, idx, uvs = parametrize()
    mesh.positions = np.ascontiguousarray(mesh.positions[vmapping])
    mesh.normals = np.ascontiguousarray(mesh.normals[vmapping])
    if mesh.colors is not None:
        mesh.colors = np.ascontiguousarray(mesh.colors[vmapping])
    mesh.indices = np.ascontiguousarray(idx, np.uint32)
    mesh.uvs = np.ascontiguousarray(uvs, np.float32)
    mesh.tangents = None
    mesh.version += 1
